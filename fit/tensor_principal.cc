// The tensor fit's derived quantities: principal moments and axes (eigen-decomposition of J,
// first-order std), the Euler angles of the principal frame matched to the body axes, and the
// intervals of the components and principal moments (seeded parametric bootstrap, as the
// ellipse's: fit/ellipse_intervals.cc). Conventions: fit/tensor.h, docs/physics.md §3.5.
#include "base/units.h"
#include "fit/distributions.h"
#include "fit/tensor_steps.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

namespace bifilar {
namespace tensor {
namespace {

// d(v_j^T J v_k)/d beta: the bilinear form of each component's unit tensor.
Vec6 Bilinear(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  Vec6 h;
  h << a.x() * b.x(), a.y() * b.y(), a.z() * b.z(), -(a.x() * b.y() + a.y() * b.x()),
      -(a.x() * b.z() + a.z() * b.x()), -(a.y() * b.z() + a.z() * b.y());
  return h;
}

// Eigen-decomposition with ascending moments and each axis' largest component positive.
void Decompose(const Vec6& beta, Eigen::Vector3d* moments, Eigen::Matrix3d* axes) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(TensorMatrix(beta));
  *moments = eig.eigenvalues();
  *axes = eig.eigenvectors();
  for (int k = 0; k < 3; ++k) {
    int largest = 0;
    axes->col(k).cwiseAbs().maxCoeff(&largest);
    if ((*axes)(largest, k) < 0) axes->col(k) *= -1.0;
  }
}

// The principal frame matched to `reference` (columns: the body axes, or an earlier match):
// column b is the principal axis most aligned with reference column b, signed along it; a
// left-handed result flips its least aligned column. Returns the permutation used.
Eigen::Matrix3d Matched(const Eigen::Matrix3d& axes, const Eigen::Matrix3d& reference,
                        std::array<int, 3>* permutation) {
  std::array<int, 3> p = {0, 1, 2}, best = p;
  double best_score = -1.0;
  do {
    double score = 0.0;
    for (int b = 0; b < 3; ++b) score += std::fabs(axes.col(p[b]).dot(reference.col(b)));
    if (score > best_score) {
      best_score = score;
      best = p;
    }
  } while (std::next_permutation(p.begin(), p.end()));
  Eigen::Matrix3d r;
  for (int b = 0; b < 3; ++b) {
    r.col(b) = axes.col(best[b]);
    if (r.col(b).dot(reference.col(b)) < 0) r.col(b) *= -1.0;
  }
  if (r.determinant() < 0) {
    int least = 0;
    Eigen::Vector3d align;
    for (int b = 0; b < 3; ++b) align(b) = std::fabs(r.col(b).dot(reference.col(b)));
    align.minCoeff(&least);
    r.col(least) *= -1.0;
  }
  if (permutation) *permutation = best;
  return r;
}

// Z-Y-X Euler angles (roll, pitch, yaw; deg) of body_from_principal = Rz(yaw) Ry(pitch) Rx(roll).
Eigen::Vector3d EulerDeg(const Eigen::Matrix3d& r) {
  const double pitch = std::asin(std::clamp(-r(2, 0), -1.0, 1.0));
  return Eigen::Vector3d(std::atan2(r(2, 1), r(2, 2)), pitch, std::atan2(r(1, 0), r(0, 0))) *
         kDegPerRad;
}

double Quantile(std::vector<double>* v, double p) {
  std::sort(v->begin(), v->end());
  const double h = p * (v->size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(h));
  const size_t hi = std::min(lo + 1, v->size() - 1);
  return (*v)[lo] + (h - lo) * ((*v)[hi] - (*v)[lo]);
}

// Replicate b: the common offset drawn and added, the components (values 0-5) and principal
// moments (6-8) recorded.
void RecordReplicate(Vec6 beta, int b, const Covariance& cov, const TensorOptions& options,
                     bool principal, std::mt19937_64* rng, std::normal_distribution<double>* normal,
                     std::vector<std::vector<double>>* values) {
  if (options.common_offset_std_kg_m2 > 0.0) {
    beta += cov.offset_direction * (options.common_offset_std_kg_m2 * (*normal)(*rng));
  }
  for (int k = 0; k < 6; ++k) (*values)[k][b] = beta(k);
  if (principal) {
    const Eigen::Vector3d m = PrincipalMoments(beta);
    for (int k = 0; k < 3; ++k) (*values)[6 + k][b] = m(k);
  }
}

// The replicates' intervals: components (values 0-5) and principal moments (6-8).
void SetQuantiles(std::vector<std::vector<double>>* values, double alpha, bool principal,
                  TensorIntervalSet* in) {
  for (int k = 0; k < 6; ++k) {
    in->lo(k) = Quantile(&(*values)[k], alpha / 2);
    in->hi(k) = Quantile(&(*values)[k], 1 - alpha / 2);
  }
  if (principal) {
    for (int k = 0; k < 3; ++k) {
      in->principal_lo(k) = Quantile(&(*values)[6 + k], alpha / 2);
      in->principal_hi(k) = Quantile(&(*values)[6 + k], 1 - alpha / 2);
    }
  }
}

}  // namespace

Eigen::Vector3d PrincipalMoments(const Vec6& beta) {
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(TensorMatrix(beta), Eigen::EigenvaluesOnly)
      .eigenvalues();
}

Principal ComputePrincipal(const Vec6& beta, const Mat6& cov) {
  Principal p;
  Decompose(beta, &p.moments, &p.axes);
  for (int k = 0; k < 3; ++k) {
    const Vec6 g = Bilinear(p.axes.col(k), p.axes.col(k));
    p.moments_std(k) = std::sqrt(std::max(0.0, g.dot(cov * g)));
    // Axis k turns towards axis j by (v_j^T dJ v_k) / (lambda_k - lambda_j).
    double var = 0.0;
    for (int j = 0; j < 3; ++j) {
      if (j == k) continue;
      const Vec6 h = Bilinear(p.axes.col(j), p.axes.col(k)) / (p.moments(k) - p.moments(j));
      var += h.dot(cov * h);
    }
    p.axes_std_deg(k) = std::sqrt(std::max(0.0, var)) * kDegPerRad;
  }
  for (int k = 0; k + 1 < 3; ++k) {
    const double gap = p.moments(k + 1) - p.moments(k);
    const double gap_std = std::hypot(p.moments_std(k), p.moments_std(k + 1));
    if (!(gap > 2.0 * gap_std)) {
      char buffer[200];
      std::snprintf(buffer, sizeof(buffer),
                    "principal moments %d and %d differ by %.3g kg m^2, within 2 std (%.3g): "
                    "their axes are ill-defined in that plane",
                    k + 1, k + 2, gap, 2.0 * gap_std);
      p.warnings.push_back(buffer);
    }
  }
  // Euler angles of the frame matched to the body axes; std by central differences with the
  // same matching.
  std::array<int, 3> permutation;
  const Eigen::Matrix3d r0 = Matched(p.axes, Eigen::Matrix3d::Identity(), &permutation);
  p.euler_deg = EulerDeg(r0);
  for (int b = 0; b < 3; ++b) p.matched_moments(b) = p.moments(permutation[b]);
  Eigen::Matrix<double, 3, 6> jac;
  const double scale = std::max(std::fabs(p.moments.maxCoeff()), 1e-300);
  for (int c = 0; c < 6; ++c) {
    const double h = 1e-6 * scale;
    Vec6 plus = beta, minus = beta;
    plus(c) += h;
    minus(c) -= h;
    Eigen::Vector3d m;
    Eigen::Matrix3d axes_plus, axes_minus;
    Decompose(plus, &m, &axes_plus);
    Decompose(minus, &m, &axes_minus);
    Eigen::Vector3d d =
        EulerDeg(Matched(axes_plus, r0, nullptr)) - EulerDeg(Matched(axes_minus, r0, nullptr));
    for (int k = 0; k < 3; ++k) d(k) = std::remainder(d(k), 360.0);
    jac.col(c) = d / (2 * h);
  }
  const Eigen::Matrix3d euler_cov = jac * cov * jac.transpose();
  for (int k = 0; k < 3; ++k) p.euler_std_deg(k) = std::sqrt(std::max(0.0, euler_cov(k, k)));
  return p;
}

namespace {

// Replicates when the scatter is estimated per orientation (Prepared::scatter_var): each point's
// noise has its stated variance s_i^2 (known) plus its pool's estimated part, drawn with that
// pool's dof (scaled inverse chi^2), so a component fed by a scattering orientation with few logs
// gets its wide interval and the others keep theirs; beta* = beta + A eps, A the solution
// operator.
TensorIntervalSet PooledReplicates(const Prepared& data, const Solution& s, const Covariance& cov,
                                   const TensorOptions& options, bool principal,
                                   TensorIntervalSet in) {
  const double alpha = 1.0 - options.confidence;
  const int nb = options.bootstrap_replicates;
  const Eigen::MatrixXd& a = cov.solution_operator;
  const Eigen::VectorXd known = data.w.cwiseInverse() - data.scatter_var;
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<std::chi_squared_distribution<double>> chi2;
  for (double dof : data.pool_dof) chi2.emplace_back(dof);
  std::vector<std::vector<double>> values(9, std::vector<double>(nb));
  std::vector<double> scale(data.pool_dof.size());
  Eigen::VectorXd eps(data.n);
  for (int b = 0; b < nb; ++b) {
    for (size_t p = 0; p < scale.size(); ++p) scale[p] = data.pool_dof[p] / chi2[p](rng);
    for (int i = 0; i < data.n; ++i) {
      const double v = std::max(0.0, known(i)) +
                       std::max(0.0, data.scatter_var(i)) * scale[data.scatter_pool[i]];
      eps(i) = std::sqrt(v) * normal(rng);
    }
    Vec6 beta = s.beta + a * eps;
    RecordReplicate(beta, b, cov, options, principal, &rng, &normal, &values);
  }
  SetQuantiles(&values, alpha, principal, &in);
  return in;
}

}  // namespace

TensorIntervalSet TensorIntervals(const Prepared& data, const Design& design, const Solution& s,
                                  const Covariance& cov, const TensorOptions& options,
                                  bool principal) {
  TensorIntervalSet in;
  const double alpha = 1.0 - options.confidence;
  const int nb = options.bootstrap_replicates;
  in.replicates = nb;
  in.principal_lo.setConstant(NAN);
  in.principal_hi.setConstant(NAN);
  if (nb == 0) {
    for (int k = 0; k < 6; ++k) {
      const double t = StudentQuantile(1 - alpha / 2, cov.component_dof(k));
      const double sd = std::sqrt(std::max(0.0, cov.cov(k, k)));
      in.lo(k) = s.beta(k) - t * sd;
      in.hi(k) = s.beta(k) + t * sd;
    }
    if (principal) {
      // A principal moment mixes the diagonal: the fewest of their dof (conservative).
      const double t = StudentQuantile(1 - alpha / 2, cov.component_dof.head<3>().minCoeff());
      const Principal p = ComputePrincipal(s.beta, cov.cov);
      in.principal_lo = p.moments - t * p.moments_std;
      in.principal_hi = p.moments + t * p.moments_std;
    }
    return in;
  }
  if (cov.per_pool) return PooledReplicates(data, s, cov, options, principal, in);
  // Replicates beta* = beta + (noise solved through the fit): with a scale estimated from the
  // data each replicate first draws its variance factor from the scaled inverse chi^2 of the
  // estimate; orientation-means mode draws one error per orientation, shared by its points.
  const bool per_group = data.covariance == EllipseCovariance::kAngleMeans;
  const Eigen::MatrixXd z = data.x * design.basis;
  std::vector<Vec6> group_solve;
  std::vector<double> group_weight;
  if (per_group) {
    for (const std::vector<int>& g : data.groups) {
      Eigen::VectorXd acc = Eigen::VectorXd::Zero(design.rank);
      double sw = 0.0;
      for (int i : g) {
        acc += s.normal_inv * z.row(i).transpose() * data.w(i);
        sw += data.w(i);
      }
      group_solve.push_back(design.basis * acc);
      group_weight.push_back(sw);
    }
  }
  const Eigen::MatrixXd chol = Eigen::LLT<Eigen::MatrixXd>(s.normal_inv).matrixL();
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::chi_squared_distribution<double> chi2(std::isfinite(cov.dof) ? cov.dof : 1.0);
  std::vector<std::vector<double>> values(9, std::vector<double>(nb));
  Eigen::VectorXd noise(design.rank);
  for (int b = 0; b < nb; ++b) {
    double vf = cov.variance_factor;
    if (std::isfinite(cov.dof)) vf *= cov.dof / chi2(rng);
    Vec6 beta = s.beta;
    if (per_group) {
      for (size_t g = 0; g < group_solve.size(); ++g) {
        beta += group_solve[g] * (std::sqrt(vf / group_weight[g]) * normal(rng));
      }
    } else {
      for (int k = 0; k < design.rank; ++k) noise(k) = normal(rng);
      beta += design.basis * (std::sqrt(vf) * (chol * noise));
    }
    RecordReplicate(beta, b, cov, options, principal, &rng, &normal, &values);
  }
  SetQuantiles(&values, alpha, principal, &in);
  return in;
}

}  // namespace tensor
}  // namespace bifilar
