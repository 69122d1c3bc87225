// Statistics of fit residuals that real gyro logs need: autocorrelation, an AR(1) description of
// the residual noise, whiteness judged against that noise's own correlation, and the
// heteroscedasticity-and-autocorrelation-consistent (HAC) covariance of a least-squares estimate.
// Method and rationale: docs/method.md ("Per-trace uncertainty", "Quality").
//
// Why HAC: real gyro residuals are coloured (vibration, quantisation, filtering, irregular
// sampling, small model misfit). The textbook covariance sigma^2 (J^T J)^-1 assumes independent
// residuals and is then too small by up to the square root of the noise's integrated correlation
// time (x6 at AR(1) phi = 0.95). The sandwich (J^T J)^-1 Omega (J^T J)^-1 with Omega the long-run
// covariance of the scores J_k r_k (Newey-West, Bartlett kernel, Andrews' AR(1) plug-in bandwidth)
// needs no noise model, costs O(N p^2), and reduces to the usual covariance on white residuals.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace bifilar {

// Autocorrelation of r at lags 1..max_lag (sample-index lags); zeros where undefined.
std::vector<double> Autocorrelation(const std::vector<double>& r, int max_lag);

// Least-squares AR(1) coefficient of r (lag-1 regression), clamped to [-0.99, 0.99].
double Ar1Coefficient(const std::vector<double>& r);

// Residual whiteness against the residual noise's own correlation: r is prewhitened with its own
// AR(1) coefficient (e_k = r_k - phi r_{k-1}); structure the model misses (a periodic misfit,
// sway) survives the prewhitening, a coloured but structureless noise does not.
struct WhitenessStats {
  double ar1_phi = 0.0;                   // residual AR(1) coefficient
  double raw_autocorr_lag1 = 0.0;         // rho_1 of r itself
  double raw_autocorr_max = 0.0;          // max |rho_k| of r, k = 1..lags
  double prewhitened_autocorr_max = 0.0;  // max |rho_k| of e, k = 1..lags
  double ljung_box_q = 0.0;               // Ljung-Box Q of e over the lags (chi^2 with `lags` dof)
};
WhitenessStats ComputeWhiteness(const std::vector<double>& r, int lags);

// Bartlett-kernel bandwidth (lags) by Andrews' (1991) AR(1) plug-in rule,
// 1.1447 (alpha N)^(1/3), alpha = 4 phi^2 / ((1 - phi)^2 (1 + phi)^2), for N samples whose
// residual AR(1) coefficient is phi; at most max_lag.
int HacBandwidth(double phi, int n, int max_lag);

// HAC covariance of the least-squares estimate for residuals r (N) and Jacobian J (N x p):
// (J^T J)^-1 Omega (J^T J)^-1 N / (N - p), Omega = sum over |l| <= L of (1 - |l|/(L+1)) Gamma_l
// of the scores s_k = J_k^T r_k. Computed as the mean outer product of moving sums of L + 1
// scores (the Bartlett estimator, O(N p^2) for any L). Returns false when J^T J is singular.
bool HacCovariance(const Eigen::MatrixXd& jacobian, const Eigen::VectorXd& residuals, int bandwidth,
                   Eigen::MatrixXd* covariance);

}  // namespace bifilar
