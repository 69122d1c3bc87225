// The trend of I against amplitude: a weighted least-squares fit
//   I_j / I_ref = I_0 (1 + c A_j^p) / I_ref
// through points (A_j, I_j +- s_j), the relative coefficient c with its std scaled by the Birge
// ratio when the points scatter about the fitted curve more than their stds (chi^2 > dof, the
// PDG rule). Deviations of a real rig from the ideal model are even in the angle; an analytic one
// starts as A^2 (p = 2), and a rig whose I rises linearly with the amplitude (hooks, wire bending,
// slack: |psi| terms) as A (p = 1). FitAmplitudeShape lets the data choose p among these. Used by
// the amplitude sweep within one log (fit/trace_sweep.cc) and across repeats of one set-up
// (pipeline/trace/repeats.cc). docs/method.md §4 and §8.
#ifndef BIFILAR_FIT_AMPLITUDE_TREND_H_
#define BIFILAR_FIT_AMPLITUDE_TREND_H_

#include <cmath>
#include <vector>

namespace bifilar {

struct AmplitudePoint {
  double amplitude_deg = 0.0;
  double inertia_kg_m2 = 0.0;
  double std_kg_m2 = 0.0;  // > 0
};

// One power-law trend I_0 (1 + c A^p).
struct AmplitudePowerFit {
  double exponent = 2.0;                      // p
  double coeff = 0.0;                         // c (per deg^p), relative to I_0
  double coeff_std = 0.0;                     // Birge-scaled against this curve
  double z = 0.0;                             // c / std (0 when the std is 0)
  double chi2 = 0.0;                          // about the curve, with the points' own stds
  int dof = 0;                                // points - 2
  double birge = 1.0;                         // sqrt(chi2 / dof) when chi2 > dof > 0, else 1
  double inertia_zero_amplitude_kg_m2 = 0.0;  // I_0
  // The mean slope dI/dA over the points' amplitude range, in % of I_0 per 10 deg:
  // 100 c (A_max^p - A_min^p) / (A_max - A_min) * 10.
  double percent_per_10deg = 0.0;
  double amplitude_min_deg = 0.0, amplitude_max_deg = 0.0;
  // The curve at amplitude a (deg).
  double InertiaAt(double a_deg) const {
    return inertia_zero_amplitude_kg_m2 * (1.0 + coeff * std::pow(std::abs(a_deg), exponent));
  }
};

// Fits I_0 (1 + c A^p) with I_ref = reference_kg_m2 (> 0) as the scale of I. False (out
// untouched) when the points do not span a range of amplitudes or the normal equations are
// singular.
bool FitAmplitudePower(const std::vector<AmplitudePoint>& points, double reference_kg_m2,
                       double exponent, AmplitudePowerFit* out);

// The exponents FitAmplitudeShape chooses among: 1, 2. (A^4 as a third choice flagged 1 of 160
// ideal simulated quadrotor logs, none without it; a quartic rig shows as A^2 as well.)
const std::vector<double>& AmplitudeTrendExponents();

// The data's choice of p among AmplitudeTrendExponents(): the curve with the lowest chi^2 (each
// has two parameters, so AIC and BIC choose the same); with 2 points every curve passes through
// both and p = 2, the leading analytic term, is kept. False when no curve can be fitted.
bool FitAmplitudeShape(const std::vector<AmplitudePoint>& points, double reference_kg_m2,
                       AmplitudePowerFit* out);

// The A^2 line (p = 2), with the field names of earlier versions.
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

// One relative coefficient c shared by several groups of points (the repeats of several
// set-ups on one rig), each group with its own I_0,g:  I_gi = I_0,g (1 + c A_gi^2). Weighted
// least squares on I_gi / I_0,g (I_0,g from a first pass, then once more). When the points
// scatter about the fit beyond their stds (chi^2 > dof, n_points - n_groups - 1 dof), a relative
// between-log variance tau^2, common to all points, is added to each point's relative variance
// so that chi^2 = dof (the Paule-Mandel estimator of random-effects meta-regression); the std of
// c comes from those weights. (A Birge scale would keep the per-log weights, which differ 10x
// on real logs, and let the few most precise logs carry the fit.)
struct PooledAmplitudeTrend {
  double coeff_per_deg2 = 0.0;
  double coeff_std_per_deg2 = 0.0;  // with tau^2 in the weights
  double z = 0.0;
  double chi2 = 0.0;  // about the fit with the points' own stds (tau = 0)
  int dof = 0;
  double birge = 1.0;              // sqrt(chi2 / dof) when > 1, else 1: how far beyond
  double scatter_relative = 0.0;   // tau, the between-log relative std (0: none needed)
  int n_points = 0, n_groups = 0;  // groups of >= 2 points, and their points
  double amplitude_min_deg = 0.0, amplitude_max_deg = 0.0;
};

// Groups with fewer than 2 points are left out. False (out untouched) when fewer than one degree
// of freedom remains or the amplitudes do not vary within any group (by more than 0.1 deg).
bool FitPooledAmplitudeTrend(const std::vector<std::vector<AmplitudePoint>>& groups,
                             PooledAmplitudeTrend* out);

}  // namespace bifilar

#endif  // BIFILAR_FIT_AMPLITUDE_TREND_H_
