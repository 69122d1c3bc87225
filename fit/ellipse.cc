// The ellipse fit as a procedure (FitEllipse), its public names and options, the model (the map
// between (A, B, C) and the six quantities) and the first step, preparing the data. The other
// steps live in ellipse_closed_form.cc, ellipse_eq7.cc, ellipse_intervals.cc and
// ellipse_diagnostics.cc; ellipse_steps.h lists them.
#include "fit/ellipse.h"

#include "base/enum_names.h"
#include "base/option_check.h"
#include "fit/ellipse_steps.h"
#include "fit/solver_logging.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <sstream>

namespace bifilar {
namespace ellipse {

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string Num(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

Eigen::RowVector3d DesignRow(double pitch_deg) {
  const double t = 2.0 * pitch_deg * kRadPerDeg;
  return Eigen::RowVector3d(1.0, std::cos(t), std::sin(t));
}

double AxisAngleDeg(double pitch_deg) {
  double a = std::fmod(pitch_deg, 180.0);
  if (a > 90.0) a -= 180.0;
  if (a <= -90.0) a += 180.0;
  return a;
}

Vec6 ToVec(const EllipseParameters& p) {
  Vec6 v;
  v << p.ix_kg_m2, p.iz_kg_m2, p.ixz_kg_m2, p.tau_deg, p.ixp_kg_m2, p.izp_kg_m2;
  return v;
}
EllipseParameters FromVec(const Vec6& v) {
  EllipseParameters p;
  p.ix_kg_m2 = v(0);
  p.iz_kg_m2 = v(1);
  p.ixz_kg_m2 = v(2);
  p.tau_deg = v(3);
  p.ixp_kg_m2 = v(4);
  p.izp_kg_m2 = v(5);
  return p;
}

EllipseParameters SixFromAbc(double a, double b, double c, double two_tau_ref_rad) {
  const double r = std::hypot(b, c);
  double phi = std::atan2(c, b);  // (-pi, pi]
  double sign = 1.0;
  // Shift by multiples of pi (each flips the sign of R) to get within pi/2 of the reference.
  while (phi - two_tau_ref_rad > kPi / 2) {
    phi -= kPi;
    sign = -sign;
  }
  while (phi - two_tau_ref_rad <= -kPi / 2) {
    phi += kPi;
    sign = -sign;
  }
  EllipseParameters p;
  p.ix_kg_m2 = a - b;
  p.iz_kg_m2 = a + b;
  p.ixz_kg_m2 = c;
  p.tau_deg = 0.5 * phi * kDegPerRad;
  p.izp_kg_m2 = a + sign * r;
  p.ixp_kg_m2 = a - sign * r;
  return p;
}

Jac63 SixJacobian(double b, double c, double sign_r) {
  Jac63 j = Jac63::Zero();
  const double r2 = b * b + c * c, r = std::sqrt(r2);
  j.row(0) << 1, -1, 0;
  j.row(1) << 1, 1, 0;
  j.row(2) << 0, 0, 1;
  if (r > 0) {
    j.row(3) << 0, -0.5 * c / r2 * kDegPerRad, 0.5 * b / r2 * kDegPerRad;
    j.row(4) << 1, -sign_r * b / r, -sign_r * c / r;
    j.row(5) << 1, sign_r * b / r, sign_r * c / r;
  }
  return j;
}

Vec6 StdFromCovariance(const Jac63& jac, const Eigen::Matrix3d& cov_abc) {
  const Eigen::Matrix<double, 6, 6> cov6 = jac * cov_abc * jac.transpose();
  Vec6 std6;
  for (int k = 0; k < 6; ++k) std6(k) = std::sqrt(std::max(0.0, cov6(k, k)));
  return std6;
}

namespace {

// One point's values, or false with *why naming the point (1-based).
bool CheckPoint(int index, const EllipsePoint& p, std::string* why) {
  const std::string where = "point " + std::to_string(index + 1) + ": ";
  if (!std::isfinite(p.pitch_deg) || p.pitch_deg < -180.0 || p.pitch_deg > 180.0) {
    *why = where + "pitch_deg must be a finite angle in [-180, 180], got " + Num(p.pitch_deg);
    return false;
  }
  if (!std::isfinite(p.inertia_kg_m2) || p.inertia_kg_m2 <= 0.0) {
    *why = where + "inertia must be finite and > 0, got " + Num(p.inertia_kg_m2);
    return false;
  }
  if (p.std_kg_m2 < 0.0 || std::isinf(p.std_kg_m2)) {
    *why = where + "std must be >= 0 and finite (0 or NaN = unknown), got " + Num(p.std_kg_m2);
    return false;
  }
  // Beyond these the squares and weights of the fit overflow or vanish (the fit would see a
  // "rank-deficient design"); no real moment comes near them, so it is a unit or typing error.
  constexpr double kTiny = 1e-100, kHuge = 1e100;
  if (p.inertia_kg_m2 < kTiny || p.inertia_kg_m2 > kHuge ||
      (p.std_kg_m2 > 0.0 && (p.std_kg_m2 < kTiny || p.std_kg_m2 > kHuge))) {
    *why = where + "inertia " + Num(p.inertia_kg_m2) + " / std " + Num(p.std_kg_m2) +
           " kg m^2 is outside [1e-100, 1e100]: check the units and values of this point";
    return false;
  }
  return true;
}

// Distinct axes: pitch mod 180 clustered with the grouping tolerance (wrapping at +-90).
int CountDistinctAxes(const std::vector<EllipsePoint>& points, double tol_deg) {
  std::vector<double> axis;
  for (const auto& p : points) axis.push_back(AxisAngleDeg(p.pitch_deg));
  std::sort(axis.begin(), axis.end());
  // A cluster spans at most the tolerance from its first axis (as the angle groups): chaining
  // neighbours would make a dense sweep (0.5 deg steps) one "angle".
  int distinct = 0;
  double cluster_start = 0.0;
  for (size_t i = 0; i < axis.size(); ++i) {
    if (i == 0 || axis[i] - cluster_start > tol_deg) {
      ++distinct;
      cluster_start = axis[i];
    }
  }
  if (distinct > 1 && axis.front() + 180.0 - axis.back() <= tol_deg) --distinct;
  return distinct;
}

// Angle groups: pitch within tol_deg of the group's first, in sorted order; with their mean
// pitch, mean moment and weight sum.
std::vector<AngleGroup> GroupByAngle(const std::vector<EllipsePoint>& points,
                                     const Eigen::VectorXd& w, double tol_deg) {
  const int n = static_cast<int>(points.size());
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return points[a].pitch_deg < points[b].pitch_deg; });
  std::vector<AngleGroup> groups;
  for (int i : order) {
    if (groups.empty() ||
        points[i].pitch_deg - points[groups.back().members.front()].pitch_deg > tol_deg) {
      groups.emplace_back();
    }
    groups.back().members.push_back(i);
  }
  for (auto& g : groups) {
    const int count = static_cast<int>(g.members.size());
    double pitch_sum = 0, inertia_sum = 0;
    for (int i : g.members) {
      pitch_sum += points[i].pitch_deg;
      inertia_sum += points[i].inertia_kg_m2;
      g.weight += w(i);
    }
    g.pitch_deg = pitch_sum / count;
    g.mean_kg_m2 = inertia_sum / count;
  }
  return groups;
}

// Groups that hold different pitches (within the tolerance) are one "angle" for Table 1, the
// per-angle statistics and the covariance: their spread then includes the curve's change across
// the group, not only the trials' scatter. Said in one warning naming the merged pitches.
void WarnMergedAngles(const std::vector<EllipsePoint>& points,
                      const std::vector<AngleGroup>& groups, double tol_deg,
                      std::vector<std::string>* warnings) {
  std::string listed;
  int merged = 0;
  for (const AngleGroup& g : groups) {
    double lo = points[g.members.front()].pitch_deg, hi = lo;
    for (int i : g.members) {
      lo = std::min(lo, points[i].pitch_deg);
      hi = std::max(hi, points[i].pitch_deg);
    }
    if (lo == hi) continue;
    if (++merged <= 5) listed += (merged > 1 ? "; " : "") + Num(lo) + " to " + Num(hi) + " deg";
  }
  if (merged == 0) return;
  if (merged > 5) listed += "; ...";
  warnings->push_back(std::to_string(merged) + " angle group" + (merged == 1 ? "" : "s") +
                      " merge different pitches within " + Num(tol_deg) + " deg (" + listed +
                      "): Table 1's per-angle std and CoV then include the curve's change "
                      "across each group, not only the trials' scatter");
}

// kAuto made concrete, then checked against the counts it needs.
bool ResolveCovariance(EllipseCovariance requested, int n_points, int n_groups,
                       EllipseCovariance* mode, std::string* why) {
  *mode = requested;
  if (*mode == EllipseCovariance::kAuto) {
    const bool replicates = n_groups < n_points;
    *mode = (replicates && n_groups >= 6) ? EllipseCovariance::kAngleMeans
                                          : EllipseCovariance::kPointResiduals;
  }
  if (*mode == EllipseCovariance::kPointResiduals && n_points <= 3) {
    *why =
        "need >= 4 points (or a std for every point and covariance 'absolute') to estimate "
        "the uncertainty, got " +
        std::to_string(n_points);
    return false;
  }
  if (*mode == EllipseCovariance::kAngleMeans && n_groups <= 3) {
    *why = "covariance 'angle_means' needs >= 4 angle groups, got " + std::to_string(n_groups);
    return false;
  }
  return true;
}

}  // namespace

bool PrepareData(const std::vector<EllipsePoint>& points, const EllipseOptions& options,
                 PreparedData* data, std::string* why) {
  const int n = static_cast<int>(points.size());
  int n_std_given = 0;
  for (int i = 0; i < n; ++i) {
    if (!CheckPoint(i, points[i], why)) return false;
    if (points[i].std_kg_m2 > 0.0) ++n_std_given;
  }
  const int distinct = CountDistinctAxes(points, options.angle_group_tol_deg);
  if (distinct < 3) {
    *why = "need moments at >= 3 distinct pitch angles (mod 180 deg) to fit the ellipse, got " +
           std::to_string(distinct);
    return false;
  }
  PreparedData& d = *data;
  d.points = points;
  d.n = n;
  d.weighted = (n_std_given == n);
  if (n_std_given > 0 && n_std_given < n) {
    d.warnings.push_back("std given for only " + std::to_string(n_std_given) + " of " +
                         std::to_string(n) + " points: fitted unweighted");
  }
  if (options.covariance == EllipseCovariance::kAbsolute && !d.weighted) {
    *why = "covariance 'absolute' needs a std for every point";
    return false;
  }
  d.x.resize(n, 3);
  d.y.resize(n);
  d.w.resize(n);
  for (int i = 0; i < n; ++i) {
    d.x.row(i) = DesignRow(points[i].pitch_deg);
    d.y(i) = points[i].inertia_kg_m2;
    d.w(i) = d.weighted ? 1.0 / (points[i].std_kg_m2 * points[i].std_kg_m2) : 1.0;
  }
  d.sqrt_w = d.w.cwiseSqrt();
  d.xw = d.sqrt_w.asDiagonal() * d.x;
  d.groups = GroupByAngle(points, d.w, options.angle_group_tol_deg);
  WarnMergedAngles(points, d.groups, options.angle_group_tol_deg, &d.warnings);
  return ResolveCovariance(options.covariance, n, static_cast<int>(d.groups.size()), &d.covariance,
                           why);
}

}  // namespace ellipse

// The rest of this file is the public face and the procedure: its steps by their names.
using namespace ellipse;

// The one table of covariance modes (config `ellipse.covariance`, --covariance, JSON).
constexpr EnumName<EllipseCovariance> kEllipseCovarianceNames[] = {
    {EllipseCovariance::kAuto, "auto"},
    {EllipseCovariance::kPointResiduals, "points"},
    {EllipseCovariance::kAngleMeans, "angle_means"},
    {EllipseCovariance::kAbsolute, "absolute"}};

const char* EllipseCovarianceName(EllipseCovariance mode) {
  return EnumToString(kEllipseCovarianceNames, mode, "?");
}

bool ParseEllipseCovariance(const std::string& name, EllipseCovariance* mode) {
  return ParseEnum(kEllipseCovarianceNames, name, mode);
}

std::string EllipseCovarianceAllowedValues() { return EnumAllowedValues(kEllipseCovarianceNames); }

bool EllipseOptions::Check(std::string* why) const {
  CheckFailure f;
  const bool ok =
      (bootstrap_replicates == 0 ||
       (bootstrap_replicates >= kMinBootstrapReplicates &&
        bootstrap_replicates <= kMaxBootstrapReplicates) ||
       CheckFail("bootstrap_replicates", bootstrap_replicates,
                 "0 (off) or in " +
                     IntervalText(kMinBootstrapReplicates, kMaxBootstrapReplicates, Ends::kClosed),
                 &f)) &&
      CheckIn("confidence", confidence, 0, 1, Ends::kOpen, &f) &&
      CheckIn("angle_group_tol_deg", angle_group_tol_deg, 0, 45, Ends::kClosedOpen, &f) &&
      CheckGt("outlier_threshold", outlier_threshold, 0, &f) &&
      CheckIn("tau_test_alpha", tau_test_alpha, 0, 1, Ends::kOpen, &f) &&
      CheckFiniteGe("common_offset_std_kg_m2", common_offset_std_kg_m2, 0, &f) &&
      CheckIn("naca_exclusion_deg", naca_exclusion_deg, 0, 45, Ends::kClosedOpen, &f);
  return ok || FailWith(f, why);
}

EllipseParameters EllipseFromCoefficients(double a, double b, double c) {
  return SixFromAbc(a, b, c, 0.0);
}

double EllipseMoment(double a, double b, double c, double pitch_deg) {
  return DesignRow(pitch_deg) * Eigen::Vector3d(a, b, c);
}

bool EllipseResult::IsUsable() const {
  return n_points >= 3 && std::isfinite(ixz.std) && std::isfinite(ix.value) &&
         std::isfinite(iz.value);
}

std::string EllipseResult::BriefReport() const {
  std::ostringstream s;
  s.precision(6);
  s << "ellipse fit: " << n_points << " points at " << n_angles << " angles, covariance "
    << EllipseCovarianceName(covariance_used) << "\n";
  s << "  I_x  = " << ix.value << " +- " << ix.std << " kg m^2\n";
  s << "  I_z  = " << iz.value << " +- " << iz.std << " kg m^2\n";
  s << "  I_xz = " << ixz.value << " +- " << ixz.std << " kg m^2\n";
  if (tau_defined) {
    s << "  tau  = " << tau_deg.value << " +- " << tau_deg.std << " deg\n";
  } else {
    s << "  tau  = undefined (I_x ~ I_z)\n";
  }
  s << "  RMSE = " << rmse_kg_m2 << " kg m^2, outliers " << n_outliers << "\n";
  for (const auto& w : warnings) s << "  warning: " << w << "\n";
  return s.str();
}

namespace {

// The steps' outputs gathered into the public result; warnings in the order of the steps.
EllipseResult AssembleResult(PreparedData data, const ClosedFormFit& closed,
                             const Eq7Fit& nelder_mead, const Eq7Fit& ceres,
                             const CovarianceEstimate& cov, const Intervals& intervals,
                             Diagnostics diagnostics) {
  EllipseResult r;
  r.n_points = data.n;
  r.n_angles = static_cast<int>(data.groups.size());
  r.weighted = data.weighted;
  r.points = std::move(data.points);

  r.a_kg_m2 = closed.abc(0);
  r.b_kg_m2 = closed.abc(1);
  r.c_kg_m2 = closed.abc(2);
  const Vec6 value = ToVec(closed.best);
  EllipseEstimate* est[6] = {&r.ix, &r.iz, &r.ixz, &r.tau_deg, &r.ixp, &r.izp};
  for (int k = 0; k < 6; ++k) {
    est[k]->value = value(k);
    est[k]->std = cov.std6(k);
    est[k]->ci_lo = intervals.lo(k);
    est[k]->ci_hi = intervals.hi(k);
    est[k]->defined = (k < 3) || cov.tau_defined;
  }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.cov_abc[i][j] = cov.cov_abc(i, j);
  r.covariance_used = data.covariance;
  r.variance_factor = cov.variance_factor;
  r.dof = cov.dof;
  r.reduced_chi2 = closed.point_var;
  r.circle_chi2 = cov.circle_chi2;
  r.tau_defined = cov.tau_defined;
  r.bootstrap_replicates = intervals.bootstrap_replicates;

  r.linear = closed.summary;
  r.linear.has_std = true;
  r.linear.std = FromVec(cov.std6);
  r.nelder_mead = nelder_mead.summary;
  r.ceres = ceres.summary;
  if (ceres.has_covariance) {
    r.ceres.std = cov.ceres_std;
    r.ceres.has_std = cov.ceres_std_defined;
  }

  r.rmse_kg_m2 = closed.rmse_kg_m2;
  r.angles = std::move(diagnostics.angles);
  r.table1 = diagnostics.table1;
  r.residuals = std::move(diagnostics.residuals);
  r.n_outliers = diagnostics.n_outliers;
  r.naca = std::move(diagnostics.naca);
  r.warnings = std::move(data.warnings);
  r.warnings.insert(r.warnings.end(), cov.warnings.begin(), cov.warnings.end());
  r.warnings.insert(r.warnings.end(), diagnostics.warnings.begin(), diagnostics.warnings.end());
  return r;
}

// A moment of inertia is > 0 and the x-z tensor [[I_x, -I_xz], [-I_xz, I_z]] positive
// definite (both principal moments > 0). A fit that breaks this (an outlier, mixed units) is a
// number no body has: said in a warning that names the moments and the worst point.
void CheckPhysical(EllipseResult* r) {
  const double ix = r->ix.value, iz = r->iz.value, ixz = r->ixz.value;
  const double det = ix * iz - ixz * ixz;
  r->physical = ix > 0.0 && iz > 0.0 && det > 0.0;
  if (r->physical) return;
  const double mean = 0.5 * (ix + iz), half = std::sqrt(0.25 * (ix - iz) * (ix - iz) + ixz * ixz);
  char buffer[400];
  std::snprintf(buffer, sizeof(buffer),
                "non-physical result: I_x = %.6g, I_z = %.6g, I_xz = %.6g kg m^2 give principal "
                "moments %.6g and %.6g; a body's moments are > 0 with I_x I_z > I_xz^2",
                ix, iz, ixz, mean + half, mean - half);
  std::string text = buffer;
  const EllipseResidual* worst = nullptr;
  for (const EllipseResidual& e : r->residuals) {
    if (std::isfinite(e.studentized) &&
        (worst == nullptr || std::abs(e.studentized) > std::abs(worst->studentized))) {
      worst = &e;
    }
  }
  if (worst != nullptr) {
    std::snprintf(buffer, sizeof(buffer),
                  ". Check the table for outliers (point %d at pitch %g deg: %.6g kg m^2, "
                  "studentized residual %.2f) and units",
                  worst->index + 1, worst->pitch_deg, worst->inertia_kg_m2, worst->studentized);
    text += buffer;
  }
  r->warnings.push_back(text);
}

}  // namespace

bool FitEllipse(const std::vector<EllipsePoint>& points, const EllipseOptions& options,
                EllipseResult* result, std::string* why) {
  const auto start = Clock::now();
  QuietSolverLogging();
  if (!options.Check(why)) return false;

  PreparedData data;
  if (!PrepareData(points, options, &data, why)) return false;
  // (a) the primary result, then (b) and (c) on paper Eq. 7 from the paper's start.
  ClosedFormFit closed;
  if (!FitClosedForm(data, &closed, why)) return false;
  const Eq7Problem eq7 = MakeEq7Problem(data, closed);
  const Eq7Fit nelder_mead = options.run_nelder_mead ? FitNelderMead(eq7) : Eq7Fit();
  const Eq7Fit ceres = options.run_ceres ? FitCeres(eq7) : Eq7Fit();
  // Uncertainty and what the fit says about the data.
  const CovarianceEstimate cov = EstimateCovariance(data, closed, ceres, options);
  const Intervals intervals = ComputeIntervals(data, closed, cov, options);
  Diagnostics diagnostics = Diagnose(data, closed, cov, nelder_mead, ceres, options);

  *result = AssembleResult(std::move(data), closed, nelder_mead, ceres, cov, intervals,
                           std::move(diagnostics));
  CheckPhysical(result);
  result->time_s = SecondsSince(start);
  return true;
}

}  // namespace bifilar
