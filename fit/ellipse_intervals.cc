// Step 7 of the ellipse fit: intervals of the six quantities at options.confidence, from a seeded
// parametric bootstrap of the closed form (default) or from t/normal quantiles of the covariance.
#include "fit/ellipse_steps.h"

#include "fit/distributions.h"

#include <algorithm>
#include <cmath>
#include <queue>
#include <random>

namespace bifilar {
namespace ellipse {

namespace {

// The two quantiles p_lo < p_hi of a stream of `count` values, interpolated linearly between the
// order statistics around p (count - 1) as for a sorted list, keeping only the tails they need:
// the smallest floor(p_lo (count - 1)) + 2 and the largest count - floor(p_hi (count - 1))
// values. Memory does not grow with the data.
class TailQuantiles {
 public:
  TailQuantiles(int count, double p_lo, double p_hi)
      : count_(count),
        p_lo_(p_lo),
        p_hi_(p_hi),
        keep_lo_(static_cast<size_t>(std::floor(p_lo * (count - 1))) + 2),
        keep_hi_(static_cast<size_t>(count) - static_cast<size_t>(std::floor(p_hi * (count - 1)))) {
  }

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
  std::priority_queue<double> low_;                                              // max on top
  std::priority_queue<double, std::vector<double>, std::greater<double>> high_;  // min on top
};

// Percentile intervals from options.bootstrap_replicates closed-form refits on noise drawn around
// the fit. With a scale estimated from the data (points or angle means), each replicate first
// draws its variance factor from the scaled inverse chi^2 of the estimate (dof degrees of
// freedom), so the linear quantities' bootstrap distribution is the Student-t one and the
// intervals stay honest with few angles. Angle-means mode draws one error per angle group,
// shared by its trials.
//
// The refit is linear, abc* = abc + S e with S = (X^T W X)^-1 X^T W, so a replicate costs O(1)
// (independent points: S e ~ N(0, vf (X^T W X)^-1), drawn through its Cholesky factor) or
// O(angle groups) (one error per group: S summed over each group's members), not O(n); and only
// the tails of the replicates are kept (TailQuantiles), so memory does not grow with the
// replicate count.
void BootstrapIntervals(const PreparedData& data, const ClosedFormFit& closed,
                        const CovarianceEstimate& cov, const EllipseOptions& options, Vec6* lo,
                        Vec6* hi) {
  const double alpha = 1.0 - options.confidence;
  const int nb = options.bootstrap_replicates;
  const int m = static_cast<int>(data.groups.size());
  const bool per_group = data.covariance == EllipseCovariance::kAngleMeans;
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::chi_squared_distribution<double> chi2_dist(std::isfinite(cov.dof) ? cov.dof : 1.0);
  Eigen::MatrixXd group_solve;  // 3 x m, angle-means mode
  if (per_group) {
    group_solve = Eigen::MatrixXd::Zero(3, m);
    for (int g = 0; g < m; ++g) {
      for (int i : data.groups[g].members) {
        group_solve.col(g) += closed.normal_inv * data.x.row(i).transpose() * data.w(i);
      }
    }
  }
  const Eigen::Matrix3d chol = Eigen::LLT<Eigen::Matrix3d>(closed.normal_inv).matrixL();
  const double offset_var = options.common_offset_std_kg_m2 * options.common_offset_std_kg_m2;
  const double two_tau_ref_rad = 2 * closed.best.tau_deg * kRadPerDeg;
  std::vector<TailQuantiles> tails(6, TailQuantiles(nb, alpha / 2, 1 - alpha / 2));
  for (int b = 0; b < nb; ++b) {
    double vf = cov.variance_factor;
    if (std::isfinite(cov.dof)) vf *= cov.dof / chi2_dist(rng);
    Eigen::Vector3d abc_b = closed.abc;
    if (per_group) {
      for (int g = 0; g < m; ++g) {
        abc_b += group_solve.col(g) * (std::sqrt(vf / data.groups[g].weight) * normal(rng));
      }
    } else {
      Eigen::Vector3d z;
      for (int k = 0; k < 3; ++k) z(k) = normal(rng);
      abc_b += std::sqrt(vf) * (chol * z);
    }
    if (offset_var > 0.0) abc_b(0) += options.common_offset_std_kg_m2 * normal(rng);
    const Vec6 v = ToVec(SixFromAbc(abc_b(0), abc_b(1), abc_b(2), two_tau_ref_rad));
    for (int k = 0; k < 6; ++k) tails[k].Add(v(k));
  }
  for (int k = 0; k < 6; ++k) {
    (*lo)(k) = tails[k].Low();
    (*hi)(k) = tails[k].High();
  }
}

}  // namespace

Intervals ComputeIntervals(const PreparedData& data, const ClosedFormFit& closed,
                           const CovarianceEstimate& cov, const EllipseOptions& options) {
  Intervals in;
  in.bootstrap_replicates = options.bootstrap_replicates;
  if (options.bootstrap_replicates > 0) {
    BootstrapIntervals(data, closed, cov, options, &in.lo, &in.hi);
  } else {
    const double alpha = 1.0 - options.confidence;
    const double t = StudentQuantile(1 - alpha / 2, cov.dof);
    const Vec6 value = ToVec(closed.best);
    in.lo = value - t * cov.std6;
    in.hi = value + t * cov.std6;
  }
  return in;
}

}  // namespace ellipse
}  // namespace bifilar
