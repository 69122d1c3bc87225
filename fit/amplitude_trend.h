// The trend of I against amplitude: a weighted least-squares line
//   I_j / I_ref = I_0 (1 + c A_j^2) / I_ref
// through points (A_j, I_j +- s_j), the relative slope c with its std scaled by the Birge ratio
// when the points scatter about the line more than their stds (chi^2 > dof, the PDG rule).
// Deviations of a real rig from the ideal model are even in the angle, so they start as A^2.
// Used by the amplitude sweep within one log (fit/trace_sweep.cc) and across repeats of one
// set-up (pipeline/repeats.cc). docs/method.md §4.
#ifndef BIFILAR_FIT_AMPLITUDE_TREND_H_
#define BIFILAR_FIT_AMPLITUDE_TREND_H_

#include <vector>

namespace bifilar {

struct AmplitudePoint {
  double amplitude_deg = 0.0;
  double inertia_kg_m2 = 0.0;
  double std_kg_m2 = 0.0;  // > 0
};

struct AmplitudeTrend {
  double coeff_per_deg2 = 0.0;      // c, relative to I_0
  double coeff_std_per_deg2 = 0.0;  // Birge-scaled
  double z = 0.0;                   // c / std (0 when the std is 0)
  // The slope dI/dA over the points' amplitude range, in % of I_0 per 10 deg:
  // 100 c (A_max^2 - A_min^2) / (A_max - A_min) * 10.
  double percent_per_10deg = 0.0;
  double inertia_zero_amplitude_kg_m2 = 0.0;  // I_0
  double amplitude_min_deg = 0.0, amplitude_max_deg = 0.0;
};

// Fits the line with I_ref = reference_kg_m2 (> 0) as the scale of I. False (out untouched)
// when the points do not span a range of amplitudes or the normal equations are singular.
bool FitAmplitudeTrend(const std::vector<AmplitudePoint>& points, double reference_kg_m2,
                       AmplitudeTrend* out);

}  // namespace bifilar

#endif  // BIFILAR_FIT_AMPLITUDE_TREND_H_
