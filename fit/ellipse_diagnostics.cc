// Step 8 of the ellipse fit: what the fit says about the data and the solvers. Studentized
// residuals and outliers, per-angle statistics and the paper's Table 1, the NACA Report 467
// three-axis estimates (paper Eq. 1) for comparison, and the parity of fits (b), (c) with (a).
#include "fit/ellipse_steps.h"

#include <algorithm>
#include <cmath>

namespace bifilar {
namespace ellipse {
namespace {

// Residuals studentized with the point scale (the given std when absolute); |r| above
// options.outlier_threshold is an outlier.
void StudentizeResiduals(const PreparedData& data, const ClosedFormFit& closed,
                         const EllipseOptions& options, Diagnostics* diag) {
  const double point_sigma =
      data.covariance == EllipseCovariance::kAbsolute ? 1.0 : std::sqrt(closed.point_var);
  for (int i = 0; i < data.n; ++i) {
    EllipseResidual r;
    r.index = i;
    r.pitch_deg = data.points[i].pitch_deg;
    r.inertia_kg_m2 = data.y(i);
    r.fitted_kg_m2 = closed.fitted(i);
    r.residual_kg_m2 = closed.resid(i);
    // Leverage h_ii of the weighted hat matrix.
    const double h = data.w(i) * data.x.row(i) * closed.normal_inv * data.x.row(i).transpose();
    const double denom = point_sigma * std::sqrt(std::max(0.0, 1.0 - h));
    r.studentized =
        denom > 1e-300 && 1.0 - h > 1e-10 ? closed.resid(i) * data.sqrt_w(i) / denom : 0.0;
    r.outlier = std::fabs(r.studentized) > options.outlier_threshold;
    if (r.outlier) ++diag->n_outliers;
    diag->residuals.push_back(r);
  }
  if (diag->n_outliers > 0) {
    diag->warnings.push_back(std::to_string(diag->n_outliers) +
                             " point(s) with |studentized residual| > " +
                             Num(options.outlier_threshold) + " (possible outlier trials)");
  }
}

// Per-angle mean, scatter and fitted value; Table 1 averages them over the angles with trials.
void AngleStatistics(const PreparedData& data, const ClosedFormFit& closed, Diagnostics* diag) {
  EllipseTable1& t = diag->table1;
  for (const AngleGroup& g : data.groups) {
    EllipseAngleStats st;
    st.pitch_deg = g.pitch_deg;
    st.n = static_cast<int>(g.members.size());
    st.mean_kg_m2 = g.mean_kg_m2;
    double ss = 0;
    for (int i : g.members) ss += (data.y(i) - st.mean_kg_m2) * (data.y(i) - st.mean_kg_m2);
    st.std_kg_m2 = st.n > 1 ? std::sqrt(ss / (st.n - 1)) : 0.0;
    st.cov_percent = 100.0 * st.std_kg_m2 / st.mean_kg_m2;
    st.fitted_kg_m2 = EllipseMoment(closed.abc(0), closed.abc(1), closed.abc(2), st.pitch_deg);
    if (st.n > 1) {
      t.mean_angle_std_kg_m2 += st.std_kg_m2;
      t.mean_cov_percent += st.cov_percent;
      ++t.n_angles_with_trials;
    }
    diag->angles.push_back(st);
  }
  if (t.n_angles_with_trials > 0) {
    t.mean_angle_std_kg_m2 /= t.n_angles_with_trials;
    t.mean_cov_percent /= t.n_angles_with_trials;
  }
  t.rmse_kg_m2 = closed.rmse_kg_m2;
}

// NACA Report 467 three-axis estimates (paper Eq. 1, phi = 90 deg + theta) at every oblique
// angle group, from its mean moment and the measured (else fitted) I_x, I_z.
void NacaEstimates(const PreparedData& data, const ClosedFormFit& closed,
                   const CovarianceEstimate& cov, const EllipseOptions& options,
                   Diagnostics* diag) {
  const std::vector<AngleGroup>& groups = data.groups;
  const int m = static_cast<int>(groups.size());
  // Standard error of a per-angle mean: the fit's variance factor over the group's weight, so
  // it carries whatever the covariance mode estimated (trial scatter, per-angle errors, or the
  // given std when absolute).
  auto mean_std = [&](int g) { return std::sqrt(cov.variance_factor / groups[g].weight); };
  // Measured body-axis moments: the angle groups at 0 (I_z) and +-90 deg (I_x).
  auto measured = [&](double axis_deg, double* value, double* std) {
    double sum = 0, var = 0;
    int count = 0;
    for (int g = 0; g < m; ++g) {
      double d = std::fabs(AxisAngleDeg(groups[g].pitch_deg) - axis_deg);
      d = std::min(d, 180.0 - d);
      if (d <= std::max(options.angle_group_tol_deg, 1e-9)) {
        const int ng = static_cast<int>(groups[g].members.size());
        sum += diag->angles[g].mean_kg_m2 * ng;
        const double s = mean_std(g);
        var += s * s * ng * ng;
        count += ng;
      }
    }
    if (count == 0) return false;
    *value = sum / count;
    *std = std::sqrt(var) / count;
    return true;
  };
  double ix = closed.best.ix_kg_m2, ix_std = cov.std6(0);
  double iz = closed.best.iz_kg_m2, iz_std = cov.std6(1);
  if (!measured(90.0, &ix, &ix_std)) {
    diag->warnings.push_back("no moment measured at +-90 deg: NACA estimates use the fitted I_x");
  }
  if (!measured(0.0, &iz, &iz_std)) {
    diag->warnings.push_back("no moment measured at 0 deg: NACA estimates use the fitted I_z");
  }
  const double min_sin = std::sin(2 * options.naca_exclusion_deg * kRadPerDeg);
  for (int g = 0; g < m; ++g) {
    const double phi = (90.0 + groups[g].pitch_deg) * kRadPerDeg;
    const double s2 = std::sin(2 * phi);
    if (std::fabs(s2) <= min_sin + 1e-12) continue;
    const double c = std::cos(phi), s = std::sin(phi);
    EllipseNacaEstimate e;
    e.pitch_deg = groups[g].pitch_deg;
    e.phi_deg = 90.0 + groups[g].pitch_deg;
    e.i_phi_kg_m2 = diag->angles[g].mean_kg_m2;
    e.ixz_kg_m2 = (ix * c * c + iz * s * s - e.i_phi_kg_m2) / s2;
    const double sphi = mean_std(g);
    e.ixz_std_kg_m2 =
        std::sqrt(sphi * sphi + std::pow(c * c * ix_std, 2) + std::pow(s * s * iz_std, 2)) /
        std::fabs(s2);
    diag->naca.push_back(e);
  }
}

// Parity: the nonlinear fits must land on the closed form, to 1e-6 of the largest moment in
// I_x, I_z and I_xz.
void CheckSolverParity(const ClosedFormFit& closed, const Eq7Fit& nelder_mead, const Eq7Fit& ceres,
                       Diagnostics* diag) {
  const EllipseParameters& best = closed.best;
  const double scale = MomentScale(closed);
  for (const EllipseSolverSummary* s : {&nelder_mead.summary, &ceres.summary}) {
    if (!s->ran) continue;
    const EllipseParameters& p = s->parameters;
    const double d =
        std::max({std::fabs(p.ix_kg_m2 - best.ix_kg_m2), std::fabs(p.iz_kg_m2 - best.iz_kg_m2),
                  std::fabs(p.ixz_kg_m2 - best.ixz_kg_m2)}) /
        scale;
    if (!s->converged || d > 1e-6) {
      diag->warnings.push_back(s->method +
                               " disagrees with the linear fit (max relative difference " + Num(d) +
                               ", " + s->message + ")");
    }
  }
}

}  // namespace

Diagnostics Diagnose(const PreparedData& data, const ClosedFormFit& closed,
                     const CovarianceEstimate& cov, const Eq7Fit& nelder_mead, const Eq7Fit& ceres,
                     const EllipseOptions& options) {
  Diagnostics diag;
  StudentizeResiduals(data, closed, options, &diag);
  AngleStatistics(data, closed, &diag);
  NacaEstimates(data, closed, cov, options, &diag);
  CheckSolverParity(closed, nelder_mead, ceres, &diag);
  return diag;
}

}  // namespace ellipse
}  // namespace bifilar
