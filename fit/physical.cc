// CheckPhysical (fit/physical.h): the triangle inequalities and positive definiteness of fitted
// moments, each margin with its first-order std from the components' covariance.
#include "fit/physical.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "base/enum_names.h"
#include "base/text_format.h"
#include "fit/distributions.h"

namespace bifilar {
namespace physical {

constexpr double kPhysicalUnknown = std::numeric_limits<double>::quiet_NaN();
using PhysicalVec = Eigen::Matrix<double, 6, 1>;
using PhysicalCov = Eigen::Matrix<double, 6, 6>;

constexpr EnumName<PhysicalStatus> kPhysicalStatusNames[] = {
    {PhysicalStatus::kNotChecked, "not_checked"},
    {PhysicalStatus::kPhysical, "physical"},
    {PhysicalStatus::kBorderline, "borderline"},
    {PhysicalStatus::kNotPhysical, "not_physical"}};

// d(n^T J n)/d(components) for the unit axis n: (nx^2, ny^2, nz^2, -2 nx ny, -2 nx nz, -2 ny nz).
PhysicalVec MomentGradient(const Eigen::Vector3d& n) {
  PhysicalVec g;
  g << n.x() * n.x(), n.y() * n.y(), n.z() * n.z(), -2 * n.x() * n.y(), -2 * n.x() * n.z(),
      -2 * n.y() * n.z();
  return g;
}

// One inequality: margin = gradient . components (linear) or given, std = sqrt(g^T C g).
PhysicalInequality Inequality(const std::string& name, double margin, const PhysicalVec& gradient,
                              const PhysicalCov& cov, const Eigen::Vector3d& against) {
  PhysicalInequality q;
  for (int k = 0; k < 3; ++k) q.against_axis[k] = against(k);
  q.name = name;
  q.margin_kg_m2 = margin;
  const double var = gradient.dot(cov * gradient);
  q.std_kg_m2 = std::sqrt(std::max(0.0, var));
  q.z = q.std_kg_m2 > 0 ? margin / q.std_kg_m2
                        : (margin >= 0 ? std::numeric_limits<double>::infinity()
                                       : -std::numeric_limits<double>::infinity());
  return q;
}

// Principal axes named by the body axis nearest each (x', y', z'), or 1, 2, 3 (ascending) when
// two share one.
std::array<std::string, 3> PrincipalLabels(const Eigen::Matrix3d& axes) {
  std::array<int, 3> nearest = {0, 0, 0};
  for (int k = 0; k < 3; ++k) axes.col(k).cwiseAbs().maxCoeff(&nearest[k]);
  const bool distinct =
      nearest[0] != nearest[1] && nearest[0] != nearest[2] && nearest[1] != nearest[2];
  std::array<std::string, 3> labels;
  for (int k = 0; k < 3; ++k) {
    labels[k] =
        distinct ? std::string("I_") + "xyz"[nearest[k]] + "'" : "I_" + std::to_string(k + 1);
  }
  return labels;
}

void CheckFull(const PhysicalVec& c, const PhysicalCov& cov, PhysicalCheck* check) {
  Eigen::Matrix3d j;
  j << c(kIxx), -c(kIxy), -c(kIxz), -c(kIxy), c(kIyy), -c(kIyz), -c(kIxz), -c(kIyz), c(kIzz);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(j);
  const Eigen::Vector3d lambda = eig.eigenvalues();  // ascending
  const std::array<std::string, 3> label = PrincipalLabels(eig.eigenvectors());
  PhysicalVec trace_gradient;
  trace_gradient << 1, 1, 1, 0, 0, 0;
  check->checked = "principal moments";
  // The triangle opposite the largest moment first: the one a body can come near breaking.
  for (int k = 2; k >= 0; --k) {
    const int a = (k + 1) % 3, b = (k + 2) % 3;
    const double margin = lambda(a) + lambda(b) - lambda(k);
    const PhysicalVec g = trace_gradient - 2.0 * MomentGradient(eig.eigenvectors().col(k));
    check->inequalities.push_back(
        Inequality(label[std::min(a, b)] + " + " + label[std::max(a, b)] + " - " + label[k], margin,
                   g, cov, eig.eigenvectors().col(k)));
  }
  check->inequalities.push_back(Inequality("smallest principal moment " + label[0], lambda(0),
                                           MomentGradient(eig.eigenvectors().col(0)), cov,
                                           eig.eigenvectors().col(0)));
}

void CheckDiagonal(const PhysicalVec& c, const PhysicalCov& cov, PhysicalCheck* check) {
  static const char* const kNames[] = {"I_xx", "I_yy", "I_zz"};
  check->checked = "diagonal moments";
  for (int k = 0; k < 3; ++k) {
    const int a = (k + 1) % 3, b = (k + 2) % 3;
    PhysicalVec g = PhysicalVec::Zero();
    g(a) = 1;
    g(b) = 1;
    g(k) = -1;
    check->inequalities.push_back(Inequality(
        std::string(kNames[std::min(a, b)]) + " + " + kNames[std::max(a, b)] + " - " + kNames[k],
        c(a) + c(b) - c(k), g, cov, Eigen::Vector3d::Unit(k)));
  }
}

// The x-z section [[I_x, -I_xz], [-I_xz, I_z]]: I_x, I_z > 0 and its smaller principal moment > 0.
void CheckPlanar(const PhysicalVec& c, const PhysicalCov& cov, PhysicalCheck* check) {
  check->checked = "x-z ellipse";
  PhysicalVec g = PhysicalVec::Zero();
  g(kIxx) = 1;
  check->inequalities.push_back(Inequality("I_x", c(kIxx), g, cov, Eigen::Vector3d::UnitX()));
  g.setZero();
  g(kIzz) = 1;
  check->inequalities.push_back(Inequality("I_z", c(kIzz), g, cov, Eigen::Vector3d::UnitZ()));
  Eigen::Matrix2d j;
  j << c(kIxx), -c(kIxz), -c(kIxz), c(kIzz);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(j);
  const Eigen::Vector2d v = eig.eigenvectors().col(0);
  g.setZero();
  g(kIxx) = v(0) * v(0);
  g(kIzz) = v(1) * v(1);
  g(kIxz) = -2 * v(0) * v(1);
  check->inequalities.push_back(Inequality("smaller principal moment of the x-z section",
                                           eig.eigenvalues()(0), g, cov,
                                           Eigen::Vector3d(v(0), 0.0, v(1))));
}

}  // namespace physical

const char* PhysicalStatusName(PhysicalStatus status) {
  return EnumToString(physical::kPhysicalStatusNames, status, "?");
}

PhysicalCheck CheckPhysical(
    const std::array<double, kTensorComponents>& components,
    const std::array<std::array<double, kTensorComponents>, kTensorComponents>& covariance,
    const PhysicalOptions& options) {
  PhysicalCheck check;
  physical::PhysicalVec c;
  physical::PhysicalCov cov;
  std::array<bool, 6> known = {};
  for (int k = 0; k < 6; ++k) {
    c(k) = components[k];
    for (int l = 0; l < 6; ++l) cov(k, l) = covariance[k][l];
    known[k] = std::isfinite(c(k)) && std::isfinite(cov(k, k));
  }
  // Unknown components: 0 with no variance, so they enter no margin.
  for (int k = 0; k < 6; ++k) {
    if (known[k]) continue;
    c(k) = 0.0;
    cov.row(k).setZero();
    cov.col(k).setZero();
  }
  if (!cov.allFinite()) return check;
  const bool diagonal = known[kIxx] && known[kIyy] && known[kIzz];
  const bool products = known[kIxy] && known[kIxz] && known[kIyz];
  if (diagonal && products) {
    physical::CheckFull(c, cov, &check);
  } else if (diagonal) {
    physical::CheckDiagonal(c, cov, &check);
  } else if (known[kIxx] && known[kIzz] && known[kIxz] && !known[kIyy]) {
    physical::CheckPlanar(c, cov, &check);
  } else {
    return check;
  }
  const double p = std::clamp(options.probability, 1e-12, 0.5);
  // Student's t at the fit's dof; the normal quantile when the stds were not estimated (dof
  // infinite or not positive: fit/distributions.h).
  check.threshold_z = StudentQuantile(p, options.dof);
  for (size_t k = 0; k < check.inequalities.size(); ++k) {
    if (check.worst < 0 || check.inequalities[k].z < check.inequalities[check.worst].z) {
      check.worst = static_cast<int>(k);
    }
  }
  const double z = check.inequalities[check.worst].z;
  check.status = z <= check.threshold_z ? PhysicalStatus::kNotPhysical
                 : z < 0.0              ? PhysicalStatus::kBorderline
                                        : PhysicalStatus::kPhysical;
  check.message = PhysicalCheckMessage(check);
  return check;
}

PhysicalCheck CheckPhysicalEllipse(const EllipseResult& fit, const PhysicalOptions& options) {
  // I_x = A - B, I_z = A + B, I_xz = C.
  Eigen::Matrix3d t;
  t << 1, -1, 0, 1, 1, 0, 0, 0, 1;
  Eigen::Matrix3d abc;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) abc(i, j) = fit.cov_abc[i][j];
  }
  const Eigen::Matrix3d xz = t * abc * t.transpose();  // (I_x, I_z, I_xz)
  std::array<double, kTensorComponents> c;
  std::array<std::array<double, kTensorComponents>, kTensorComponents> cov;
  c.fill(physical::kPhysicalUnknown);
  for (auto& row : cov) row.fill(physical::kPhysicalUnknown);
  const int index[3] = {kIxx, kIzz, kIxz};
  const double value[3] = {fit.ix.value, fit.iz.value, fit.ixz.value};
  for (int i = 0; i < 3; ++i) {
    c[index[i]] = value[i];
    for (int j = 0; j < 3; ++j) cov[index[i]][index[j]] = xz(i, j);
  }
  PhysicalOptions o = options;
  if (std::isfinite(fit.dof) && fit.dof > 0) o.dof = fit.dof;
  return CheckPhysical(c, cov, o);
}

std::string PhysicalCheckMessage(const PhysicalCheck& check) {
  const PhysicalInequality* w = check.Worst();
  if (w == nullptr) return "";
  const std::string numbers = w->name + " = " + Fmt("%.4g", w->margin_kg_m2) + " +- " +
                              Fmt("%.2g", w->std_kg_m2) + " kg m^2 (z = " + Fmt("%.2f", w->z) + ")";
  const std::string what = check.checked == "x-z ellipse"
                               ? "a body's moments are > 0 and its x-z section positive definite"
                               : "a body's moments obey I_a + I_b >= I_c and are > 0";
  switch (check.status) {
    case PhysicalStatus::kPhysical:
      return "physical: every inequality of a body holds (worst " + numbers + ")";
    case PhysicalStatus::kBorderline:
      return "borderline: " + numbers + " breaks " + what +
             ", but within the noise (not physical at z <= " + Fmt("%.2f", check.threshold_z) +
             "); a flat body comes this close. Check the attitudes' logs if the body is not flat";
    case PhysicalStatus::kNotPhysical: {
      std::string text = "NOT PHYSICAL: " + numbers +
                         ", below z = " + Fmt("%.2f", check.threshold_z) +
                         ": no rigid body has these moments (" + what + ")";
      if (!check.attitude.empty()) {
        text += ". The logs at " + check.attitude + " drive it";
        if (std::isfinite(check.z_without_attitude)) {
          text += " (without them the worst z is " + Fmt("%+.2f", check.z_without_attitude) + ")";
        }
      }
      return text +
             ". Likely causes: " + (check.attitude.empty() ? "some swings" : "those swings") +
             " made on another rig geometry or wire length (L, D), the body off-centre between "
             "the wires, or the wrong axis (attitude) named for them. Check and refit; do not "
             "use these numbers";
    }
    default:
      return "";
  }
}

}  // namespace bifilar
