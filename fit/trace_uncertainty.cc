// Steps 6-7 of FitTrace (fit/trace_fit_steps.h): the statistical uncertainty of the fit (HAC
// sandwich covariance) and the input uncertainty budget (implicit-function derivative of I).
#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "fit/trace_fit_steps.h"

namespace bifilar {
namespace trace {
namespace {

// Jacobian and residuals of `cost` at p, restricted to the free parameters (those not held).
bool FreeJacobian(const TraceRateCost& cost, const double* p, const std::vector<int>& free,
                  Eigen::MatrixXd* jac_free, Eigen::VectorXd* residuals) {
  const int n = cost.num_residuals();
  Eigen::Matrix<double, Eigen::Dynamic, kNumTraceParams, Eigen::RowMajor> jac(n, kNumTraceParams);
  residuals->resize(n);
  if (!cost.Evaluate(p, residuals->data(), jac.data(), nullptr)) return false;
  jac_free->resize(n, static_cast<Eigen::Index>(free.size()));
  for (size_t j = 0; j < free.size(); ++j) jac_free->col(j) = jac.col(free[j]);
  return true;
}

}  // namespace

FreeParamStd StatisticalStd(const TraceRateCost& cost, const double* p,
                            const std::vector<int>& free) {
  FreeParamStd out;
  Eigen::MatrixXd jac;
  Eigen::VectorXd r;
  if (!FreeJacobian(cost, p, free, &jac, &r)) return out;
  const int n = static_cast<int>(r.size()), np = static_cast<int>(free.size());
  if (n <= np) return out;
  const std::vector<double> rv(r.data(), r.data() + n);
  out.bandwidth = HacBandwidth(Ar1Coefficient(rv), n, n / 4);
  Eigen::MatrixXd cov;
  if (!HacCovariance(jac, r, out.bandwidth, &cov)) return out;
  const Eigen::MatrixXd jtj = jac.transpose() * jac;
  const Eigen::MatrixXd jtj_inv = jtj.ldlt().solve(Eigen::MatrixXd::Identity(np, np));
  const double sigma2 = r.squaredNorm() / (n - np);
  for (int j = 0; j < np; ++j) {
    out.hac.push_back(std::sqrt(std::max(0.0, cov(j, j))));
    out.iid.push_back(std::sqrt(std::max(0.0, jtj_inv(j, j) * sigma2)));
  }
  out.ok = std::all_of(out.hac.begin(), out.hac.end(), [](double v) { return std::isfinite(v); });
  return out;
}

StatisticalUncertainty EstimateStatisticalStd(const TraceRateCost& cost, const Minimum& minimum) {
  const double scale = cost.inertia_scale();
  std::vector<int> free = {kTraceInertia};
  if (!minimum.fixed[0]) free.push_back(kTraceDrag);
  if (!minimum.fixed[1]) free.push_back(kTraceViscous);
  for (int j : {kTraceAngle0, kTraceRate0, kTraceBias}) free.push_back(j);
  StatisticalUncertainty out;
  const FreeParamStd stat = StatisticalStd(cost, minimum.p.data(), free);
  if (!stat.ok) {
    out.findings.Warn("covariance_failed", "the covariance of the fit could not be computed");
    return out;
  }
  out.inertia_std_kg_m2 = scale * stat.hac[0];
  out.inertia_iid_std_kg_m2 = scale * stat.iid[0];
  out.hac_bandwidth = stat.bandwidth;
  for (size_t j = 0; j < free.size(); ++j) {
    if (free[j] == kTraceDrag) out.drag_coeff_std = scale * stat.hac[j];
    if (free[j] == kTraceViscous) out.viscous_coeff_std = scale * stat.hac[j];
  }
  return out;
}

// At the minimum J^T r = 0; moving an input q moves the solution by
//   dp/dq = -(J^T J)^{-1} J^T dr/dq   (Gauss-Newton; the r * Hessian term is noise-sized),
// with dr/dq = d psi'/dq by a central difference (relative step 1e-4; the integrator at 1e-10
// keeps the difference error near 1e-6 of the derivative). Outside the hot path: 2 integrations
// without sensitivities per input.
InputBudget ComputeInputBudget(const TraceFitInput& input, const TraceFitOptions& options,
                               const TraceRateCost& cost, const Minimum& minimum,
                               const Solution& solution) {
  struct Input {
    const char* name;
    double std_input;
    double RigGeometry::*field;
  };
  const Input budget_inputs[] = {
      {"filar_length", options.filar_length_std_m, &RigGeometry::filar_length_m},
      {"filar_separation", options.filar_separation_std_m, &RigGeometry::filar_separation_m},
      {"mass", options.mass_std_kg, &RigGeometry::mass_kg},
      {"gravity", options.gravity_std_mps2, &RigGeometry::gravity_mps2}};
  InputBudget out;
  bool any_budget = false;
  for (const Input& in : budget_inputs) any_budget = any_budget || in.std_input > 0.0;
  any_budget = any_budget || options.gyro_scale_std > 0.0;
  if (!any_budget) return out;

  const size_t n = input.t_s.size();
  const double scale = cost.inertia_scale();
  const double* p = minimum.p.data();
  Eigen::Matrix<double, Eigen::Dynamic, kNumTraceParams, Eigen::RowMajor> jac(n, kNumTraceParams);
  std::vector<double> rtmp(n);
  if (!cost.Evaluate(p, rtmp.data(), jac.data(), nullptr)) return out;
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(jac);
  double sum_sq = 0.0;
  std::string why;
  for (const Input& in : budget_inputs) {
    if (!(in.std_input > 0.0)) continue;
    const double q0 = input.geometry.*(in.field);
    const double h = 1e-4 * q0;
    Eigen::VectorXd dr(n);
    bool ok = true;
    Trajectory plus, minus;
    for (int side = 0; side < 2 && ok; ++side) {
      RigGeometry g = input.geometry;
      g.*(in.field) = q0 + (side == 0 ? h : -h);
      PendulumIntegrator integ(options.model, g, options.integrator);
      ok = integ.Integrate(solution.params, solution.angle0_rad, solution.rate0_rad_per_s,
                           input.t_s, false, side == 0 ? &plus : &minus, &why);
    }
    UncertaintyContribution c;
    c.name = in.name;
    c.std_input = in.std_input;
    if (ok) {
      for (size_t k = 0; k < n; ++k)
        dr(k) = (plus.rate_rad_per_s[k] - minus.rate_rad_per_s[k]) / (2.0 * h);
      const Eigen::VectorXd dp = -qr.solve(dr);
      c.d_inertia = scale * dp(kTraceInertia);
      c.contribution_kg_m2 = std::abs(c.d_inertia) * in.std_input;
    } else {
      out.findings.flags.push_back(std::string("budget_failed_") + in.name);
    }
    sum_sq += c.contribution_kg_m2 * c.contribution_kg_m2;
    out.contributions.push_back(c);
  }
  if (options.gyro_scale_std > 0.0) {
    // A gyro reading (1 + e) psi' + b: to first order the data move by e psi'(t_k), the
    // fitted rate, so dp/de = +(J^T J)^{-1} J^T psi' (data, not model, moved). Exact, no refit.
    Eigen::VectorXd dr(n);
    for (size_t k = 0; k < n; ++k) dr(k) = solution.trajectory.rate_rad_per_s[k];
    const Eigen::VectorXd dp = qr.solve(dr);
    UncertaintyContribution c;
    c.name = "gyro_scale";
    c.std_input = options.gyro_scale_std;
    c.d_inertia = scale * dp(kTraceInertia);
    c.contribution_kg_m2 = std::abs(c.d_inertia) * options.gyro_scale_std;
    sum_sq += c.contribution_kg_m2 * c.contribution_kg_m2;
    out.contributions.push_back(c);
  }
  out.inertia_std_kg_m2 = std::sqrt(sum_sq);
  Cost(cost, p, &rtmp);  // restore the cache at the solution (cheap: cache hit)
  return out;
}

}  // namespace trace
}  // namespace bifilar
