// FitTrace (fit/trace_fit.h) as its named steps, listed with their files in
// fit/trace_fit_steps.h; here the steps that read or write the public result (validation, the
// solution, the assembly) and the options' Check and the result's BriefReport.
#include "fit/trace_fit.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <tuple>

#include "base/enum_names.h"
#include "base/option_check.h"
#include "base/text_format.h"
#include "fit/residual_stats.h"
#include "fit/trace_cost.h"
#include "fit/trace_fit_steps.h"
#include "fit/trace_guess.h"

namespace bifilar {
namespace trace {

double RmsAboutMean(const std::vector<double>& v) {
  if (v.empty()) return 0.0;
  double mean = 0.0, sq = 0.0;
  for (double x : v) mean += x;
  mean /= static_cast<double>(v.size());
  for (double x : v) sq += (x - mean) * (x - mean);
  return std::sqrt(sq / static_cast<double>(v.size()));
}

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

bool ValidateTraceFit(const TraceFitInput& input, const TraceFitOptions& options,
                      std::string* why) {
  auto fail = [why](const std::string& m) {
    *why = m;
    return false;
  };
  std::string detail;
  if (!options.Check(&detail)) return fail("invalid fit options: " + detail);
  if (!input.geometry.Check(&detail)) return fail("invalid rig geometry: " + detail);
  const size_t n = input.t_s.size();
  if (input.rate_rad_per_s.size() != n) return fail("time and rate series differ in length");
  if (n == 0) return fail("empty window: no samples");
  for (size_t k = 0; k < n; ++k) {
    if (!std::isfinite(input.t_s[k]) || !std::isfinite(input.rate_rad_per_s[k])) {
      std::ostringstream s;
      s << "non-finite value (NaN or inf) at sample " << k;
      return fail(s.str());
    }
    if (k > 0 && !(input.t_s[k] > input.t_s[k - 1])) {
      std::ostringstream s;
      s << "timestamps not strictly increasing at sample " << k << " (t = " << input.t_s[k]
        << " s)";
      return fail(s.str());
    }
  }
  // Timestamps the integrator can step through: a span of at most 1e6 s, and a double at the
  // largest |t| resolving 1e-3 of the median step (as the log readers require).
  if (n >= 2) {
    const double span = input.t_s.back() - input.t_s.front();
    std::vector<double> steps(n - 1);
    for (size_t k = 1; k < n; ++k) steps[k - 1] = input.t_s[k] - input.t_s[k - 1];
    std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
    const double largest = std::max(std::abs(input.t_s.front()), std::abs(input.t_s.back()));
    if (span > 1e6)
      return fail("the window spans " + Fmt("%g", span) +
                  " s, more than 1e6 s: check the time unit");
    if (largest * std::numeric_limits<double>::epsilon() > 1e-3 * steps[steps.size() / 2])
      return fail("timestamps near " + Fmt("%g", largest) + " s are too large for samples " +
                  Fmt("%g", steps[steps.size() / 2]) +
                  " s apart (a double resolves them too coarsely); subtract the start time");
  }
  if (!std::isfinite(input.noise_rad_per_s) || !std::isfinite(input.secondary_motion_ratio))
    return fail("non-finite noise or secondary motion ratio");
  return true;
}

Solution MakeSolution(const TraceFitInput& input, const TraceRateCost& cost, const Minimum& minimum,
                      double period_s, double noise_rad_per_s) {
  const double* p = minimum.p.data();
  Solution s;
  s.params = TraceRateCost::Unscale(p, cost.inertia_scale());
  s.angle0_rad = p[kTraceAngle0];
  s.rate0_rad_per_s = p[kTraceRate0];
  s.bias_rad_per_s = p[kTraceBias];
  s.residual_rms_rad_per_s = RmsOfCost(minimum.final_cost, input.t_s.size());
  s.rms_over_noise = noise_rad_per_s > 0.0 ? s.residual_rms_rad_per_s / noise_rad_per_s : 0.0;
  s.trajectory = cost.last_trajectory();
  std::tie(s.amplitude_start_deg, s.amplitude_end_deg) =
      AmplitudeAtEnds(input.t_s, s.trajectory, period_s);
  s.signal_rms_rad_per_s = RmsAboutMean(s.trajectory.rate_rad_per_s);
  return s;
}

namespace {

TraceFitResult Error(TraceFitResult result, const std::string& message) {
  result.status = TraceFitStatus::kError;
  result.message = message;
  return result;
}

// The guess could not find an oscillation to fit: rejected, with the guess for the report.
TraceFitResult NoUsableOscillation(TraceFitResult result, const TraceInitialGuess& guess,
                                   const std::string& why) {
  result.status = TraceFitStatus::kRejected;
  result.message = why;
  result.flags.push_back("no_usable_oscillation");
  result.guess = guess;
  return result;
}

// The guess and what it fixes for the rest of the fit: the period, the noise the checks use
// (the rest segment's when given, else the window's own scatter).
void RecordGuess(const TraceFitInput& input, const TraceInitialGuess& guess,
                 TraceFitResult* result) {
  result->guess = guess;
  result->period_s = guess.period_s;
  result->num_samples = static_cast<int>(input.t_s.size());
  result->noise_from_input = input.noise_rad_per_s > 0.0;
  result->noise_rad_per_s =
      result->noise_from_input ? input.noise_rad_per_s : guess.data_noise_rad_per_s;
}

void Append(const Findings& findings, TraceFitResult* result) {
  result->flags.insert(result->flags.end(), findings.flags.begin(), findings.flags.end());
  result->warnings.insert(result->warnings.end(), findings.warnings.begin(),
                          findings.warnings.end());
}

// The public result from the steps' outputs (`result` holds the guess), flags and warnings in
// step order; an error when a value came out non-finite.
TraceFitResult AssembleResult(const TraceFitInput& input, const TraceFitOptions& options,
                              TraceFitResult result, const Minimum& minimum,
                              const Solution& solution, const StatisticalUncertainty& stat,
                              const InputBudget& budget, const AmplitudeSweep& sweep,
                              const SweepRule& rule, const WhitenessStats& whiteness,
                              const Quality& quality) {
  result.iterations = minimum.iterations;
  result.initial_cost = minimum.initial_cost;
  result.final_cost = minimum.final_cost;
  result.nlopt_refined = minimum.nlopt_refined;

  result.params = solution.params;
  result.params.inertia_kg_m2 = rule.inertia_kg_m2;
  result.angle0_rad = solution.angle0_rad;
  result.rate0_rad_per_s = solution.rate0_rad_per_s;
  result.bias_rad_per_s = solution.bias_rad_per_s;
  result.residual_rms_rad_per_s = solution.residual_rms_rad_per_s;
  result.rms_over_noise = solution.rms_over_noise;
  result.amplitude_start_deg = solution.amplitude_start_deg;
  result.amplitude_end_deg = solution.amplitude_end_deg;
  result.signal_rms_rad_per_s = solution.signal_rms_rad_per_s;

  result.drag_coeff_std = stat.drag_coeff_std;
  result.viscous_coeff_std = stat.viscous_coeff_std;
  result.inertia_iid_std_kg_m2 = stat.inertia_iid_std_kg_m2;
  result.hac_bandwidth = stat.hac_bandwidth;
  result.budget = budget.contributions;
  result.inertia_budget_std_kg_m2 = budget.inertia_std_kg_m2;
  result.inertia_window_kg_m2 = solution.params.inertia_kg_m2;
  result.sweep = sweep;
  result.inertia_stat_std_kg_m2 = rule.inertia_stat_std_kg_m2;
  result.model_inadequacy_std_kg_m2 = rule.model_inadequacy_std_kg_m2;
  result.inertia_source = rule.inertia_source;
  result.inertia_std_kg_m2 =
      std::sqrt(result.inertia_stat_std_kg_m2 * result.inertia_stat_std_kg_m2 +
                result.model_inadequacy_std_kg_m2 * result.model_inadequacy_std_kg_m2 +
                result.inertia_budget_std_kg_m2 * result.inertia_budget_std_kg_m2);

  result.residual_autocorr_lag1 = whiteness.raw_autocorr_lag1;
  result.residual_autocorr_max = whiteness.raw_autocorr_max;
  result.residual_ar1_phi = whiteness.ar1_phi;
  result.prewhitened_autocorr_max = whiteness.prewhitened_autocorr_max;
  result.ljung_box_q = whiteness.ljung_box_q;

  // The most important first: the amplitude rule, the quality warnings, then the uncertainty's.
  for (const Findings* f : {&rule.findings, &quality.findings, &stat.findings, &budget.findings})
    Append(*f, &result);

  // Never NaN in the output.
  const double values[] = {result.params.inertia_kg_m2,
                           result.params.drag_coeff_kg_m2,
                           result.params.viscous_coeff_kg_m2_per_s,
                           result.inertia_std_kg_m2,
                           result.bias_rad_per_s,
                           result.residual_rms_rad_per_s,
                           result.angle0_rad,
                           result.rate0_rad_per_s};
  for (double v : values) {
    if (!std::isfinite(v)) {
      TraceFitResult bad;
      bad.model = options.model;
      bad.guess = result.guess;
      return Error(bad, "fit produced a non-finite value");
    }
  }

  if (quality.reasons.empty()) {
    result.status = TraceFitStatus::kOk;
  } else {
    result.status = TraceFitStatus::kRejected;
    std::string m;
    for (size_t i = 0; i < quality.reasons.size(); ++i) m += (i ? "; " : "") + quality.reasons[i];
    result.message = m;
  }

  if (options.keep_series) {
    const std::vector<double>& r = minimum.residuals;
    const size_t n = input.t_s.size();
    result.t_s = input.t_s;
    result.measured_rate_rad_per_s = input.rate_rad_per_s;
    result.residual_rad_per_s = r;
    result.fitted_rate_rad_per_s.resize(n);
    for (size_t k = 0; k < n; ++k) result.fitted_rate_rad_per_s[k] = input.rate_rad_per_s[k] + r[k];
  }
  return result;
}

// A fit stopped by its budget, with no parameters: rejected at a work bound (iterations,
// integrator steps), an error when abandoned by the time guard or interrupted.
TraceFitResult Stopped(TraceFitResult result, const SolveBudget& budget) {
  result.iterations = budget.iterations();
  result.integrator_steps = budget.integrator_steps();
  result.message = budget.Message();
  switch (budget.stop()) {
    case SolveBudget::Stop::kInterrupted:
      result.status = TraceFitStatus::kError;
      result.interrupted = true;
      result.flags.push_back("interrupted");
      break;
    case SolveBudget::Stop::kTimeGuard:
      result.status = TraceFitStatus::kError;
      result.time_guard = true;
      result.flags.push_back("time_guard");
      break;
    case SolveBudget::Stop::kIterations:
    case SolveBudget::Stop::kSteps:
    case SolveBudget::Stop::kNone:
      result.status = TraceFitStatus::kRejected;
      result.solver_bound = true;
      result.flags.push_back("solver_bound");
      break;
  }
  return result;
}

// The wall time, and the label in front of any message.
TraceFitResult Finish(TraceFitResult r, const std::string& label,
                      std::chrono::steady_clock::time_point start) {
  const std::string prefix = label.empty() ? "" : label + ": ";
  r.fit_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!r.message.empty() && r.message.compare(0, prefix.size(), prefix) != 0)
    r.message = prefix + r.message;
  return r;
}

}  // namespace
}  // namespace trace

constexpr EnumName<TraceFitStatus> kTraceFitStatusNames[] = {
    {TraceFitStatus::kOk, "ok"},
    {TraceFitStatus::kRejected, "rejected"},
    {TraceFitStatus::kError, "error"}};

const char* ToString(TraceFitStatus status) {
  return EnumToString(kTraceFitStatusNames, status, "error");
}

bool TraceFitOptions::Check(std::string* why) const {
  std::string integ_why;
  if (!integrator.Check(&integ_why)) return SetWhy(why, "integrator: " + integ_why);
  CheckFailure f;
  const bool ok =
      CheckGt("max_iterations", max_iterations, 0, &f) &&
      CheckGe("max_total_iterations", max_total_iterations, 1, &f) &&
      CheckGe("max_integrator_steps", static_cast<double>(max_integrator_steps), 1, &f) &&
      CheckFiniteGt("time_guard_cpu_seconds", time_guard_cpu_seconds, 0, &f) &&
      TraceQualityOptions::Check(&f) && CheckGe("min_amplitude_deg", min_amplitude_deg, 0, &f) &&
      CheckGt("max_amplitude_deg", max_amplitude_deg, "min_amplitude_deg", min_amplitude_deg, &f) &&
      CheckLe("max_amplitude_deg", max_amplitude_deg, 90, &f) &&
      CheckGt("refine_rms_over_noise", refine_rms_over_noise, 1, &f) &&
      AmplitudeSweepOptions::Check(&f) &&
      // The budget's uncertainties (geometry, gyro scale).
      CheckFiniteGe("filar_length_std_m", filar_length_std_m, 0, &f) &&
      CheckFiniteGe("filar_separation_std_m", filar_separation_std_m, 0, &f) &&
      CheckFiniteGe("mass_std_kg", mass_std_kg, 0, &f) &&
      CheckFiniteGe("gravity_std_mps2", gravity_std_mps2, 0, &f) &&
      CheckFiniteGe("gyro_scale_std", gyro_scale_std, 0, &f);
  return ok || FailWith(f, why);
}

std::string TraceFitResult::BriefReport() const {
  std::ostringstream s;
  s << ToString(status) << " [" << ToString(model) << "]";
  if (status != TraceFitStatus::kError && params.inertia_kg_m2 > 0.0) {
    s << " I = " << Fmt("%.5g", params.inertia_kg_m2) << " +- " << Fmt("%.2g", inertia_std_kg_m2)
      << " kg m^2"
      << " (stat " << Fmt("%.2g", inertia_stat_std_kg_m2) << ")"
      << ", K_D = " << Fmt("%.3g", params.drag_coeff_kg_m2)
      << ", C = " << Fmt("%.3g", params.viscous_coeff_kg_m2_per_s) << ", amplitude "
      << Fmt("%.1f", amplitude_start_deg) << "->" << Fmt("%.1f", amplitude_end_deg) << " deg"
      << ", rms/noise " << Fmt("%.2f", rms_over_noise) << ", rho1 "
      << Fmt("%.2f", residual_autocorr_lag1) << ", " << iterations << " it"
      << ", " << Fmt("%.1f", fit_seconds * 1e3) << " ms";
  }
  if (!message.empty()) s << ": " << message;
  for (const std::string& w : warnings) s << "; warning: " << w;
  return s.str();
}

TraceFitResult FitTrace(const TraceFitInput& input, const TraceFitOptions& options) {
  using namespace trace;
  const auto start = std::chrono::steady_clock::now();
  const auto finish = [&](TraceFitResult r) { return Finish(std::move(r), input.label, start); };
  TraceFitResult result;
  result.model = options.model;
  std::string why;

  // 1. Validate the options, the geometry and the window.
  if (!ValidateTraceFit(input, options, &why)) return finish(Error(result, why));

  // 2. Initial guess from the data alone; it fixes the period and the noise the checks use.
  TraceInitialGuess guess;
  if (!EstimateTraceGuess(input, options.model, options.integrator, options.min_periods, &guess,
                          &why)) {
    return finish(NoUsableOscillation(result, guess, why));
  }
  RecordGuess(input, guess, &result);
  const double noise = result.noise_rad_per_s;

  // 3. Levenberg-Marquardt from the guess, with an active set for K_D, C >= 0 and one retry.
  const TraceRateCost cost(&input.t_s, &input.rate_rad_per_s, options.model, input.geometry,
                           options.integrator, guess.params.inertia_kg_m2);
  // Every solver step below spends from one budget (iterations, integrator steps, the time
  // guard, interrupt).
  SolveBudget solve_budget(options);
  const Params from_guess = StartFromGuess(guess);
  Minimum minimum = MinimizeLm(cost, from_guess, options.max_iterations, &solve_budget);
  if (solve_budget.Exhausted()) return finish(Stopped(std::move(result), solve_budget));
  if (!minimum.lm.ok) return finish(Error(result, "fit failed: " + minimum.lm.message));

  // 4. NLopt refinement of I when that first fit is poor.
  if (NeedsRefinement(minimum, noise, options))
    RefineInertia(cost, from_guess, options.max_iterations, &minimum, &solve_budget);
  if (solve_budget.Exhausted()) return finish(Stopped(std::move(result), solve_budget));

  // 5. The solution: parameters, residual RMS, fitted trajectory and amplitude.
  const trace::Solution solution = MakeSolution(input, cost, minimum, guess.period_s, noise);

  // 6. Statistical uncertainty (HAC), 7. the input uncertainty budget.
  const StatisticalUncertainty stat = EstimateStatisticalStd(cost, minimum);
  const InputBudget budget = ComputeInputBudget(input, options, cost, minimum, solution);

  // 8. Amplitude sweep, and its rule for a rig that departs from the model.
  const AmplitudeSweep sweep =
      options.amplitude_sweep
          ? RunAmplitudeSweep(input, options, minimum.p.data(), cost.inertia_scale(),
                              solution.trajectory, guess.period_s, &solve_budget)
          : AmplitudeSweep();
  if (solve_budget.Exhausted()) return finish(Stopped(std::move(result), solve_budget));
  const SweepRule rule = ApplySweepRule(sweep, solution, stat, options);

  // 9. Whiteness of the residuals against their own AR(1) noise, 10. quality.
  const WhitenessStats whiteness = ComputeWhiteness(minimum.residuals, options.whiteness_lags);
  const Quality quality = JudgeQuality(input, options, minimum, solution, sweep, whiteness, noise);

  // 11. The result: non-finite guard, status, kept series (and the band fit's, when the result
  // is a band's).
  result = AssembleResult(input, options, std::move(result), minimum, solution, stat, budget, sweep,
                          rule, whiteness, quality);
  if (options.keep_series && result.HasFit() && rule.inertia_source == "low_amplitude_band") {
    result.band_fitted_rate_rad_per_s =
        BandFittedRate(input, options, minimum.p.data(), cost.inertia_scale(),
                       sweep.bands[sweep.low_band], &result.band_first_index);
  }
  result.integrator_steps = solve_budget.integrator_steps();
  return finish(std::move(result));
}

}  // namespace bifilar
