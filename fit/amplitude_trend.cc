#include "fit/amplitude_trend.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace bifilar {

bool FitAmplitudeTrend(const std::vector<AmplitudePoint>& points, double ref,
                       AmplitudeTrend* out) {
  Eigen::Matrix2d xtwx = Eigen::Matrix2d::Zero();
  Eigen::Vector2d xtwy = Eigen::Vector2d::Zero();
  double a_min = HUGE_VAL, a_max = 0.0;
  for (const AmplitudePoint& p : points) {
    const double w = 1.0 / std::pow(p.std_kg_m2 / ref, 2);
    const Eigen::Vector2d x(1.0, p.amplitude_deg * p.amplitude_deg);
    xtwx += w * x * x.transpose();
    xtwy += w * x * (p.inertia_kg_m2 / ref);
    a_min = std::min(a_min, p.amplitude_deg);
    a_max = std::max(a_max, p.amplitude_deg);
  }
  if (!(std::abs(xtwx.determinant()) > 0.0) || !(a_max > a_min)) return false;
  const Eigen::Matrix2d cov = xtwx.inverse();
  const Eigen::Vector2d coef = cov * xtwy;
  double chi2 = 0.0;
  for (const AmplitudePoint& p : points) {
    const double x = p.amplitude_deg * p.amplitude_deg;
    chi2 += std::pow((p.inertia_kg_m2 / ref - coef(0) - coef(1) * x) / (p.std_kg_m2 / ref), 2);
  }
  const double dof = static_cast<double>(points.size()) - 2.0;
  const double birge = dof > 0 && chi2 > dof ? chi2 / dof : 1.0;  // Birge ratio, PDG rule
  const double c = coef(1) / coef(0);  // relative to I_0
  out->coeff_per_deg2 = c;
  out->coeff_std_per_deg2 = std::sqrt(cov(1, 1) * birge) / coef(0);
  out->z = out->coeff_std_per_deg2 > 0.0 ? c / out->coeff_std_per_deg2 : 0.0;
  out->percent_per_10deg = 100.0 * c * (a_max * a_max - a_min * a_min) / (a_max - a_min) * 10.0;
  out->inertia_zero_amplitude_kg_m2 = ref * coef(0);
  out->amplitude_min_deg = a_min;
  out->amplitude_max_deg = a_max;
  return true;
}

}  // namespace bifilar
