// The trace-fit residual's analytic Jacobian (forward sensitivities, fit/trace_cost.h) against
// central differences of the residual itself, for the three models and both integrators. The
// test FAILS on mismatch.
//
// Tolerance: both sides integrate at rel_tol 1e-12 / abs_tol 1e-14. Central differences with
// step h have truncation error ~h^2 |r'''| (h = 1e-6 in scaled parameters: ~1e-12) and
// round-off/integration error ~1e-12 / h = 1e-6 relative; the sensitivities themselves are
// error-controlled to ~1e-10. A column agrees when ||J_num - J_an|| <= 1e-4 ||J_num||: two
// orders above the numerical floor, and a 0.1 % error in any column (a wrong partial, a missing
// scale factor) fails it, as the last test shows.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>

#include "fit/trace_cost.h"
#include "fit/trace_synth.h"

namespace bifilar {
namespace {

constexpr double kColumnRelTol = 1e-4;

using RowMajorJacobian = Eigen::Matrix<double, Eigen::Dynamic, kNumTraceParams, Eigen::RowMajor>;

struct JacobianCase {
  TraceFitInput input;
  IntegratorOptions integrator;
};

JacobianCase MakeSetup(PendulumModel model, double amplitude_deg, IntegratorMethod method) {
  SyntheticTraceOptions o = ExampleRigTraceOptions(amplitude_deg, 3);
  o.model = model;
  o.duration_s = 20.0;  // 7 periods: long enough for sensitivities to grow, quick to run
  JacobianCase s;
  EXPECT_TRUE(MakeSyntheticTrace(o, &s.input));
  s.integrator.rel_tol = 1e-12;
  s.integrator.abs_tol = 1e-14;
  s.integrator.method = method;
  return s;
}

RowMajorJacobian NumericJacobian(const TraceRateCost& cost, const double* p) {
  const int n = cost.num_residuals();
  RowMajorJacobian jac(n, kNumTraceParams);
  std::vector<double> a(n), b(n), c(n);
  for (int j = 0; j < kNumTraceParams; ++j) {
    const double h = 1e-6;
    double q[kNumTraceParams];
    std::copy(p, p + kNumTraceParams, q);
    const bool at_bound = (j == kTraceDrag || j == kTraceViscous) && p[j] - h < 0.0;
    if (!at_bound) {  // central: (r(p+h) - r(p-h)) / 2h
      q[j] = p[j] + h;
      EXPECT_TRUE(cost.Evaluate(q, a.data(), nullptr, nullptr));
      q[j] = p[j] - h;
      EXPECT_TRUE(cost.Evaluate(q, b.data(), nullptr, nullptr));
      for (int k = 0; k < n; ++k) jac(k, j) = (a[k] - b[k]) / (2 * h);
    } else {  // K_D or C at 0 (negative is not allowed): one-sided, also O(h^2)
      EXPECT_TRUE(cost.Evaluate(q, a.data(), nullptr, nullptr));
      q[j] = p[j] + h;
      EXPECT_TRUE(cost.Evaluate(q, b.data(), nullptr, nullptr));
      q[j] = p[j] + 2 * h;
      EXPECT_TRUE(cost.Evaluate(q, c.data(), nullptr, nullptr));
      for (int k = 0; k < n; ++k) jac(k, j) = (-3 * a[k] + 4 * b[k] - c[k]) / (2 * h);
    }
  }
  return jac;
}

// Worst column mismatch ||J_num - J_an|| / ||J_num||.
double WorstColumnError(const RowMajorJacobian& numeric, const RowMajorJacobian& analytic,
                        int* worst_column) {
  double worst = 0.0;
  for (int j = 0; j < kNumTraceParams; ++j) {
    const double e = (numeric.col(j) - analytic.col(j)).norm() / numeric.col(j).norm();
    if (e > worst) {
      worst = e;
      *worst_column = j;
    }
  }
  return worst;
}

void CheckJacobian(PendulumModel model, IntegratorMethod method, double amplitude_deg,
                   const double* p) {
  const JacobianCase s = MakeSetup(model, amplitude_deg, method);
  const TraceRateCost cost(&s.input.t_s, &s.input.rate_rad_per_s, model, s.input.geometry,
                           s.integrator, 1.1616);
  const int n = cost.num_residuals();
  RowMajorJacobian analytic(n, kNumTraceParams);
  std::vector<double> r(n);
  std::string why;
  ASSERT_TRUE(cost.Evaluate(p, r.data(), analytic.data(), &why)) << why;
  const RowMajorJacobian numeric = NumericJacobian(cost, p);
  int column = -1;
  const double err = WorstColumnError(numeric, analytic, &column);
  std::printf("  %s/%s: worst column relative error %.2e (column %d)\n", ToString(model),
              ToString(method), err, column);
  EXPECT_LT(err, kColumnRelTol) << ToString(model) << "/" << ToString(method) << " column "
                                << column;
  // The bias column is exactly 1 and the residual at the point is rate + b - measured.
  for (int k = 0; k < n; k += 101) EXPECT_EQ(analytic(k, kTraceBias), 1.0);
}

// A point off the optimum (I 0.3 % high, other values shifted) with both damping terms active.
const double kDampedPoint[kNumTraceParams] = {1.003, 0.005, 0.0015, 0.35, 0.02, 0.004};
// Undamped: K_D = C = 0 exercises the |psi'| kink's partials at zero drag.
const double kUndampedPoint[kNumTraceParams] = {0.998, 0.0, 0.0, -0.3, -0.05, -0.002};

TEST(TraceJacobian, FullModelMatchesNumericDifferentiation) {
  CheckJacobian(PendulumModel::kFull, IntegratorMethod::kRungeKutta, 20.0, kDampedPoint);
  CheckJacobian(PendulumModel::kFull, IntegratorMethod::kRungeKutta, 20.0, kUndampedPoint);
}

TEST(TraceJacobian, JardinModelMatchesNumericDifferentiation) {
  CheckJacobian(PendulumModel::kJardin, IntegratorMethod::kRungeKutta, 20.0, kDampedPoint);
  CheckJacobian(PendulumModel::kJardin, IntegratorMethod::kRungeKutta, 20.0, kUndampedPoint);
}

TEST(TraceJacobian, LinearModelMatchesNumericDifferentiation) {
  CheckJacobian(PendulumModel::kLinear, IntegratorMethod::kRungeKutta, 20.0, kDampedPoint);
  CheckJacobian(PendulumModel::kLinear, IntegratorMethod::kRungeKutta, 20.0, kUndampedPoint);
}

TEST(TraceJacobian, CvodesSensitivitiesMatchToo) {
  CheckJacobian(PendulumModel::kFull, IntegratorMethod::kCvodes, 20.0, kDampedPoint);
  CheckJacobian(PendulumModel::kJardin, IntegratorMethod::kCvodes, 20.0, kDampedPoint);
  CheckJacobian(PendulumModel::kLinear, IntegratorMethod::kCvodes, 20.0, kDampedPoint);
}

TEST(TraceJacobian, CheckCatchesA0p1PercentColumnError) {
  const JacobianCase s = MakeSetup(PendulumModel::kFull, 20.0, IntegratorMethod::kRungeKutta);
  const TraceRateCost cost(&s.input.t_s, &s.input.rate_rad_per_s, PendulumModel::kFull,
                           s.input.geometry, s.integrator, 1.1616);
  const int n = cost.num_residuals();
  RowMajorJacobian analytic(n, kNumTraceParams);
  std::vector<double> r(n);
  ASSERT_TRUE(cost.Evaluate(kDampedPoint, r.data(), analytic.data(), nullptr));
  const RowMajorJacobian numeric = NumericJacobian(cost, kDampedPoint);
  for (int j = 0; j < kNumTraceParams; ++j) {
    RowMajorJacobian wrong = analytic;
    wrong.col(j) *= 1.001;
    int column = -1;
    EXPECT_GT(WorstColumnError(numeric, wrong, &column), kColumnRelTol) << "column " << j;
    EXPECT_EQ(column, j);
  }
}

TEST(TraceJacobian, CacheReturnsTheRightPoint) {
  const JacobianCase s = MakeSetup(PendulumModel::kFull, 15.0, IntegratorMethod::kRungeKutta);
  const TraceRateCost cost(&s.input.t_s, &s.input.rate_rad_per_s, PendulumModel::kFull,
                           s.input.geometry, s.integrator, 1.1616);
  const int n = cost.num_residuals();
  std::vector<double> r1(n), r2(n), r3(n);
  RowMajorJacobian j1(n, kNumTraceParams), j3(n, kNumTraceParams);
  ASSERT_TRUE(cost.Evaluate(kDampedPoint, r1.data(), j1.data(), nullptr));
  ASSERT_TRUE(cost.Evaluate(kUndampedPoint, r2.data(), nullptr, nullptr));
  ASSERT_TRUE(cost.Evaluate(kDampedPoint, r3.data(), j3.data(), nullptr));
  EXPECT_EQ(r1, r3);
  EXPECT_EQ((j1 - j3).norm(), 0.0);
  EXPECT_NE(r1[n / 2], r2[n / 2]);
  // Bias only shifts the residuals (no new integration needed, same trajectory).
  double q[kNumTraceParams];
  std::copy(kDampedPoint, kDampedPoint + kNumTraceParams, q);
  q[kTraceBias] += 0.01;
  ASSERT_TRUE(cost.Evaluate(q, r2.data(), nullptr, nullptr));
  EXPECT_NEAR(r2[n / 3] - r1[n / 3], 0.01, 1e-15);
}

TEST(TraceJacobian, FailedIntegrationIsReportedNotInvented) {
  const JacobianCase s = MakeSetup(PendulumModel::kFull, 15.0, IntegratorMethod::kRungeKutta);
  const TraceRateCost cost(&s.input.t_s, &s.input.rate_rad_per_s, PendulumModel::kFull,
                           s.input.geometry, s.integrator, 1.1616);
  std::vector<double> r(cost.num_residuals());
  const double negative_inertia[kNumTraceParams] = {-1.0, 0, 0, 0.1, 0, 0};
  std::string why;
  EXPECT_FALSE(cost.Evaluate(negative_inertia, r.data(), nullptr, &why));
  EXPECT_FALSE(why.empty());
  const double nan_angle[kNumTraceParams] = {1.0, 0, 0, std::nan(""), 0, 0};
  EXPECT_FALSE(cost.Evaluate(nan_angle, r.data(), nullptr, &why));
}

}  // namespace
}  // namespace bifilar
