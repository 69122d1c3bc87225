// The physical check of fitted moments (fit/physical.h) and the tensor fit's use of it
// (fit/tensor.h: TensorResult::physical, the orientation that drives a break, and the scatter
// sought per orientation). Known bodies, known noise: issue 32.
#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "fit/physical.h"
#include "fit/tensor.h"

namespace bifilar {
namespace {

using Cov6 = std::array<std::array<double, kTensorComponents>, kTensorComponents>;

Cov6 Diagonal(double sd, int n = 6) {
  Cov6 c = {};
  for (int k = 0; k < n; ++k) c[k][k] = sd * sd;
  return c;
}

TEST(PhysicalCheck, HealthyBodyIsPhysical) {
  const PhysicalCheck c = CheckPhysical({0.2, 0.3, 0.45, 0.008, 0.01, -0.009}, Diagonal(1e-3), {});
  EXPECT_EQ(c.status, PhysicalStatus::kPhysical);
  EXPECT_EQ(c.checked, "principal moments");
  ASSERT_EQ(c.inequalities.size(), 4u);
  EXPECT_GT(c.Worst()->z, 10);
}

// I_x' + I_y' - I_z' = 0.2 + 0.3 - 0.6 = -0.1 with stds ~ 1e-3: far beyond the noise, named.
TEST(PhysicalCheck, BrokenTriangleIsNotPhysical) {
  const PhysicalCheck c = CheckPhysical({0.2, 0.3, 0.6, 0.0, 0.0, 0.0}, Diagonal(1e-3), {});
  EXPECT_EQ(c.status, PhysicalStatus::kNotPhysical);
  ASSERT_NE(c.Worst(), nullptr);
  EXPECT_EQ(c.Worst()->name, "I_x' + I_y' - I_z'");
  EXPECT_NEAR(c.Worst()->margin_kg_m2, -0.1, 1e-12);
  // std of Ixx + Iyy - Izz with independent 1e-3 stds: sqrt(3) 1e-3.
  EXPECT_NEAR(c.Worst()->std_kg_m2, std::sqrt(3.0) * 1e-3, 1e-9);
  EXPECT_NEAR(c.threshold_z, -3.09, 0.01);
  EXPECT_NE(c.message.find("NOT PHYSICAL"), std::string::npos);
  EXPECT_NE(c.message.find("another rig geometry"), std::string::npos);
}

// A flat plate (I_z = I_x + I_y) measured a little high: within the noise, a warning only.
TEST(PhysicalCheck, FlatBodyWithinTheNoiseIsBorderline) {
  const PhysicalCheck c = CheckPhysical({0.2, 0.3, 0.502, 0.0, 0.0, 0.0}, Diagonal(1e-3), {});
  EXPECT_EQ(c.status, PhysicalStatus::kBorderline);
  EXPECT_NEAR(c.Worst()->z, -0.002 / (std::sqrt(3.0) * 1e-3), 1e-6);
}

// Three axes without products: the triangle inequalities of the diagonal.
TEST(PhysicalCheck, DiagonalOnly) {
  const double nan = NAN;
  Cov6 cov = Diagonal(1e-3, 3);
  for (int k = 3; k < 6; ++k) cov[k][k] = nan;
  const PhysicalCheck c = CheckPhysical({0.6, 0.2, 0.3, nan, nan, nan}, cov, {});
  EXPECT_EQ(c.checked, "diagonal moments");
  EXPECT_EQ(c.status, PhysicalStatus::kNotPhysical);
  EXPECT_EQ(c.Worst()->name, "I_yy + I_zz - I_xx");
  EXPECT_EQ(c.Worst()->against_axis[0], 1.0);
}

// The planar ellipse: I_x I_z > I_xz^2 fails for I_xz = 0.5 with I_x = 0.2, I_z = 0.45.
TEST(PhysicalCheck, Ellipse) {
  EllipseResult e;
  e.ix.value = 0.2;
  e.iz.value = 0.45;
  e.ixz.value = 0.5;
  e.dof = 20;
  for (int k = 0; k < 3; ++k) e.cov_abc[k][k] = 1e-6;
  PhysicalCheck c = CheckPhysicalEllipse(e, {});
  EXPECT_EQ(c.checked, "x-z ellipse");
  EXPECT_EQ(c.status, PhysicalStatus::kNotPhysical);
  EXPECT_EQ(c.Worst()->name, "smaller principal moment of the x-z section");
  e.ixz.value = 0.01;
  c = CheckPhysicalEllipse(e, {});
  EXPECT_EQ(c.status, PhysicalStatus::kPhysical);
}

// Points of the UAV of configs/simulate_three_axes.yaml (I = 0.2, 0.3, 0.45) about x, y, z,
// `trials` each, relative noise `noise`; `scale` multiplies the moments about axis `bad`,
// `scatter` adds a relative scatter to them.
std::vector<TensorPoint> ThreeAxes(int trials, double noise, int bad, double scale, double scatter,
                                   std::mt19937_64* rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  const std::array<double, 3> truth = {0.2, 0.3, 0.45};
  std::vector<TensorPoint> points;
  for (int axis = 0; axis < 3; ++axis) {
    for (int t = 0; t < trials; ++t) {
      TensorPoint p;
      p.direction_in_body = {axis == 0 ? 1.0 : 0.0, axis == 1 ? 1.0 : 0.0, axis == 2 ? 1.0 : 0.0};
      double i = truth[axis] * (1.0 + noise * normal(*rng));
      if (axis == bad) i *= scale * (1.0 + scatter * normal(*rng));
      p.inertia_kg_m2 = i;
      p.std_kg_m2 = noise * truth[axis];
      p.group = axis;
      points.push_back(p);
    }
  }
  return points;
}

TEST(PhysicalCheck, ThreeAxisFitNamesTheInflatedAxis) {
  std::mt19937_64 rng(3);
  TensorOptions options;
  options.bootstrap_replicates = 0;
  TensorResult r;
  std::string why;
  ASSERT_TRUE(FitTensor(ThreeAxes(2, 1e-3, 2, 1.2, 0.0, &rng), options, &r, &why)) << why;
  EXPECT_EQ(r.physical.status, PhysicalStatus::kNotPhysical) << r.physical.message;
  ASSERT_EQ(r.physical.orientation, 2);
  EXPECT_NE(r.physical.attitude.find("+1.000)"), std::string::npos) << r.physical.attitude;
  ASSERT_TRUE(FitTensor(ThreeAxes(2, 1e-3, 2, 1.0, 0.0, &rng), options, &r, &why)) << why;
  EXPECT_EQ(r.physical.status, PhysicalStatus::kPhysical) << r.physical.message;
}

// A full design (12 attitudes of configs/simulate_tensor.yaml, 2 trials): one attitude's moments
// 40 % high break the principal moments' triangle; the refits without each attitude name it.
TEST(PhysicalCheck, FullTensorFitNamesTheAttitudeWhoseRemovalRestoresIt) {
  const std::array<double, 6> truth = {0.2, 0.3, 0.45, 0.008, 0.010, -0.009};
  const std::vector<std::array<double, 2>> attitudes = {{0, 0},    {0, 45},   {0, -45},   {0, -90},
                                                        {45, 0},   {-45, 0},  {90, 0},    {45, 45},
                                                        {-45, 45}, {45, -45}, {-45, -45}, {90, 45}};
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<TensorPoint> points;
  for (size_t g = 0; g < attitudes.size(); ++g) {
    for (int t = 0; t < 2; ++t) {
      TensorPoint p;
      p.direction_in_body = DownInBodyFromAttitude(attitudes[g][0], attitudes[g][1]);
      const double i = TensorMoment(truth, p.direction_in_body);
      p.inertia_kg_m2 = i * (1.0 + 5e-4 * normal(rng)) * (g == 0 ? 1.4 : 1.0);
      p.std_kg_m2 = 5e-4 * i;
      p.group = static_cast<int>(g);
      points.push_back(p);
    }
  }
  TensorOptions options;
  options.bootstrap_replicates = 0;
  TensorResult r;
  std::string why;
  ASSERT_TRUE(FitTensor(points, options, &r, &why)) << why;
  EXPECT_EQ(r.physical.status, PhysicalStatus::kNotPhysical) << r.physical.message;
  EXPECT_EQ(r.physical.orientation, 0) << r.physical.message;
  EXPECT_GT(r.physical.z_without_attitude, 0.0);
}

// Scatter where it is: the y logs scattered by 2 % beyond their 0.05 % stds widen I_yy only, and
// I_yy's interval takes the few dof of its own logs.
// Over 60 campaigns the 95 % intervals of I_xx and I_zz cover the truth 53-60 times (binomial
// 95 % range of 60 draws at 0.95 is 54-60; one less for the intervals' own approximations).
TEST(PhysicalCheck, ScatterOfOneAxisWidensThatAxisAlone) {
  std::mt19937_64 rng(11);
  TensorOptions options;
  options.bootstrap_replicates = 0;
  int covered_x = 0, covered_y = 0, covered_z = 0, n = 60;
  double ratio_y = 0.0;
  std::vector<double> dof_y;
  for (int k = 0; k < n; ++k) {
    TensorResult r;
    std::string why;
    ASSERT_TRUE(FitTensor(ThreeAxes(4, 5e-4, 1, 1.0, 0.02, &rng), options, &r, &why)) << why;
    covered_x += r.components[kIxx].ci_lo <= 0.2 && 0.2 <= r.components[kIxx].ci_hi;
    covered_z += r.components[kIzz].ci_lo <= 0.45 && 0.45 <= r.components[kIzz].ci_hi;
    covered_y += r.components[kIyy].ci_lo <= 0.3 && 0.3 <= r.components[kIyy].ci_hi;
    // Each component has the dof of its own scatter: I_yy about the 3 of its 4 scattered logs
    // (more when they happen to agree, and their stated stds weigh in), I_xx and I_zz far more
    // (their logs agree within their stds: the estimated part is small).
    dof_y.push_back(r.components[kIyy].dof);
    EXPECT_GE(r.components[kIyy].dof, 3.0) << k;
    EXPECT_GT(r.components[kIxx].dof, 6.0) << k;
    EXPECT_GT(r.components[kIzz].dof, 6.0) << k;
    // I_xx's std stays that of its own logs (0.05 % / sqrt(4)), within its scale's spread.
    EXPECT_LT(r.components[kIxx].std, 3.0 * 0.2 * 5e-4 / 2.0) << k;
    ratio_y += r.components[kIyy].std / (0.3 * 5e-4 / 2.0) / n;
  }
  EXPECT_GE(covered_x, 53);
  EXPECT_GE(covered_z, 53);
  // I_yy's interval takes its 3 dof (t = 3.18, not the 6 dof of the pooled logs' 2.45): its
  // coverage holds too.
  EXPECT_GE(covered_y, 54);
  std::nth_element(dof_y.begin(), dof_y.begin() + n / 2, dof_y.end());
  EXPECT_NEAR(dof_y[n / 2], 3.0, 0.3);
  EXPECT_GT(ratio_y, 5.0);  // I_yy widened by its own scatter (2 % / 0.05 % = 40 before sqrt(4))
}

}  // namespace
}  // namespace bifilar
