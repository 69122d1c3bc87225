// The tensor fit's primary solver: weighted least squares of I(n) = d(n) . beta with Ceres
// (Levenberg-Marquardt, analytic Jacobian), over the coordinates gamma of the design's row
// space, beta = basis gamma, so that a design that does not determine every component is still
// a full-rank problem. Its parity with the closed form (tensor.cc) is checked by FitTensor.
#include "fit/tensor_steps.h"

#include <chrono>
#include <cmath>
#include <vector>

#include <ceres/ceres.h>

namespace bifilar {
namespace tensor {
namespace {

// r = sqrt(w) (z . gamma - I_measured), z = the point's design row times the row-space basis.
class MomentResidual : public ceres::CostFunction {
 public:
  MomentResidual(const Eigen::VectorXd& z, double inertia, double sqrt_w)
      : z_(z), inertia_(inertia), sqrt_w_(sqrt_w) {
    set_num_residuals(1);
    mutable_parameter_block_sizes()->push_back(static_cast<int>(z.size()));
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    double f = 0.0;
    for (int k = 0; k < z_.size(); ++k) f += z_(k) * parameters[0][k];
    residuals[0] = sqrt_w_ * (f - inertia_);
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      for (int k = 0; k < z_.size(); ++k) jacobians[0][k] = sqrt_w_ * z_(k);
    }
    return true;
  }
  static ceres::CostFunction* Create(const Eigen::VectorXd& z, double inertia, double sqrt_w) {
    return new MomentResidual(z, inertia, sqrt_w);
  }

 private:
  const Eigen::VectorXd z_;
  const double inertia_, sqrt_w_;
};

}  // namespace

Solution FitTensorCeres(const Prepared& data, const Design& design, const Solution& closed,
                        EllipseSolverSummary* summary) {
  const auto start = std::chrono::steady_clock::now();
  const Eigen::MatrixXd z = data.x * design.basis;
  // Start: the mean moment on the diagonal, no products (the guess a user would make).
  Vec6 beta0 = Vec6::Zero();
  const double mean = data.y.mean();
  beta0(kIxx) = beta0(kIyy) = beta0(kIzz) = mean;
  std::vector<double> gamma(design.rank);
  const Eigen::VectorXd gamma0 = design.basis.transpose() * beta0;
  for (int k = 0; k < design.rank; ++k) gamma[k] = gamma0(k);

  ceres::Problem problem;
  for (int i = 0; i < data.n; ++i) {
    problem.AddResidualBlock(
        MomentResidual::Create(z.row(i).transpose(), data.y(i), data.sqrt_w(i)), nullptr,
        gamma.data());
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 100;
  options.function_tolerance = 1e-16;
  options.gradient_tolerance = 1e-20;
  options.parameter_tolerance = 1e-15;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary ceres_summary;
  ceres::Solve(options, &problem, &ceres_summary);

  Solution s;
  s.gamma = Eigen::Map<const Eigen::VectorXd>(gamma.data(), design.rank);
  s.beta = design.basis * s.gamma;
  s.normal_inv = closed.normal_inv;
  s.fitted = data.x * s.beta;
  s.resid = data.y - s.fitted;
  s.chi2 = s.resid.cwiseProduct(s.resid).dot(data.w);

  summary->method = "ceres";
  summary->ran = true;
  summary->converged = ceres_summary.IsSolutionUsable();
  summary->message = ceres_summary.message;
  summary->iterations = static_cast<int>(ceres_summary.iterations.size());
  summary->initial_cost = ceres_summary.initial_cost;
  summary->final_cost = ceres_summary.final_cost;
  summary->time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // A fit Ceres could not finish falls back to the closed form (same problem, exact).
  if (!summary->converged || !s.beta.allFinite()) {
    Solution fallback = closed;
    summary->message += " (closed form used)";
    return fallback;
  }
  return s;
}

}  // namespace tensor
}  // namespace bifilar
