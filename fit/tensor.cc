// The tensor fit as a procedure (FitTensor), its public names, and the linear steps: preparing
// the data, the design's rank and row space, the closed form, the covariance and the residuals.
// Ceres lives in tensor_solve.cc, the principal axes and intervals in tensor_principal.cc;
// tensor_steps.h lists the steps. Conventions: fit/tensor.h, docs/physics.md §3.5.
#include "fit/tensor.h"

#include "base/option_check.h"
#include "base/text_format.h"
#include "base/units.h"
#include "fit/distributions.h"
#include "fit/solver_logging.h"
#include "fit/tensor_steps.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

namespace bifilar {
namespace tensor {
namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

Eigen::Vector3d ToVector(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }

}  // namespace

Eigen::Matrix<double, 1, 6> DesignRow(const Eigen::Vector3d& n) {
  Eigen::Matrix<double, 1, 6> row;
  row << n.x() * n.x(), n.y() * n.y(), n.z() * n.z(), -2 * n.x() * n.y(), -2 * n.x() * n.z(),
      -2 * n.y() * n.z();
  return row;
}

Eigen::Matrix3d TensorMatrix(const Vec6& c) {
  Eigen::Matrix3d j;
  j << c(kIxx), -c(kIxy), -c(kIxz), -c(kIxy), c(kIyy), -c(kIyz), -c(kIxz), -c(kIyz), c(kIzz);
  return j;
}

bool PrepareTensorData(const std::vector<TensorPoint>& points, const TensorOptions& options,
                       Prepared* data, std::string* why) {
  Prepared& d = *data;
  d.n = static_cast<int>(points.size());
  if (d.n == 0) {
    *why = "no moments to fit";
    return false;
  }
  int n_std = 0, n_grouped = 0;
  std::vector<Eigen::Vector3d> used(d.n), nominal(d.n);
  for (int i = 0; i < d.n; ++i) {
    const TensorPoint& p = points[i];
    const std::string where = "point " + std::to_string(i + 1) + ": ";
    used[i] = ToVector(p.direction_in_body);
    nominal[i] = ToVector(p.nominal_in_body);
    // Normalised after dividing by the largest component, so no square overflows or underflows:
    // (1e308, 0, 1) used to get norm() = inf and become (0, 0, 0), an axis that silently observed
    // nothing (and, alone, crashed the SVD). Any finite, non-zero vector is an axis.
    const auto axis = [&](const Eigen::Vector3d& v, const char* what, bool zero_allowed,
                          Eigen::Vector3d* unit) {
      const double largest = v.cwiseAbs().maxCoeff();
      if (v.allFinite() && largest > 0) {
        const Eigen::Vector3d scaled = v / largest;
        *unit = scaled / scaled.norm();
        return true;
      }
      if (zero_allowed && largest == 0) return true;
      *why = where + "the " + what + " must be a finite, non-zero vector" +
             (zero_allowed ? " (or all zero: the swing axis)" : "") + ", got (" + Fmt("%g", v(0)) +
             ", " + Fmt("%g", v(1)) + ", " + Fmt("%g", v(2)) + ")";
      return false;
    };
    Eigen::Vector3d nominal_unit = Eigen::Vector3d::Zero();
    if (!axis(used[i], "swing axis", false, &used[i]) ||
        !axis(nominal[i], "nominal swing axis", true, &nominal_unit)) {
      return false;
    }
    nominal[i] = nominal_unit.isZero(0.0) ? used[i] : nominal_unit;
    if (!std::isfinite(p.inertia_kg_m2) || !(p.inertia_kg_m2 > 0.0) || p.inertia_kg_m2 > 1e100 ||
        p.inertia_kg_m2 < 1e-100) {
      *why = where + "inertia must be finite and in [1e-100, 1e100] kg m^2, got " +
             Fmt("%g", p.inertia_kg_m2);
      return false;
    }
    if (p.std_kg_m2 < 0.0 || std::isinf(p.std_kg_m2) || (p.std_kg_m2 > 0 && p.std_kg_m2 < 1e-100)) {
      *why =
          where + "std must be >= 0 and finite (0 or NaN = unknown), got " + Fmt("%g", p.std_kg_m2);
      return false;
    }
    if (p.std_kg_m2 > 0.0) ++n_std;
    if (p.group >= 0) ++n_grouped;
  }
  d.weighted = n_std == d.n;
  if (n_std > 0 && !d.weighted) {
    d.warnings.push_back("std given for only " + std::to_string(n_std) + " of " +
                         std::to_string(d.n) + " points: fitted unweighted");
  }
  if (options.covariance == EllipseCovariance::kAbsolute && !d.weighted) {
    *why = "covariance 'absolute' needs a std for every point";
    return false;
  }
  d.x.resize(d.n, 6);
  d.x_nominal.resize(d.n, 6);
  d.y.resize(d.n);
  d.w.resize(d.n);
  for (int i = 0; i < d.n; ++i) {
    d.x.row(i) = DesignRow(used[i]);
    d.axes.push_back(used[i]);
    d.x_nominal.row(i) = DesignRow(nominal[i]);
    d.y(i) = points[i].inertia_kg_m2;
    d.w(i) = d.weighted ? 1.0 / (points[i].std_kg_m2 * points[i].std_kg_m2) : 1.0;
  }
  d.sqrt_w = d.w.cwiseSqrt();
  // Orientation groups: the given ids when every point has one, else nominal axes within the
  // tolerance of a group's first axis (sign-free: n and -n are one axis).
  const double cos_tol = std::cos(options.group_tol_deg * kRadPerDeg);
  std::vector<int> ids;
  for (int i = 0; i < d.n; ++i) {
    int g = -1;
    if (n_grouped == d.n) {
      for (size_t k = 0; k < ids.size(); ++k) {
        if (ids[k] == points[i].group) g = static_cast<int>(k);
      }
    } else {
      for (size_t k = 0; k < d.group_axis.size(); ++k) {
        if (std::fabs(d.group_axis[k].dot(nominal[i])) >= cos_tol) {
          g = static_cast<int>(k);
          break;
        }
      }
    }
    if (g < 0) {
      g = static_cast<int>(d.groups.size());
      d.groups.emplace_back();
      d.group_axis.push_back(nominal[i]);
      ids.push_back(points[i].group);
    }
    d.groups[g].push_back(i);
  }
  return true;
}

bool AnalyseDesign(const Prepared& data, const TensorOptions& options, Design* design,
                   std::string* why) {
  Design& g = *design;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(data.x_nominal, Eigen::ComputeFullV);
  const Eigen::VectorXd s = svd.singularValues();
  g.singular_values.setZero();
  for (int k = 0; k < s.size() && k < 6; ++k) g.singular_values(k) = s(k);
  const double s_max = s.size() > 0 ? s(0) : 0.0;
  g.rank = 0;
  for (int k = 0; k < s.size(); ++k) {
    if (s(k) > options.rank_tolerance * s_max) ++g.rank;
  }
  if (g.rank == 0) {  // an SVD of the 6 x 0 rest below is undefined (it dereferenced null)
    *why =
        "the swing axes determine none of the six components (the design has rank 0): swing "
        "about more axes";
    return false;
  }
  const Eigen::MatrixXd v = svd.matrixV();
  g.basis = v.leftCols(g.rank);
  g.condition_number = g.rank > 0 ? s_max / s(g.rank - 1) : kInf;
  // A component is observable when its unit vector lies in the row space: no null-space part.
  const Eigen::MatrixXd null_space = v.rightCols(6 - g.rank);
  for (int c = 0; c < 6; ++c) {
    g.observable[c] = g.rank == 6 || null_space.row(c).norm() < 1e-6;
    if (!g.observable[c]) g.unobservable.push_back(TensorComponentName(c));
  }
  // Row-space directions not spanned by the observable components: combinations the data
  // determine without determining their parts. Project the observable unit vectors out.
  Eigen::MatrixXd rest = g.basis;
  for (int c = 0; c < 6; ++c) {
    if (g.observable[c]) rest.row(c).setZero();
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> rest_svd(rest, Eigen::ComputeThinU);
  for (int k = 0; k < rest_svd.singularValues().size(); ++k) {
    if (rest_svd.singularValues()(k) < 1e-6) continue;
    Eigen::VectorXd u = rest_svd.matrixU().col(k);
    int largest = 0;
    u.cwiseAbs().maxCoeff(&largest);
    u /= u(largest);
    std::string text;
    for (int c = 0; c < 6; ++c) {
      if (std::fabs(u(c)) < 1e-6) continue;
      char buffer[48];
      std::snprintf(buffer, sizeof(buffer), "%s%.3g %s",
                    text.empty() ? (u(c) < 0 ? "-" : "") : (u(c) < 0 ? " - " : " + "),
                    std::fabs(u(c)), TensorComponentName(c));
      text += buffer;
    }
    g.combinations.push_back(text);
  }
  if (g.rank == 0 || g.unobservable.size() == 6) {
    *why =
        "the swing axes determine none of the six components (Ixx, Iyy, Izz, Ixy, Ixz, Iyz are "
        "all unobservable";
    if (!g.combinations.empty()) *why += "; only " + g.combinations.front() + " is";
    *why += "): swing about more axes";
    return false;
  }
  // Resolve the covariance mode now that the number of parameters is known.
  return true;
}

bool FitTensorClosedForm(const Prepared& data, const Design& design, Solution* s,
                         std::string* why) {
  const Eigen::MatrixXd z = data.x * design.basis;
  const Eigen::MatrixXd zw = data.sqrt_w.asDiagonal() * z;
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(zw);
  if (qr.rank() < design.rank) {
    *why =
        "the measured swing axes do not determine the components the design should (singular "
        "fit)";
    return false;
  }
  s->gamma = qr.solve(data.sqrt_w.cwiseProduct(data.y));
  s->beta = design.basis * s->gamma;
  s->normal_inv = (zw.transpose() * zw).inverse();
  s->fitted = data.x * s->beta;
  s->resid = data.y - s->fitted;
  s->chi2 = s->resid.cwiseProduct(s->resid).dot(data.w);
  return true;
}

// Per-orientation scatter: component k's variance is sum_i a_ki^2 (s_i^2 + e_i) (+ the common
// offset's), a_k its row of the solution operator, s_i^2 known and e_i estimated in pool p with
// nu_p dof. Welch-Satterthwaite: nu_k = var_k^2 / sum_p (sum_{i in p} a_ki^2 e_i)^2 / nu_p. A
// component that only orientations without scatter feed keeps many dof (its interval ~normal),
// one fed by an orientation whose few logs scatter gets that orientation's few.
namespace {
void ComponentDof(const Prepared& data, const TensorOptions& options, Covariance* c) {
  const Eigen::MatrixXd& a = c->solution_operator;
  const int pools = static_cast<int>(data.pool_dof.size());
  const double off2 = options.common_offset_std_kg_m2 * options.common_offset_std_kg_m2;
  for (int k = 0; k < 6; ++k) {
    std::vector<double> estimated(pools, 0.0);
    double variance = 0.0;
    for (int i = 0; i < data.n; ++i) {
      const double a2 = a(k, i) * a(k, i);
      variance += a2 / data.w(i);
      estimated[data.scatter_pool[i]] += a2 * std::max(0.0, data.scatter_var(i));
    }
    variance += off2 * c->offset_direction(k) * c->offset_direction(k);
    double denominator = 0.0;
    for (int p = 0; p < pools; ++p) denominator += estimated[p] * estimated[p] / data.pool_dof[p];
    c->component_dof(k) = denominator > 0.0 ? std::max(1.0, variance * variance / denominator)
                                            : std::numeric_limits<double>::infinity();
  }
}
}  // namespace

bool EstimateTensorCovariance(const Prepared& data, const Design& design, const Solution& s,
                              const TensorOptions& options, Covariance* c, std::string* why) {
  const int n = data.n, m = static_cast<int>(data.groups.size()), r = design.rank;
  const EllipseCovariance mode =
      data.scale_dof > 0 && data.covariance == EllipseCovariance::kPointResiduals
          ? EllipseCovariance::kAbsolute
          : data.covariance;
  switch (mode) {
    case EllipseCovariance::kPointResiduals:
      if (n <= r) {
        *why = std::to_string(n) + " moments for " + std::to_string(r) +
               " fitted components leave nothing to estimate the scatter: swing more trials or "
               "give every moment a std with covariance 'absolute'";
        return false;
      }
      c->variance_factor = s.chi2 / (n - r);
      c->dof = n - r;
      break;
    case EllipseCovariance::kAngleMeans: {
      if (m <= r) {
        *why = "covariance 'angle_means' needs more orientations (" + std::to_string(m) +
               ") than fitted components (" + std::to_string(r) + ")";
        return false;
      }
      double ss = 0.0;
      for (const std::vector<int>& g : data.groups) {
        double sw = 0, sy = 0, sf = 0;
        for (int i : g) {
          sw += data.w(i);
          sy += data.w(i) * data.y(i);
          sf += data.w(i) * s.fitted(i);
        }
        const double d = (sy - sf) / sw;
        ss += sw * d * d;
      }
      c->variance_factor = ss / (m - r);
      c->dof = m - r;
      break;
    }
    default:
      c->variance_factor = 1.0;
      c->dof = data.scale_dof > 0 ? data.scale_dof : kInf;
      break;
  }
  c->cov_gamma = s.normal_inv * c->variance_factor;
  c->cov = design.basis * c->cov_gamma * design.basis.transpose();
  c->component_dof.setConstant(c->dof);
  const bool per_pool =
      mode == EllipseCovariance::kAbsolute && data.scale_dof > 0 && data.scatter_var.size() == n;
  // A common offset c adds c to every moment: the components answer with S 1, S the solution
  // operator (for a full design exactly (1, 1, 1, 0, 0, 0)).
  const Eigen::MatrixXd z = data.x * design.basis;
  const Eigen::VectorXd response =
      s.normal_inv * (z.transpose() * data.w);  // S 1 in row-space coordinates
  c->offset_direction = design.basis * response;
  const double off = options.common_offset_std_kg_m2;
  c->cov += off * off * c->offset_direction * c->offset_direction.transpose();
  c->per_pool = per_pool;
  if (per_pool) {
    c->solution_operator = design.basis * s.normal_inv * z.transpose() * data.w.asDiagonal();
    ComponentDof(data, options, c);
  }
  return true;
}

}  // namespace tensor

using namespace tensor;

const char* TensorComponentName(int component) {
  static const char* const kNames[] = {"Ixx", "Iyy", "Izz", "Ixy", "Ixz", "Iyz"};
  return component >= 0 && component < 6 ? kNames[component] : "?";
}

std::array<double, 3> DownInBodyFromAttitude(double roll_deg, double pitch_deg) {
  const double t = pitch_deg * kRadPerDeg, f = roll_deg * kRadPerDeg;
  return {-std::sin(t), std::sin(f) * std::cos(t), std::cos(f) * std::cos(t)};
}

double TensorMoment(const std::array<double, kTensorComponents>& c,
                    const std::array<double, 3>& n) {
  Vec6 beta;
  for (int k = 0; k < 6; ++k) beta(k) = c[k];
  // Scaled by the largest component first: no square of a huge or tiny component overflows.
  Eigen::Vector3d u(n[0], n[1], n[2]);
  u /= u.cwiseAbs().maxCoeff();
  u.normalize();
  return DesignRow(u) * beta;
}

bool TensorOptions::Check(std::string* why) const {
  EllipseOptions e;
  e.bootstrap_replicates = bootstrap_replicates;
  e.confidence = confidence;
  e.outlier_threshold = outlier_threshold;
  e.common_offset_std_kg_m2 = common_offset_std_kg_m2;
  if (!e.Check(why)) return false;
  CheckFailure f;
  return (CheckIn("group_tol_deg", group_tol_deg, 0, 45, Ends::kClosedOpen, &f) &&
          CheckIn("rank_tolerance", rank_tolerance, 0, 1, Ends::kOpen, &f)) ||
         FailWith(f, why);
}

bool TensorResult::IsUsable() const {
  for (const TensorEstimate& e : components) {
    if (e.observable && std::isfinite(e.value) && std::isfinite(e.std)) return true;
  }
  return false;
}

std::string TensorResult::BriefReport() const {
  std::ostringstream s;
  s.precision(6);
  s << "tensor fit: " << n_points << " moments about " << n_orientations << " axes, rank " << rank
    << ", condition " << condition_number << ", covariance "
    << EllipseCovarianceName(covariance_used) << "\n";
  for (int k = 0; k < 6; ++k) {
    s << "  " << TensorComponentName(k) << " = ";
    if (components[k].observable) {
      s << components[k].value << " +- " << components[k].std << " kg m^2\n";
    } else {
      s << "not observable\n";
    }
  }
  if (full) {
    s << "  principal moments: ";
    for (int k = 0; k < 3; ++k) {
      s << (k ? ", " : "") << principal_moments[k].value << " +- " << principal_moments[k].std;
    }
    s << " kg m^2\n";
  }
  for (const std::string& w : warnings) s << "  warning: " << w << "\n";
  return s.str();
}

namespace {

// Point and orientation residuals (studentized with the hat matrix of the reduced fit).
void DiagnoseTensor(const Prepared& data, const Design& design, const Solution& s,
                    const Covariance& cov, const TensorOptions& options, TensorResult* r) {
  const Eigen::MatrixXd z = data.x * design.basis;
  r->orientations.resize(data.groups.size());
  std::vector<int> orientation_of(data.n, 0);
  for (size_t g = 0; g < data.groups.size(); ++g) {
    TensorOrientation& o = r->orientations[g];
    o.members = data.groups[g];
    for (int k = 0; k < 3; ++k) o.nominal_in_body[k] = data.group_axis[g](k);
    double sw = 0, sy = 0, sf = 0, sum = 0, sum2 = 0;
    for (int i : o.members) {
      orientation_of[i] = static_cast<int>(g);
      sw += data.w(i);
      sy += data.w(i) * data.y(i);
      sf += data.w(i) * s.fitted(i);
      sum += data.y(i);
      sum2 += data.y(i) * data.y(i);
    }
    const double count = static_cast<double>(o.members.size());
    o.mean_kg_m2 = sy / sw;
    o.fitted_kg_m2 = sf / sw;
    o.residual_kg_m2 = o.mean_kg_m2 - o.fitted_kg_m2;
    o.residual_std_kg_m2 = std::sqrt(cov.variance_factor / sw);
    o.z = o.residual_std_kg_m2 > 0 ? o.residual_kg_m2 / o.residual_std_kg_m2 : 0.0;
    o.scatter_kg_m2 =
        count > 1 ? std::sqrt(std::max(0.0, (sum2 - sum * sum / count) / (count - 1))) : 0.0;
  }
  for (int i = 0; i < data.n; ++i) {
    TensorPointResidual p;
    p.index = i;
    p.orientation = orientation_of[i];
    p.inertia_kg_m2 = data.y(i);
    p.fitted_kg_m2 = s.fitted(i);
    p.residual_kg_m2 = s.resid(i);
    const double h = data.w(i) * z.row(i) * s.normal_inv * z.row(i).transpose();
    const double denominator = cov.variance_factor * (1.0 - h) / data.w(i);
    p.studentized = denominator > 0 ? s.resid(i) / std::sqrt(denominator) : 0.0;
    p.outlier = std::fabs(p.studentized) > options.outlier_threshold;
    r->n_outliers += p.outlier;
    r->residuals.push_back(p);
  }
}

// d I(n) / d(axis): the moment's sensitivity to tilting the axis, |2 (J n - (n^T J n) n)| per
// rad (the gradient of n^T J n on the unit sphere), at the fitted tensor.
Eigen::VectorXd AttitudeSensitivity(const Prepared& data, const Vec6& beta) {
  const Eigen::Matrix3d j = TensorMatrix(beta);
  Eigen::VectorXd g(data.n);
  for (int i = 0; i < data.n; ++i) {
    // The used direction from its design row: (nx^2, ny^2, nz^2, -2 nx ny, ...) is not
    // invertible in sign, so keep the unit axes in Prepared.
    const Eigen::Vector3d& n = data.axes[i];
    const Eigen::Vector3d jn = j * n;
    g(i) = 2.0 * (jn - n.dot(jn) * n).norm();
  }
  return g;
}

double ReweighPerOrientation(const Design& design, Prepared* data, Solution* fit,
                             std::vector<double>* by_group);

// A swing axis is known only to within the attitude the aircraft hung at (set by hand, or
// measured by an accelerometer with a bias): an error of sigma_a rad about a horizontal axis moves
// the moment by g_i sigma_a, far above a trace fit's own std (1e-4 of I against ~1e-3 for 0.5
// deg). With a full design the fit weighs each point by 1/(s_i^2 + sigma_a^2 g_i^2), sigma_a
// solved from the residuals (sum r_i^2 / (s_i^2 + sigma_a^2 g_i^2) = n - rank, the Paule-Mandel
// equation), refitting with the new weights until they settle. Returns sigma_a (rad; 0 when the
// stated stds explain the scatter or the design is not full or unweighted), NaN when a refit fails.
// With a design that is not full (three axes, say, often principal ones, where g_i ~ 0) the
// same equation is solved for a relative scatter instead, s_i^2 + (sigma_r I_i)^2: repeats of a
// real rig scatter by 0.2-0.3 % (release amplitude, hanging) where each log's std says 0.02-0.15 %.
// *relative receives sigma_r (0 when not used).
double ReweighForAttitudeScatter(const Design& design, const TensorOptions& options, Prepared* data,
                                 Solution* fit, double* relative, std::vector<double>* by_group) {
  *relative = 0.0;
  if (!options.attitude_scatter || !data->weighted || data->n <= design.rank) return 0.0;
  const bool full = design.rank == 6;
  if (!full) {
    *relative = ReweighPerOrientation(design, data, fit, by_group);
    return std::isfinite(*relative) ? 0.0 : NAN;
  }
  const Eigen::VectorXd s2 = data->w.cwiseInverse();  // the stated variances
  double sigma2 = 0.0;
  for (int iteration = 0; iteration < 8; ++iteration) {
    const Eigen::VectorXd g2 =
        full ? Eigen::VectorXd(AttitudeSensitivity(*data, fit->beta).array().square())
             : Eigen::VectorXd(fit->fitted.array().square());
    const Eigen::VectorXd r2 = fit->resid.array().square();
    auto excess = [&](double v) {
      return (r2.array() / (s2.array() + v * g2.array())).sum() - (data->n - design.rank);
    };
    double next = 0.0;
    if (excess(0.0) > 0.0) {
      double lo = 0.0, hi = 1e-6;
      while (excess(hi) > 0.0 && hi < 1.0) hi *= 4.0;  // 1 rad^2: beyond any attitude error
      for (int k = 0; k < 100; ++k) {
        const double mid = 0.5 * (lo + hi);
        (excess(mid) > 0.0 ? lo : hi) = mid;
      }
      next = 0.5 * (lo + hi);
    }
    const bool settled = std::fabs(next - sigma2) <= 1e-4 * std::max(next, 1e-300);
    sigma2 = next;
    data->w = (s2.array() + sigma2 * g2.array()).inverse().matrix();
    data->sqrt_w = data->w.cwiseSqrt();
    std::string why;
    if (!FitTensorClosedForm(*data, design, fit, &why)) return NAN;
    if (settled) break;
  }
  if (!full) {
    *relative = std::sqrt(sigma2);
    return 0.0;
  }
  return std::sqrt(sigma2);
}

// Designs that are not full (three axes, say): a scatter of the moments beyond their stds is
// sought where it is. Each orientation's points have n_g - h_g degrees of freedom (h_g its share of
// the hat matrix); an orientation whose chi^2 per dof exceeds the others' at p < 0.01 (F test)
// gets a relative scatter of its own, solved on its points alone (sum r^2 / (s^2 + (sigma_g
// I)^2) = its dof); the others share one (the Paule-Mandel equation over their points). So an
// attitude whose logs scatter widens its own components only. *by_group: each orientation's
// relative scatter (0 when none); returns the shared one; the dof of the shared one go to
// data->scale_dof. NaN when a refit fails.
double ReweighPerOrientation(const Design& design, Prepared* data, Solution* fit,
                             std::vector<double>* by_group) {
  const int m = static_cast<int>(data->groups.size());
  const Eigen::VectorXd s2 = data->w.cwiseInverse();
  std::vector<bool> own(m, false);
  std::vector<double> sigma2(m, 0.0);
  double shared2 = 0.0, shared_dof = 0.0;
  std::vector<double> dof(m);  // each orientation's, as its scatter was solved with
  for (int iteration = 0; iteration < 8; ++iteration) {
    const Eigen::MatrixXd z = data->x * design.basis;
    const Eigen::VectorXd r2 = fit->resid.array().square();
    const Eigen::VectorXd i2 = fit->fitted.array().square();
    std::vector<double> chi2(m, 0.0);
    dof.assign(m, 0.0);
    for (int g = 0; g < m; ++g) {
      for (int i : data->groups[g]) {
        dof[g] += 1.0 - data->w(i) * z.row(i) * fit->normal_inv * z.row(i).transpose();
        chi2[g] += r2(i) / s2(i);
      }
    }
    // Which orientations scatter beyond the others (on the stated stds alone).
    double chi2_all = 0.0, dof_all = 0.0;
    for (int g = 0; g < m; ++g) {
      chi2_all += chi2[g];
      dof_all += dof[g];
    }
    for (int g = 0; g < m; ++g) {
      const double rest_dof = dof_all - dof[g], rest_chi2 = chi2_all - chi2[g];
      own[g] = dof[g] > 0.5 && rest_dof > 0.5 && rest_chi2 > 0 && chi2[g] / dof[g] > 1.0 &&
               FUpperTail((chi2[g] / dof[g]) / (rest_chi2 / rest_dof), dof[g], rest_dof) < 0.01;
    }
    // Solve sum r^2 / (s^2 + v I^2) = target over `members` for v >= 0.
    const auto solve = [&](const std::vector<int>& members, double target) {
      auto excess = [&](double v) {
        double sum = 0.0;
        for (int i : members) sum += r2(i) / (s2(i) + v * i2(i));
        return sum - target;
      };
      if (!(target > 0) || excess(0.0) <= 0.0) return 0.0;
      double lo = 0.0, hi = 1e-8;
      while (excess(hi) > 0.0 && hi < 1.0) hi *= 4.0;
      for (int k = 0; k < 100; ++k) {
        const double mid = 0.5 * (lo + hi);
        (excess(mid) > 0.0 ? lo : hi) = mid;
      }
      return 0.5 * (lo + hi);
    };
    std::vector<int> shared_members;
    shared_dof = 0.0;
    for (int g = 0; g < m; ++g) {
      if (own[g]) {
        sigma2[g] = solve(data->groups[g], dof[g]);
      } else {
        shared_members.insert(shared_members.end(), data->groups[g].begin(), data->groups[g].end());
        shared_dof += dof[g];
      }
    }
    const double next_shared = solve(shared_members, shared_dof);
    const bool settled = std::fabs(next_shared - shared2) <= 1e-4 * std::max(next_shared, 1e-300);
    shared2 = next_shared;
    for (int g = 0; g < m; ++g) {
      const double v = own[g] ? sigma2[g] : shared2;
      for (int i : data->groups[g]) data->w(i) = 1.0 / (s2(i) + v * i2(i));
    }
    data->sqrt_w = data->w.cwiseSqrt();
    std::string why;
    if (!FitTensorClosedForm(*data, design, fit, &why)) return NAN;
    if (settled && iteration > 0) break;
  }
  by_group->assign(m, 0.0);
  for (int g = 0; g < m; ++g) (*by_group)[g] = std::sqrt(own[g] ? sigma2[g] : shared2);
  data->scale_dof = std::max(shared_dof, 1.0);
  // The estimated part of each point's variance and the pool it was estimated in (pool 0: the
  // shared one; then one per orientation with its own scatter), for the components' dof.
  data->scatter_var = data->w.cwiseInverse() - s2;
  data->scatter_pool.assign(data->n, 0);
  data->pool_dof.assign(1, data->scale_dof);
  for (int g = 0; g < m; ++g) {
    if (!own[g]) continue;
    data->pool_dof.push_back(std::max(dof[g], 1.0));
    for (int i : data->groups[g])
      data->scatter_pool[i] = static_cast<int>(data->pool_dof.size()) - 1;
  }
  return std::sqrt(shared2);
}

// Lack-of-fit F test at 5 %: do the orientations' means scatter about the fit more than their
// trials scatter about the means? Needs repeats and more orientations than components.
bool OrientationsScatterBeyondTrials(const Prepared& data, const Design& design,
                                     const Solution& fit) {
  const int n = data.n, m = static_cast<int>(data.groups.size()), r = design.rank;
  if (m >= n || m <= r) return false;
  double pure = 0.0, lack = 0.0;
  for (const std::vector<int>& g : data.groups) {
    double sw = 0, sy = 0, sf = 0;
    for (int i : g) {
      sw += data.w(i);
      sy += data.w(i) * data.y(i);
      sf += data.w(i) * fit.fitted(i);
    }
    const double mean = sy / sw, fitted = sf / sw;
    for (int i : g) pure += data.w(i) * (data.y(i) - mean) * (data.y(i) - mean);
    lack += sw * (mean - fitted) * (mean - fitted);
  }
  if (!(pure > 0.0)) return lack > 0.0;
  const double f = (lack / (m - r)) / (pure / (n - m));
  return FUpperTail(f, m - r, n - m) < 0.05;
}

// The covariance mode (kAuto: orientation means when the orientations scatter beyond their
// trials, points otherwise).
EllipseCovariance CovarianceMode(const Prepared& data, const Design& design, const Solution& closed,
                                 const TensorOptions& options) {
  if (options.covariance != EllipseCovariance::kAuto) return options.covariance;
  return OrientationsScatterBeyondTrials(data, design, closed) ? EllipseCovariance::kAngleMeans
                                                               : EllipseCovariance::kPointResiduals;
}

// Counts, design, covariance mode and goodness of fit of the solution.
void FillFitSummary(const Prepared& data, const Design& design, const Solution& solved,
                    const Covariance& cov, TensorResult* result) {
  TensorResult& r = *result;
  r.n_points = data.n;
  r.n_orientations = static_cast<int>(data.groups.size());
  r.rank = design.rank;
  r.weighted = data.weighted;
  r.full = design.rank == 6;
  r.condition_number = design.condition_number;
  for (int k = 0; k < 6; ++k) r.design_singular_values[k] = design.singular_values(k);
  r.covariance_used = data.covariance;
  r.variance_factor = cov.variance_factor;
  r.dof = cov.dof;
  r.reduced_chi2 = data.n > design.rank ? solved.chi2 / (data.n - design.rank) : 0.0;
  r.rmse_kg_m2 = std::sqrt(solved.resid.squaredNorm() / data.n);
  r.unobservable = design.unobservable;
  r.observable_combinations = design.combinations;
}

// Ceres against the closed form, relative to the largest moment; warns above 1e-6.
void CompareWithClosedForm(const Solution& closed, const Solution& solved, TensorResult* result) {
  TensorResult& r = *result;
  double scale = 0.0;
  for (int k = 0; k < 3; ++k) scale = std::max(scale, std::fabs(closed.beta(k)));
  for (int k = 0; k < 6; ++k) {
    r.closed_form_max_relative_difference =
        std::max(r.closed_form_max_relative_difference,
                 std::fabs(solved.beta(k) - closed.beta(k)) / std::max(scale, 1e-300));
  }
  if (r.closed_form_max_relative_difference > 1e-6) {
    r.warnings.push_back("Ceres and the closed form disagree by " +
                         Fmt("%g", r.closed_form_max_relative_difference) +
                         " of the largest moment");
  }
}

// The six components with their std, intervals and covariance (NaN where not observable).
void FillComponents(const Design& design, const Solution& solved, const Covariance& cov,
                    const TensorIntervalSet& intervals, TensorResult* result) {
  TensorResult& r = *result;
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  for (int k = 0; k < 6; ++k) {
    TensorEstimate& e = r.components[k];
    e.observable = design.observable[k];
    e.value = e.observable ? solved.beta(k) : kNaN;
    e.std = e.observable ? std::sqrt(std::max(0.0, cov.cov(k, k))) : kNaN;
    e.ci_lo = e.observable ? intervals.lo(k) : kNaN;
    e.ci_hi = e.observable ? intervals.hi(k) : kNaN;
    e.dof = cov.component_dof(k);
    for (int l = 0; l < 6; ++l) {
      r.covariance[k][l] = design.observable[k] && design.observable[l] ? cov.cov(k, l) : kNaN;
    }
  }
}

// Names the components the swing axes cannot see, and the combinations they can.
void WarnUnobservable(TensorResult* result) {
  TensorResult& r = *result;
  if (r.unobservable.empty()) return;
  std::string names;
  for (const std::string& u : r.unobservable) names += (names.empty() ? "" : ", ") + u;
  std::string text = "not observable from these swing axes: " + names;
  if (!r.observable_combinations.empty()) {
    text += " (the data determine only";
    for (size_t k = 0; k < r.observable_combinations.size(); ++k) {
      text += (k ? "; " : " ") + r.observable_combinations[k];
    }
    text += ")";
  }
  r.warnings.push_back(text + "; swing about axes that mix them to measure them");
}

// Principal moments, axes and Euler angles of a full tensor (NaN otherwise).
void FillPrincipal(const Solution& solved, const Covariance& cov,
                   const TensorIntervalSet& intervals, const TensorOptions& options,
                   TensorResult* result) {
  TensorResult& r = *result;
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  if (!r.full) {
    for (int k = 0; k < 3; ++k) {
      r.principal_moments[k] = {kNaN, kNaN, kNaN, kNaN, false};
      r.euler_deg[k] = {kNaN, kNaN, kNaN, kNaN, false};
      r.principal_axes_std_deg[k] = kNaN;
      r.principal_moments_matched_kg_m2[k] = kNaN;
      for (int c = 0; c < 3; ++c) r.principal_axes[k][c] = kNaN;
    }
    return;
  }
  const Principal p = ComputePrincipal(solved.beta, cov.cov);
  for (int k = 0; k < 3; ++k) {
    r.principal_moments[k] = {p.moments(k), p.moments_std(k), intervals.principal_lo(k),
                              intervals.principal_hi(k), true};
    for (int c = 0; c < 3; ++c) r.principal_axes[k][c] = p.axes(c, k);
    r.principal_axes_std_deg[k] = p.axes_std_deg(k);
    // Euler intervals: normal, value -+ z std (first order; the angles are not bootstrapped).
    const double z = NormalQuantile(0.5 + 0.5 * options.confidence);
    r.euler_deg[k] = {p.euler_deg(k), p.euler_std_deg(k), p.euler_deg(k) - z * p.euler_std_deg(k),
                      p.euler_deg(k) + z * p.euler_std_deg(k), true};
    r.principal_moments_matched_kg_m2[k] = p.matched_moments(k);
  }
  r.warnings.insert(r.warnings.end(), p.warnings.begin(), p.warnings.end());
  if (r.condition_number > 100) {
    r.warnings.push_back("the swing axes are nearly degenerate (design condition number " +
                         Fmt("%g", r.condition_number) +
                         "): some components are poorly determined");
  }
}

}  // namespace

bool FitTensor(const std::vector<TensorPoint>& points, const TensorOptions& options,
               TensorResult* result, std::string* why) {
  const auto start = std::chrono::steady_clock::now();
  if (!FitTensorOnce(points, options, result, why)) return false;
  CheckTensorPhysical(points, options, result);
  result->time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return true;
}

namespace tensor {

bool FitTensorOnce(const std::vector<TensorPoint>& points, const TensorOptions& options,
                   TensorResult* result, std::string* why) {
  const auto start = std::chrono::steady_clock::now();
  QuietSolverLogging();
  if (!options.Check(why)) return false;
  Prepared data;
  if (!PrepareTensorData(points, options, &data, why)) return false;
  Design design;
  if (!AnalyseDesign(data, options, &design, why)) return false;
  Solution closed;
  if (!FitTensorClosedForm(data, design, &closed, why)) return false;
  // Each axis is known to within an attitude error: weights 1/(s_i^2 + sigma_a^2 g_i^2).
  double relative_scatter = 0.0;
  std::vector<double> scatter_by_orientation;
  const double attitude_scatter_rad = ReweighForAttitudeScatter(
      design, options, &data, &closed, &relative_scatter, &scatter_by_orientation);
  if (!std::isfinite(attitude_scatter_rad)) {
    *why = "the refit with the attitude scatter failed (singular fit)";
    return false;
  }
  data.covariance = CovarianceMode(data, design, closed, options);
  TensorResult r;
  const Solution solved = FitTensorCeres(data, design, closed, &r.ceres);
  Covariance cov;
  if (!EstimateTensorCovariance(data, design, solved, options, &cov, why)) return false;
  FillFitSummary(data, design, solved, cov, &r);
  r.attitude_scatter_deg = attitude_scatter_rad * kDegPerRad;
  r.relative_scatter = relative_scatter;
  r.orientation_relative_scatter = scatter_by_orientation;
  CompareWithClosedForm(closed, solved, &r);
  const TensorIntervalSet intervals = TensorIntervals(data, design, solved, cov, options, r.full);
  r.bootstrap_replicates = intervals.replicates;
  FillComponents(design, solved, cov, intervals, &r);
  WarnUnobservable(&r);
  FillPrincipal(solved, cov, intervals, options, &r);
  DiagnoseTensor(data, design, solved, cov, options, &r);
  r.warnings.insert(r.warnings.begin(), data.warnings.begin(), data.warnings.end());
  r.warnings.insert(r.warnings.end(), cov.warnings.begin(), cov.warnings.end());
  r.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  *result = std::move(r);
  return true;
}

}  // namespace tensor
}  // namespace bifilar
