// One set-up or two: repeats that disagree far beyond their stds may be two hangings of the
// body (re-hung, a changed rig) named as one group, and not repeats released at different
// amplitudes. The test (docs/method.md, "Repeats: one set-up or two"):
//   1. Cochran's Q of the repeats on their per-log stds, before any amplitude correction, must
//      reject one value at p < 0.001 (Wilson-Hilferty z > 3.09);
//   2. the logs, sorted by I, are cut into two clusters of at least 2 logs where the scatter
//      left within the clusters is smallest; the clusters' gap over its std (each cluster's
//      weighted mean, both stds scaled by the Birge ratio of the scatter within the clusters)
//      must reach 5, and the gap 3 times the largest range of I within a cluster;
//   3. the release amplitudes must not explain the gap: it stays 5 sigma beyond what the logs'
//      own I(A) trends allow (their A^2 coefficient pooled, plus 3 times its std, times the
//      clusters' difference in mean squared amplitude); when no log measured its own trend, the
//      clusters' amplitudes must interleave (no monotonic I(A) gives two levels at the same
//      amplitudes);
//   4. the swing axes in the IMU frame: clusters whose mean axes lie at least 1 deg and 3 times
//      their within-cluster spread apart are a second, independent sign of a changed hanging,
//      and the 5 sigma of 2 and 3 become 3.
// Used by `fit --repeats` for each group (pipeline/trace/repeats.h) and by a campaign for the
// logs of one attitude (pipeline/campaign/campaign.cc).
#ifndef BIFILAR_PIPELINE_REPEAT_SETUPS_H_
#define BIFILAR_PIPELINE_REPEAT_SETUPS_H_

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "pipeline/records/trace_record.h"

namespace bifilar {

struct SetupSplit {
  bool tested = false;      // >= 4 usable logs that disagree beyond their stds (step 1)
  bool two_setups = false;  // steps 2-3 (with 4) hold
  std::string note;         // why it was not tested, or why the clusters are not two set-ups
  double q = NAN;           // Cochran's Q on the per-log stds, before any amplitude correction
  double q_z = NAN;         // its Wilson-Hilferty z (n - 1 dof)
  // The best cut: indices into the records (as given to TestTwoSetups), lower I first.
  std::array<std::vector<int>, 2> clusters;
  std::array<double, 2> mean_kg_m2 = {NAN, NAN};         // weighted mean of each cluster
  std::array<double, 2> mean_std_kg_m2 = {NAN, NAN};     // Birge-scaled (scatter within clusters)
  std::array<double, 2> amplitude_rms_deg = {NAN, NAN};  // RMS of the results' amplitudes
  double gap_percent = NAN;                              // (mean 2 - mean 1) / mean 1
  double gap_z = NAN;                                    // gap over its std
  double separation = NAN;  // gap over the largest range of I within a cluster
  bool amplitudes_interleave = false;
  // The logs' own I(A) trends as one A^2 coefficient (weighted mean, Birge-scaled), over the
  // logs whose sweep measured one (n_own); the largest gap they allow between the clusters (%)
  // and the gap's z beyond it. NaN when no log measured its own trend.
  int n_own = 0;
  double own_coeff_per_deg2 = NAN, own_coeff_std_per_deg2 = NAN;
  double amplitude_allows_percent = NAN;
  double gap_z_beyond_amplitude = NAN;
  // Swing axes (IMU frame): the IMU axis nearest the group's mean axis (0 x, 1 y, 2 z), each
  // cluster's range of angles from it, the angle between the clusters' mean axes and the
  // largest angle of a log's axis from its cluster's mean. NaN without axes.
  int imu_axis = -1;
  std::array<std::array<double, 2>, 2> axis_from_imu_deg = {{{NAN, NAN}, {NAN, NAN}}};
  double axis_angle_deg = NAN, axis_spread_deg = NAN;
  bool axes_differ = false;
};

// Mean squared amplitude (deg^2) of the part of the log its result comes from: the lowest
// band's when the result is that band, else the RMS of the fitted start and end amplitudes.
double ResultAmplitudeSquared(const TraceRecord& r);

// The logs' own I(A) trends (their amplitude sweeps) as one A^2 coefficient of I_0 (1 + c A^2):
// each log's c (a trend in A converted by its chord over the bands' amplitudes), weighted mean,
// its std scaled by the Birge ratio of their scatter. False (outputs untouched) when no log
// measured a trend.
bool PooledOwnTrend(const std::vector<const TraceRecord*>& records, double* coeff_per_deg2,
                    double* coeff_std_per_deg2, int* n_logs);

// The test on `records` (ok, finite I and std > 0; the caller chooses them). Values as they are
// (a caller that corrected them for amplitude passes the uncorrected ones).
SetupSplit TestTwoSetups(const std::vector<const TraceRecord*>& records);

// "two set-ups, not one: a, b at I = ... and c, d at I = ... (...)" with each log named
// by `names` (same order as the records given to TestTwoSetups); "" unless two_setups.
std::string TwoSetupsText(const SetupSplit& split, const std::vector<std::string>& names);

}  // namespace bifilar

#endif  // BIFILAR_PIPELINE_REPEAT_SETUPS_H_
