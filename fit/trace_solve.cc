// Steps 3-4 of FitTrace (fit/trace_fit_steps.h): Levenberg-Marquardt with an active set for the
// damping coefficients, and the NLopt refinement of I when that first fit is poor.
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>

#include <ceres/ceres.h>
#include <Eigen/Dense>
#include <nlopt.hpp>

#include "fit/solver_logging.h"
#include "fit/trace_fit_steps.h"

namespace bifilar {
namespace trace {
namespace {

// Ceres adapter: one residual block of N residuals (one per sample) and one parameter block of
// kNumTraceParams; residual and Jacobian as documented in fit/trace_cost.h. Returns false (an
// invalid step for Ceres) when CVODES fails, never an invented number.
class TraceCeresCost : public ceres::CostFunction {
 public:
  TraceCeresCost(const TraceRateCost* cost, SolveBudget* budget) : cost_(cost), budget_(budget) {
    set_num_residuals(cost->num_residuals());
    mutable_parameter_block_sizes()->push_back(kNumTraceParams);
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    if (budget_->Exhausted()) return false;  // Ceres then stops (at the start) or the watch does
    const long before = cost_->integrator_steps();
    const bool ok = cost_->Evaluate(parameters[0], residuals,
                                    jacobians != nullptr ? jacobians[0] : nullptr, nullptr);
    budget_->CountSteps(cost_->integrator_steps() - before);
    return ok;
  }

 private:
  const TraceRateCost* cost_;  // not owned
  SolveBudget* budget_;        // not owned
};

// Counts the iterations of a solve against the fit's budget and aborts the solve when it is
// exhausted. Reads nothing of the solver's state, so it changes no result of a solve it lets run.
class BudgetWatch : public ceres::IterationCallback {
 public:
  explicit BudgetWatch(SolveBudget* budget) : budget_(budget) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    if (summary.iteration > 0) budget_->CountIteration();
    return budget_->Exhausted() ? ceres::SOLVER_ABORT : ceres::SOLVER_CONTINUE;
  }

 private:
  SolveBudget* budget_;
};

double ThreadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Ends the solve when a free damping coefficient lands on its bound (0) after an accepted step:
// Ceres handles bounds by projecting the step, and with the coefficient pinned there
// Levenberg-Marquardt crawls (step ratio ~0.2 for tens of iterations). SolveWithActiveSet then
// holds it at 0 (active set) and solves the smaller problem, which converges in a few iterations.
class BoundWatch : public ceres::IterationCallback {
 public:
  BoundWatch(const double* p, const bool* fixed) : p_(p), fixed_(fixed) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    if (summary.iteration == 0 || !summary.step_is_successful) return ceres::SOLVER_CONTINUE;
    const bool at =
        (!fixed_[0] && p_[kTraceDrag] <= 0.0) || (!fixed_[1] && p_[kTraceViscous] <= 0.0);
    count_ = at ? count_ + 1 : 0;
    if (count_ >= 1) {
      triggered_ = true;
      return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
    }
    return ceres::SOLVER_CONTINUE;
  }
  bool triggered() const { return triggered_; }

 private:
  const double* p_;
  const bool* fixed_;
  int count_ = 0;
  bool triggered_ = false;
};

// Adds the residual to *problem with I > 0 and K_D, C >= 0, the damping coefficients marked in
// fixed[0] (K_D), fixed[1] (C) held constant at their current value.
void AddTraceResidual(const TraceRateCost& cost, const bool fixed[2], double* p,
                      SolveBudget* budget, ceres::Problem* problem) {
  problem->AddResidualBlock(new TraceCeresCost(&cost, budget), nullptr, p);
  std::vector<int> constant;
  if (fixed[0]) constant.push_back(kTraceDrag);
  if (fixed[1]) constant.push_back(kTraceViscous);
  if (!constant.empty())
    problem->SetManifold(p, new ceres::SubsetManifold(kNumTraceParams, constant));
  problem->SetParameterLowerBound(p, kTraceInertia, 1e-3);
  if (!fixed[0]) problem->SetParameterLowerBound(p, kTraceDrag, 0.0);
  if (!fixed[1]) problem->SetParameterLowerBound(p, kTraceViscous, 0.0);
}

// Levenberg-Marquardt with an active set for K_D, C >= 0: a coefficient that settles on 0 is
// held there and the rest re-solved; a held coefficient is released (and the problem re-solved
// with bounds) when the KKT condition fails, i.e. when freeing it would lower the cost by more
// than 0.05 sigma^2 (quadratic model with the other parameters re-optimised:
// g_j^2 (H^-1)_jj / 2, g = J^T r, H = J^T J). fixed[] returns the final active set.
SolveOutcome SolveWithActiveSet(const TraceRateCost& cost, int max_iterations, double* p,
                                bool fixed[2], SolveBudget* budget) {
  fixed[0] = fixed[1] = false;
  SolveOutcome lm;
  int iterations = 0;
  double initial_cost = 0.0;
  const int n = cost.num_residuals();
  for (int round = 0; round < 4; ++round) {
    lm = SolveLm(cost, max_iterations, fixed, round < 3, p, budget);
    if (round == 0) initial_cost = lm.initial_cost;
    iterations += lm.iterations;
    if (!lm.ok) break;
    if (lm.stopped_at_bound) {
      if (!fixed[0] && p[kTraceDrag] <= 0.0) fixed[0] = true, p[kTraceDrag] = 0.0;
      if (!fixed[1] && p[kTraceViscous] <= 0.0) fixed[1] = true, p[kTraceViscous] = 0.0;
      continue;
    }
    if (!fixed[0] && !fixed[1]) break;
    Eigen::Matrix<double, Eigen::Dynamic, kNumTraceParams, Eigen::RowMajor> jac(n, kNumTraceParams);
    Eigen::VectorXd r(n);
    if (!cost.Evaluate(p, r.data(), jac.data(), nullptr)) break;
    const Eigen::VectorXd g = jac.transpose() * r;
    const Eigen::MatrixXd h = jac.transpose() * jac;
    const Eigen::MatrixXd h_inv = h.completeOrthogonalDecomposition().pseudoInverse();
    const double sigma2 = r.squaredNorm() / std::max(1, n - kNumTraceParams);
    bool release = false;
    const int index[2] = {kTraceDrag, kTraceViscous};
    for (int i = 0; i < 2; ++i) {
      const int j = index[i];
      if (fixed[i] && g(j) < 0.0 && 0.5 * g(j) * g(j) * h_inv(j, j) > 0.05 * sigma2) {
        fixed[i] = false;
        release = true;
      }
    }
    if (!release) break;
  }
  lm.iterations = iterations;
  lm.initial_cost = initial_cost;
  return lm;
}

}  // namespace

SolveBudget::SolveBudget(const TraceFitOptions& options)
    : options_(options), start_cpu_s_(ThreadCpuSeconds()) {}

double SolveBudget::cpu_seconds() const { return ThreadCpuSeconds() - start_cpu_s_; }

bool SolveBudget::Exhausted() {
  if (stop_ != Stop::kNone) return true;
  if (options_.interrupt != nullptr && options_.interrupt->load()) {
    stop_ = Stop::kInterrupted;
  } else if (iterations_ >= options_.max_total_iterations) {
    stop_ = Stop::kIterations;
  } else if (integrator_steps_ >= options_.max_integrator_steps) {
    stop_ = Stop::kSteps;
  } else if (cpu_seconds() > options_.time_guard_cpu_seconds) {
    stop_ = Stop::kTimeGuard;
  }
  return stop_ != Stop::kNone;
}

std::string SolveBudget::Message() const {
  char text[480];
  const double cpu = cpu_seconds();
  switch (stop_) {
    case Stop::kInterrupted:
      std::snprintf(text, sizeof(text), "interrupted after %d iterations and %.1f s", iterations_,
                    cpu);
      break;
    case Stop::kIterations:
    case Stop::kSteps: {
      const std::string iterations = std::to_string(options_.max_total_iterations) + " iterations";
      const std::string steps = std::to_string(options_.max_integrator_steps) + " integrator steps";
      const bool by_steps = stop_ == Stop::kSteps;
      std::snprintf(text, sizeof(text),
                    "the solver was stopped after %d iterations and %ld integrator steps (bound "
                    "reached: %s per fit; the other: %s), before the fit settled; set a window "
                    "on the free oscillation (fit.windows or --window)",
                    iterations_, integrator_steps_, (by_steps ? steps : iterations).c_str(),
                    (by_steps ? iterations : steps).c_str());
      break;
    }
    case Stop::kTimeGuard:
      std::snprintf(text, sizeof(text),
                    "abandoned by the time guard after %.1f s of CPU time (guard: %g s per fit; "
                    "%d iterations and %ld integrator steps done), far beyond any real fit; "
                    "this outcome depends on the machine's speed, so it is an error, not a "
                    "judgement of the log, and it is not cached; set a window on the free "
                    "oscillation (fit.windows or --window)",
                    cpu, options_.time_guard_cpu_seconds, iterations_, integrator_steps_);
      break;
    case Stop::kNone:
      return "";
  }
  return text;
}

double Cost(const TraceRateCost& cost, const double* p, std::vector<double>* r) {
  if (!cost.Evaluate(p, r->data(), nullptr, nullptr)) return HUGE_VAL;
  double s = 0.0;
  for (double v : *r) s += v * v;
  return 0.5 * s;
}

SolveOutcome SolveLm(const TraceRateCost& cost, int max_iterations, const bool fixed[2],
                     bool stop_at_bound, double* p, SolveBudget* budget) {
  if (budget->Exhausted()) {
    SolveOutcome out;
    out.message = budget->Message();
    return out;
  }
  QuietSolverLogging();  // also from the Python module and tests, not only the command line
  ceres::Problem problem;
  AddTraceResidual(cost, fixed, p, budget, &problem);
  ceres::Solver::Options options;
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.linear_solver_type =
      ceres::DENSE_NORMAL_CHOLESKY;  // 6x6 normal equations: N x 6 QR costs more
  options.max_num_iterations = max_iterations;
  // Stop inside the noise: a relative cost change of 1e-7 is N * 1e-7 = 6e-4 units of chi^2 at
  // N = 6000 samples (a parameter 0.025 sigma from the optimum), and 1e-9 relative steps are far
  // below sigma (~1e-5 of I). Tighter is pointless: at the default integrator tolerance the cost
  // itself carries ~2e-8 relative integration noise, and LM then takes steps of ratio ~1e-3.
  options.function_tolerance = 1e-7;
  options.parameter_tolerance = 1e-9;
  options.gradient_tolerance = 1e-14;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  BoundWatch watch(p, fixed);
  if (stop_at_bound) {
    options.update_state_every_iteration = true;
    options.callbacks.push_back(&watch);
  }
  BudgetWatch budget_watch(budget);
  options.callbacks.push_back(&budget_watch);
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  SolveOutcome out;
  out.iterations = static_cast<int>(summary.iterations.size()) - 1;
  out.initial_cost = summary.initial_cost;
  out.final_cost = summary.final_cost;
  out.stopped_at_bound = watch.triggered();
  out.converged = summary.termination_type == ceres::CONVERGENCE;
  out.ok = summary.IsSolutionUsable() && std::isfinite(summary.final_cost);
  out.message = budget->stop() != SolveBudget::Stop::kNone ? budget->Message() : summary.message;
  return out;
}

Params StartFromGuess(const TraceInitialGuess& guess) {
  const double scale = guess.params.inertia_kg_m2;
  Params p;
  p[kTraceInertia] = 1.0;
  p[kTraceDrag] = guess.params.drag_coeff_kg_m2 / scale;
  p[kTraceViscous] = guess.params.viscous_coeff_kg_m2_per_s / scale;
  p[kTraceAngle0] = guess.angle0_rad;
  p[kTraceRate0] = guess.rate0_rad_per_s;
  p[kTraceBias] = guess.bias_rad_per_s;
  return p;
}

Minimum MinimizeLm(const TraceRateCost& cost, const Params& start, int max_iterations,
                   SolveBudget* budget) {
  Minimum m;
  m.p = start;
  m.lm = SolveWithActiveSet(cost, max_iterations, m.p.data(), m.fixed, budget);
  if (!m.lm.ok && !budget->Exhausted()) {
    // One retry from the guess with K_D, C started at zero.
    m.p = start;
    m.p[kTraceDrag] = 0.0;
    m.p[kTraceViscous] = 0.0;
    m.lm = SolveWithActiveSet(cost, max_iterations, m.p.data(), m.fixed, budget);
  }
  if (!m.lm.ok) return m;
  m.initial_cost = m.lm.initial_cost;
  m.iterations = m.lm.iterations;
  m.residuals.resize(cost.num_residuals());
  m.final_cost = Cost(cost, m.p.data(), &m.residuals);
  return m;
}

bool NeedsRefinement(const Minimum& minimum, double noise_rad_per_s,
                     const TraceFitOptions& options) {
  return options.use_nlopt_refine && noise_rad_per_s > 0.0 &&
         RmsOfCost(minimum.final_cost, minimum.residuals.size()) >
             options.refine_rms_over_noise * noise_rad_per_s;
}

void RefineInertia(const TraceRateCost& cost, const Params& start, int max_iterations,
                   Minimum* minimum, SolveBudget* budget) {
  const size_t n = minimum->residuals.size();
  minimum->nlopt_refined = true;
  // Cost along I alone with the other parameters at the guess: a sum of squares whose global
  // minimum over a +-10 % bracket is near the true I; local minima are phase wraps.
  Params q = start;
  std::vector<double> rr(n);
  nlopt::opt global(nlopt::GN_DIRECT_L, 1);
  auto objective = [&](double inertia_scaled) {
    if (budget->Exhausted()) {
      global.force_stop();  // optimize() then throws nlopt::forced_stop, caught below
      return 1e300;
    }
    q[kTraceInertia] = inertia_scaled;
    const long before = cost.integrator_steps();
    const double c = Cost(cost, q.data(), &rr);
    budget->CountSteps(cost.integrator_steps() - before);
    return std::isfinite(c) ? c : 1e300;
  };
  global.set_lower_bounds(std::vector<double>{0.9});
  global.set_upper_bounds(std::vector<double>{1.1});
  global.set_maxeval(120);
  using Objective = decltype(objective);
  global.set_min_objective([](unsigned, const double* x, double*,
                              void* data) { return (*static_cast<Objective*>(data))(x[0]); },
                           &objective);
  std::vector<double> x{1.0};
  double best = 0.0;
  try {
    global.optimize(x, best);
  } catch (const std::exception&) {
    // keep x as left by NLopt (its best point so far)
  }
  Params p2 = start;
  p2[kTraceInertia] = x[0];
  bool fixed2[2];
  const SolveOutcome lm2 = SolveWithActiveSet(cost, max_iterations, p2.data(), fixed2, budget);
  std::vector<double> r2(n);
  const double cost2 = lm2.ok ? Cost(cost, p2.data(), &r2) : HUGE_VAL;
  if (cost2 < minimum->final_cost) {
    minimum->p = p2;
    minimum->lm = lm2;
    minimum->final_cost = cost2;
    minimum->fixed[0] = fixed2[0];
    minimum->fixed[1] = fixed2[1];
    minimum->residuals.swap(r2);
    minimum->iterations += lm2.iterations;
  }
  Cost(cost, minimum->p.data(),
       &minimum->residuals);  // leave the cache (trajectory, Jacobian) at the chosen point
}

}  // namespace trace
}  // namespace bifilar
