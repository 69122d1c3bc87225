#include "fit/residual_stats.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace bifilar {

std::vector<double> Autocorrelation(const std::vector<double>& r, int max_lag) {
  const size_t n = r.size();
  std::vector<double> rho(std::max(0, max_lag), 0.0);
  if (n < 2) return rho;
  double mean = 0.0;
  for (double v : r) mean += v;
  mean /= static_cast<double>(n);
  double c0 = 0.0;
  for (double v : r) c0 += (v - mean) * (v - mean);
  if (!(c0 > 0.0)) return rho;
  for (int k = 1; k <= max_lag && static_cast<size_t>(k) < n; ++k) {
    double ck = 0.0;
    for (size_t i = k; i < n; ++i) ck += (r[i] - mean) * (r[i - k] - mean);
    rho[k - 1] = ck / c0;
  }
  return rho;
}

double Ar1Coefficient(const std::vector<double>& r) {
  double num = 0.0, den = 0.0;
  for (size_t i = 1; i < r.size(); ++i) {
    num += r[i] * r[i - 1];
    den += r[i - 1] * r[i - 1];
  }
  if (!(den > 0.0)) return 0.0;
  return std::clamp(num / den, -0.99, 0.99);
}

WhitenessStats ComputeWhiteness(const std::vector<double>& r, int lags) {
  WhitenessStats w;
  const std::vector<double> rho = Autocorrelation(r, lags);
  w.raw_autocorr_lag1 = rho.empty() ? 0.0 : rho[0];
  for (double v : rho) w.raw_autocorr_max = std::max(w.raw_autocorr_max, std::abs(v));
  w.ar1_phi = Ar1Coefficient(r);
  if (r.size() < 3) return w;
  std::vector<double> e(r.size() - 1);
  for (size_t i = 1; i < r.size(); ++i) e[i - 1] = r[i] - w.ar1_phi * r[i - 1];
  const std::vector<double> rho_e = Autocorrelation(e, lags);
  const double n = static_cast<double>(e.size());
  double q = 0.0;
  for (int k = 1; k <= lags; ++k) {
    const double v = rho_e[k - 1];
    w.prewhitened_autocorr_max = std::max(w.prewhitened_autocorr_max, std::abs(v));
    if (n > k) q += v * v / (n - k);
  }
  w.ljung_box_q = n * (n + 2.0) * q;
  return w;
}

int HacBandwidth(double phi, int n, int max_lag) {
  phi = std::clamp(phi, -0.97, 0.97);
  const double alpha = 4.0 * phi * phi / ((1.0 - phi) * (1.0 - phi) * (1.0 + phi) * (1.0 + phi));
  const double l = 1.1447 * std::cbrt(alpha * std::max(1, n));
  return std::clamp(static_cast<int>(std::ceil(l)), 0, std::max(0, max_lag));
}

bool HacCovariance(const Eigen::MatrixXd& jacobian, const Eigen::VectorXd& residuals, int bandwidth,
                   Eigen::MatrixXd* covariance) {
  const Eigen::Index n = jacobian.rows(), p = jacobian.cols();
  if (n <= p || residuals.size() != n || bandwidth < 0) return false;
  const Eigen::MatrixXd jtj = jacobian.transpose() * jacobian;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(jtj);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) return false;
  const Eigen::MatrixXd bread = ldlt.solve(Eigen::MatrixXd::Identity(p, p));
  // Prefix sums of the scores s_k = J_k r_k; each block of L + 1 consecutive scores (partial at
  // the ends) contributes its outer product, so the pair (k, k + l) appears in L + 1 - |l| blocks:
  // exactly the Bartlett weights.
  const Eigen::Index lag = std::min<Eigen::Index>(bandwidth, n - 1);
  Eigen::MatrixXd prefix(n + 1, p);
  prefix.row(0).setZero();
  for (Eigen::Index k = 0; k < n; ++k)
    prefix.row(k + 1) = prefix.row(k) + residuals(k) * jacobian.row(k);
  Eigen::MatrixXd omega = Eigen::MatrixXd::Zero(p, p);
  Eigen::RowVectorXd block(p);
  for (Eigen::Index t = -lag; t < n; ++t) {
    const Eigen::Index lo = std::max<Eigen::Index>(t, 0),
                       hi = std::min<Eigen::Index>(t + lag + 1, n);
    block = prefix.row(hi) - prefix.row(lo);
    omega.noalias() += block.transpose() * block;
  }
  omega /= static_cast<double>(lag + 1);
  *covariance = bread * omega * bread * (static_cast<double>(n) / static_cast<double>(n - p));
  return covariance->allFinite();
}

}  // namespace bifilar
