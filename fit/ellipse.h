// Ellipse of inertia in the aircraft x-z plane: moments measured at many pitch angles in, I_x, I_z,
// I_xz, the principal inclination angle tau and the principal moments out, with uncertainty.
//
// Conventions: docs/physics.md section 3 (body x forward, z down, pitch nose-up positive,
// I_xz = integral of x z dm, tau in (-45, 45] deg, tau > 0: the principal x axis lies tau below
// body x). The model is paper Eq. 4 written linearly,
//     I(theta) = A + B cos 2theta + C sin 2theta,  A = (I_x + I_z)/2, B = (I_z - I_x)/2, C = I_xz,
// which is the same curve as paper Eq. 7, I(theta) = I_zp cos^2(theta - tau) + I_xp sin^2(theta -
// tau), with B = R cos 2tau, C = R sin 2tau, R = (I_zp - I_xp)/2. I_zp is the principal moment
// about the principal axis nearest body z.
//
// Three fits are run on the same data (FitEllipse):
//   (a) weighted linear least squares in (A, B, C), closed form: the primary result;
//   (b) paper Eq. 7 minimised with NLopt Nelder-Mead from the paper's start (the parity check
//       with MATLAB fminsearch);
//   (c) Ceres on Eq. 7 with ceres::Covariance.
// FitEllipse runs the steps listed in fit/ellipse_steps.h (private to fit/, one file per idea);
// solver types stay inside fit/ellipse_eq7.cc, and this header is plain C++ and Eigen-free.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace bifilar {

// One measured moment: one trial (or one per-angle mean) at one pitch angle.
struct EllipsePoint {
  double pitch_deg = 0.0;      // nose-up pitch of the aircraft in the rig (deg), in [-180, 180]
  double inertia_kg_m2 = 0.0;  // moment of inertia about the vertical swing axis (kg m^2), > 0
  double std_kg_m2 = 0.0;      // standard error of inertia_kg_m2 (kg m^2); 0 or NaN = unknown
};

// How the covariance of (A, B, C) is scaled. Every mode uses the same point estimate.
enum class EllipseCovariance {
  // kAngleMeans when some angle has two or more trials and there are >= 6 angle groups,
  // otherwise kPointResiduals.
  kAuto,
  // Points independent; variance factor chi^2/(n - 3) from the point residuals; t with n - 3 dof.
  kPointResiduals,
  // Variance factor from the scatter of the per-angle (weighted) mean moments about the curve,
  // t with n_groups - 3 dof. Honest when each angle carries its own error (mounting, angle
  // setting, tare) shared by its trials, which the paper's data show (regression RMSE 0.0125
  // against a trial scatter of 0.0045 slug ft^2); equals kPointResiduals in expectation when not.
  kAngleMeans,
  // The given std_kg_m2 are trusted as absolute (all must be given); normal quantiles.
  kAbsolute,
};

const char* EllipseCovarianceName(EllipseCovariance mode);
// Parses "auto", "points", "angle_means", "absolute"; false if unknown.
bool ParseEllipseCovariance(const std::string& name, EllipseCovariance* mode);
// The allowed values for messages and help: "auto, points, angle_means or absolute".
std::string EllipseCovarianceAllowedValues();

// Limits of EllipseOptions::bootstrap_replicates (besides 0 = off). Fewer than 100 replicates
// cannot place a 95 % percentile; 100000 puts the Monte Carlo error of the 2.5 % quantile far
// below any statistical one and runs in well under a second.
constexpr int kMinBootstrapReplicates = 100;
constexpr int kMaxBootstrapReplicates = 100000;

struct EllipseOptions {
  // Parametric bootstrap replicates for the intervals (closed-form refits); 0 = use the
  // covariance (t or normal) intervals instead; else in [kMinBootstrapReplicates,
  // kMaxBootstrapReplicates]. Memory does not grow with it. Default 2000.
  int bootstrap_replicates = 2000;
  // Seed of the bootstrap's random numbers (std::mt19937_64). Default 1.
  std::uint64_t seed = 1;
  // Confidence level of the intervals, in (0, 1). Default 0.95.
  double confidence = 0.95;
  // Covariance scaling, see EllipseCovariance. Default kAuto.
  EllipseCovariance covariance = EllipseCovariance::kAuto;
  // Points whose pitch differs by at most this much are one angle group (deg), >= 0. Default 0.5.
  double angle_group_tol_deg = 0.5;
  // |studentized residual| above this flags an outlier, > 0. Default 3.
  double outlier_threshold = 3.0;
  // tau (and I_xp, I_zp) are reported as ill-defined when the test of "the curve is a circle"
  // (B = C = 0, i.e. I_x = I_z and I_xz = 0) is not rejected at this level: chi^2 = (B, C)
  // Cov_BC^-1 (B, C)^T < -2 ln(alpha), the chi^2 quantile with 2 dof. In (0, 1). Default 0.05.
  double tau_test_alpha = 0.05;
  // NACA Report 467 estimates skip angles within this of 0 or +-90 deg (sin 2 theta ~ 0), in
  // [0, 45) deg. Default 5.
  double naca_exclusion_deg = 5.0;
  // Standard uncertainty (kg m^2) of an offset common to every moment, such as the rig inertia
  // subtracted from all of them; >= 0, finite. Default 0. A constant offset moves A = (I_x +
  // I_z)/2 only (cos^2 + sin^2 = 1), so its variance is added to var(A) after the fit: it enters
  // I_x, I_z, I_xp, I_zp (fully correlated between them) and not I_xz or tau. The points' own
  // std must not include it.
  double common_offset_std_kg_m2 = 0.0;
  // Run the Nelder-Mead (b) and Ceres (c) fits. Default true.
  bool run_nelder_mead = true;
  bool run_ceres = true;

  bool Check(std::string* why) const;
};

// A derived quantity with its delta-method standard error and an interval at options.confidence
// (bootstrap percentile interval when bootstrap_replicates > 0, else value -+ t * std).
// defined == false (tau, I_xp, I_zp when I_x ~ I_z): value, std and interval are meaningless
// and must not be printed as numbers.
struct EllipseEstimate {
  double value = 0.0;
  double std = 0.0;
  double ci_lo = 0.0;
  double ci_hi = 0.0;
  bool defined = true;
};

// The six quantities in one solver's terms (SI, tau in deg).
struct EllipseParameters {
  double ix_kg_m2 = 0.0;
  double iz_kg_m2 = 0.0;
  double ixz_kg_m2 = 0.0;
  double tau_deg = 0.0;
  double ixp_kg_m2 = 0.0;
  double izp_kg_m2 = 0.0;
};

// Maps the linear coefficients to the six quantities with tau in (-45, 45].
EllipseParameters EllipseFromCoefficients(double a, double b, double c);
// The curve I(theta) (kg m^2) of the coefficients.
double EllipseMoment(double a, double b, double c, double pitch_deg);

// Summary of one solver, independent of the solver library.
struct EllipseSolverSummary {
  std::string method;  // "linear_ls", "nelder_mead", "ceres"
  bool ran = false;    // false when disabled in the options
  bool converged = false;
  std::string message;        // solver's termination message
  int iterations = 0;         // function evaluations (Nelder-Mead) or iterations (Ceres)
  int restarts = 0;           // Nelder-Mead restarts from its own result
  double initial_cost = 0.0;  // 0.5 * sum w r^2 at the start (kg^2 m^4, relative weights)
  double final_cost = 0.0;
  double time_s = 0.0;
  EllipseParameters parameters;
  // Standard errors (Ceres covariance scaled by the variance factor, same as the linear fit);
  // only for "linear_ls" and "ceres". has_std is false when unavailable.
  bool has_std = false;
  EllipseParameters std;
};

// Statistics of the trials at one angle group.
struct EllipseAngleStats {
  double pitch_deg = 0.0;     // mean pitch of the group
  int n = 0;                  // number of points
  double mean_kg_m2 = 0.0;    // mean moment
  double std_kg_m2 = 0.0;     // sample standard deviation (0 when n == 1)
  double cov_percent = 0.0;   // 100 * std / mean
  double fitted_kg_m2 = 0.0;  // fitted curve at pitch_deg
};

// One point's residual.
struct EllipseResidual {
  int index = 0;  // index into the input points
  double pitch_deg = 0.0;
  double inertia_kg_m2 = 0.0;
  double fitted_kg_m2 = 0.0;
  double residual_kg_m2 = 0.0;  // measured - fitted
  double studentized = 0.0;     // internally studentized residual
  bool outlier = false;         // |studentized| > options.outlier_threshold
};

// NACA Report 467 three-axis estimate at one oblique angle group (paper Eq. 1, phi = 90 + theta).
struct EllipseNacaEstimate {
  double pitch_deg = 0.0;
  double phi_deg = 0.0;
  double i_phi_kg_m2 = 0.0;  // per-angle mean moment used
  double ixz_kg_m2 = 0.0;
  double ixz_std_kg_m2 = 0.0;  // propagated from the errors of I_phi, I_x, I_z (independent)
};

// The paper's Table 1.
struct EllipseTable1 {
  double mean_angle_std_kg_m2 = 0.0;  // mean over angles with >= 2 trials of the per-angle std
  double mean_cov_percent = 0.0;      // mean per-angle coefficient of variation (%)
  double rmse_kg_m2 = 0.0;            // sqrt(mean squared residual) of the regression
  int n_angles_with_trials = 0;       // angles with >= 2 trials (0: the first two are undefined)
};

struct EllipseResult {
  // Input and grouping.
  std::vector<EllipsePoint> points;
  int n_points = 0;
  int n_angles = 0;       // angle groups (pitch within angle_group_tol_deg)
  bool weighted = false;  // true when every point had a std (weights 1/std^2)

  // The primary result (linear least squares) with uncertainty.
  double a_kg_m2 = 0.0, b_kg_m2 = 0.0, c_kg_m2 = 0.0;
  EllipseEstimate ix, iz, ixz, tau_deg, ixp, izp;
  double cov_abc[3][3] = {{0}};  // covariance of (A, B, C) (kg^2 m^4)
  EllipseCovariance covariance_used = EllipseCovariance::kPointResiduals;
  double variance_factor = 1.0;  // the scale applied to (X^T W X)^-1
  double dof = 0.0;              // degrees of freedom of the intervals (inf for kAbsolute)
  double reduced_chi2 = 0.0;     // chi^2 / (n - 3) of the points (meaningful when weighted)
  double circle_chi2 = 0.0;      // (B, C) Cov_BC^-1 (B, C)^T, the test statistic for tau
  bool tau_defined = true;       // false when I_x ~ I_z
  int bootstrap_replicates = 0;  // replicates used (0: covariance intervals)

  // The three fits side by side.
  EllipseSolverSummary linear, nelder_mead, ceres;

  double rmse_kg_m2 = 0.0;
  std::vector<EllipseAngleStats> angles;
  EllipseTable1 table1;
  std::vector<EllipseResidual> residuals;
  int n_outliers = 0;
  std::vector<EllipseNacaEstimate> naca;
  std::vector<std::string> warnings;  // human-readable, e.g. tau ill-defined, fits disagree
  // false when the fitted tensor is not one of a body: I_x or I_z <= 0, or I_x I_z <= I_xz^2
  // (a principal moment <= 0); a warning then says so, and the commands exit 1.
  bool physical = true;

  double time_s = 0.0;

  // The primary fit exists and its covariance is finite.
  bool IsUsable() const;
  // A few lines: I_x, I_z, I_xz, tau with errors, RMSE, warnings.
  std::string BriefReport() const;
};

// Fits the ellipse. Returns false with *why set on bad input (fewer than 3 distinct angles mod
// 180 deg, non-finite or non-positive inertia, pitch outside [-180, 180], negative std, bad
// options); then *result is unspecified.
bool FitEllipse(const std::vector<EllipsePoint>& points, const EllipseOptions& options,
                EllipseResult* result, std::string* why);

// Experiment planning: predicted standard errors from the least-squares covariance for a design.
struct EllipsePlanOptions {
  std::vector<double> pitch_deg;  // proposed pitch angles (deg), >= 3 distinct mod 180
  int trials_per_angle = 3;       // trials at each angle, >= 1
  double sigma_kg_m2 = 0.0;       // per-trial standard deviation (kg m^2), in [1e-300, 1e100]
  // Guesses of the aircraft (kg m^2); tau's error depends on I_z - I_x and I_xz.
  double ix_kg_m2 = 0.0;  // > 0
  double iz_kg_m2 = 0.0;  // > 0
  double ixz_kg_m2 = 0.0;
  bool Check(std::string* why) const;
};

struct EllipsePlan {
  int n_points = 0;
  EllipseParameters truth;  // from the guesses
  EllipseParameters std;    // predicted standard errors (tau in deg)
  bool tau_defined = true;  // false when the guessed I_x == I_z and I_xz == 0
};

bool PlanEllipse(const EllipsePlanOptions& options, EllipsePlan* plan, std::string* why);

}  // namespace bifilar
