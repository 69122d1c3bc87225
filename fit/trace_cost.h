// The trace-fit residual, solver-free (Ceres wraps it in fit/trace_solve.cc; the Jacobian test
// calls it directly). Conventions: docs/physics.md §2.
//
// Parameters (kNumTraceParams, scaled so every entry is O(1e-3..1) for the solver):
//   p[0] = I / I_s,  p[1] = K_D / I_s,  p[2] = C / I_s,  p[3] = psi(t0) (rad),
//   p[4] = psi'(t0) (rad/s),  p[5] = b (rad/s)           with I_s = inertia_scale_kg_m2
// Residuals, one per sample:
//   r_k = psi'(t_k; I, K_D, C, psi(t0), psi'(t0)) + b - omega_meas(t_k)
// Jacobian (analytic): columns 0..4 are the CVODES forward sensitivities d psi'(t_k)/d(.)
// (times I_s for the first three), column 5 is 1.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "pendulum/integrator.h"
#include "pendulum/model.h"

namespace bifilar {

enum TraceParamIndex {
  kTraceInertia = 0,
  kTraceDrag = 1,
  kTraceViscous = 2,
  kTraceAngle0 = 3,
  kTraceRate0 = 4,
  kTraceBias = 5,
  kNumTraceParams = 6
};

class TraceRateCost {
 public:
  // t_s and rate_rad_per_s must outlive the object.
  TraceRateCost(const std::vector<double>* t_s, const std::vector<double>* rate_rad_per_s,
                PendulumModel model, const RigGeometry& geometry,
                const IntegratorOptions& integrator, double inertia_scale_kg_m2);

  int num_residuals() const { return static_cast<int>(t_s_->size()); }
  double inertia_scale() const { return inertia_scale_; }

  // residuals: N values; jacobian_row_major: N x kNumTraceParams row-major, or null. Returns
  // false with *why (may be null) when the integration fails. Always integrates with
  // sensitivities and caches the last point, so Ceres' residual-only evaluation of a candidate
  // followed by the Jacobian evaluation at the same accepted point costs one integration.
  bool Evaluate(const double* params, double* residuals, double* jacobian_row_major,
                std::string* why) const;

  // Internal integrator steps of every integration this object has run (cache hits run none,
  // failed integrations count the steps they took): the work the fit's budget counts.
  long integrator_steps() const { return integrator_steps_; }

  // Trajectory (angle, rate, sensitivities) at the last evaluated point.
  const Trajectory& last_trajectory() const { return traj_; }

  static PendulumParams Unscale(const double* params, double inertia_scale_kg_m2);

 private:
  const std::vector<double>* t_s_;
  const std::vector<double>* rate_;
  double inertia_scale_;
  mutable PendulumIntegrator integrator_;
  mutable Trajectory traj_;
  mutable bool cache_valid_ = false;
  mutable long integrator_steps_ = 0;
  mutable double cache_params_[kNumTraceParams] = {0, 0, 0, 0, 0, 0};
};

}  // namespace bifilar
