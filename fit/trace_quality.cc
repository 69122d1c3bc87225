// Step 10 of FitTrace (fit/trace_fit_steps.h): the quality rules (docs/method.md §7). Rejected
// only for a fit that should not be used; the statistics whose thresholds were set on real logs
// give warnings.
#include <cmath>
#include <string>

#include "fit/trace_fit_steps.h"

namespace bifilar {
namespace trace {

Quality JudgeQuality(const TraceFitInput& input, const TraceFitOptions& options,
                     const Minimum& minimum, const Solution& solution,
                     const AmplitudeSweep& sweep, const WhitenessStats& whiteness,
                     double noise_rad_per_s) {
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
    warn("secondary_motion", "secondary motion " + Fmt("%.3f", secondary) +
                                 " of the swing energy (warning above " +
                                 Fmt("%.3f", options.max_secondary_motion_ratio) +
                                 "); steady the rig before release");
  }

  // Warnings: residual level and structure, amplitude outside the band.
  if (noise_rad_per_s > 0.0 && solution.rms_over_noise > options.max_rms_over_noise) {
    warn("rms_above_noise",
         "residual RMS " + Fmt("%.3g", solution.residual_rms_rad_per_s) + " rad/s is " +
             Fmt("%.2f", solution.rms_over_noise) + "x the noise estimate (warning above " +
             Fmt("%.2f", options.max_rms_over_noise) + "; raise fit.quality.max_rms_over_noise "
             "if the gyro is known to be this noisy)");
  }
  if (whiteness.prewhitened_autocorr_max > options.max_residual_autocorr) {
    warn("residuals_not_white",
         "residuals show structure beyond their own AR(1) noise: max |autocorrelation| " +
             Fmt("%.2f", whiteness.prewhitened_autocorr_max) + " at lags 1.." +
             std::to_string(options.whiteness_lags) + " after prewhitening (warning above " +
             Fmt("%.2f", options.max_residual_autocorr) + ")");
  }
  if (solution.amplitude_start_deg > options.max_amplitude_deg + 1.0) {
    warn("amplitude_above_band", "amplitude " + Fmt("%.1f", solution.amplitude_start_deg) +
                                     " deg above the band max " +
                                     Fmt("%.1f", options.max_amplitude_deg));
  }
  if (solution.amplitude_end_deg < options.min_amplitude_deg - 0.5) {
    warn("amplitude_below_band", "amplitude " + Fmt("%.2f", solution.amplitude_end_deg) +
                                     " deg below the band min " +
                                     Fmt("%.2f", options.min_amplitude_deg));
  }
  return q;
}

}  // namespace trace
}  // namespace bifilar
