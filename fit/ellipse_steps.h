// The steps of FitEllipse (fit/ellipse.h) and the data passed between them. Private to fit/: the
// public header stays solver-free, this one speaks Eigen.
//
// The procedure (FitEllipse in fit/ellipse.cc), one function per step:
//   PrepareData          validated points, weights, angle groups, covariance mode  (ellipse.cc)
//   FitClosedForm        (a) weighted linear least squares in (A, B, C) (ellipse_closed_form.cc)
//   MakeEq7Problem       paper Eq. 7 as an objective, from the paper's start (ellipse_eq7.cc)
//   FitNelderMead        (b) NLopt Nelder-Mead on Eq. 7, the fminsearch parity (ellipse_eq7.cc)
//   FitCeres             (c) Ceres on Eq. 7 with ceres::Covariance (ellipse_eq7.cc)
//   EstimateCovariance   variance factor, covariance of the six quantities, is tau defined
//                                                                     (ellipse_closed_form.cc)
//   ComputeIntervals     parametric bootstrap or t/normal intervals          (ellipse_intervals.cc)
//   Diagnose             residuals and outliers, per-angle statistics, Table 1, NACA 467,
//                        solver parity                                     (ellipse_diagnostics.cc)
// Each step reads the outputs of the earlier ones and writes only its own struct; warnings are
// collected per step and joined in this order.
#pragma once

#include "base/units.h"
#include "fit/ellipse.h"

#include <chrono>
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace bifilar {
namespace ellipse {

using Clock = std::chrono::steady_clock;
double SecondsSince(Clock::time_point start);

// A number for a message, 6 significant digits.
std::string Num(double v);

// --- The model (ellipse.cc).

// Row of the linear design: I = A + B cos 2theta + C sin 2theta.
Eigen::RowVector3d DesignRow(double pitch_deg);

// Pitch reduced to the axis angle in (-90, 90] (theta and theta + 180 are the same axis).
double AxisAngleDeg(double pitch_deg);

// The six quantities as a vector: Ix, Iz, Ixz, tau_deg, Ixp, Izp.
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Jac63 = Eigen::Matrix<double, 6, 3>;
Vec6 ToVec(const EllipseParameters& p);
EllipseParameters FromVec(const Vec6& v);
// Square roots of the diagonal of J cov J^T (negative rounding clipped to 0).
Vec6 StdFromCovariance(const Jac63& jac, const Eigen::Matrix3d& cov_abc);

// Six quantities from (A, B, C), choosing the branch of 2 tau nearest two_tau_ref_rad (the
// canonical branch (-90, 90] deg when two_tau_ref_rad == 0 and not at the boundary). R is signed:
// I_zp = A + R, I_xp = A - R, B = R cos 2tau, C = R sin 2tau.
EllipseParameters SixFromAbc(double a, double b, double c, double two_tau_ref_rad);

// Jacobian of the six quantities with respect to (A, B, C) at the canonical branch; sign_r is the
// sign of I_zp - I_xp.
Jac63 SixJacobian(double b, double c, double sign_r);

// --- Step 1: the prepared data (ellipse.cc).

// Points whose pitch lies within options.angle_group_tol_deg of the group's first (in sorted
// order) are one angle group.
struct AngleGroup {
  std::vector<int> members;  // indices into the points, by increasing pitch
  double pitch_deg = 0.0;    // mean pitch (deg)
  double mean_kg_m2 = 0.0;   // unweighted mean moment (kg m^2)
  double weight = 0.0;       // sum of the members' weights
};

struct PreparedData {
  std::vector<EllipsePoint> points;  // as given, validated
  int n = 0;                         // number of points
  bool weighted = false;             // every point has a std: weights 1/std^2, else 1
  Eigen::MatrixXd x;                 // n x 3 design, rows DesignRow(pitch)
  Eigen::VectorXd y;                 // measured moments (kg m^2)
  Eigen::VectorXd w;                 // weights
  Eigen::VectorXd sqrt_w;
  Eigen::MatrixXd xw;  // whitened design diag(sqrt_w) X
  std::vector<AngleGroup> groups;
  EllipseCovariance covariance = EllipseCovariance::kPointResiduals;  // kAuto resolved
  std::vector<std::string> warnings;
};

// Validates the points against the options, weighs and groups them, resolves the covariance
// mode. False with *why on bad input.
bool PrepareData(const std::vector<EllipsePoint>& points, const EllipseOptions& options,
                 PreparedData* data, std::string* why);

// --- Step 2: (a) the closed form (ellipse_closed_form.cc).

struct ClosedFormFit {
  Eigen::Vector3d abc;           // (A, B, C) (kg m^2)
  Eigen::Matrix3d normal_inv;    // (X^T W X)^-1
  Eigen::VectorXd fitted;        // the curve at each point (kg m^2)
  Eigen::VectorXd resid;         // measured - fitted (kg m^2)
  double chi2 = 0.0;             // sum w resid^2
  double point_var = 0.0;        // chi2 / (n - 3), 0 when n == 3
  double rmse_kg_m2 = 0.0;       // sqrt(mean resid^2)
  EllipseParameters best;        // the six quantities, canonical branch
  EllipseSolverSummary summary;  // "linear_ls"; its std is set by EstimateCovariance
};

// QR of the whitened design. False with *why when the design is rank-deficient.
bool FitClosedForm(const PreparedData& data, ClosedFormFit* fit, std::string* why);

// Largest of |I_x|, |I_z| of the closed form: the scale of relative comparisons (kg m^2).
double MomentScale(const ClosedFormFit& fit);

// --- Steps 3-5: (b), (c) paper Eq. 7 (ellipse_eq7.cc).

// Above this many points, fits (b) and (c) run on the exact sufficient statistics of their
// least-squares cost instead of point by point: Eq. 7 is the linear model in (A, B, C) written
// in other parameters, so sum w (y - f)^2 = chi2_min + (abc - abc_hat)^T N (abc - abc_hat), with
// N = X^T W X and abc_hat the closed-form solution. Same optimum, same J^T J, O(1) per evaluation
// (a 1e6-row table took 50 s and 1.6 GB point by point).
constexpr int kCompressAbovePoints = 4096;

// Paper Eq. 7, I(theta) = I_zp cos^2(theta - tau) + I_xp sin^2(theta - tau), as a weighted
// least-squares problem in p = (I_zp, I_xp, tau_rad), with the paper's starting point.
struct Eq7Problem {
  std::vector<double> pitch_rad, inertia_kg_m2, weight, sqrt_weight;  // one per point
  bool compressed = false;  // use the sufficient statistics below instead of the points
  Eigen::Matrix3d u;        // N = X^T W X = U^T U
  Eigen::Vector3d abc_hat;  // the closed-form (A, B, C)
  double chi2_min = 0.0;    // the closed form's chi^2
  // The paper's start: tau = 0, I_zp = the (mean) moment nearest 0 deg, I_xp nearest +-90 deg.
  double start[3] = {0.0, 0.0, 0.0};
  double scale_kg_m2 = 1.0;  // MomentScale of the closed form, for the restart test
};

Eq7Problem MakeEq7Problem(const PreparedData& data, const ClosedFormFit& closed);

// One nonlinear fit of Eq. 7.
struct Eq7Fit {
  EllipseSolverSummary summary;  // ran == false when disabled; std set by EstimateCovariance
  Eigen::Vector3d abc = Eigen::Vector3d::Zero();  // (A, B, C) of the optimum
  // Ceres only: (J^T J)^-1 in (I_zp, I_xp, tau) and d(A, B, C)/d(I_zp, I_xp, tau), unscaled.
  bool has_covariance = false;
  Eigen::Matrix<double, 3, 3, Eigen::RowMajor> cov_eq7;
  Eigen::Matrix3d jac_abc;
};

// (b) Nelder-Mead from the paper's start, restarted from its own result until it stops moving.
Eq7Fit FitNelderMead(const Eq7Problem& problem);
// (c) Ceres from the same start, with its covariance.
Eq7Fit FitCeres(const Eq7Problem& problem);

// --- Step 6: covariance (ellipse_closed_form.cc).

struct CovarianceEstimate {
  double variance_factor = 1.0;    // the scale applied to (X^T W X)^-1
  double dof = 0.0;                // of the intervals (inf for kAbsolute)
  Eigen::Matrix3d cov_abc;         // of (A, B, C), common offset included (kg^2 m^4)
  Vec6 std6;                       // delta-method standard errors of the six quantities
  double circle_chi2 = 0.0;        // (B, C) Cov_BC^-1 (B, C)^T
  bool tau_defined = true;         // the curve is distinguishable from a circle
  EllipseParameters ceres_std;     // Ceres' covariance on the same scale (when it has one)
  bool ceres_std_defined = false;  // ... and its radius R > 0, so that tau's error exists
  std::vector<std::string> warnings;
};

// The variance factor of options.covariance (data.covariance), the covariance of (A, B, C) and
// of the six quantities, the circle test for tau; Ceres' covariance on the same scale.
CovarianceEstimate EstimateCovariance(const PreparedData& data, const ClosedFormFit& closed,
                                      const Eq7Fit& ceres, const EllipseOptions& options);

// --- Step 7: intervals (ellipse_intervals.cc).

struct Intervals {
  Vec6 lo, hi;                   // at options.confidence, the six quantities
  int bootstrap_replicates = 0;  // 0: t or normal quantiles
};

// Seeded parametric bootstrap of the closed form when options.bootstrap_replicates > 0, else
// value -+ t * std.
Intervals ComputeIntervals(const PreparedData& data, const ClosedFormFit& closed,
                           const CovarianceEstimate& cov, const EllipseOptions& options);

// --- Step 8: diagnostics (ellipse_diagnostics.cc).

struct Diagnostics {
  std::vector<EllipseResidual> residuals;
  int n_outliers = 0;
  std::vector<EllipseAngleStats> angles;
  EllipseTable1 table1;
  std::vector<EllipseNacaEstimate> naca;
  std::vector<std::string> warnings;
};

// Studentized residuals and outliers, per-angle statistics and Table 1, the NACA 467 estimates,
// and the parity of the nonlinear fits with the closed form.
Diagnostics Diagnose(const PreparedData& data, const ClosedFormFit& closed,
                     const CovarianceEstimate& cov, const Eq7Fit& nelder_mead, const Eq7Fit& ceres,
                     const EllipseOptions& options);

}  // namespace ellipse
}  // namespace bifilar
