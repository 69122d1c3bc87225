#include "fit/trace_fit.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include <ceres/ceres.h>
#include <nlopt.hpp>
#include <Eigen/Dense>

#include "fit/trace_cost.h"
#include "fit/trace_guess.h"

namespace bifilar {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegPerRad = 180.0 / kPi;

// Ceres adapter: one residual block of N residuals (one per sample) and one parameter block of
// kNumTraceParams; residual and Jacobian as documented in fit/trace_cost.h. Returns false (an
// invalid step for Ceres) when CVODES fails, never an invented number.
class TraceCeresCost : public ceres::CostFunction {
 public:
  explicit TraceCeresCost(const TraceRateCost* cost) : cost_(cost) {
    set_num_residuals(cost->num_residuals());
    mutable_parameter_block_sizes()->push_back(kNumTraceParams);
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    return cost_->Evaluate(parameters[0], residuals,
                           jacobians != nullptr ? jacobians[0] : nullptr, nullptr);
  }

 private:
  const TraceRateCost* cost_;  // not owned
};

struct SolveOutcome {
  bool ok = false;
  std::string message;
  int iterations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  bool converged = false;
  bool stopped_at_bound = false;  // a free damping coefficient reached 0
};

// Ends the solve when a free damping coefficient lands on its bound (0) after an accepted step:
// Ceres handles bounds by projecting the step, and with the coefficient pinned there
// Levenberg-Marquardt crawls (step ratio ~0.2 for tens of iterations). FitTrace then holds it
// at 0 (active set) and solves the smaller problem, which converges in a few iterations.
class BoundWatch : public ceres::IterationCallback {
 public:
  BoundWatch(const double* p, const bool* fixed) : p_(p), fixed_(fixed) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    if (summary.iteration == 0 || !summary.step_is_successful) return ceres::SOLVER_CONTINUE;
    const bool at = (!fixed_[0] && p_[kTraceDrag] <= 0.0) ||
                    (!fixed_[1] && p_[kTraceViscous] <= 0.0);
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
                      ceres::Problem* problem) {
  problem->AddResidualBlock(new TraceCeresCost(&cost), nullptr, p);
  std::vector<int> constant;
  if (fixed[0]) constant.push_back(kTraceDrag);
  if (fixed[1]) constant.push_back(kTraceViscous);
  if (!constant.empty())
    problem->SetManifold(p, new ceres::SubsetManifold(kNumTraceParams, constant));
  problem->SetParameterLowerBound(p, kTraceInertia, 1e-3);
  if (!fixed[0]) problem->SetParameterLowerBound(p, kTraceDrag, 0.0);
  if (!fixed[1]) problem->SetParameterLowerBound(p, kTraceViscous, 0.0);
}

// Levenberg-Marquardt on p (in place).
SolveOutcome SolveLm(const TraceRateCost& cost, int max_iterations, const bool fixed[2],
                     bool stop_at_bound, double* p) {
  ceres::Problem problem;
  AddTraceResidual(cost, fixed, p, &problem);
  ceres::Solver::Options options;
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;  // 6x6 normal equations: N x 6 QR costs more
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
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  SolveOutcome out;
  out.iterations = static_cast<int>(summary.iterations.size()) - 1;
  out.initial_cost = summary.initial_cost;
  out.final_cost = summary.final_cost;
  out.stopped_at_bound = watch.triggered();
  out.converged = summary.termination_type == ceres::CONVERGENCE;
  out.ok = summary.IsSolutionUsable() && std::isfinite(summary.final_cost);
  out.message = summary.message;
  return out;
}

// Levenberg-Marquardt with an active set for K_D, C >= 0: a coefficient that settles on 0 is
// held there and the rest re-solved; a held coefficient is released (and the problem re-solved
// with bounds) when the KKT condition fails, i.e. when freeing it would lower the cost by more
// than 0.05 sigma^2 (quadratic model with the other parameters re-optimised:
// g_j^2 (H^-1)_jj / 2, g = J^T r, H = J^T J). fixed[] returns the final active set.
SolveOutcome SolveWithActiveSet(const TraceRateCost& cost, int max_iterations, double* p,
                                bool fixed[2]) {
  fixed[0] = fixed[1] = false;
  SolveOutcome lm;
  int iterations = 0;
  double initial_cost = 0.0;
  const int n = cost.num_residuals();
  for (int round = 0; round < 4; ++round) {
    lm = SolveLm(cost, max_iterations, fixed, round < 3, p);
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

double Cost(const TraceRateCost& cost, const double* p, std::vector<double>* r) {
  if (!cost.Evaluate(p, r->data(), nullptr, nullptr)) return HUGE_VAL;
  double s = 0.0;
  for (double v : *r) s += v * v;
  return 0.5 * s;
}

// Autocorrelation of the residuals at lags 1..h (sample index lags).
std::vector<double> Autocorrelation(const std::vector<double>& r, int h) {
  const size_t n = r.size();
  double mean = 0.0;
  for (double v : r) mean += v;
  mean /= n;
  double c0 = 0.0;
  for (double v : r) c0 += (v - mean) * (v - mean);
  std::vector<double> rho(h, 0.0);
  if (!(c0 > 0.0)) return rho;
  for (int k = 1; k <= h && static_cast<size_t>(k) < n; ++k) {
    double ck = 0.0;
    for (size_t i = k; i < n; ++i) ck += (r[i] - mean) * (r[i - k] - mean);
    rho[k - 1] = ck / c0;
  }
  return rho;
}

TraceFitResult Error(TraceFitResult result, const std::string& message) {
  result.status = TraceFitStatus::kError;
  result.message = message;
  return result;
}

std::string Fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), format, v);
  return buf;
}

}  // namespace

const char* ToString(TraceFitStatus status) {
  switch (status) {
    case TraceFitStatus::kOk:
      return "ok";
    case TraceFitStatus::kRejected:
      return "rejected";
    case TraceFitStatus::kError:
      return "error";
  }
  return "error";
}

bool TraceFitOptions::Check(std::string* why) const {
  auto fail = [why](const std::string& m) {
    if (why != nullptr) *why = m;
    return false;
  };
  std::string integ_why;
  if (!integrator.Check(&integ_why)) return fail("integrator: " + integ_why);
  if (max_iterations <= 0) return fail("max_iterations must be > 0");
  if (!(max_rms_over_noise > 1.0)) return fail("max_rms_over_noise must be > 1");
  if (!(max_residual_autocorr > 0.0 && max_residual_autocorr < 1.0))
    return fail("max_residual_autocorr must be in (0, 1)");
  if (whiteness_lags < 1) return fail("whiteness_lags must be >= 1");
  if (!(max_secondary_motion_ratio >= 0.0)) return fail("max_secondary_motion_ratio must be >= 0");
  if (!(min_amplitude_deg >= 0.0)) return fail("min_amplitude_deg must be >= 0");
  if (!(max_amplitude_deg > min_amplitude_deg && max_amplitude_deg <= 90.0))
    return fail("max_amplitude_deg must be in (min_amplitude_deg, 90]");
  if (!(min_periods >= 2.0)) return fail("min_periods must be >= 2");
  if (!(refine_rms_over_noise > 1.0)) return fail("refine_rms_over_noise must be > 1");
  for (double std_input : {filar_length_std_m, filar_separation_std_m, mass_std_kg,
                           gravity_std_mps2, gyro_scale_std}) {
    if (!(std_input >= 0.0) || !std::isfinite(std_input))
      return fail("budget uncertainties (geometry, gyro scale) must be finite and >= 0");
  }
  return true;
}

std::string TraceFitResult::BriefReport() const {
  std::ostringstream s;
  s << ToString(status) << " [" << ToString(model) << "]";
  if (status != TraceFitStatus::kError && params.inertia_kg_m2 > 0.0) {
    s << " I = " << Fmt("%.6f", params.inertia_kg_m2) << " +- "
      << Fmt("%.2g", inertia_std_kg_m2) << " kg m^2"
      << " (stat " << Fmt("%.2g", inertia_stat_std_kg_m2) << ")"
      << ", K_D = " << Fmt("%.3g", params.drag_coeff_kg_m2)
      << ", C = " << Fmt("%.3g", params.viscous_coeff_kg_m2_per_s)
      << ", amplitude " << Fmt("%.1f", amplitude_start_deg) << "->"
      << Fmt("%.1f", amplitude_end_deg) << " deg"
      << ", rms/noise " << Fmt("%.2f", rms_over_noise)
      << ", rho1 " << Fmt("%.2f", residual_autocorr_lag1) << ", " << iterations << " it"
      << ", " << Fmt("%.1f", fit_seconds * 1e3) << " ms";
  }
  if (!message.empty()) s << ": " << message;
  return s.str();
}

TraceFitResult FitTrace(const TraceFitInput& input, const TraceFitOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  TraceFitResult result;
  result.model = options.model;
  const std::string prefix = input.label.empty() ? "" : input.label + ": ";
  auto finish = [&](TraceFitResult r) {
    r.fit_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!r.message.empty() && r.message.compare(0, prefix.size(), prefix) != 0)
      r.message = prefix + r.message;
    return r;
  };

  // --- Validate -----------------------------------------------------------------------------
  std::string why;
  if (!options.Check(&why)) return finish(Error(result, "invalid fit options: " + why));
  if (!input.geometry.Check(&why)) return finish(Error(result, "invalid rig geometry: " + why));
  const size_t n = input.t_s.size();
  if (input.rate_rad_per_s.size() != n)
    return finish(Error(result, "time and rate series differ in length"));
  if (n == 0) return finish(Error(result, "empty window: no samples"));
  for (size_t k = 0; k < n; ++k) {
    if (!std::isfinite(input.t_s[k]) || !std::isfinite(input.rate_rad_per_s[k])) {
      std::ostringstream s;
      s << "non-finite value (NaN or inf) at sample " << k;
      return finish(Error(result, s.str()));
    }
    if (k > 0 && !(input.t_s[k] > input.t_s[k - 1])) {
      std::ostringstream s;
      s << "timestamps not strictly increasing at sample " << k << " (t = " << input.t_s[k]
        << " s)";
      return finish(Error(result, s.str()));
    }
  }
  if (!std::isfinite(input.noise_rad_per_s) || !std::isfinite(input.secondary_motion_ratio))
    return finish(Error(result, "non-finite noise or secondary motion ratio"));

  // --- Initial guess ------------------------------------------------------------------------
  TraceInitialGuess guess;
  if (!EstimateTraceGuess(input, options.model, options.integrator, options.min_periods, &guess,
                          &why)) {
    result.status = TraceFitStatus::kRejected;
    result.message = why;
    result.flags.push_back("no_usable_oscillation");
    result.guess = guess;
    return finish(result);
  }
  result.guess = guess;
  result.period_s = guess.period_s;
  result.num_samples = static_cast<int>(n);
  result.noise_from_input = input.noise_rad_per_s > 0.0;
  result.noise_rad_per_s =
      result.noise_from_input ? input.noise_rad_per_s : guess.data_noise_rad_per_s;

  // --- Levenberg-Marquardt --------------------------------------------------------------------
  const double scale = guess.params.inertia_kg_m2;
  TraceRateCost cost(&input.t_s, &input.rate_rad_per_s, options.model, input.geometry,
                     options.integrator, scale);
  double p[kNumTraceParams];
  p[kTraceInertia] = 1.0;
  p[kTraceDrag] = guess.params.drag_coeff_kg_m2 / scale;
  p[kTraceViscous] = guess.params.viscous_coeff_kg_m2_per_s / scale;
  p[kTraceAngle0] = guess.angle0_rad;
  p[kTraceRate0] = guess.rate0_rad_per_s;
  p[kTraceBias] = guess.bias_rad_per_s;
  const double p_guess[kNumTraceParams] = {p[0], p[1], p[2], p[3], p[4], p[5]};

  bool fixed[2] = {false, false};
  SolveOutcome lm = SolveWithActiveSet(cost, options.max_iterations, p, fixed);
  if (!lm.ok) {
    // One retry from the guess with K_D, C started at zero (a bad damping guess can make the
    // first integration fail).
    std::copy(p_guess, p_guess + kNumTraceParams, p);
    p[kTraceDrag] = 0.0;
    p[kTraceViscous] = 0.0;
    lm = SolveWithActiveSet(cost, options.max_iterations, p, fixed);
  }
  if (!lm.ok) return finish(Error(result, "fit failed: " + lm.message));
  result.initial_cost = lm.initial_cost;
  result.iterations = lm.iterations;

  std::vector<double> r(n);
  double final_cost = Cost(cost, p, &r);
  auto rms_of = [n](double c) { return std::sqrt(2.0 * c / n); };
  const double noise = result.noise_rad_per_s;

  // --- NLopt 1-D refinement of I when the first fit is poor -----------------------------------
  if (options.use_nlopt_refine && noise > 0.0 &&
      rms_of(final_cost) > options.refine_rms_over_noise * noise) {
    result.nlopt_refined = true;
    // Cost along I alone with the other parameters at the guess: a sum of squares whose global
    // minimum over a +-10 % bracket is near the true I; local minima are phase wraps.
    double q[kNumTraceParams];
    std::copy(p_guess, p_guess + kNumTraceParams, q);
    std::vector<double> rr(n);
    auto objective = [&](double inertia_scaled) {
      q[kTraceInertia] = inertia_scaled;
      const double c = Cost(cost, q, &rr);
      return std::isfinite(c) ? c : 1e300;
    };
    nlopt::opt global(nlopt::GN_DIRECT_L, 1);
    global.set_lower_bounds(std::vector<double>{0.9});
    global.set_upper_bounds(std::vector<double>{1.1});
    global.set_maxeval(120);
    using Objective = decltype(objective);
    global.set_min_objective(
        [](unsigned, const double* x, double*, void* data) {
          return (*static_cast<Objective*>(data))(x[0]);
        },
        &objective);
    std::vector<double> x{1.0};
    double best = 0.0;
    try {
      global.optimize(x, best);
    } catch (const std::exception&) {
      // keep x as left by NLopt (its best point so far)
    }
    double p2[kNumTraceParams];
    std::copy(p_guess, p_guess + kNumTraceParams, p2);
    p2[kTraceInertia] = x[0];
    bool fixed2[2];
    const SolveOutcome lm2 = SolveWithActiveSet(cost, options.max_iterations, p2, fixed2);
    std::vector<double> r2(n);
    const double cost2 = lm2.ok ? Cost(cost, p2, &r2) : HUGE_VAL;
    if (cost2 < final_cost) {
      std::copy(p2, p2 + kNumTraceParams, p);
      lm = lm2;
      final_cost = cost2;
      fixed[0] = fixed2[0];
      fixed[1] = fixed2[1];
      r.swap(r2);
      result.iterations += lm2.iterations;
    }
    Cost(cost, p, &r);  // leave the cache (trajectory, Jacobian) at the chosen point
  }
  result.final_cost = final_cost;

  // --- Solution -------------------------------------------------------------------------------
  result.params = TraceRateCost::Unscale(p, scale);
  result.angle0_rad = p[kTraceAngle0];
  result.rate0_rad_per_s = p[kTraceRate0];
  result.bias_rad_per_s = p[kTraceBias];
  result.residual_rms_rad_per_s = rms_of(final_cost);
  result.rms_over_noise = noise > 0.0 ? result.residual_rms_rad_per_s / noise : 0.0;
  const Trajectory traj = cost.last_trajectory();

  // --- Statistical uncertainty: Ceres covariance scaled by the residual variance ---------------
  const double dof = static_cast<double>(n) - kNumTraceParams;
  const double sigma2 = dof > 0 ? 2.0 * final_cost / dof : 0.0;
  {
    ceres::Covariance::Options cov_options;
    cov_options.algorithm_type = ceres::DENSE_SVD;
    cov_options.num_threads = 1;
    ceres::Covariance covariance(cov_options);
    std::vector<std::pair<const double*, const double*>> blocks = {{p, p}};
    double cov[kNumTraceParams * kNumTraceParams];
    ceres::Problem cov_problem;  // the same residual, at the chosen solution
    AddTraceResidual(cost, fixed, p, &cov_problem);
    if (covariance.Compute(blocks, &cov_problem) && covariance.GetCovarianceBlock(p, p, cov)) {
      auto stdev = [&](int j) { return scale * std::sqrt(std::max(0.0, cov[j * 7]) * sigma2); };
      result.inertia_stat_std_kg_m2 = stdev(kTraceInertia);
      result.drag_coeff_std = stdev(kTraceDrag);
      result.viscous_coeff_std = stdev(kTraceViscous);
    } else {
      result.flags.push_back("covariance_failed");
    }
  }

  // --- Uncertainty budget: implicit-function derivative dI/dq -------------------------------
  // At the minimum J^T r = 0; moving an input q moves the solution by
  //   dp/dq = -(J^T J)^{-1} J^T dr/dq   (Gauss-Newton; the r * Hessian term is noise-sized),
  // with dr/dq = d psi'/dq by a central difference (relative step 1e-4; CVODES at 1e-10 keeps
  // the difference error near 1e-6 of the derivative). Outside the hot path: 2 integrations
  // without sensitivities per input.
  struct Input {
    const char* name;
    double std_input;
    double RigGeometry::*field;
  };
  const Input budget_inputs[] = {
      {"filar_length", options.filar_length_std_m, &RigGeometry::filar_length_m},
      {"filar_separation", options.filar_separation_std_m, &RigGeometry::filar_separation_m},
      {"mass", options.mass_std_kg, &RigGeometry::mass_kg},
      {"gravity", options.gravity_std_mps2, &RigGeometry::gravity_mps2}};
  bool any_budget = false;
  for (const Input& in : budget_inputs) any_budget = any_budget || in.std_input > 0.0;
  any_budget = any_budget || options.gyro_scale_std > 0.0;
  if (any_budget) {
    Eigen::Matrix<double, Eigen::Dynamic, kNumTraceParams, Eigen::RowMajor> jac(n, kNumTraceParams);
    std::vector<double> rtmp(n);
    if (cost.Evaluate(p, rtmp.data(), jac.data(), nullptr)) {
      const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(jac);
      double sum_sq = 0.0;
      for (const Input& in : budget_inputs) {
        if (!(in.std_input > 0.0)) continue;
        const double q0 = input.geometry.*(in.field);
        const double h = 1e-4 * q0;
        Eigen::VectorXd dr(n);
        bool ok = true;
        Trajectory plus, minus;
        for (int side = 0; side < 2 && ok; ++side) {
          RigGeometry g = input.geometry;
          g.*(in.field) = q0 + (side == 0 ? h : -h);
          PendulumIntegrator integ(options.model, g, options.integrator);
          ok = integ.Integrate(result.params, result.angle0_rad, result.rate0_rad_per_s,
                               input.t_s, false, side == 0 ? &plus : &minus, &why);
        }
        UncertaintyContribution c;
        c.name = in.name;
        c.std_input = in.std_input;
        if (ok) {
          for (size_t k = 0; k < n; ++k)
            dr(k) = (plus.rate_rad_per_s[k] - minus.rate_rad_per_s[k]) / (2.0 * h);
          const Eigen::VectorXd dp = -qr.solve(dr);
          c.d_inertia = scale * dp(kTraceInertia);
          c.contribution_kg_m2 = std::abs(c.d_inertia) * in.std_input;
        } else {
          result.flags.push_back(std::string("budget_failed_") + in.name);
        }
        sum_sq += c.contribution_kg_m2 * c.contribution_kg_m2;
        result.budget.push_back(c);
      }
      if (options.gyro_scale_std > 0.0) {
        // A gyro reading (1 + e) psi' + b: to first order the data move by e psi'(t_k), the
        // fitted rate, so dp/de = +(J^T J)^{-1} J^T psi' (data, not model, moved). Exact, no refit.
        Eigen::VectorXd dr(n);
        for (size_t k = 0; k < n; ++k) dr(k) = traj.rate_rad_per_s[k];
        const Eigen::VectorXd dp = qr.solve(dr);
        UncertaintyContribution c;
        c.name = "gyro_scale";
        c.std_input = options.gyro_scale_std;
        c.d_inertia = scale * dp(kTraceInertia);
        c.contribution_kg_m2 = std::abs(c.d_inertia) * options.gyro_scale_std;
        sum_sq += c.contribution_kg_m2 * c.contribution_kg_m2;
        result.budget.push_back(c);
      }
      result.inertia_budget_std_kg_m2 = std::sqrt(sum_sq);
      Cost(cost, p, &rtmp);  // restore the cache at the solution (cheap: cache hit)
    }
  }
  result.inertia_std_kg_m2 = std::hypot(result.inertia_stat_std_kg_m2,
                                        result.inertia_budget_std_kg_m2);

  // --- Amplitude of the fitted part -----------------------------------------------------------
  {
    const double t0 = input.t_s.front(), t1 = input.t_s.back(), T = guess.period_s;
    double a0 = 0.0, a1 = 0.0;
    for (size_t k = 0; k < n; ++k) {
      const double a = std::abs(traj.angle_rad[k]);
      if (input.t_s[k] <= t0 + T) a0 = std::max(a0, a);
      if (input.t_s[k] >= t1 - T) a1 = std::max(a1, a);
    }
    result.amplitude_start_deg = a0 * kDegPerRad;
    result.amplitude_end_deg = a1 * kDegPerRad;
  }

  // --- Whiteness ------------------------------------------------------------------------------
  {
    const std::vector<double> rho = Autocorrelation(r, options.whiteness_lags);
    result.residual_autocorr_lag1 = rho.empty() ? 0.0 : rho[0];
    double q = 0.0, mx = 0.0;
    for (int k = 1; k <= options.whiteness_lags; ++k) {
      const double v = rho[k - 1];
      mx = std::max(mx, std::abs(v));
      if (static_cast<size_t>(k) < n) q += v * v / (static_cast<double>(n) - k);
    }
    result.residual_autocorr_max = mx;
    result.ljung_box_q = static_cast<double>(n) * (n + 2.0) * q;
  }

  // --- Quality flags --------------------------------------------------------------------------
  std::vector<std::string> reasons;
  if (!lm.converged) {
    result.flags.push_back("not_converged");
    reasons.push_back("solver did not converge in " + std::to_string(options.max_iterations) +
                      " iterations");
  }
  if (noise > 0.0 && result.rms_over_noise > options.max_rms_over_noise) {
    result.flags.push_back("rms_above_noise");
    reasons.push_back("residual RMS " + Fmt("%.3g", result.residual_rms_rad_per_s) +
                      " rad/s is " + Fmt("%.2f", result.rms_over_noise) + "x the noise (max " +
                      Fmt("%.2f", options.max_rms_over_noise) + ")");
  }
  if (result.residual_autocorr_max > options.max_residual_autocorr) {
    result.flags.push_back("residuals_not_white");
    reasons.push_back("residuals show structure: max |autocorrelation| " +
                      Fmt("%.2f", result.residual_autocorr_max) + " at lags 1.." +
                      std::to_string(options.whiteness_lags) + " (max " +
                      Fmt("%.2f", options.max_residual_autocorr) + ")");
  }
  if (input.secondary_motion_ratio >= 0.0 &&
      input.secondary_motion_ratio > options.max_secondary_motion_ratio) {
    result.flags.push_back("secondary_motion");
    reasons.push_back("secondary motion " + Fmt("%.3f", input.secondary_motion_ratio) +
                      " of the swing energy (max " +
                      Fmt("%.3f", options.max_secondary_motion_ratio) + ")");
  }
  if (result.amplitude_start_deg > options.max_amplitude_deg + 1.0) {
    result.flags.push_back("amplitude_above_band");
    reasons.push_back("amplitude " + Fmt("%.1f", result.amplitude_start_deg) +
                      " deg above the band max " + Fmt("%.1f", options.max_amplitude_deg));
  }
  if (result.amplitude_end_deg < options.min_amplitude_deg - 0.5) {
    result.flags.push_back("amplitude_below_band");
    reasons.push_back("amplitude " + Fmt("%.2f", result.amplitude_end_deg) +
                      " deg below the band min " + Fmt("%.2f", options.min_amplitude_deg));
  }

  // Never NaN in the output.
  const double values[] = {result.params.inertia_kg_m2, result.params.drag_coeff_kg_m2,
                           result.params.viscous_coeff_kg_m2_per_s, result.inertia_std_kg_m2,
                           result.bias_rad_per_s, result.residual_rms_rad_per_s,
                           result.angle0_rad, result.rate0_rad_per_s};
  for (double v : values) {
    if (!std::isfinite(v)) {
      TraceFitResult bad;
      bad.model = options.model;
      bad.guess = guess;
      return finish(Error(bad, "fit produced a non-finite value"));
    }
  }

  if (reasons.empty()) {
    result.status = TraceFitStatus::kOk;
  } else {
    result.status = TraceFitStatus::kRejected;
    std::string m;
    for (size_t i = 0; i < reasons.size(); ++i) m += (i ? "; " : "") + reasons[i];
    result.message = m;
  }

  if (options.keep_series) {
    result.t_s = input.t_s;
    result.measured_rate_rad_per_s = input.rate_rad_per_s;
    result.residual_rad_per_s = r;
    result.fitted_rate_rad_per_s.resize(n);
    for (size_t k = 0; k < n; ++k) result.fitted_rate_rad_per_s[k] = input.rate_rad_per_s[k] + r[k];
  }
  return finish(result);
}

}  // namespace bifilar
