// The steps of FitTensor (fit/tensor.h) and the data passed between them. Private to fit/: the
// public header stays solver-free, this one speaks Eigen.
//
// The procedure (FitTensor in fit/tensor.cc), one function per step:
//   PrepareTensorData   validated points, unit directions, weights, orientation groups  (tensor.cc)
//   AnalyseDesign       SVD of the nominal design: rank, row space, unobservable components,
//                       condition number (tensor.cc)
//   FitTensorClosedForm weighted least squares in row-space coordinates by QR (parity) (tensor.cc)
//   FitTensorCeres      the same problem with Ceres: the primary result (tensor_solve.cc)
//   EstimateTensorCovariance  variance factor of the covariance mode, covariance of the six
//                       components with the common offset (tensor.cc)
//   ComputePrincipal    eigen-decomposition, principal moments/axes with std, Euler angles
//                                                                           (tensor_principal.cc)
//   TensorIntervals     parametric bootstrap (or t) intervals              (tensor_principal.cc)
//   DiagnoseTensor      point and orientation residuals, outliers                       (tensor.cc)
#pragma once

#include "fit/tensor.h"

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace bifilar {
namespace tensor {

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

// Row of the design for the unit axis n: (nx^2, ny^2, nz^2, -2 nx ny, -2 nx nz, -2 ny nz).
Eigen::Matrix<double, 1, 6> DesignRow(const Eigen::Vector3d& n);
// The tensor J of the six components (products positive convention, fit/tensor.h).
Eigen::Matrix3d TensorMatrix(const Vec6& components);

struct Prepared {
  int n = 0;
  bool weighted = false;
  std::vector<Eigen::Vector3d> axes;  // the fitted (used) unit directions
  Eigen::MatrixXd x;                  // n x 6 design of the fitted (used) directions
  Eigen::MatrixXd x_nominal;          // n x 6 design of the nominal directions
  Eigen::VectorXd y, w, sqrt_w;
  std::vector<std::vector<int>> groups;     // orientation groups, point indices
  std::vector<Eigen::Vector3d> group_axis;  // the first member's nominal axis (unit)
  EllipseCovariance covariance = EllipseCovariance::kPointResiduals;  // resolved after the rank
  std::vector<std::string> warnings;
  // Per-orientation scatter (designs that are not full): the weights already hold each
  // orientation's scatter, so the covariance takes them as they are (variance factor 1) with
  // `scale_dof` degrees of freedom (those of the pooled scatter). 0: not used.
  double scale_dof = 0.0;
  // With per-orientation scatter: each point's variance 1/w is its stated s^2 (known) plus the
  // estimated part scatter_var = sigma^2 I^2 of its pool (an orientation with a scatter of its
  // own, or the shared pool of the others), estimated with pool_dof[scatter_pool] degrees of
  // freedom. Empty when not used.
  Eigen::VectorXd scatter_var;
  std::vector<int> scatter_pool;
  std::vector<double> pool_dof;
};

bool PrepareTensorData(const std::vector<TensorPoint>& points, const TensorOptions& options,
                       Prepared* data, std::string* why);

struct Design {
  int rank = 0;
  Eigen::MatrixXd basis;  // 6 x rank, orthonormal basis of the design's row space
  Eigen::Matrix<double, 6, 1> singular_values;  // descending
  std::array<bool, 6> observable = {};
  double condition_number = 0.0;
  std::vector<std::string> unobservable, combinations;
};

// False with *why when nothing is observable.
bool AnalyseDesign(const Prepared& data, const TensorOptions& options, Design* design,
                   std::string* why);

struct Solution {
  Eigen::VectorXd gamma;       // row-space coordinates
  Vec6 beta = Vec6::Zero();    // the six components (min-norm: zero off the row space)
  Eigen::MatrixXd normal_inv;  // (Z^T W Z)^-1, Z = X basis (rank x rank)
  Eigen::VectorXd fitted, resid;
  double chi2 = 0.0;
};

// Weighted least squares by QR of the whitened reduced design. False when singular.
bool FitTensorClosedForm(const Prepared& data, const Design& design, Solution* s, std::string* why);
// The same problem solved by Ceres (Levenberg-Marquardt, analytic Jacobian) from the mean
// moment on the diagonal; normal_inv taken from `closed`.
Solution FitTensorCeres(const Prepared& data, const Design& design, const Solution& closed,
                        EllipseSolverSummary* summary);

struct Covariance {
  double variance_factor = 1.0, dof = 0.0;
  // Each component's own degrees of freedom (Welch-Satterthwaite over the pools of estimated
  // scatter that feed it; inf when none does); equal to `dof` unless the scatter is per
  // orientation.
  Vec6 component_dof = Vec6::Constant(std::numeric_limits<double>::infinity());
  bool per_pool = false;  // component_dof from the pools of Prepared::scatter_var
  // With per_pool: the solution operator A = basis (Z^T W Z)^-1 Z^T W (6 x n), beta = A y.
  Eigen::MatrixXd solution_operator;
  Mat6 cov = Mat6::Zero();               // of the six components, common offset included
  Eigen::MatrixXd cov_gamma;             // rank x rank, without the offset (bootstrap)
  Vec6 offset_direction = Vec6::Zero();  // the components' response to a unit common offset
  std::vector<std::string> warnings;
};

bool EstimateTensorCovariance(const Prepared& data, const Design& design, const Solution& s,
                              const TensorOptions& options, Covariance* cov, std::string* why);

// Principal moments (ascending) and axes, Euler angles of the matched frame, their std.
struct Principal {
  Eigen::Vector3d moments;
  Eigen::Matrix3d axes;  // columns: unit axes of the moments, largest component > 0
  Eigen::Vector3d moments_std, axes_std_deg;
  Eigen::Vector3d euler_deg, euler_std_deg;  // roll, pitch, yaw
  Eigen::Vector3d matched_moments;           // about x', y', z'
  std::vector<std::string> warnings;
};
Principal ComputePrincipal(const Vec6& beta, const Mat6& cov);
// Eigenvalues ascending of the tensor of `beta`.
Eigen::Vector3d PrincipalMoments(const Vec6& beta);

struct TensorIntervalSet {
  Vec6 lo = Vec6::Zero(), hi = Vec6::Zero();  // components
  Eigen::Vector3d principal_lo, principal_hi;
  int replicates = 0;
};
TensorIntervalSet TensorIntervals(const Prepared& data, const Design& design, const Solution& s,
                                  const Covariance& cov, const TensorOptions& options,
                                  bool principal);

// FitTensor without naming the attitude that drives a non-physical result (no refits).
bool FitTensorOnce(const std::vector<TensorPoint>& points, const TensorOptions& options,
                   TensorResult* result, std::string* why);
// Fills result->physical (fit/physical.h) and, when it is not physical or borderline, names the
// orientation that drives it by refitting without each (tensor_physical.cc).
void CheckTensorPhysical(const std::vector<TensorPoint>& points, const TensorOptions& options,
                         TensorResult* result);

}  // namespace tensor
}  // namespace bifilar
