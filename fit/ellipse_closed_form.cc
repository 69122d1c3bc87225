// Step (a) of the ellipse fit, weighted linear least squares in (A, B, C) in closed form, and the
// covariance step: the variance factor, the covariance of the six quantities and whether tau is
// defined. PlanEllipse predicts the same covariance for a design before any data exist.
#include "fit/ellipse_steps.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "base/option_check.h"

namespace bifilar {
namespace ellipse {
namespace {

// The variance factor of the covariance mode and the degrees of freedom of its intervals.
void VarianceFactor(const PreparedData& data, const ClosedFormFit& closed, double* factor,
                    double* dof) {
  const int n = data.n, m = static_cast<int>(data.groups.size());
  switch (data.covariance) {
    case EllipseCovariance::kPointResiduals:
      *factor = closed.point_var;
      *dof = n - 3;
      return;
    case EllipseCovariance::kAngleMeans: {
      // Scatter of the weighted per-angle mean measured value about the weighted mean fitted one.
      double means_ss = 0.0;
      for (const AngleGroup& g : data.groups) {
        double sy = 0, sf = 0;
        for (int i : g.members) {
          sy += data.w(i) * data.y(i);
          sf += data.w(i) * closed.fitted(i);
        }
        const double d = (sy - sf) / g.weight;
        means_ss += g.weight * d * d;
      }
      *factor = means_ss / (m - 3);
      *dof = m - 3;
      return;
    }
    default:
      *factor = 1.0;
      *dof = std::numeric_limits<double>::infinity();  // normal intervals
      return;
  }
}

// Is the curve distinguishable from a circle? chi^2 of (B, C) against its covariance.
double CircleChi2(const Eigen::Vector3d& abc, const Eigen::Matrix3d& cov_abc) {
  const Eigen::Matrix2d cov_bc = cov_abc.block<2, 2>(1, 1);
  const Eigen::Vector2d bc(abc(1), abc(2));
  const Eigen::LDLT<Eigen::Matrix2d> ldlt(cov_bc);
  if (std::hypot(abc(1), abc(2)) == 0.0) return 0.0;
  if (!(ldlt.info() == Eigen::Success && cov_bc.determinant() > 0)) {
    return std::numeric_limits<double>::infinity();
  }
  return bc.dot(ldlt.solve(bc));
}

// Standard errors of the six quantities from Ceres' (J^T J)^-1 in (I_zp, I_xp, tau): mapped to
// (A, B, C) and scaled like the closed form (a).
EllipseParameters CeresStd(const Eq7Fit& ceres, double variance_factor) {
  const Eigen::Matrix3d cov_c =
      ceres.jac_abc * ceres.cov_eq7 * ceres.jac_abc.transpose() * variance_factor;
  const EllipseParameters& pc = ceres.summary.parameters;
  const Jac63 j6 =
      SixJacobian(ceres.abc(1), ceres.abc(2), pc.izp_kg_m2 >= pc.ixp_kg_m2 ? 1.0 : -1.0);
  return FromVec(StdFromCovariance(j6, cov_c));
}

}  // namespace

bool FitClosedForm(const PreparedData& data, ClosedFormFit* fit, std::string* why) {
  const auto start = Clock::now();
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(data.xw);
  if (qr.rank() < 3) {
    *why = "the pitch angles do not determine the ellipse (rank-deficient design)";
    // Weights 1/std^2 that far apart leave the other points no say: name the std, not the design.
    if (data.weighted) {
      std::vector<double> stds;
      int smallest = 0;
      for (int i = 0; i < data.n; ++i) {
        stds.push_back(data.points[i].std_kg_m2);
        if (data.points[i].std_kg_m2 < data.points[smallest].std_kg_m2) smallest = i;
      }
      std::nth_element(stds.begin(), stds.begin() + stds.size() / 2, stds.end());
      const double median = stds[stds.size() / 2], least = data.points[smallest].std_kg_m2;
      if (least < 1e-6 * median) {
        char buffer[400];
        std::snprintf(buffer, sizeof(buffer),
                      ": point %d (pitch %g deg) has std %g kg m^2, %.3g times below the median "
                      "std %g, so its weight 1/std^2 swamps every other point; check that std "
                      "(its units, or a typo), or drop the std column",
                      smallest + 1, data.points[smallest].pitch_deg, least, median / least, median);
        *why += buffer;
      }
    }
    return false;
  }
  ClosedFormFit& f = *fit;
  f.abc = qr.solve(data.sqrt_w.cwiseProduct(data.y));
  f.normal_inv = (data.xw.transpose() * data.xw).inverse();
  f.fitted = data.x * f.abc;
  f.resid = data.y - f.fitted;
  f.chi2 = f.resid.cwiseProduct(f.resid).dot(data.w);
  f.rmse_kg_m2 = std::sqrt(f.resid.squaredNorm() / data.n);
  f.point_var = data.n > 3 ? f.chi2 / (data.n - 3) : 0.0;
  f.best = SixFromAbc(f.abc(0), f.abc(1), f.abc(2), 0.0);
  f.summary.method = "linear_ls";
  f.summary.ran = true;
  f.summary.converged = true;
  f.summary.message = "closed form (QR)";
  f.summary.final_cost = 0.5 * f.chi2;
  f.summary.parameters = f.best;
  f.summary.time_s = SecondsSince(start);
  return true;
}

double MomentScale(const ClosedFormFit& fit) {
  return std::max(std::fabs(fit.best.ix_kg_m2), std::fabs(fit.best.iz_kg_m2));
}

CovarianceEstimate EstimateCovariance(const PreparedData& data, const ClosedFormFit& closed,
                                      const Eq7Fit& ceres, const EllipseOptions& options) {
  CovarianceEstimate c;
  VarianceFactor(data, closed, &c.variance_factor, &c.dof);
  // The common offset adds to A alone (see EllipseOptions::common_offset_std_kg_m2).
  c.cov_abc = closed.normal_inv * c.variance_factor;
  c.cov_abc(0, 0) += options.common_offset_std_kg_m2 * options.common_offset_std_kg_m2;

  const Eigen::Vector3d& abc = closed.abc;
  const double sign_r = (closed.best.izp_kg_m2 - closed.best.ixp_kg_m2) >= 0 ? 1.0 : -1.0;
  c.std6 = StdFromCovariance(SixJacobian(abc(1), abc(2), sign_r), c.cov_abc);

  c.circle_chi2 = CircleChi2(abc, c.cov_abc);
  const double chi2_threshold = -2.0 * std::log(options.tau_test_alpha);
  // Below 1e-9 of A the radius is rounding, not a measurement (inputs carry ~16 digits, every
  // real rig fewer than 6): there (B, C) and their covariance are both noise and the chi^2 test
  // alone would give tau from rounding, with an interval that need not contain it.
  constexpr double kRoundingRadius = 1e-9;
  c.tau_defined = std::hypot(abc(1), abc(2)) > kRoundingRadius * std::fabs(abc(0)) &&
                  c.circle_chi2 > chi2_threshold;
  if (!c.tau_defined) {
    c.warnings.push_back(
        "tau is ill-defined: the data do not distinguish the ellipse from a circle (I_x ~ I_z and "
        "I_xz ~ 0; " +
        (c.circle_chi2 > chi2_threshold
             ? std::string("a circle to rounding")
             : "chi^2 " + Num(c.circle_chi2) + " < " + Num(chi2_threshold)) +
        "); I_xz is still reported, tau, I_xp and I_zp are not");
  }

  if (ceres.has_covariance) {
    c.ceres_std = CeresStd(ceres, c.variance_factor);
    c.ceres_std_defined = std::hypot(ceres.abc(1), ceres.abc(2)) > 0;
  }
  return c;
}

}  // namespace ellipse

using namespace ellipse;

bool EllipsePlanOptions::Check(std::string* why) const {
  // 1e100 kg m^2 bounds every moment and std, as the fits' inputs; any sigma down to 1e-300
  // works (the plan is computed for sigma 1 and scaled, as the stds are linear in it).
  constexpr double kMax = 1e100;
  CheckFailure f;
  bool ok = CheckGe("trials_per_angle", trials_per_angle, 1, &f) &&
            CheckIn("sigma_kg_m2", sigma_kg_m2, 1e-300, kMax, Ends::kClosed, &f) &&
            CheckIn("ix_kg_m2", ix_kg_m2, 0, kMax, Ends::kOpenClosed, &f) &&
            CheckIn("iz_kg_m2", iz_kg_m2, 0, kMax, Ends::kOpenClosed, &f) &&
            CheckIn("ixz_kg_m2", ixz_kg_m2, -kMax, kMax, Ends::kClosed, &f);
  for (size_t i = 0; ok && i < pitch_deg.size(); ++i) {
    ok = CheckIn("pitch_deg", pitch_deg[i], -180, 180, Ends::kClosed, &f);
  }
  if (!ok) return FailWith(f, why);
  std::vector<double> axis;
  for (double a : pitch_deg) axis.push_back(AxisAngleDeg(a));
  std::sort(axis.begin(), axis.end());
  axis.erase(std::unique(axis.begin(), axis.end()), axis.end());
  if (!CheckGe("distinct pitch angles (mod 180 deg)", static_cast<double>(axis.size()), 3, &f)) {
    return FailWith(f, why);
  }

  return true;
}

bool PlanEllipse(const EllipsePlanOptions& options, EllipsePlan* plan, std::string* why) {
  if (!options.Check(why)) return false;
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  for (double a : options.pitch_deg) {
    const Eigen::RowVector3d row = DesignRow(a);
    normal += options.trials_per_angle * row.transpose() * row;
  }
  // The covariance for sigma = 1: the stds are linear in sigma and multiplied by it below, so
  // no sigma^2 overflows (1e200) or underflows (1e-170) on the way.
  const Eigen::Matrix3d cov = normal.inverse();
  const double a = 0.5 * (options.ix_kg_m2 + options.iz_kg_m2);
  const double b = 0.5 * (options.iz_kg_m2 - options.ix_kg_m2);
  const double c = options.ixz_kg_m2;
  *plan = EllipsePlan();
  plan->n_points = static_cast<int>(options.pitch_deg.size()) * options.trials_per_angle;
  plan->truth = SixFromAbc(a, b, c, 0.0);
  plan->tau_defined = std::hypot(b, c) > 0;
  const double sign_r = plan->truth.izp_kg_m2 >= plan->truth.ixp_kg_m2 ? 1.0 : -1.0;
  const Jac63 j = SixJacobian(b, c, sign_r);
  plan->std = FromVec(StdFromCovariance(j, cov) * options.sigma_kg_m2);
  for (double s : {plan->std.ix_kg_m2, plan->std.iz_kg_m2, plan->std.ixz_kg_m2}) {
    if (!(std::isfinite(s) && s > 0)) {
      *why =
          "internal: a predicted std is " + Num(s) + "; please report this with the command line";
      return false;
    }
  }
  return true;
}

}  // namespace bifilar
