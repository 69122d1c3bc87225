// Steps (b) and (c) of the ellipse fit: paper Eq. 7, I(theta) = I_zp cos^2(theta - tau) + I_xp
// sin^2(theta - tau), minimised in p = (I_zp, I_xp, tau_rad) from the paper's start, by NLopt
// Nelder-Mead (derivative-free, the MATLAB fminsearch parity) and by Ceres with its covariance.
// Both must land on the closed form (a); Diagnose warns when they do not.
#include "fit/ellipse_steps.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <ceres/ceres.h>
#include <nlopt.h>

namespace bifilar {
namespace ellipse {
namespace {

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

// Eq. 7 against the sufficient statistics (kCompressAbovePoints): r = U (abc(p) - abc_hat),
// N = U^T U.
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

// Coefficients (A, B, C) and their Jacobian from Eq. 7 parameters (I_zp, I_xp, tau_rad).
void AbcFromEq7(const double* p, Eigen::Vector3d* abc, Eigen::Matrix3d* jac) {
  const double a = 0.5 * (p[0] + p[1]), r = 0.5 * (p[0] - p[1]);
  const double c2 = std::cos(2 * p[2]), s2 = std::sin(2 * p[2]);
  *abc << a, r * c2, r * s2;
  if (jac != nullptr) {
    *jac << 0.5, 0.5, 0, 0.5 * c2, -0.5 * c2, -2 * r * s2, 0.5 * s2, -0.5 * s2, 2 * r * c2;
  }
}

// 0.5 sum w (Eq. 7 - measured)^2, the Nelder-Mead objective (paper Eq. 8 with weights); data is
// the Eq7Problem.
double Eq7Cost(unsigned n, const double* p, double* grad, void* data) {
  (void)n;
  (void)grad;
  const auto* d = static_cast<const Eq7Problem*>(data);
  if (d->compressed) {
    Eigen::Vector3d abc;
    AbcFromEq7(p, &abc, nullptr);
    return 0.5 * (d->chi2_min + (d->u * (abc - d->abc_hat)).squaredNorm());
  }
  double cost = 0.0;
  for (size_t i = 0; i < d->pitch_rad.size(); ++i) {
    const double cs = std::cos(d->pitch_rad[i] - p[2]);
    const double sn = std::sin(d->pitch_rad[i] - p[2]);
    const double r = p[0] * cs * cs + p[1] * sn * sn - d->inertia_kg_m2[i];
    cost += d->weight[i] * r * r;
  }
  return 0.5 * cost;
}

const char* NloptResultName(nlopt_result r) {
  switch (r) {
    case NLOPT_SUCCESS:
      return "success";
    case NLOPT_STOPVAL_REACHED:
      return "stopval reached";
    case NLOPT_FTOL_REACHED:
      return "ftol reached";
    case NLOPT_XTOL_REACHED:
      return "xtol reached";
    case NLOPT_MAXEVAL_REACHED:
      return "maxeval reached";
    case NLOPT_MAXTIME_REACHED:
      return "maxtime reached";
    case NLOPT_ROUNDOFF_LIMITED:
      return "roundoff limited";
    default:
      return "failure";
  }
}

// One Nelder-Mead run from p (updated in place) with initial steps 5 % of |p| (at least 1e-3
// kg m^2) and 0.05 rad, times step_scale. Adds its evaluations to *evaluations.
nlopt_result RunNelderMead(const Eq7Problem& problem, double step_scale, double p[3], double* cost,
                           int* evaluations) {
  nlopt_opt opt = nlopt_create(NLOPT_LN_NELDERMEAD, 3);
  // NLopt passes its data as void*; Eq7Cost only reads it.
  nlopt_set_min_objective(opt, Eq7Cost, const_cast<Eq7Problem*>(&problem));
  const double steps[3] = {std::max(1e-3, 0.05 * std::fabs(p[0])) * step_scale,
                           std::max(1e-3, 0.05 * std::fabs(p[1])) * step_scale, 0.05 * step_scale};
  nlopt_set_initial_step(opt, steps);
  nlopt_set_xtol_rel(opt, 1e-15);
  nlopt_set_ftol_rel(opt, 0.0);
  nlopt_set_maxeval(opt, 20000);
  const nlopt_result status = nlopt_optimize(opt, p, cost);
  *evaluations += nlopt_get_numevals(opt);
  nlopt_destroy(opt);
  return status;
}

}  // namespace

Eq7Problem MakeEq7Problem(const PreparedData& data, const ClosedFormFit& closed) {
  Eq7Problem e;
  const int n = data.n;
  e.pitch_rad.resize(n);
  e.inertia_kg_m2.resize(n);
  e.weight.resize(n);
  e.sqrt_weight.resize(n);
  for (int i = 0; i < n; ++i) {
    e.pitch_rad[i] = data.points[i].pitch_deg * kRadPerDeg;
    e.inertia_kg_m2[i] = data.y(i);
    e.weight[i] = data.w(i);
    e.sqrt_weight[i] = data.sqrt_w(i);
  }
  e.compressed = n > kCompressAbovePoints;
  if (e.compressed) {
    // U from the normal matrix (X^T W X)^-1's inverse: the upper Cholesky factor of X^T W X.
    const Eigen::Matrix3d normal = data.xw.transpose() * data.xw;
    e.u = Eigen::LLT<Eigen::Matrix3d>(normal).matrixU();
    e.abc_hat = closed.abc;
    e.chi2_min = closed.chi2;
  }
  // The paper's start: the angle groups nearest 0 and +-90 deg.
  double best_z = std::numeric_limits<double>::infinity(), best_x = best_z;
  for (const AngleGroup& g : data.groups) {
    const double a = AxisAngleDeg(g.pitch_deg);
    if (std::fabs(a) < best_z) {
      best_z = std::fabs(a);
      e.start[0] = g.mean_kg_m2;
    }
    if (90.0 - std::fabs(a) < best_x) {
      best_x = 90.0 - std::fabs(a);
      e.start[1] = g.mean_kg_m2;
    }
  }
  e.scale_kg_m2 = MomentScale(closed);
  return e;
}

Eq7Fit FitNelderMead(const Eq7Problem& problem) {
  const auto start = Clock::now();
  Eq7Fit fit;
  EllipseSolverSummary& s = fit.summary;
  s.method = "nelder_mead";
  s.ran = true;
  double p[3] = {problem.start[0], problem.start[1], problem.start[2]};
  s.initial_cost = Eq7Cost(3, p, nullptr, const_cast<Eq7Problem*>(&problem));  // read only
  nlopt_result status = NLOPT_FAILURE;
  double cost = s.initial_cost;
  // Nelder-Mead stalls on its shrinking simplex before full precision; restarting from its own
  // result with a fresh simplex (smaller steps each time) converges to the least-squares optimum.
  // Stop when a restart no longer moves the point.
  double step_scale = 1.0;
  for (int attempt = 0; attempt < 12; ++attempt) {
    const double before[3] = {p[0], p[1], p[2]};
    status = RunNelderMead(problem, step_scale, p, &cost, &s.iterations);
    if (status < 0) break;
    const double moved =
        std::max({std::fabs(p[0] - before[0]) / problem.scale_kg_m2,
                  std::fabs(p[1] - before[1]) / problem.scale_kg_m2, std::fabs(p[2] - before[2])});
    if (attempt > 0) ++s.restarts;
    if (attempt > 0 && moved < 1e-14) break;
    step_scale = std::max(1e-6, std::min(1.0, 10 * moved / 0.05));
  }
  s.final_cost = cost;
  s.converged = status > 0;
  s.message = NloptResultName(status);
  AbcFromEq7(p, &fit.abc, nullptr);
  s.parameters = SixFromAbc(fit.abc(0), fit.abc(1), fit.abc(2), 0.0);
  s.time_s = SecondsSince(start);
  return fit;
}

Eq7Fit FitCeres(const Eq7Problem& problem) {
  const auto start = Clock::now();
  Eq7Fit fit;
  EllipseSolverSummary& s = fit.summary;
  s.method = "ceres";
  s.ran = true;
  double p[3] = {problem.start[0], problem.start[1], problem.start[2]};
  ceres::Problem ceres_problem;
  if (problem.compressed) {
    ceres_problem.AddResidualBlock(Eq7CompressedResidual::Create(problem.u, problem.abc_hat),
                                   nullptr, p);
  } else {
    for (size_t i = 0; i < problem.pitch_rad.size(); ++i) {
      ceres_problem.AddResidualBlock(
          Eq7Residual::Create(problem.pitch_rad[i], problem.inertia_kg_m2[i],
                              problem.sqrt_weight[i]),
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
  ceres::Solve(solver_options, &ceres_problem, &summary);
  s.converged = summary.IsSolutionUsable();
  s.message = summary.message;
  s.iterations = static_cast<int>(summary.iterations.size());
  // The compressed cost leaves out the constant 0.5 chi2_min: add it back.
  const double constant = problem.compressed ? 0.5 * problem.chi2_min : 0.0;
  s.initial_cost = summary.initial_cost + constant;
  s.final_cost = summary.final_cost + constant;
  AbcFromEq7(p, &fit.abc, &fit.jac_abc);
  s.parameters = SixFromAbc(fit.abc(0), fit.abc(1), fit.abc(2), 0.0);

  ceres::Covariance::Options cov_options;
  cov_options.algorithm_type = ceres::DENSE_SVD;
  cov_options.null_space_rank = -1;  // pseudo-inverse: I_x ~ I_z makes tau unidentifiable
  ceres::Covariance covariance(cov_options);
  const std::vector<std::pair<const double*, const double*>> blocks = {{p, p}};
  if (s.converged && covariance.Compute(blocks, &ceres_problem)) {
    covariance.GetCovarianceBlock(p, p, fit.cov_eq7.data());
    fit.has_covariance = true;
  }
  s.time_s = SecondsSince(start);
  return fit;
}

}  // namespace ellipse
}  // namespace bifilar
