// Step 10 of FitTrace (fit/trace_fit_steps.h): the quality rules (docs/method.md §7). Rejected
// only for a fit that should not be used; the statistics whose thresholds were set on real logs
// give warnings.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "fit/trace_fit_steps.h"

namespace bifilar {
namespace trace {

namespace {

// What a residual larger than the noise looks like, from the residual series alone
// (docs/method.md §7): a step or a spike (a glitch: the segment means part by more than the
// residual RMS, or one sample is far outside the rest's robust scatter), coherent and larger at
// large amplitude (the rig departs from the model: lag-1 autocorrelation rho_1 high and the RMS
// over the window's first third, where the swing is largest, above that over its last third,
// relative to the swing's own decay), or white (noise: the gyro is noisier than the noise
// estimate says).
struct ResidualShape {
  enum class Cause { kNoise, kModel, kGlitch } cause = Cause::kNoise;
  double early_over_late = 1.0;         // residual RMS, first third over last third
  double signal_early_over_late = 1.0;  // the same for the fitted swing rate
  double step_over_rms = 0.0;     // largest difference of the means before/after a split, / RMS
  double spike_over_sigma = 0.0;  // largest |r| over the robust sigma (1.4826 MAD)
  double glitch_t_s = 0.0;        // where the step or the spike is
};

double RmsOf(const std::vector<double>& v, size_t first, size_t last) {
  double sum2 = 0.0;
  for (size_t k = first; k < last; ++k) sum2 += v[k] * v[k];
  return last > first ? std::sqrt(sum2 / static_cast<double>(last - first)) : 0.0;
}

ResidualShape ClassifyResidual(const std::vector<double>& t, const std::vector<double>& r,
                               const std::vector<double>& fitted_rate, double rho1) {
  ResidualShape shape;
  const size_t n = r.size();
  if (n < 30 || t.size() != n) return shape;
  const double rms = RmsOf(r, 0, n);
  if (!(rms > 0.0)) return shape;
  // Step: the split (10-90 % of the samples) whose means before and after differ most.
  std::vector<double> prefix(n + 1, 0.0);
  for (size_t k = 0; k < n; ++k) prefix[k + 1] = prefix[k] + r[k];
  for (size_t k = n / 10; k < n - n / 10; ++k) {
    const double before = prefix[k] / k, after = (prefix[n] - prefix[k]) / (n - k);
    const double d = std::abs(before - after) / rms;
    if (d > shape.step_over_rms) {
      shape.step_over_rms = d;
      if (d > 1.2) shape.glitch_t_s = t[k];
    }
  }
  // Spike: one sample far outside the robust scatter of the rest.
  std::vector<double> a(n);
  for (size_t k = 0; k < n; ++k) a[k] = std::abs(r[k]);
  std::vector<double> sorted = a;
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
  const double robust_sigma = 1.4826 * sorted[n / 2];
  const size_t worst = static_cast<size_t>(std::max_element(a.begin(), a.end()) - a.begin());
  shape.spike_over_sigma = robust_sigma > 0.0 ? a[worst] / robust_sigma : 0.0;
  // Growth with amplitude: the residual's RMS over the first and last thirds, against the
  // swing rate's.
  const double res_late = RmsOf(r, n - n / 3, n), sig_late = RmsOf(fitted_rate, n - n / 3, n);
  shape.early_over_late = res_late > 0.0 ? RmsOf(r, 0, n / 3) / res_late : 1.0;
  shape.signal_early_over_late =
      sig_late > 0.0 && fitted_rate.size() == n ? RmsOf(fitted_rate, 0, n / 3) / sig_late : 1.0;

  const bool grows = shape.early_over_late > 1.2 &&
                     shape.early_over_late > 1.0 + 0.5 * (shape.signal_early_over_late - 1.0);
  if (shape.step_over_rms > 1.2) {
    shape.cause = ResidualShape::Cause::kGlitch;
  } else if (shape.spike_over_sigma > 10.0) {
    shape.cause = ResidualShape::Cause::kGlitch;
    shape.glitch_t_s = t[worst];
  } else if ((rho1 > 0.8 && grows) || rho1 > 0.95) {
    shape.cause = ResidualShape::Cause::kModel;
  }
  return shape;
}

// The residual warning: its likely cause from the residual's shape, and what to do about it.
// The first sentence is the one-line summary with the action.
void WarnResidualAboveNoise(const TraceFitInput& input, const TraceFitOptions& options,
                            const Minimum& minimum, const Solution& solution, double rho1,
                            Findings* findings) {
  std::vector<double> fitted_rate = solution.trajectory.rate_rad_per_s;
  const ResidualShape shape = ClassifyResidual(input.t_s, minimum.residuals, fitted_rate, rho1);
  const std::string level = "residual " + Fmt("%.3g", solution.rms_over_noise) + "x noise";
  const std::string detail =
      " The residual RMS " + Fmt("%.3g", solution.residual_rms_rad_per_s) + " rad/s is " +
      Fmt("%.2f", solution.rms_over_noise) + "x the noise estimate (warning above " +
      Fmt("%.2f", options.max_rms_over_noise) + "); lag-1 autocorrelation " + Fmt("%.3f", rho1) +
      ", RMS over the window's first third " + Fmt("%.2f", shape.early_over_late) +
      "x that over its last third (the swing rate's " + Fmt("%.2f", shape.signal_early_over_late) +
      "x), largest step between segment means " + Fmt("%.2f", shape.step_over_rms) +
      "x the RMS, largest sample " + Fmt("%.1f", shape.spike_over_sigma) + "x the robust scatter.";
  switch (shape.cause) {
    case ResidualShape::Cause::kGlitch:
      findings->Warn("rms_above_noise",
                     level + " from a step or spike near t = " + Fmt("%.2f", shape.glitch_t_s) +
                         " s (a glitch): fit the part before or after it (fit.windows or "
                         "--window), or lower fit.glitch's thresholds." +
                         detail);
      findings->flags.push_back("residual_glitch");
      return;
    case ResidualShape::Cause::kModel:
      findings->Warn("rms_above_noise",
                     level + ", growing with amplitude: the rig departs from the model; " +
                         AmplitudeAction(options) + ". Coherent (rho_1 " + Fmt("%.2f", rho1) +
                         ")." + detail);
      findings->flags.push_back("residual_model");
      return;
    case ResidualShape::Cause::kNoise:
      findings->Warn("rms_above_noise",
                     level +
                         ", white and even (noise): if the gyro is this noisy in the "
                         "swing, raise fit.quality.max_rms_over_noise." +
                         detail);
      findings->flags.push_back("residual_noise");
      return;
  }
}

// A damping coefficient held at its bound 0 by the active set (fit/trace_solve.cc): the decay
// asked for a negative value, so the fit is the best with that term off.
// The advice says "fit a longer window" only when the log holds one (the window does not run to
// the end of the free swing already); else a longer log is what separates the terms.
void WarnAtBounds(const Minimum& minimum, const TraceFitOptions& options, Findings* findings) {
  const bool drag = minimum.fixed[0] || minimum.p[kTraceDrag] <= 0.0;
  const bool viscous = minimum.fixed[1] || minimum.p[kTraceViscous] <= 0.0;
  const std::string longer = options.longer_window_available
                                 ? "fit a longer window (fit.windows or --window)"
                                 : "log a longer swing (this window runs to the log's end)";
  if (drag && viscous) {
    findings->Warn("damping_at_bound",
                   "K_D = C = 0 (both damping terms at their bound): the swing does not decay in "
                   "this window; " +
                       longer +
                       ", and check that nothing drives the swing. The "
                       "fit holds both at 0, where the data asked for negative damping.");
  } else if (drag) {
    findings->Warn("drag_at_bound",
                   "K_D = 0 (air drag at its bound): the damping is all in C here; " + longer +
                       " to separate them. The fit holds K_D at 0, where the data asked for a "
                       "negative air drag; I depends little on how the damping is split.");
  } else if (viscous) {
    findings->Warn("viscous_at_bound",
                   "C = 0 (linear damping at its bound): the damping is all in K_D here; " +
                       longer +
                       " to separate them. The fit holds C at 0, where the data asked "
                       "for a negative linear damping; I depends little on how the damping is "
                       "split.");
  }
}

}  // namespace

Quality JudgeQuality(const TraceFitInput& input, const TraceFitOptions& options,
                     const Minimum& minimum, const Solution& solution, const AmplitudeSweep& sweep,
                     const WhitenessStats& whiteness, double noise_rad_per_s) {
  Quality q;
  auto reject = [&q](const char* flag, const std::string& why) {
    q.findings.flags.push_back(flag);
    q.reasons.push_back(why);
  };
  auto warn = [&q](const char* flag, const std::string& why) { q.findings.Warn(flag, why); };

  // Reasons to reject: no convergence, a fit that does not follow the data, the wrong axis.
  if (!minimum.lm.converged) {
    reject("not_converged", "the fit did not converge in " +
                                std::to_string(options.max_iterations) +
                                " iterations; set a window (fit.windows or --window) on the "
                                "free oscillation");
  }
  double residual_fraction = solution.signal_rms_rad_per_s > 0.0
                                 ? solution.residual_rms_rad_per_s / solution.signal_rms_rad_per_s
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
    warn("secondary_motion",
         "secondary motion " + Fmt("%.3f", secondary) + " of the swing energy (warning above " +
             Fmt("%.3f", options.max_secondary_motion_ratio) + "); steady the rig before release");
  }

  // Warnings, the most important first: residual level (with its cause) and structure,
  // parameters at their bounds, secondary motion, amplitude outside the band.
  if (noise_rad_per_s > 0.0 && solution.rms_over_noise > options.max_rms_over_noise) {
    WarnResidualAboveNoise(input, options, minimum, solution, whiteness.raw_autocorr_lag1,
                           &q.findings);
  }
  if (whiteness.prewhitened_autocorr_max > options.max_residual_autocorr) {
    warn("residuals_not_white",
         "residuals have structure the model misses: steady the rig before release, swing "
         "lower if it grows with amplitude, and look at the residual panel (--plot). Sway or a "
         "second oscillation leaves this mark. Max |autocorrelation| " +
             Fmt("%.2f", whiteness.prewhitened_autocorr_max) + " at lags 1.." +
             std::to_string(options.whiteness_lags) +
             " after prewhitening with the residuals' own AR(1) noise (warning above " +
             Fmt("%.2f", options.max_residual_autocorr) +
             "); the std of I is robust to correlated residuals (HAC), not to a wrong model.");
  }
  WarnAtBounds(minimum, options, &q.findings);
  if (solution.amplitude_start_deg > options.max_amplitude_deg + 1.0) {
    warn("amplitude_above_band",
         "amplitude " + Fmt("%.1f", solution.amplitude_start_deg) + " deg above the band max " +
             Fmt("%.1f", options.max_amplitude_deg) +
             ": start the window later, at a smaller amplitude (fit.windows or --window).");
  }
  if (solution.amplitude_end_deg < options.min_amplitude_deg - 0.5) {
    warn("amplitude_below_band", "amplitude " + Fmt("%.2f", solution.amplitude_end_deg) +
                                     " deg below the band min " +
                                     Fmt("%.2f", options.min_amplitude_deg) +
                                     ": end the window earlier (fit.windows or --window).");
  }
  return q;
}

}  // namespace trace
}  // namespace bifilar
