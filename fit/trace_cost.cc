#include "fit/trace_cost.h"

#include <algorithm>
#include <cmath>

namespace bifilar {

TraceRateCost::TraceRateCost(const std::vector<double>* t_s,
                             const std::vector<double>* rate_rad_per_s, PendulumModel model,
                             const RigGeometry& geometry, const IntegratorOptions& integrator,
                             double inertia_scale_kg_m2)
    : t_s_(t_s),
      rate_(rate_rad_per_s),
      inertia_scale_(inertia_scale_kg_m2),
      integrator_(model, geometry, integrator) {}

PendulumParams TraceRateCost::Unscale(const double* params, double inertia_scale_kg_m2) {
  PendulumParams p;
  p.inertia_kg_m2 = params[kTraceInertia] * inertia_scale_kg_m2;
  p.drag_coeff_kg_m2 = params[kTraceDrag] * inertia_scale_kg_m2;
  p.viscous_coeff_kg_m2_per_s = params[kTraceViscous] * inertia_scale_kg_m2;
  return p;
}

bool TraceRateCost::Evaluate(const double* params, double* residuals, double* jacobian_row_major,
                             std::string* why) const {
  for (int j = 0; j < kNumTraceParams; ++j) {
    if (!std::isfinite(params[j])) {
      if (why != nullptr) *why = "non-finite parameter";
      return false;
    }
  }
  const bool hit = cache_valid_ && std::equal(params, params + kNumTraceParams, cache_params_);
  if (!hit) {
    cache_valid_ = false;
    std::string local_why;
    const PendulumParams p = Unscale(params, inertia_scale_);
    if (!(p.inertia_kg_m2 > 0.0) || p.drag_coeff_kg_m2 < 0.0 || p.viscous_coeff_kg_m2_per_s < 0.0) {
      if (why != nullptr) *why = "parameters out of range";
      return false;
    }
    const bool integrated = integrator_.Integrate(p, params[kTraceAngle0], params[kTraceRate0],
                                                  *t_s_, true, &traj_, &local_why);
    integrator_steps_ += integrator_.last_stats().steps;
    if (!integrated) {
      if (why != nullptr) *why = local_why;
      return false;
    }
    std::copy(params, params + kNumTraceParams, cache_params_);
    cache_valid_ = true;
  }
  const size_t n = t_s_->size();
  const double bias = params[kTraceBias];
  for (size_t k = 0; k < n; ++k) residuals[k] = traj_.rate_rad_per_s[k] + bias - (*rate_)[k];
  if (jacobian_row_major != nullptr) {
    const Eigen::MatrixXd& s = traj_.d_rate;
    for (size_t k = 0; k < n; ++k) {
      double* row = jacobian_row_major + k * kNumTraceParams;
      row[kTraceInertia] = s(k, kSensInertia) * inertia_scale_;
      row[kTraceDrag] = s(k, kSensDrag) * inertia_scale_;
      row[kTraceViscous] = s(k, kSensViscous) * inertia_scale_;
      row[kTraceAngle0] = s(k, kSensAngle0);
      row[kTraceRate0] = s(k, kSensRate0);
      row[kTraceBias] = 1.0;
    }
  }
  return true;
}

}  // namespace bifilar
