#include "fit/trace_fit.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <tuple>

#include <ceres/ceres.h>
#include <nlopt.hpp>
#include <Eigen/Dense>

#include "fit/residual_stats.h"
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


// Jacobian and residuals of `cost` at p, restricted to the free parameters (those not held).
bool FreeJacobian(const TraceRateCost& cost, const double* p, const std::vector<int>& free,
                  Eigen::MatrixXd* jac_free, Eigen::VectorXd* residuals) {
  const int n = cost.num_residuals();
  Eigen::Matrix<double, Eigen::Dynamic, kNumTraceParams, Eigen::RowMajor> jac(n, kNumTraceParams);
  residuals->resize(n);
  if (!cost.Evaluate(p, residuals->data(), jac.data(), nullptr)) return false;
  jac_free->resize(n, static_cast<Eigen::Index>(free.size()));
  for (size_t j = 0; j < free.size(); ++j) jac_free->col(j) = jac.col(free[j]);
  return true;
}

// Statistical std of the scaled parameter `free[index]` by the HAC sandwich (residual_stats.h),
// bandwidth from the residuals' own AR(1) coefficient; also the textbook iid std.
struct StatStd {
  bool ok = false;
  std::vector<double> hac;  // per free parameter (scaled units)
  std::vector<double> iid;
  int bandwidth = 0;
};
StatStd StatisticalStd(const TraceRateCost& cost, const double* p, const std::vector<int>& free) {
  StatStd out;
  Eigen::MatrixXd jac;
  Eigen::VectorXd r;
  if (!FreeJacobian(cost, p, free, &jac, &r)) return out;
  const int n = static_cast<int>(r.size()), np = static_cast<int>(free.size());
  if (n <= np) return out;
  const std::vector<double> rv(r.data(), r.data() + n);
  out.bandwidth = HacBandwidth(Ar1Coefficient(rv), n, n / 4);
  Eigen::MatrixXd cov;
  if (!HacCovariance(jac, r, out.bandwidth, &cov)) return out;
  const Eigen::MatrixXd jtj = jac.transpose() * jac;
  const Eigen::MatrixXd jtj_inv = jtj.ldlt().solve(Eigen::MatrixXd::Identity(np, np));
  const double sigma2 = r.squaredNorm() / (n - np);
  for (int j = 0; j < np; ++j) {
    out.hac.push_back(std::sqrt(std::max(0.0, cov(j, j))));
    out.iid.push_back(std::sqrt(std::max(0.0, jtj_inv(j, j) * sigma2)));
  }
  out.ok = std::all_of(out.hac.begin(), out.hac.end(), [](double v) { return std::isfinite(v); });
  return out;
}

// 95 % quantile of chi^2 with dof degrees of freedom (1..30; Wilson-Hilferty beyond).
double ChiSquare95(int dof) {
  static const double kTable[] = {3.841, 5.991, 7.815, 9.488, 11.070, 12.592, 14.067, 15.507,
                                  16.919, 18.307, 19.675, 21.026, 22.362, 23.685, 24.996};
  if (dof >= 1 && dof <= 15) return kTable[dof - 1];
  const double k = std::max(1, dof), z = 1.6449;
  return k * std::pow(1.0 - 2.0 / (9.0 * k) + z * std::sqrt(2.0 / (9.0 * k)), 3);
}

// RMS of v about its mean (0 for an empty v).
double RmsAboutMean(const std::vector<double>& v) {
  if (v.empty()) return 0.0;
  double mean = 0.0, sq = 0.0;
  for (double x : v) mean += x;
  mean /= static_cast<double>(v.size());
  for (double x : v) sq += (x - mean) * (x - mean);
  return std::sqrt(sq / static_cast<double>(v.size()));
}

// Peak |psi| over the first and the last period of a trajectory sampled at t.
std::pair<double, double> AmplitudeAtEnds(const std::vector<double>& t, const Trajectory& traj,
                                          double period_s) {
  double a0 = 0.0, a1 = 0.0;
  for (size_t k = 0; k < t.size(); ++k) {
    const double a = std::abs(traj.angle_rad[k]);
    if (t[k] <= t.front() + period_s) a0 = std::max(a0, a);
    if (t[k] >= t.back() - period_s) a1 = std::max(a1, a);
  }
  return {a0 * kDegPerRad, a1 * kDegPerRad};
}

// The amplitude sweep: I refitted in successive equal-cycle bands of the window, starting from
// the window fit's state at each band's first sample, K_D and C held at the window fit.
AmplitudeSweep RunAmplitudeSweep(const TraceFitInput& input, const TraceFitOptions& options,
                                 const double* p, double scale, const Trajectory& traj,
                                 double period_s) {
  AmplitudeSweep sweep;
  const double t0 = input.t_s.front(), t1 = input.t_s.back();
  const double cycles = period_s > 0.0 ? (t1 - t0) / period_s : 0.0;
  const double min_cycles = options.sweep_min_cycles_per_band;
  const int bands = std::min(options.sweep_max_bands,
                             static_cast<int>(std::floor(cycles / min_cycles)));
  if (bands < 2) {
    sweep.note = "the window holds " + Fmt("%.1f", cycles) + " cycles; a sweep needs 2 bands of " +
                 Fmt("%g", options.sweep_min_cycles_per_band) + " cycles";
    return sweep;
  }
  const size_t n = input.t_s.size();
  const std::vector<int> free = {kTraceInertia, kTraceAngle0, kTraceRate0, kTraceBias};
  const bool fixed[2] = {true, true};
  size_t first = 0;
  for (int j = 0; j < bands; ++j) {
    const double tb = j + 1 == bands ? HUGE_VAL : t0 + (t1 - t0) * (j + 1) / bands;
    size_t last = first;
    while (last < n && input.t_s[last] < tb) ++last;  // band = [first, last)
    AmplitudeSweepBand band;
    band.num_samples = static_cast<int>(last - first);
    if (band.num_samples < 20) {
      first = last;
      continue;
    }
    const std::vector<double> t(input.t_s.begin() + first, input.t_s.begin() + last);
    const std::vector<double> rate(input.rate_rad_per_s.begin() + first,
                                   input.rate_rad_per_s.begin() + last);
    band.t0_s = t.front();
    band.t1_s = t.back();
    band.cycles = (band.t1_s - band.t0_s) / period_s;
    TraceRateCost cost(&t, &rate, options.model, input.geometry, options.integrator, scale);
    double q[kNumTraceParams];
    std::copy(p, p + kNumTraceParams, q);
    q[kTraceAngle0] = traj.angle_rad[first];
    q[kTraceRate0] = traj.rate_rad_per_s[first];
    const SolveOutcome lm = SolveLm(cost, options.max_iterations, fixed, false, q);
    first = last;
    if (!lm.ok) {
      sweep.bands.push_back(band);
      continue;
    }
    const StatStd stat = StatisticalStd(cost, q, free);
    {
      std::vector<double> rr(t.size());
      const double residual_rms = std::sqrt(2.0 * Cost(cost, q, &rr) / static_cast<double>(t.size()));
      const double signal_rms = RmsAboutMean(cost.last_trajectory().rate_rad_per_s);
      band.residual_fraction = signal_rms > 0.0 ? residual_rms / signal_rms : HUGE_VAL;
    }
    const auto [a0, a1] = AmplitudeAtEnds(t, cost.last_trajectory(), period_s);
    band.amplitude_start_deg = a0;
    band.amplitude_end_deg = a1;
    band.amplitude_mean_deg = 0.5 * (a0 + a1);
    band.inertia_kg_m2 = scale * q[kTraceInertia];
    band.inertia_std_kg_m2 = stat.ok ? scale * stat.hac[0] : 0.0;
    band.ok = lm.ok && stat.ok && band.inertia_std_kg_m2 > 0.0 && std::isfinite(band.inertia_kg_m2);
    sweep.bands.push_back(band);
  }
  // Weighted line of I/I_ref against A^2.
  std::vector<const AmplitudeSweepBand*> good;
  for (size_t j = 0; j < sweep.bands.size(); ++j) {
    const AmplitudeSweepBand& b = sweep.bands[j];
    if (!b.ok) continue;
    good.push_back(&b);
    if (sweep.low_band < 0 || b.amplitude_mean_deg < sweep.bands[sweep.low_band].amplitude_mean_deg)
      sweep.low_band = static_cast<int>(j);
  }
  if (good.size() < 2) {
    sweep.note = "fewer than 2 bands could be fitted";
    return sweep;
  }
  const double ref = scale;
  Eigen::Matrix2d xtwx = Eigen::Matrix2d::Zero();
  Eigen::Vector2d xtwy = Eigen::Vector2d::Zero();
  double a_min = HUGE_VAL, a_max = 0.0;
  for (const AmplitudeSweepBand* b : good) {
    const double w = 1.0 / std::pow(b->inertia_std_kg_m2 / ref, 2);
    const Eigen::Vector2d x(1.0, b->amplitude_mean_deg * b->amplitude_mean_deg);
    xtwx += w * x * x.transpose();
    xtwy += w * x * (b->inertia_kg_m2 / ref);
    a_min = std::min(a_min, b->amplitude_mean_deg);
    a_max = std::max(a_max, b->amplitude_mean_deg);
  }
  if (!(std::abs(xtwx.determinant()) > 0.0) || !(a_max > a_min)) {
    sweep.note = "the bands do not span a range of amplitudes";
    return sweep;
  }
  const Eigen::Matrix2d cov = xtwx.inverse();
  const Eigen::Vector2d coef = cov * xtwy;
  double chi2 = 0.0;
  for (const AmplitudeSweepBand* b : good) {
    const double x = b->amplitude_mean_deg * b->amplitude_mean_deg;
    chi2 += std::pow((b->inertia_kg_m2 / ref - coef(0) - coef(1) * x) / (b->inertia_std_kg_m2 / ref), 2);
  }
  const double dof = static_cast<double>(good.size()) - 2.0;
  const double birge = dof > 0 && chi2 > dof ? chi2 / dof : 1.0;  // Birge ratio, PDG rule
  sweep.evaluated = true;
  {
    double wsum = 0.0, wi = 0.0;
    for (const AmplitudeSweepBand* b : good) {
      const double w = 1.0 / (b->inertia_std_kg_m2 * b->inertia_std_kg_m2);
      wsum += w;
      wi += w * b->inertia_kg_m2;
    }
    const double mean = wi / wsum;
    for (const AmplitudeSweepBand* b : good)
      sweep.chi2_constant += std::pow((b->inertia_kg_m2 - mean) / b->inertia_std_kg_m2, 2);
    sweep.chi2_dof = static_cast<int>(good.size()) - 1;
    // The std is scaled whenever the bands scatter more than their stds (the PDG rule); the
    // flag says so only when the scatter is significant at 5 %.
    if (sweep.chi2_constant > sweep.chi2_dof)
      sweep.std_scale = std::sqrt(sweep.chi2_constant / sweep.chi2_dof);
    sweep.bands_disagree = sweep.chi2_constant > ChiSquare95(sweep.chi2_dof);
  }
  const double c = coef(1) / coef(0);  // relative to I_0
  sweep.trend_coeff_per_deg2 = c;
  sweep.trend_coeff_std_per_deg2 = std::sqrt(cov(1, 1) * birge) / coef(0);
  sweep.trend_z = sweep.trend_coeff_std_per_deg2 > 0.0 ? c / sweep.trend_coeff_std_per_deg2 : 0.0;
  sweep.trend_percent_per_10deg = 100.0 * c * (a_max * a_max - a_min * a_min) / (a_max - a_min) * 10.0;
  sweep.inertia_zero_amplitude_kg_m2 = ref * coef(0);
  sweep.trend_detected = std::abs(sweep.trend_z) > options.sweep_trend_z;
  return sweep;
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
  if (!(reject_secondary_motion_ratio >= max_secondary_motion_ratio))
    return fail("reject_secondary_motion_ratio must be >= max_secondary_motion_ratio");
  if (!(reject_residual_fraction > 0.0 && reject_residual_fraction <= 1.0))
    return fail("reject_residual_fraction must be in (0, 1]");
  if (!(sweep_min_cycles_per_band >= 1.0 && sweep_min_cycles_per_band <= 1000.0))
    return fail("sweep_min_cycles_per_band must be in [1, 1000]");
  if (sweep_max_bands < 2 || sweep_max_bands > 20) return fail("sweep_max_bands must be in [2, 20]");
  if (!(sweep_trend_z > 0.0 && sweep_trend_z < 1e3)) return fail("sweep_trend_z must be in (0, 1000)");
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
    s << " I = " << Fmt("%.5g", params.inertia_kg_m2) << " +- "
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
  for (const std::string& w : warnings) s << "; warning: " << w;
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

  // --- Statistical uncertainty: HAC sandwich over the free parameters -------------------------
  {
    std::vector<int> free = {kTraceInertia};
    if (!fixed[0]) free.push_back(kTraceDrag);
    if (!fixed[1]) free.push_back(kTraceViscous);
    for (int j : {kTraceAngle0, kTraceRate0, kTraceBias}) free.push_back(j);
    const StatStd stat = StatisticalStd(cost, p, free);
    if (stat.ok) {
      result.inertia_stat_std_kg_m2 = scale * stat.hac[0];
      result.inertia_iid_std_kg_m2 = scale * stat.iid[0];
      result.hac_bandwidth = stat.bandwidth;
      for (size_t j = 0; j < free.size(); ++j) {
        if (free[j] == kTraceDrag) result.drag_coeff_std = scale * stat.hac[j];
        if (free[j] == kTraceViscous) result.viscous_coeff_std = scale * stat.hac[j];
      }
    } else {
      result.flags.push_back("covariance_failed");
      result.warnings.push_back("the covariance of the fit could not be computed");
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
  // --- Amplitude of the fitted part -----------------------------------------------------------
  std::tie(result.amplitude_start_deg, result.amplitude_end_deg) =
      AmplitudeAtEnds(input.t_s, traj, guess.period_s);
  result.signal_rms_rad_per_s = RmsAboutMean(traj.rate_rad_per_s);

  // --- Amplitude sweep: I against amplitude, and the rule for a rig that departs from the model --
  result.inertia_window_kg_m2 = result.params.inertia_kg_m2;
  if (options.amplitude_sweep) {
    result.sweep = RunAmplitudeSweep(input, options, p, scale, traj, guess.period_s);
  }
  const AmplitudeSweep& sweep = result.sweep;
  if (sweep.evaluated && sweep.std_scale > 1.0) result.inertia_stat_std_kg_m2 *= sweep.std_scale;
  if (sweep.bands_disagree) result.flags.push_back("bands_disagree");
  if (sweep.trend_detected) {
    // The result comes from the lowest-amplitude band; the trend's bias left at that band's
    // amplitude, |c| A_low^2 I, is the model-inadequacy term (docs/method.md).
    const AmplitudeSweepBand* low = &sweep.bands[sweep.low_band];
    result.params.inertia_kg_m2 = low->inertia_kg_m2;
    result.inertia_stat_std_kg_m2 = low->inertia_std_kg_m2 * sweep.std_scale;
    result.inertia_source = "low_amplitude_band";
    result.model_inadequacy_std_kg_m2 = std::abs(sweep.trend_coeff_per_deg2) *
                                        low->amplitude_mean_deg * low->amplitude_mean_deg *
                                        low->inertia_kg_m2;
    result.flags.push_back("amplitude_trend");
    result.warnings.push_back(
        "I depends on the amplitude beyond its statistical error (" +
        Fmt("%+.3g", sweep.trend_percent_per_10deg) + " % per 10 deg between " +
        Fmt("%.1f", sweep.bands.back().amplitude_mean_deg) + " and " +
        Fmt("%.1f", sweep.bands.front().amplitude_mean_deg) + " deg, z = " +
        Fmt("%.1f", sweep.trend_z) + "): the rig departs from the ideal model; I is taken from "
        "the lowest-amplitude band (" + Fmt("%.1f", low->amplitude_mean_deg) +
        " deg) with a model-inadequacy std of " + Fmt("%.2g", result.model_inadequacy_std_kg_m2) +
        " kg m^2. Swing at smaller amplitude, or set fit.max_amplitude_deg");
  }
  result.inertia_std_kg_m2 =
      std::sqrt(result.inertia_stat_std_kg_m2 * result.inertia_stat_std_kg_m2 +
                result.model_inadequacy_std_kg_m2 * result.model_inadequacy_std_kg_m2 +
                result.inertia_budget_std_kg_m2 * result.inertia_budget_std_kg_m2);

  // --- Whiteness, against the residual noise's own correlation ----------------------------------
  {
    const WhitenessStats w = ComputeWhiteness(r, options.whiteness_lags);
    result.residual_autocorr_lag1 = w.raw_autocorr_lag1;
    result.residual_autocorr_max = w.raw_autocorr_max;
    result.residual_ar1_phi = w.ar1_phi;
    result.prewhitened_autocorr_max = w.prewhitened_autocorr_max;
    result.ljung_box_q = w.ljung_box_q;
  }

  // --- Quality: reasons to reject, and warnings --------------------------------------------------
  std::vector<std::string> reasons;
  auto reject = [&](const char* flag, const std::string& why) {
    result.flags.push_back(flag);
    reasons.push_back(why);
  };
  auto warn = [&](const char* flag, const std::string& why) {
    result.flags.push_back(flag);
    result.warnings.push_back(why);
  };
  if (!lm.converged) {
    reject("not_converged", "the fit did not converge in " +
                                std::to_string(options.max_iterations) +
                                " iterations; set a window (fit.windows or --window) on the "
                                "free oscillation");
  }
  double residual_fraction = result.signal_rms_rad_per_s > 0.0
                                 ? result.residual_rms_rad_per_s / result.signal_rms_rad_per_s
                                 : HUGE_VAL;
  if (sweep.trend_detected) {
    // The result comes from the low-amplitude band: judge that fit (the window fit of a rig far
    // from the model may not follow the data at large amplitude, which is what the sweep shows).
    residual_fraction = sweep.bands[sweep.low_band].residual_fraction;
  }
  if (residual_fraction > options.reject_residual_fraction) {
    reject("fit_does_not_follow_data",
           "the fit does not follow the data: residual RMS is " + Fmt("%.2f", residual_fraction) +
               " of the swing rate's RMS (max " + Fmt("%.2f", options.reject_residual_fraction) +
               "); check the swing axis (imu.swing_axis) and the window");
  }
  const double secondary = input.secondary_motion_ratio;
  if (secondary >= 0.0 && secondary > options.reject_secondary_motion_ratio) {
    reject("secondary_motion",
           "heavy secondary motion: " + Fmt("%.3f", secondary) +
               " of the swing energy on the other axes (max " +
               Fmt("%.3f", options.reject_secondary_motion_ratio) +
               "); the swing axis may be wrong (set imu.swing_axis) or the rig sways");
  } else if (secondary >= 0.0 && secondary > options.max_secondary_motion_ratio) {
    warn("secondary_motion", "secondary motion " + Fmt("%.3f", secondary) +
                                 " of the swing energy (warning above " +
                                 Fmt("%.3f", options.max_secondary_motion_ratio) +
                                 "); steady the rig before release");
  }
  if (noise > 0.0 && result.rms_over_noise > options.max_rms_over_noise) {
    warn("rms_above_noise",
         "residual RMS " + Fmt("%.3g", result.residual_rms_rad_per_s) + " rad/s is " +
             Fmt("%.2f", result.rms_over_noise) + "x the noise estimate (warning above " +
             Fmt("%.2f", options.max_rms_over_noise) + "; raise fit.quality.max_rms_over_noise "
             "if the gyro is known to be this noisy)");
  }
  if (result.prewhitened_autocorr_max > options.max_residual_autocorr) {
    warn("residuals_not_white",
         "residuals show structure beyond their own AR(1) noise: max |autocorrelation| " +
             Fmt("%.2f", result.prewhitened_autocorr_max) + " at lags 1.." +
             std::to_string(options.whiteness_lags) + " after prewhitening (warning above " +
             Fmt("%.2f", options.max_residual_autocorr) + ")");
  }
  if (result.amplitude_start_deg > options.max_amplitude_deg + 1.0) {
    warn("amplitude_above_band", "amplitude " + Fmt("%.1f", result.amplitude_start_deg) +
                                     " deg above the band max " +
                                     Fmt("%.1f", options.max_amplitude_deg));
  }
  if (result.amplitude_end_deg < options.min_amplitude_deg - 0.5) {
    warn("amplitude_below_band", "amplitude " + Fmt("%.2f", result.amplitude_end_deg) +
                                     " deg below the band min " +
                                     Fmt("%.2f", options.min_amplitude_deg));
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
