// Gyro glitches, single samples or short runs of 2-3 (a radio or bus error that writes absurd
// readings), found before the swing axis, the window, the guess and the fit see the data, so that
// a few bad samples neither reject a trace nor move its window (issue 8, "a reader for real
// files"; issue 15 item 9).
//
// Detector (per gyro axis, a Hampel-type test at the log's real timestamps): each sample x_k is
// predicted by the cubic through its four nearest neighbours (two on each side inside the log),
// and its residual e_k = (x_k - pred_k) / sqrt(1 + sum w_j^2) has the sample noise as its std.
// The noise scale s is robust: 1.4826 * median |e| over the series, floored at 1e-3 of the
// series' excursion (99th percentile of |x - median|: the swing, blind to the glitches), so a
// noise-free log is not searched below 0.1 % of its swing, and at the series' smallest non-zero
// step (its quantum). x_k is a glitch when all of
//   |e_k| > threshold_sigmas * s                              (far outside the noise),
//   x_k lies outside the range [lo, hi] of its four neighbours by more than
//       range_factor * (hi - lo)                              (a smooth swing cannot do that:
//       a peak between irregular samples stays within ~1x that range, however coarse the
//       sampling), and
//   by more than excursion_fraction * the series' excursion  (large on the scale of the swing;
//       hand tremor at 4-9 Hz sampled at 30 Hz is not).
// On the 24 real Crazyflie logs (30 Hz, steps of 8-160 ms) and simulated logs of that rig, no
// clean sample beyond 10 sigma passes both range tests (the closest: 1.55x the range at 0.34x
// the excursion, 0.98x at 1.3x); 5 and 50 rad/s glitches reach 11-90x and 4-12x.
// Short runs (issue 15 item 9): two glitches adjacent, or one sample apart, widen each other's
// neighbour range, so neither passes the test alone (two 50 rad/s samples rejected the trace; a
// pair of 2 rad/s ones moved the window start by 15 s). Each span of 2 or 3 consecutive samples
// is therefore also tested against the cubic through the two samples on each side of it: when its
// first and last samples both pass the three tests above, they are glitches, and so is its middle
// sample (span of 3) only if it passes them too. Longer runs are the signal, not glitches.
#pragma once

#include <string>
#include <vector>

#include "base/option_table.h"
#include "pendulum/imu_data.h"

namespace bifilar {

// `fit.glitch` of a config: one struct, its table (config keys, bounds) and Check.
struct GlitchOptions {
  bool enabled = true;  // the search runs (before the fit and on its residuals); default true
  // Residual threshold in robust noise sigmas (dimensionless); [3, 1000]. Default 10: Gaussian
  // noise exceeds it once per ~1e23 samples, so clean logs are untouched. (FindGlitches also
  // finds none at 0 or below.)
  double threshold_sigmas = 10.0;
  // Distance beyond the neighbours' range, in units of that range (dimensionless); [1, 100].
  double range_factor = 2.0;
  // ... and in units of the series' excursion (dimensionless); [0, 10].
  double excursion_fraction = 0.5;
  // The search is skipped when more than this fraction of the samples would be glitches
  // (dimensionless, in (0, 0.1]): that is not a glitch but the signal. Default 0.01.
  double max_fraction = 0.01;

  static const OptionFields<GlitchOptions>& Fields();  // config key, member, bound
  bool Check(CheckFailure* failure) const;             // the table's bounds
  bool Check(std::string* why) const;                  // *why = "glitch: <field> = ..."
};

// Indices (increasing) of the glitches of x at times t (same size, t increasing): isolated
// samples and runs of 2-3. Fewer than 6 samples: none.
std::vector<size_t> FindGlitches(const std::vector<double>& t_s, const std::vector<double>& x,
                                 const GlitchOptions& options);

// The glitches of any gyro axis of `data` (indices, increasing, unique).
std::vector<size_t> FindGyroGlitches(const ImuData& data, const GlitchOptions& options);

// `data` without the samples at `indices` (increasing), all columns alike; warnings kept.
ImuData WithoutSamples(const ImuData& data, const std::vector<size_t>& indices);

// "2 glitch samples ignored (single gyro readings far outside the swing, up to 50 rad/s) at
// t = 12.345, 40.1 s": for the record's warnings. Lists at most 5 times.
std::string DescribeGlitches(const ImuData& data, const std::vector<size_t>& indices);

}  // namespace bifilar
