#include "fit/amplitude_trend.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace bifilar {

bool FitAmplitudePower(const std::vector<AmplitudePoint>& points, double ref, double exponent,
                       AmplitudePowerFit* out) {
  Eigen::Matrix2d xtwx = Eigen::Matrix2d::Zero();
  Eigen::Vector2d xtwy = Eigen::Vector2d::Zero();
  double a_min = HUGE_VAL, a_max = 0.0;
  for (const AmplitudePoint& p : points) {
    const double w = 1.0 / std::pow(p.std_kg_m2 / ref, 2);
    const Eigen::Vector2d x(1.0, std::pow(std::abs(p.amplitude_deg), exponent));
    xtwx += w * x * x.transpose();
    xtwy += w * x * (p.inertia_kg_m2 / ref);
    a_min = std::min(a_min, p.amplitude_deg);
    a_max = std::max(a_max, p.amplitude_deg);
  }
  if (!(std::abs(xtwx.determinant()) > 0.0) || !(a_max > a_min)) return false;
  const Eigen::Matrix2d cov = xtwx.inverse();
  const Eigen::Vector2d coef = cov * xtwy;
  if (!(coef(0) > 0.0) || !coef.allFinite()) return false;
  double chi2 = 0.0;
  for (const AmplitudePoint& p : points) {
    const double x = std::pow(std::abs(p.amplitude_deg), exponent);
    chi2 += std::pow((p.inertia_kg_m2 / ref - coef(0) - coef(1) * x) / (p.std_kg_m2 / ref), 2);
  }
  const int dof = static_cast<int>(points.size()) - 2;
  const double birge2 = dof > 0 && chi2 > dof ? chi2 / dof : 1.0;  // Birge ratio^2, PDG rule
  const double c = coef(1) / coef(0);                              // relative to I_0
  out->exponent = exponent;
  out->coeff = c;
  out->coeff_std = std::sqrt(cov(1, 1) * birge2) / coef(0);
  out->z = out->coeff_std > 0.0 ? c / out->coeff_std : 0.0;
  out->chi2 = chi2;
  out->dof = dof;
  out->birge = std::sqrt(birge2);
  out->inertia_zero_amplitude_kg_m2 = ref * coef(0);
  out->percent_per_10deg =
      100.0 * c * (std::pow(a_max, exponent) - std::pow(a_min, exponent)) / (a_max - a_min) * 10.0;
  out->amplitude_min_deg = a_min;
  out->amplitude_max_deg = a_max;
  return true;
}

const std::vector<double>& AmplitudeTrendExponents() {
  static const std::vector<double> kExponents = {1.0, 2.0};
  return kExponents;
}

bool FitAmplitudeShape(const std::vector<AmplitudePoint>& points, double ref,
                       AmplitudePowerFit* out) {
  AmplitudePowerFit best;
  bool any = false;
  // p = 2 first: on a tie (2 points, or curves that fit equally well) the analytic term stays.
  for (double p : {2.0, 1.0}) {
    AmplitudePowerFit fit;
    if (!FitAmplitudePower(points, ref, p, &fit)) continue;
    // A relative margin, so that rounding does not decide between curves through 2 points.
    if (!any || fit.chi2 < best.chi2 * (1.0 - 1e-9) - 1e-12) best = fit;
    any = true;
  }
  if (any) *out = best;
  return any;
}

bool FitAmplitudeTrend(const std::vector<AmplitudePoint>& points, double ref, AmplitudeTrend* out) {
  AmplitudePowerFit fit;
  if (!FitAmplitudePower(points, ref, 2.0, &fit)) return false;
  out->coeff_per_deg2 = fit.coeff;
  out->coeff_std_per_deg2 = fit.coeff_std;
  out->z = fit.z;
  out->percent_per_10deg = fit.percent_per_10deg;
  out->inertia_zero_amplitude_kg_m2 = fit.inertia_zero_amplitude_kg_m2;
  out->amplitude_min_deg = fit.amplitude_min_deg;
  out->amplitude_max_deg = fit.amplitude_max_deg;
  return true;
}

namespace {

// One weighted pass of the pooled fit on relative values y = I / I_0,g with relative stds s and a
// between-log relative variance tau2 added to every s^2: the slope b, the sum of weighted
// squared deviations of x, chi^2, and the intercepts (relative to the current I_0,g).
struct PooledPass {
  double b = 0.0, sxx = 0.0, chi2 = 0.0;
  std::vector<double> intercept;
};

PooledPass PooledWeightedPass(const std::vector<const std::vector<AmplitudePoint>*>& used,
                              const std::vector<double>& i0, double tau2) {
  PooledPass out;
  double sxy = 0.0;
  std::vector<double> xm(used.size()), ym(used.size());
  auto weight = [&](const AmplitudePoint& p, size_t k) {
    return 1.0 / (std::pow(p.std_kg_m2 / i0[k], 2) + tau2);
  };
  for (size_t k = 0; k < used.size(); ++k) {
    double sw = 0.0, swx = 0.0, swy = 0.0;
    for (const AmplitudePoint& p : *used[k]) {
      const double w = weight(p, k);
      sw += w;
      swx += w * p.amplitude_deg * p.amplitude_deg;
      swy += w * p.inertia_kg_m2 / i0[k];
    }
    xm[k] = swx / sw;
    ym[k] = swy / sw;
    for (const AmplitudePoint& p : *used[k]) {
      const double dx = p.amplitude_deg * p.amplitude_deg - xm[k];
      out.sxx += weight(p, k) * dx * dx;
      sxy += weight(p, k) * dx * (p.inertia_kg_m2 / i0[k] - ym[k]);
    }
  }
  if (!(out.sxx > 0.0)) return out;
  out.b = sxy / out.sxx;
  for (size_t k = 0; k < used.size(); ++k) {
    const double a = ym[k] - out.b * xm[k];
    out.intercept.push_back(a);
    for (const AmplitudePoint& p : *used[k]) {
      out.chi2 +=
          weight(p, k) *
          std::pow(p.inertia_kg_m2 / i0[k] - a - out.b * p.amplitude_deg * p.amplitude_deg, 2);
    }
  }
  return out;
}

}  // namespace

bool FitPooledAmplitudeTrend(const std::vector<std::vector<AmplitudePoint>>& groups,
                             PooledAmplitudeTrend* out) {
  std::vector<const std::vector<AmplitudePoint>*> used;
  for (const auto& g : groups) {
    bool ok = g.size() >= 2;
    for (const AmplitudePoint& p : g) {
      ok = ok && std::isfinite(p.amplitude_deg) && std::isfinite(p.inertia_kg_m2) &&
           p.inertia_kg_m2 > 0.0 && p.std_kg_m2 > 0.0 && std::isfinite(p.std_kg_m2);
    }
    if (ok) used.push_back(&g);
  }
  int n = 0;
  bool varies = false;  // some group spans more than 0.1 deg, far below what a fit resolves
  for (const auto* g : used) {
    n += static_cast<int>(g->size());
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (const AmplitudePoint& p : *g) {
      lo = std::min(lo, p.amplitude_deg);
      hi = std::max(hi, p.amplitude_deg);
    }
    varies = varies || hi - lo > 0.1;
  }
  const int dof = n - static_cast<int>(used.size()) - 1;
  if (used.empty() || dof < 1 || !varies) return false;
  // I_0,g: the weighted mean first, then the intercept of the first pass, so that the second
  // pass measures I relative to I_0,g itself and its slope is c.
  std::vector<double> i0(used.size());
  for (size_t k = 0; k < used.size(); ++k) {
    double sw = 0.0, swy = 0.0;
    for (const AmplitudePoint& p : *used[k]) {
      const double w = 1.0 / (p.std_kg_m2 * p.std_kg_m2);
      sw += w;
      swy += w * p.inertia_kg_m2;
    }
    i0[k] = swy / sw;
  }
  PooledPass pass = PooledWeightedPass(used, i0, 0.0);
  if (!(pass.sxx > 0.0)) return false;
  for (size_t k = 0; k < used.size(); ++k) i0[k] *= pass.intercept[k];
  pass = PooledWeightedPass(used, i0, 0.0);
  // Points that scatter beyond their stds: a relative between-log variance tau^2 added to every
  // point's, chosen so that chi^2 = dof (Paule-Mandel; chi^2 falls as tau^2 grows). Unlike a
  // Birge scale of the stds, it does not let the few most precise logs carry the fit.
  const double chi2_unscaled = pass.chi2;
  double tau2 = 0.0;
  if (pass.chi2 > dof) {
    double lo = 0.0, hi = 1e-6;
    while (PooledWeightedPass(used, i0, hi).chi2 > dof && hi < 1.0) hi *= 4.0;
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      (PooledWeightedPass(used, i0, mid).chi2 > dof ? lo : hi) = mid;
    }
    tau2 = hi;
    pass = PooledWeightedPass(used, i0, tau2);
  }
  if (!std::isfinite(pass.b) || !(pass.sxx > 0.0)) return false;
  out->coeff_per_deg2 = pass.b;
  out->coeff_std_per_deg2 = std::sqrt(1.0 / pass.sxx);
  out->z = pass.b / out->coeff_std_per_deg2;
  out->chi2 = chi2_unscaled;
  out->dof = dof;
  out->birge = chi2_unscaled > dof ? std::sqrt(chi2_unscaled / dof) : 1.0;
  out->scatter_relative = std::sqrt(tau2);
  out->n_points = n;
  out->n_groups = static_cast<int>(used.size());
  out->amplitude_min_deg = HUGE_VAL;
  out->amplitude_max_deg = 0.0;
  for (const auto* g : used) {
    for (const AmplitudePoint& p : *g) {
      out->amplitude_min_deg = std::min(out->amplitude_min_deg, p.amplitude_deg);
      out->amplitude_max_deg = std::max(out->amplitude_max_deg, p.amplitude_deg);
    }
  }
  return true;
}

}  // namespace bifilar
