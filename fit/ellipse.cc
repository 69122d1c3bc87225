#include "fit/ellipse.h"

#include "fit/solver_logging.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <queue>
#include <random>
#include <sstream>

#include <Eigen/Dense>
#include <ceres/ceres.h>
#include <nlopt.h>

namespace bifilar {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegToRad = kPi / 180.0;
constexpr double kRadToDeg = 180.0 / kPi;
constexpr double kInf = std::numeric_limits<double>::infinity();

using Clock = std::chrono::steady_clock;
double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Row of the linear design: I = A + B cos 2theta + C sin 2theta.
Eigen::RowVector3d DesignRow(double pitch_deg) {
  const double t = 2.0 * pitch_deg * kDegToRad;
  return Eigen::RowVector3d(1.0, std::cos(t), std::sin(t));
}

// Pitch reduced to the axis angle in (-90, 90] (theta and theta + 180 are the same axis).
double AxisAngleDeg(double pitch_deg) {
  double a = std::fmod(pitch_deg, 180.0);
  if (a > 90.0) a -= 180.0;
  if (a <= -90.0) a += 180.0;
  return a;
}

// Standard normal quantile (Acklam's rational approximation refined by one Halley step; the
// refinement makes it accurate to ~1e-15).
double NormalQuantile(double p) {
  static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02, -2.759285104469687e+02,
                             1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
  static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                             6.680131188771972e+01,  -1.328068155288572e+01};
  static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                             -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                             3.754408661907416e+00};
  double x;
  if (p < 0.02425) {
    const double q = std::sqrt(-2 * std::log(p));
    x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
  } else if (p > 1 - 0.02425) {
    const double q = std::sqrt(-2 * std::log(1 - p));
    x = -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
  } else {
    const double q = p - 0.5, r = q * q;
    x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1);
  }
  const double e = 0.5 * std::erfc(-x / std::sqrt(2.0)) - p;
  const double u = e * std::sqrt(2 * kPi) * std::exp(x * x / 2);
  return x - u / (1 + x * u / 2);
}

// Student-t quantile (Cornish-Fisher expansion in 1/dof; accurate to ~1e-4 for dof >= 3, exact
// in the normal limit). dof = inf gives the normal quantile.
double StudentQuantile(double p, double dof) {
  const double z = NormalQuantile(p);
  if (!std::isfinite(dof)) return z;
  if (dof == 1.0) return std::tan(kPi * (p - 0.5));
  if (dof == 2.0) {
    const double q = 2 * p - 1;
    return q * std::sqrt(2.0 / (1 - q * q));
  }
  const double z2 = z * z, n = dof;
  const double g1 = (z2 + 1) * z / 4;
  const double g2 = ((5 * z2 + 16) * z2 + 3) * z / 96;
  const double g3 = (((3 * z2 + 19) * z2 + 17) * z2 - 15) * z / 384;
  const double g4 = ((((79 * z2 + 776) * z2 + 1482) * z2 - 1920) * z2 - 945) * z / 92160;
  return z + g1 / n + g2 / (n * n) + g3 / (n * n * n) + g4 / (n * n * n * n);
}

// The two quantiles p_lo < p_hi of a stream of `count` values, interpolated linearly between the
// order statistics around p (count - 1) as for a sorted list, keeping only the tails they need:
// the smallest floor(p_lo (count - 1)) + 2 and the largest count - floor(p_hi (count - 1))
// values. Memory does not grow with the data.
class TailQuantiles {
 public:
  TailQuantiles(int count, double p_lo, double p_hi)
      : count_(count), p_lo_(p_lo), p_hi_(p_hi),
        keep_lo_(static_cast<size_t>(std::floor(p_lo * (count - 1))) + 2),
        keep_hi_(static_cast<size_t>(count) -
                 static_cast<size_t>(std::floor(p_hi * (count - 1)))) {}

  void Add(double v) {
    if (low_.size() < keep_lo_) {
      low_.push(v);
    } else if (v < low_.top()) {
      low_.pop();
      low_.push(v);
    }
    if (high_.size() < keep_hi_) {
      high_.push(v);
    } else if (v > high_.top()) {
      high_.pop();
      high_.push(v);
    }
  }

  double Low() const { return FromLow(p_lo_); }
  double High() const { return FromHigh(p_hi_); }

 private:
  // The kept smallest values are sorted[0 .. keep_lo_), the largest sorted[count - keep_hi_ ..
  // count): both hold the two order statistics the interpolation reads.
  double FromLow(double p) const { return Interpolate(Drain(low_), 0, p); }
  double FromHigh(double p) const {
    std::vector<double> v = Drain(high_);
    const size_t first = static_cast<size_t>(count_) - v.size();
    return Interpolate(std::move(v), first, p);
  }
  double Interpolate(std::vector<double> v, size_t first, double p) const {
    std::sort(v.begin(), v.end());
    const double h = p * (count_ - 1);
    const size_t lo = static_cast<size_t>(std::floor(h));
    const size_t hi = std::min(lo + 1, static_cast<size_t>(count_) - 1);
    return v[lo - first] + (h - lo) * (v[hi - first] - v[lo - first]);
  }
  template <typename Heap>
  static std::vector<double> Drain(Heap heap) {
    std::vector<double> v;
    for (; !heap.empty(); heap.pop()) v.push_back(heap.top());
    return v;
  }

  int count_;
  double p_lo_, p_hi_;
  size_t keep_lo_, keep_hi_;
  std::priority_queue<double> low_;                                            // max on top
  std::priority_queue<double, std::vector<double>, std::greater<double>> high_;  // min on top
};

// The six quantities as a vector: Ix, Iz, Ixz, tau_deg, Ixp, Izp.
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Jac63 = Eigen::Matrix<double, 6, 3>;

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

// Six quantities from (A, B, C), choosing the branch of 2 tau nearest two_tau_ref_rad (the
// canonical branch (-90, 90] deg when two_tau_ref_rad == 0 and not at the boundary). R is signed:
// I_zp = A + R, I_xp = A - R, B = R cos 2tau, C = R sin 2tau.
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
  p.tau_deg = 0.5 * phi * kRadToDeg;
  p.izp_kg_m2 = a + sign * r;
  p.ixp_kg_m2 = a - sign * r;
  return p;
}

// Jacobian of the six quantities with respect to (A, B, C) at the canonical branch.
Jac63 SixJacobian(double b, double c, double sign_r) {
  Jac63 j = Jac63::Zero();
  const double r2 = b * b + c * c, r = std::sqrt(r2);
  j.row(0) << 1, -1, 0;
  j.row(1) << 1, 1, 0;
  j.row(2) << 0, 0, 1;
  if (r > 0) {
    j.row(3) << 0, -0.5 * c / r2 * kRadToDeg, 0.5 * b / r2 * kRadToDeg;
    j.row(4) << 1, -sign_r * b / r, -sign_r * c / r;
    j.row(5) << 1, sign_r * b / r, sign_r * c / r;
  }
  return j;
}

// Paper Eq. 7 as a Ceres residual: r = sqrt(w) (I_zp cos^2(theta - tau) + I_xp sin^2(theta - tau)
// - I_measured), parameters p = (I_zp, I_xp, tau_rad).
struct Eq7Residual {
  Eq7Residual(double pitch_rad, double inertia, double sqrt_w)
      : pitch_rad_(pitch_rad), inertia_(inertia), sqrt_w_(sqrt_w) {}
  template <typename T>
  bool operator()(const T* p, T* residual) const {
    const T cs = cos(T(pitch_rad_) - p[2]);
    const T sn = sin(T(pitch_rad_) - p[2]);
    residual[0] = T(sqrt_w_) * (p[0] * cs * cs + p[1] * sn * sn - T(inertia_));
    return true;
  }
  static ceres::CostFunction* Create(double pitch_rad, double inertia, double sqrt_w) {
    return new ceres::AutoDiffCostFunction<Eq7Residual, 1, 3>(
        new Eq7Residual(pitch_rad, inertia, sqrt_w));
  }
  const double pitch_rad_, inertia_, sqrt_w_;
};

void AbcFromEq7(const double* p, Eigen::Vector3d* abc, Eigen::Matrix3d* jac);

// Above this many points, fits (b) and (c) run on the exact sufficient statistics of their
// least-squares cost instead of point by point: Eq. 7 is the linear model in (A, B, C) written
// in other parameters, so sum w (y - f)^2 = chi2_min + (abc - abc_hat)^T N (abc - abc_hat), with
// N = X^T W X and abc_hat the closed-form solution. Same optimum, same J^T J, O(1) per evaluation
// (a 1e6-row table took 50 s and 1.6 GB point by point).
constexpr int kCompressAbovePoints = 4096;

// Eq. 7 against the sufficient statistics: r = U (abc(p) - abc_hat), N = U^T U.
struct Eq7CompressedResidual {
  Eq7CompressedResidual(const Eigen::Matrix3d& u, const Eigen::Vector3d& abc_hat)
      : u_(u), abc_hat_(abc_hat) {}
  template <typename T>
  bool operator()(const T* p, T* residual) const {
    const T a = T(0.5) * (p[0] + p[1]), r = T(0.5) * (p[0] - p[1]);
    const T d[3] = {a - T(abc_hat_(0)), r * cos(T(2) * p[2]) - T(abc_hat_(1)),
                    r * sin(T(2) * p[2]) - T(abc_hat_(2))};
    for (int k = 0; k < 3; ++k) {
      residual[k] = T(u_(k, 0)) * d[0] + T(u_(k, 1)) * d[1] + T(u_(k, 2)) * d[2];
    }
    return true;
  }
  static ceres::CostFunction* Create(const Eigen::Matrix3d& u, const Eigen::Vector3d& abc_hat) {
    return new ceres::AutoDiffCostFunction<Eq7CompressedResidual, 3, 3>(
        new Eq7CompressedResidual(u, abc_hat));
  }
  const Eigen::Matrix3d u_;
  const Eigen::Vector3d abc_hat_;
};

struct Eq7Data {
  const std::vector<double>* pitch_rad;
  const std::vector<double>* inertia;
  const std::vector<double>* weight;
  bool compressed = false;  // use the members below instead of the points
  Eigen::Matrix3d u;        // N = U^T U
  Eigen::Vector3d abc_hat;
  double chi2_min = 0.0;
};

// 0.5 sum w (Eq. 7 - measured)^2, the Nelder-Mead objective (paper Eq. 8 with weights).
double Eq7Cost(unsigned n, const double* p, double* grad, void* data) {
  (void)n;
  (void)grad;
  const auto* d = static_cast<const Eq7Data*>(data);
  if (d->compressed) {
    Eigen::Vector3d abc;
    AbcFromEq7(p, &abc, nullptr);
    return 0.5 * (d->chi2_min + (d->u * (abc - d->abc_hat)).squaredNorm());
  }
  double cost = 0.0;
  for (size_t i = 0; i < d->pitch_rad->size(); ++i) {
    const double cs = std::cos((*d->pitch_rad)[i] - p[2]);
    const double sn = std::sin((*d->pitch_rad)[i] - p[2]);
    const double r = p[0] * cs * cs + p[1] * sn * sn - (*d->inertia)[i];
    cost += (*d->weight)[i] * r * r;
  }
  return 0.5 * cost;
}

// Coefficients (A, B, C) and their Jacobian from Eq. 7 parameters (I_zp, I_xp, tau_rad).
void AbcFromEq7(const double* p, Eigen::Vector3d* abc, Eigen::Matrix3d* jac) {
  const double a = 0.5 * (p[0] + p[1]), r = 0.5 * (p[0] - p[1]);
  const double c2 = std::cos(2 * p[2]), s2 = std::sin(2 * p[2]);
  *abc << a, r * c2, r * s2;
  if (jac != nullptr) {
    *jac << 0.5, 0.5, 0, 0.5 * c2, -0.5 * c2, -2 * r * s2, 0.5 * s2, -0.5 * s2, 2 * r * c2;
  }
}

const char* NloptResultName(nlopt_result r) {
  switch (r) {
    case NLOPT_SUCCESS: return "success";
    case NLOPT_STOPVAL_REACHED: return "stopval reached";
    case NLOPT_FTOL_REACHED: return "ftol reached";
    case NLOPT_XTOL_REACHED: return "xtol reached";
    case NLOPT_MAXEVAL_REACHED: return "maxeval reached";
    case NLOPT_MAXTIME_REACHED: return "maxtime reached";
    case NLOPT_ROUNDOFF_LIMITED: return "roundoff limited";
    default: return "failure";
  }
}

struct Group {
  std::vector<int> members;
  double pitch_deg = 0.0;  // mean pitch
};

std::string Num(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

}  // namespace

const char* EllipseCovarianceName(EllipseCovariance mode) {
  switch (mode) {
    case EllipseCovariance::kAuto: return "auto";
    case EllipseCovariance::kPointResiduals: return "points";
    case EllipseCovariance::kAngleMeans: return "angle_means";
    case EllipseCovariance::kAbsolute: return "absolute";
  }
  return "?";
}

bool ParseEllipseCovariance(const std::string& name, EllipseCovariance* mode) {
  for (EllipseCovariance m : {EllipseCovariance::kAuto, EllipseCovariance::kPointResiduals,
                              EllipseCovariance::kAngleMeans, EllipseCovariance::kAbsolute}) {
    if (name == EllipseCovarianceName(m)) {
      *mode = m;
      return true;
    }
  }
  return false;
}

bool EllipseOptions::Check(std::string* why) const {
  if (bootstrap_replicates < 0 ||
      (bootstrap_replicates > 0 && bootstrap_replicates < kMinBootstrapReplicates) ||
      bootstrap_replicates > kMaxBootstrapReplicates) {
    *why = "bootstrap replicates must be 0 (off) or in [" +
           std::to_string(kMinBootstrapReplicates) + ", " +
           std::to_string(kMaxBootstrapReplicates) + "], got " +
           std::to_string(bootstrap_replicates);
    return false;
  }
  if (!(confidence > 0.0 && confidence < 1.0)) {
    *why = "confidence must be in (0, 1), got " + Num(confidence);
    return false;
  }
  if (!(angle_group_tol_deg >= 0.0 && angle_group_tol_deg < 45.0)) {
    *why = "angle_group_tol_deg must be in [0, 45), got " + Num(angle_group_tol_deg);
    return false;
  }
  if (!(outlier_threshold > 0.0)) {
    *why = "outlier_threshold must be > 0, got " + Num(outlier_threshold);
    return false;
  }
  if (!(tau_test_alpha > 0.0 && tau_test_alpha < 1.0)) {
    *why = "tau_test_alpha must be in (0, 1), got " + Num(tau_test_alpha);
    return false;
  }
  if (!(common_offset_std_kg_m2 >= 0.0 && std::isfinite(common_offset_std_kg_m2))) {
    *why = "common_offset_std_kg_m2 must be finite and >= 0, got " + Num(common_offset_std_kg_m2);
    return false;
  }
  if (!(naca_exclusion_deg >= 0.0 && naca_exclusion_deg < 45.0)) {
    *why = "naca_exclusion_deg must be in [0, 45), got " + Num(naca_exclusion_deg);
    return false;
  }
  return true;
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

bool FitEllipse(const std::vector<EllipsePoint>& points, const EllipseOptions& options,
                EllipseResult* result, std::string* why) {
  const auto start = Clock::now();
  QuietSolverLogging();
  if (!options.Check(why)) return false;
  *result = EllipseResult();
  EllipseResult& res = *result;
  const int n = static_cast<int>(points.size());

  // --- Validate the points.
  int n_std_given = 0;
  for (int i = 0; i < n; ++i) {
    const EllipsePoint& p = points[i];
    const std::string where = "point " + std::to_string(i + 1) + ": ";
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
    if (p.std_kg_m2 > 0.0) ++n_std_given;
  }
  // Distinct axes: pitch mod 180 clustered with the grouping tolerance (wrapping at +-90).
  {
    std::vector<double> axis;
    for (const auto& p : points) axis.push_back(AxisAngleDeg(p.pitch_deg));
    std::sort(axis.begin(), axis.end());
    // A cluster spans at most the tolerance from its first axis (as the angle groups below):
    // chaining neighbours would make a dense sweep (0.5 deg steps) one "angle".
    int distinct = 0;
    double cluster_start = 0.0;
    for (size_t i = 0; i < axis.size(); ++i) {
      if (i == 0 || axis[i] - cluster_start > options.angle_group_tol_deg) {
        ++distinct;
        cluster_start = axis[i];
      }
    }
    if (distinct > 1 && axis.front() + 180.0 - axis.back() <= options.angle_group_tol_deg) {
      --distinct;
    }
    if (distinct < 3) {
      *why = "need moments at >= 3 distinct pitch angles (mod 180 deg) to fit the ellipse, got " +
             std::to_string(distinct);
      return false;
    }
  }
  res.points = points;
  res.n_points = n;
  res.weighted = (n_std_given == n);
  if (n_std_given > 0 && n_std_given < n) {
    res.warnings.push_back("std given for only " + std::to_string(n_std_given) + " of " +
                           std::to_string(n) + " points: fitted unweighted");
  }
  EllipseCovariance mode = options.covariance;
  if (mode == EllipseCovariance::kAbsolute && !res.weighted) {
    *why = "covariance 'absolute' needs a std for every point";
    return false;
  }

  // --- Angle groups (pitch within the tolerance of the group's first, in sorted order).
  std::vector<Group> groups;
  {
    std::vector<int> order(n);
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return points[a].pitch_deg < points[b].pitch_deg; });
    for (int i : order) {
      if (groups.empty() || points[i].pitch_deg - points[groups.back().members.front()].pitch_deg >
                                options.angle_group_tol_deg) {
        groups.emplace_back();
      }
      groups.back().members.push_back(i);
    }
    for (auto& g : groups) {
      double sum = 0;
      for (int i : g.members) sum += points[i].pitch_deg;
      g.pitch_deg = sum / g.members.size();
    }
  }
  const int m = static_cast<int>(groups.size());
  res.n_angles = m;
  const bool replicates = m < n;
  if (mode == EllipseCovariance::kAuto) {
    mode = (replicates && m >= 6) ? EllipseCovariance::kAngleMeans
                                  : EllipseCovariance::kPointResiduals;
  }
  if (mode == EllipseCovariance::kPointResiduals && n <= 3) {
    *why = "need >= 4 points (or a std for every point and covariance 'absolute') to estimate "
           "the uncertainty, got " + std::to_string(n);
    return false;
  }
  if (mode == EllipseCovariance::kAngleMeans && m <= 3) {
    *why = "covariance 'angle_means' needs >= 4 angle groups, got " + std::to_string(m);
    return false;
  }
  res.covariance_used = mode;

  // --- (a) Weighted linear least squares, closed form (QR of the whitened design).
  const auto t_linear = Clock::now();
  Eigen::MatrixXd x(n, 3);
  Eigen::VectorXd y(n), w(n);
  for (int i = 0; i < n; ++i) {
    x.row(i) = DesignRow(points[i].pitch_deg);
    y(i) = points[i].inertia_kg_m2;
    w(i) = res.weighted ? 1.0 / (points[i].std_kg_m2 * points[i].std_kg_m2) : 1.0;
  }
  const Eigen::VectorXd sqrt_w = w.cwiseSqrt();
  const Eigen::MatrixXd xw = sqrt_w.asDiagonal() * x;
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(xw);
  if (qr.rank() < 3) {
    *why = "the pitch angles do not determine the ellipse (rank-deficient design)";
    return false;
  }
  const Eigen::Vector3d abc = qr.solve(sqrt_w.cwiseProduct(y));
  const Eigen::Matrix3d normal_inv = (xw.transpose() * xw).inverse();
  const Eigen::VectorXd fitted = x * abc;
  const Eigen::VectorXd resid = y - fitted;
  const double chi2 = resid.cwiseProduct(resid).dot(w);
  res.a_kg_m2 = abc(0);
  res.b_kg_m2 = abc(1);
  res.c_kg_m2 = abc(2);
  res.rmse_kg_m2 = std::sqrt(resid.squaredNorm() / n);
  const double point_var = n > 3 ? chi2 / (n - 3) : 0.0;
  res.reduced_chi2 = point_var;

  // Group sums of weights, weighted mean measured and fitted values.
  std::vector<double> group_w(m, 0.0);
  double means_ss = 0.0;
  for (int g = 0; g < m; ++g) {
    double sy = 0, sf = 0;
    for (int i : groups[g].members) {
      group_w[g] += w(i);
      sy += w(i) * y(i);
      sf += w(i) * fitted(i);
    }
    const double d = (sy - sf) / group_w[g];
    means_ss += group_w[g] * d * d;
  }
  switch (mode) {
    case EllipseCovariance::kPointResiduals:
      res.variance_factor = point_var;
      res.dof = n - 3;
      break;
    case EllipseCovariance::kAngleMeans:
      res.variance_factor = means_ss / (m - 3);
      res.dof = m - 3;
      break;
    default:
      res.variance_factor = 1.0;
      res.dof = kInf;
      break;
  }
  // The common offset adds to A alone (see EllipseOptions::common_offset_std_kg_m2).
  Eigen::Matrix3d cov = normal_inv * res.variance_factor;
  const double offset_var = options.common_offset_std_kg_m2 * options.common_offset_std_kg_m2;
  cov(0, 0) += offset_var;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) res.cov_abc[r][c] = cov(r, c);

  const EllipseParameters best = SixFromAbc(abc(0), abc(1), abc(2), 0.0);
  const double r_abs = std::hypot(abc(1), abc(2));
  const double sign_r = (best.izp_kg_m2 - best.ixp_kg_m2) >= 0 ? 1.0 : -1.0;
  const Jac63 jac = SixJacobian(abc(1), abc(2), sign_r);
  const Eigen::Matrix<double, 6, 6> cov6 = jac * cov * jac.transpose();
  const Vec6 best_vec = ToVec(best);
  Vec6 std6;
  for (int k = 0; k < 6; ++k) std6(k) = std::sqrt(std::max(0.0, cov6(k, k)));
  // Is the curve distinguishable from a circle? chi^2 of (B, C) against its covariance.
  {
    const Eigen::Matrix2d cov_bc = cov.block<2, 2>(1, 1);
    const Eigen::Vector2d bc(abc(1), abc(2));
    const Eigen::LDLT<Eigen::Matrix2d> ldlt(cov_bc);
    res.circle_chi2 = r_abs == 0.0 ? 0.0
                      : (ldlt.info() == Eigen::Success && cov_bc.determinant() > 0)
                          ? bc.dot(ldlt.solve(bc))
                          : kInf;
  }
  const double chi2_threshold = -2.0 * std::log(options.tau_test_alpha);
  // Below 1e-9 of A the radius is rounding, not a measurement (inputs carry ~16 digits, every
  // real rig fewer than 6): there (B, C) and their covariance are both noise and the chi^2 test
  // alone would give tau from rounding, with an interval that need not contain it.
  constexpr double kRoundingRadius = 1e-9;
  res.tau_defined = r_abs > kRoundingRadius * std::fabs(abc(0)) && res.circle_chi2 > chi2_threshold;
  if (!res.tau_defined) {
    res.warnings.push_back(
        "tau is ill-defined: the data do not distinguish the ellipse from a circle (I_x ~ I_z and "
        "I_xz ~ 0; " +
        (res.circle_chi2 > chi2_threshold
             ? std::string("a circle to rounding")
             : "chi^2 " + Num(res.circle_chi2) + " < " + Num(chi2_threshold)) +
        "); I_xz is "
        "still reported, tau, I_xp and I_zp are not");
  }
  res.linear.method = "linear_ls";
  res.linear.ran = true;
  res.linear.converged = true;
  res.linear.message = "closed form (QR)";
  res.linear.final_cost = 0.5 * chi2;
  res.linear.parameters = best;
  res.linear.has_std = true;
  res.linear.std = FromVec(std6);
  res.linear.time_s = SecondsSince(t_linear);

  // --- Intervals: seeded parametric bootstrap or t/normal quantiles.
  const double alpha = 1.0 - options.confidence;
  Vec6 lo, hi;
  res.bootstrap_replicates = options.bootstrap_replicates;
  if (options.bootstrap_replicates > 0) {
    // Noise is drawn around the fit. With a scale estimated from the data (points or angle
    // means), each replicate first draws its variance factor from the scaled inverse chi^2 of
    // the estimate (dof degrees of freedom), so the linear quantities' bootstrap distribution is
    // the Student-t one and the intervals stay honest with few angles. Angle-means mode draws
    // one error per angle group, shared by its trials.
    //
    // The refit is linear, abc* = abc + S e with S = (X^T W X)^-1 X^T W, so a replicate costs
    // O(1) (independent points: S e ~ N(0, vf (X^T W X)^-1), drawn through its Cholesky factor)
    // or O(angle groups) (one error per group: S summed over each group's members), not O(n);
    // and only the tails of the replicates are kept (TailQuantiles), so memory does not grow
    // with the replicate count.
    const int nb = options.bootstrap_replicates;
    std::mt19937_64 rng(options.seed);
    std::normal_distribution<double> normal(0.0, 1.0);
    std::chi_squared_distribution<double> chi2_dist(std::isfinite(res.dof) ? res.dof : 1.0);
    Eigen::MatrixXd group_solve;  // 3 x m, angle-means mode
    if (mode == EllipseCovariance::kAngleMeans) {
      group_solve = Eigen::MatrixXd::Zero(3, m);
      for (int g = 0; g < m; ++g) {
        for (int i : groups[g].members) {
          group_solve.col(g) += normal_inv * x.row(i).transpose() * w(i);
        }
      }
    }
    const Eigen::Matrix3d chol = Eigen::LLT<Eigen::Matrix3d>(normal_inv).matrixL();
    std::vector<TailQuantiles> tails(6, TailQuantiles(nb, alpha / 2, 1 - alpha / 2));
    for (int b = 0; b < nb; ++b) {
      double vf = res.variance_factor;
      if (std::isfinite(res.dof)) vf *= res.dof / chi2_dist(rng);
      Eigen::Vector3d abc_b = abc;
      if (mode == EllipseCovariance::kAngleMeans) {
        for (int g = 0; g < m; ++g) {
          abc_b += group_solve.col(g) * (std::sqrt(vf / group_w[g]) * normal(rng));
        }
      } else {
        Eigen::Vector3d z;
        for (int k = 0; k < 3; ++k) z(k) = normal(rng);
        abc_b += std::sqrt(vf) * (chol * z);
      }
      if (offset_var > 0.0) abc_b(0) += options.common_offset_std_kg_m2 * normal(rng);
      const Vec6 v = ToVec(SixFromAbc(abc_b(0), abc_b(1), abc_b(2), 2 * best.tau_deg * kDegToRad));
      for (int k = 0; k < 6; ++k) tails[k].Add(v(k));
    }
    for (int k = 0; k < 6; ++k) {
      lo(k) = tails[k].Low();
      hi(k) = tails[k].High();
    }
  } else {
    const double t = StudentQuantile(1 - alpha / 2, res.dof);
    lo = best_vec - t * std6;
    hi = best_vec + t * std6;
  }
  EllipseEstimate* est[6] = {&res.ix, &res.iz, &res.ixz, &res.tau_deg, &res.ixp, &res.izp};
  for (int k = 0; k < 6; ++k) {
    est[k]->value = best_vec(k);
    est[k]->std = std6(k);
    est[k]->ci_lo = lo(k);
    est[k]->ci_hi = hi(k);
    est[k]->defined = (k < 3) || res.tau_defined;
  }

  // --- Residuals, studentized with the point scale (given std when absolute).
  const double point_sigma = mode == EllipseCovariance::kAbsolute ? 1.0 : std::sqrt(point_var);
  for (int i = 0; i < n; ++i) {
    EllipseResidual r;
    r.index = i;
    r.pitch_deg = points[i].pitch_deg;
    r.inertia_kg_m2 = y(i);
    r.fitted_kg_m2 = fitted(i);
    r.residual_kg_m2 = resid(i);
    const double h = w(i) * x.row(i) * normal_inv * x.row(i).transpose();
    const double denom = point_sigma * std::sqrt(std::max(0.0, 1.0 - h));
    r.studentized = denom > 1e-300 && 1.0 - h > 1e-10 ? resid(i) * sqrt_w(i) / denom : 0.0;
    r.outlier = std::fabs(r.studentized) > options.outlier_threshold;
    if (r.outlier) ++res.n_outliers;
    res.residuals.push_back(r);
  }
  if (res.n_outliers > 0) {
    res.warnings.push_back(std::to_string(res.n_outliers) + " point(s) with |studentized residual| > " +
                           Num(options.outlier_threshold) + " (possible outlier trials)");
  }

  // --- Per-angle statistics and the paper's Table 1.
  for (int g = 0; g < m; ++g) {
    EllipseAngleStats st;
    st.pitch_deg = groups[g].pitch_deg;
    st.n = static_cast<int>(groups[g].members.size());
    double sum = 0;
    for (int i : groups[g].members) sum += y(i);
    st.mean_kg_m2 = sum / st.n;
    double ss = 0;
    for (int i : groups[g].members) ss += (y(i) - st.mean_kg_m2) * (y(i) - st.mean_kg_m2);
    st.std_kg_m2 = st.n > 1 ? std::sqrt(ss / (st.n - 1)) : 0.0;
    st.cov_percent = 100.0 * st.std_kg_m2 / st.mean_kg_m2;
    st.fitted_kg_m2 = EllipseMoment(abc(0), abc(1), abc(2), st.pitch_deg);
    if (st.n > 1) {
      res.table1.mean_angle_std_kg_m2 += st.std_kg_m2;
      res.table1.mean_cov_percent += st.cov_percent;
      ++res.table1.n_angles_with_trials;
    }
    res.angles.push_back(st);
  }
  if (res.table1.n_angles_with_trials > 0) {
    res.table1.mean_angle_std_kg_m2 /= res.table1.n_angles_with_trials;
    res.table1.mean_cov_percent /= res.table1.n_angles_with_trials;
  }
  res.table1.rmse_kg_m2 = res.rmse_kg_m2;

  // --- NACA Report 467 three-axis estimates (paper Eq. 1, phi = 90 deg + theta).
  {
    // Standard error of a per-angle mean: the fit's variance factor over the group's weight, so
    // it carries whatever the covariance mode estimated (trial scatter, per-angle errors, or the
    // given std when absolute).
    auto mean_std = [&](int g) { return std::sqrt(res.variance_factor / group_w[g]); };
    // Measured body-axis moments: the angle groups at 0 (I_z) and +-90 deg (I_x).
    auto measured = [&](double axis_deg, double* value, double* std) {
      double sum = 0, var = 0;
      int count = 0;
      for (int g = 0; g < m; ++g) {
        double d = std::fabs(AxisAngleDeg(groups[g].pitch_deg) - axis_deg);
        d = std::min(d, 180.0 - d);
        if (d <= std::max(options.angle_group_tol_deg, 1e-9)) {
          const int ng = static_cast<int>(groups[g].members.size());
          sum += res.angles[g].mean_kg_m2 * ng;
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
    double ix = best.ix_kg_m2, ix_std = std6(0), iz = best.iz_kg_m2, iz_std = std6(1);
    if (!measured(90.0, &ix, &ix_std)) {
      res.warnings.push_back("no moment measured at +-90 deg: NACA estimates use the fitted I_x");
    }
    if (!measured(0.0, &iz, &iz_std)) {
      res.warnings.push_back("no moment measured at 0 deg: NACA estimates use the fitted I_z");
    }
    const double min_sin = std::sin(2 * options.naca_exclusion_deg * kDegToRad);
    for (int g = 0; g < m; ++g) {
      const double phi = (90.0 + groups[g].pitch_deg) * kDegToRad;
      const double s2 = std::sin(2 * phi);
      if (std::fabs(s2) <= min_sin + 1e-12) continue;
      const double c = std::cos(phi), s = std::sin(phi);
      EllipseNacaEstimate e;
      e.pitch_deg = groups[g].pitch_deg;
      e.phi_deg = 90.0 + groups[g].pitch_deg;
      e.i_phi_kg_m2 = res.angles[g].mean_kg_m2;
      e.ixz_kg_m2 = (ix * c * c + iz * s * s - e.i_phi_kg_m2) / s2;
      const double sphi = mean_std(g);
      e.ixz_std_kg_m2 = std::sqrt(sphi * sphi + std::pow(c * c * ix_std, 2) +
                                  std::pow(s * s * iz_std, 2)) / std::fabs(s2);
      res.naca.push_back(e);
    }
  }

  // --- (b) Paper Eq. 7 with Nelder-Mead from the paper's start.
  std::vector<double> pitch_rad(n), inertia(n), weight(n);
  for (int i = 0; i < n; ++i) {
    pitch_rad[i] = points[i].pitch_deg * kDegToRad;
    inertia[i] = y(i);
    weight[i] = w(i);
  }
  // The paper's start: tau = 0, I_zp = the (mean) moment nearest 0 deg, I_xp nearest +-90 deg.
  double start_p[3] = {0, 0, 0};
  {
    double best_z = kInf, best_x = kInf;
    for (int g = 0; g < m; ++g) {
      const double a = AxisAngleDeg(groups[g].pitch_deg);
      if (std::fabs(a) < best_z) {
        best_z = std::fabs(a);
        start_p[0] = res.angles[g].mean_kg_m2;
      }
      if (90.0 - std::fabs(a) < best_x) {
        best_x = 90.0 - std::fabs(a);
        start_p[1] = res.angles[g].mean_kg_m2;
      }
    }
  }
  const double scale = std::max(std::fabs(best.ix_kg_m2), std::fabs(best.iz_kg_m2));
  Eq7Data data;
  data.pitch_rad = &pitch_rad;
  data.inertia = &inertia;
  data.weight = &weight;
  data.compressed = n > kCompressAbovePoints;
  if (data.compressed) {
    // U from the normal matrix (X^T W X)^-1's inverse: the upper Cholesky factor of X^T W X.
    const Eigen::Matrix3d normal = xw.transpose() * xw;
    data.u = Eigen::LLT<Eigen::Matrix3d>(normal).matrixU();
    data.abc_hat = abc;
    data.chi2_min = chi2;
  }
  auto disagreement = [&](const EllipseParameters& p) {
    // Largest difference in I_x, I_z, I_xz relative to the largest moment.
    return std::max({std::fabs(p.ix_kg_m2 - best.ix_kg_m2), std::fabs(p.iz_kg_m2 - best.iz_kg_m2),
                     std::fabs(p.ixz_kg_m2 - best.ixz_kg_m2)}) / scale;
  };
  if (options.run_nelder_mead) {
    const auto t0 = Clock::now();
    EllipseSolverSummary& s = res.nelder_mead;
    s.method = "nelder_mead";
    s.ran = true;
    double p[3] = {start_p[0], start_p[1], start_p[2]};
    s.initial_cost = Eq7Cost(3, p, nullptr, &data);
    nlopt_result status = NLOPT_FAILURE;
    double cost = s.initial_cost;
    // Nelder-Mead stalls on its shrinking simplex before full precision; restarting from its
    // own result with a fresh simplex (smaller steps each time) converges to the least-squares
    // optimum. Stop when a restart no longer moves the point.
    double step_scale = 1.0;
    for (int attempt = 0; attempt < 12; ++attempt) {
      nlopt_opt opt = nlopt_create(NLOPT_LN_NELDERMEAD, 3);
      nlopt_set_min_objective(opt, Eq7Cost, &data);
      const double steps[3] = {std::max(1e-3, 0.05 * std::fabs(p[0])) * step_scale,
                               std::max(1e-3, 0.05 * std::fabs(p[1])) * step_scale,
                               0.05 * step_scale};
      nlopt_set_initial_step(opt, steps);
      nlopt_set_xtol_rel(opt, 1e-15);
      nlopt_set_ftol_rel(opt, 0.0);
      nlopt_set_maxeval(opt, 20000);
      const double before[3] = {p[0], p[1], p[2]};
      status = nlopt_optimize(opt, p, &cost);
      s.iterations += nlopt_get_numevals(opt);
      nlopt_destroy(opt);
      if (status < 0) break;
      const double moved = std::max({std::fabs(p[0] - before[0]) / scale,
                                     std::fabs(p[1] - before[1]) / scale,
                                     std::fabs(p[2] - before[2])});
      if (attempt > 0) ++s.restarts;
      if (attempt > 0 && moved < 1e-14) break;
      step_scale = std::max(1e-6, std::min(1.0, 10 * moved / 0.05));
    }
    s.final_cost = cost;
    s.converged = status > 0;
    s.message = NloptResultName(status);
    Eigen::Vector3d abc_nm;
    AbcFromEq7(p, &abc_nm, nullptr);
    s.parameters = SixFromAbc(abc_nm(0), abc_nm(1), abc_nm(2), 0.0);
    s.time_s = SecondsSince(t0);
  }

  // --- (c) Ceres on Eq. 7 from the same start, with ceres::Covariance.
  if (options.run_ceres) {
    const auto t0 = Clock::now();
    EllipseSolverSummary& s = res.ceres;
    s.method = "ceres";
    s.ran = true;
    double p[3] = {start_p[0], start_p[1], start_p[2]};
    ceres::Problem problem;
    if (data.compressed) {
      problem.AddResidualBlock(Eq7CompressedResidual::Create(data.u, data.abc_hat), nullptr, p);
    } else {
      for (int i = 0; i < n; ++i) {
        problem.AddResidualBlock(Eq7Residual::Create(pitch_rad[i], inertia[i], sqrt_w(i)),
                                 nullptr, p);
      }
    }
    ceres::Solver::Options solver_options;
    solver_options.linear_solver_type = ceres::DENSE_QR;
    solver_options.function_tolerance = 1e-16;
    solver_options.gradient_tolerance = 1e-20;
    solver_options.parameter_tolerance = 1e-16;
    solver_options.max_num_iterations = 200;
    solver_options.num_threads = 1;
    solver_options.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &problem, &summary);
    s.converged = summary.IsSolutionUsable();
    s.message = summary.message;
    s.iterations = static_cast<int>(summary.iterations.size());
    // The compressed cost leaves out the constant 0.5 chi2_min: add it back.
    const double constant = data.compressed ? 0.5 * data.chi2_min : 0.0;
    s.initial_cost = summary.initial_cost + constant;
    s.final_cost = summary.final_cost + constant;
    Eigen::Vector3d abc_c;
    Eigen::Matrix3d jac_c;
    AbcFromEq7(p, &abc_c, &jac_c);
    s.parameters = SixFromAbc(abc_c(0), abc_c(1), abc_c(2), 0.0);
    ceres::Covariance::Options cov_options;
    cov_options.algorithm_type = ceres::DENSE_SVD;
    cov_options.null_space_rank = -1;  // pseudo-inverse: I_x ~ I_z makes tau unidentifiable
    ceres::Covariance covariance(cov_options);
    std::vector<std::pair<const double*, const double*>> blocks = {{p, p}};
    if (s.converged && covariance.Compute(blocks, &problem)) {
      Eigen::Matrix<double, 3, 3, Eigen::RowMajor> cp;
      covariance.GetCovarianceBlock(p, p, cp.data());
      // Ceres gives (J^T J)^-1 in (I_zp, I_xp, tau); map to (A, B, C) and scale like (a).
      const Eigen::Matrix3d cov_c = jac_c * cp * jac_c.transpose() * res.variance_factor;
      const double r_c = std::hypot(abc_c(1), abc_c(2));
      const EllipseParameters& pc = s.parameters;
      const Jac63 j6 = SixJacobian(abc_c(1), abc_c(2), pc.izp_kg_m2 >= pc.ixp_kg_m2 ? 1.0 : -1.0);
      const Eigen::Matrix<double, 6, 6> c6 = j6 * cov_c * j6.transpose();
      Vec6 sd;
      for (int k = 0; k < 6; ++k) sd(k) = std::sqrt(std::max(0.0, c6(k, k)));
      s.std = FromVec(sd);
      s.has_std = r_c > 0;
    }
    s.time_s = SecondsSince(t0);
  }
  // Parity: the nonlinear fits must land on the closed form.
  for (const EllipseSolverSummary* s : {&res.nelder_mead, &res.ceres}) {
    if (!s->ran) continue;
    const double d = disagreement(s->parameters);
    if (!s->converged || d > 1e-6) {
      res.warnings.push_back(s->method + " disagrees with the linear fit (max relative difference " +
                             Num(d) + ", " + s->message + ")");
    }
  }
  res.time_s = SecondsSince(start);
  return true;
}

bool EllipsePlanOptions::Check(std::string* why) const {
  if (trials_per_angle < 1) {
    *why = "trials per angle must be >= 1, got " + std::to_string(trials_per_angle);
    return false;
  }
  if (!(sigma_kg_m2 > 0.0) || !std::isfinite(sigma_kg_m2)) {
    *why = "sigma must be finite and > 0, got " + Num(sigma_kg_m2);
    return false;
  }
  if (!(ix_kg_m2 > 0.0) || !(iz_kg_m2 > 0.0) || !std::isfinite(ix_kg_m2) ||
      !std::isfinite(iz_kg_m2) || !std::isfinite(ixz_kg_m2)) {
    *why = "I_x and I_z guesses must be finite and > 0 and I_xz finite";
    return false;
  }
  for (double a : pitch_deg) {
    if (!std::isfinite(a) || a < -180.0 || a > 180.0) {
      *why = "pitch angles must be in [-180, 180], got " + Num(a);
      return false;
    }
  }
  std::vector<double> axis;
  for (double a : pitch_deg) axis.push_back(AxisAngleDeg(a));
  std::sort(axis.begin(), axis.end());
  axis.erase(std::unique(axis.begin(), axis.end()), axis.end());
  if (axis.size() < 3) {
    *why = "need >= 3 distinct pitch angles (mod 180 deg), got " + std::to_string(axis.size());
    return false;
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
  const Eigen::Matrix3d cov = normal.inverse() * options.sigma_kg_m2 * options.sigma_kg_m2;
  const double a = 0.5 * (options.ix_kg_m2 + options.iz_kg_m2);
  const double b = 0.5 * (options.iz_kg_m2 - options.ix_kg_m2);
  const double c = options.ixz_kg_m2;
  *plan = EllipsePlan();
  plan->n_points = static_cast<int>(options.pitch_deg.size()) * options.trials_per_angle;
  plan->truth = SixFromAbc(a, b, c, 0.0);
  plan->tau_defined = std::hypot(b, c) > 0;
  const double sign_r = plan->truth.izp_kg_m2 >= plan->truth.ixp_kg_m2 ? 1.0 : -1.0;
  const Jac63 j = SixJacobian(b, c, sign_r);
  const Eigen::Matrix<double, 6, 6> c6 = j * cov * j.transpose();
  Vec6 sd;
  for (int k = 0; k < 6; ++k) sd(k) = std::sqrt(std::max(0.0, c6(k, k)));
  plan->std = FromVec(sd);
  return true;
}

}  // namespace bifilar
