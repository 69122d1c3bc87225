// The full inertia tensor fit (fit/tensor.h) against known truth: exact and noisy 3-D designs
// with non-zero I_xy and I_yz, principal moments, axes and Euler angles, the three-axis case,
// designs that leave components unobservable, agreement with the ellipse on a planar design, the
// common offset, and bad input.
#include "fit/tensor.h"

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "base/option_check.h"
#include "base/units.h"
#include "fit/ellipse.h"

namespace bifilar {
namespace {

using Tensor = std::array<double, 6>;  // Ixx, Iyy, Izz, Ixy, Ixz, Iyz

// A small UAV with an off-centre payload: products 2-4 % of the moments.
const Tensor kTruth = {0.200, 0.300, 0.450, 0.006, 0.012, -0.009};

// Twelve attitudes (roll, pitch) a rig can reach: level, pitched, rolled, and both.
const std::vector<std::array<double, 2>> kAttitudes = {{0, 0},    {0, 45},   {0, -45},   {0, -90},
                                                       {45, 0},   {-45, 0},  {90, 0},    {45, 45},
                                                       {-45, 45}, {45, -45}, {-45, -45}, {90, 45}};

Eigen::Matrix3d Matrix(const Tensor& t) {
  Eigen::Matrix3d j;
  j << t[0], -t[3], -t[4], -t[3], t[1], -t[5], -t[4], -t[5], t[2];
  return j;
}

std::vector<TensorPoint> Campaign(const Tensor& truth, int trials, double sigma,
                                  std::mt19937_64* rng, double std_given = 0.0) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<TensorPoint> points;
  int group = 0;
  for (const auto& a : kAttitudes) {
    for (int k = 0; k < trials; ++k) {
      TensorPoint p;
      p.direction_in_body = DownInBodyFromAttitude(a[0], a[1]);
      p.inertia_kg_m2 =
          TensorMoment(truth, p.direction_in_body) + (sigma > 0 ? sigma * normal(*rng) : 0);
      p.std_kg_m2 = std_given;
      p.group = group;
      points.push_back(p);
    }
    ++group;
  }
  return points;
}

TEST(Tensor, AttitudeGivesTheDownVectorOfPhysicsMd) {
  // docs/physics.md §3.5: n = (-sin theta, sin phi cos theta, cos phi cos theta).
  auto n = DownInBodyFromAttitude(0, -90);  // swing about body x
  EXPECT_NEAR(n[0], 1, 1e-15);
  EXPECT_NEAR(n[1], 0, 1e-15);
  EXPECT_NEAR(n[2], 0, 1e-15);
  n = DownInBodyFromAttitude(90, 0);  // about body y
  EXPECT_NEAR(n[1], 1, 1e-15);
  EXPECT_NEAR(n[2], 0, 1e-15);
  // I(n) = n^T J n with the products' positive convention.
  const auto d = DownInBodyFromAttitude(30, 20);
  const Eigen::Vector3d v(d[0], d[1], d[2]);
  EXPECT_NEAR(TensorMoment(kTruth, d), v.dot(Matrix(kTruth) * v), 1e-15);
}

TEST(Tensor, ExactDataRecoverEveryComponentAndThePrincipalFrame) {
  std::mt19937_64 rng(1);
  std::vector<TensorPoint> points = Campaign(kTruth, 1, 0.0, &rng);
  points[0].inertia_kg_m2 *= 1 + 1e-12;  // a residual, so the scatter is not exactly 0
  TensorOptions options;
  options.bootstrap_replicates = 0;
  TensorResult r;
  std::string why;
  ASSERT_TRUE(FitTensor(points, options, &r, &why)) << why;
  EXPECT_TRUE(r.full);
  EXPECT_EQ(r.rank, 6);
  EXPECT_TRUE(r.unobservable.empty());
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(r.components[k].value, kTruth[k], 1e-11) << k;
  EXPECT_LT(r.closed_form_max_relative_difference, 1e-9);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(Matrix(kTruth));
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(r.principal_moments[k].value, eig.eigenvalues()(k), 1e-11);
    const Eigen::Vector3d axis(r.principal_axes[k][0], r.principal_axes[k][1],
                               r.principal_axes[k][2]);
    EXPECT_NEAR(std::fabs(axis.dot(eig.eigenvectors().col(k))), 1.0, 1e-10);
  }
  EXPECT_GT(r.condition_number, 1.0);
  EXPECT_LT(r.condition_number, 20.0);  // a well spread design
}

TEST(Tensor, EulerAnglesOfARotatedTensor) {
  // Principal moments 0.2, 0.3, 0.45 about axes turned by roll 4, pitch -6, yaw 9 deg.
  const double roll = 4, pitch = -6, yaw = 9;
  const Eigen::Matrix3d rot = (Eigen::AngleAxisd(yaw * kRadPerDeg, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(pitch * kRadPerDeg, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(roll * kRadPerDeg, Eigen::Vector3d::UnitX()))
                                  .toRotationMatrix();
  const Eigen::Matrix3d j = rot * Eigen::Vector3d(0.2, 0.3, 0.45).asDiagonal() * rot.transpose();
  const Tensor truth = {j(0, 0), j(1, 1), j(2, 2), -j(0, 1), -j(0, 2), -j(1, 2)};
  std::mt19937_64 rng(2);
  std::vector<TensorPoint> points = Campaign(truth, 2, 1e-9, &rng);
  TensorOptions options;
  options.bootstrap_replicates = 0;
  TensorResult r;
  std::string why;
  ASSERT_TRUE(FitTensor(points, options, &r, &why)) << why;
  EXPECT_NEAR(r.euler_deg[0].value, roll, 1e-5);
  EXPECT_NEAR(r.euler_deg[1].value, pitch, 1e-5);
  EXPECT_NEAR(r.euler_deg[2].value, yaw, 1e-5);
  EXPECT_NEAR(r.principal_moments_matched_kg_m2[0], 0.2, 1e-8);
  EXPECT_NEAR(r.principal_moments_matched_kg_m2[2], 0.45, 1e-8);
}

TEST(Tensor, NoisyCampaignsAreWithinTheirStd) {
  // 200 seeded campaigns of 12 attitudes x 2 trials, trial sigma 0.1 % of the largest moment,
  // independent trials: auto picks the points' scatter (the orientations show no error of their
  // own, F test), so each component's (value - truth) / std is Student-t with 24 - 6 = 18 dof:
  // within 1 std 67.0 %, within 3 std 99.2 % of the time. Over 1200 component fits the binomial
  // std of those fractions is 1.4 % and 0.26 %; the bounds are ~4 of those (the six components
  // of one campaign share their variance factor, which widens the spread a little).
  constexpr double kSigma = 0.00045;
  std::mt19937_64 rng(7);
  int within1 = 0, within3 = 0, total = 0, principal_within = 0, points_mode = 0;
  const Eigen::Vector3d true_principal =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(Matrix(kTruth)).eigenvalues();
  for (int c = 0; c < 200; ++c) {
    TensorOptions options;
    options.bootstrap_replicates = 0;
    TensorResult r;
    std::string why;
    ASSERT_TRUE(FitTensor(Campaign(kTruth, 2, kSigma, &rng), options, &r, &why)) << why;
    points_mode += r.covariance_used == EllipseCovariance::kPointResiduals;
    for (int k = 0; k < 6; ++k) {
      const double z = std::fabs(r.components[k].value - kTruth[k]) / r.components[k].std;
      within1 += z < 1;
      within3 += z < 3;
      ++total;
    }
    for (int k = 0; k < 3; ++k) {
      principal_within += std::fabs(r.principal_moments[k].value - true_principal(k)) <
                          3 * r.principal_moments[k].std;
    }
  }
  EXPECT_GT(points_mode, 180);  // the F test at 5 % picks orientation means ~5 % of the time
  EXPECT_GT(within1, 0.60 * total);
  EXPECT_LT(within1, 0.74 * total);
  EXPECT_GT(within3, 0.975 * total);
  EXPECT_GT(principal_within, 0.975 * 600);
}

TEST(Tensor, AnErrorSharedByTheTrialsOfAnOrientationWidensTheStd) {
  // Each orientation carries an error of 0.3 % shared by its 3 trials (trial noise 0.05 %): the
  // F test picks orientation means (12 - 6 = 6 dof), and the truth stays within 3 std in at
  // least 95 % of 600 component fits (t with 6 dof: 97.6 %).
  std::mt19937_64 rng(21);
  std::normal_distribution<double> normal(0.0, 1.0);
  int means_mode = 0, within3 = 0;
  for (int c = 0; c < 100; ++c) {
    std::vector<TensorPoint> points = Campaign(kTruth, 3, 0.0001, &rng, 0.0001);
    for (size_t i = 0; i < points.size(); i += 3) {
      const double shared = 0.0013 * normal(rng);
      for (size_t k = i; k < i + 3; ++k) points[k].inertia_kg_m2 += shared;
    }
    TensorOptions options;
    options.bootstrap_replicates = 0;
    options.attitude_scatter = false;  // the shared error here is not an attitude's
    TensorResult r;
    std::string why;
    ASSERT_TRUE(FitTensor(points, options, &r, &why)) << why;
    means_mode += r.covariance_used == EllipseCovariance::kAngleMeans;
    for (int k = 0; k < 6; ++k) {
      within3 += std::fabs(r.components[k].value - kTruth[k]) < 3 * r.components[k].std;
    }
  }
  EXPECT_GT(means_mode, 95);
  EXPECT_GT(within3, 0.95 * 600);
}

TEST(Tensor, AttitudeScatterIsFoundAndWeighed) {
  // Every trial hung with its own 0.5 deg attitude error (roll and pitch), trace stds of 1e-4 of
  // I (what a trace fit reports): the stated stds explain nothing, the fit finds the attitude
  // scatter (~0.5 deg: 0.5 deg in each of two angles tilts the axis by 0.5 deg about the one
  // horizontal direction that matters) and the truth stays within 3 std in >= 97 % of the
  // component fits (t with 18 dof: 99.2 %; the scatter estimate adds a little).
  std::mt19937_64 rng(33);
  std::normal_distribution<double> normal(0.0, 1.0);
  int within3 = 0;
  double scatter_sum = 0.0;
  for (int c = 0; c < 100; ++c) {
    std::vector<TensorPoint> points;
    for (const auto& a : kAttitudes) {
      for (int k = 0; k < 2; ++k) {
        TensorPoint p;
        p.nominal_in_body = DownInBodyFromAttitude(a[0], a[1]);
        p.direction_in_body = p.nominal_in_body;
        const auto truth_axis =
            DownInBodyFromAttitude(a[0] + 0.5 * normal(rng), a[1] + 0.5 * normal(rng));
        p.inertia_kg_m2 = TensorMoment(kTruth, truth_axis) * (1 + 1e-4 * normal(rng));
        p.std_kg_m2 = 1e-4 * p.inertia_kg_m2;
        points.push_back(p);
      }
    }
    TensorOptions options;
    options.bootstrap_replicates = 0;
    TensorResult r;
    std::string why;
    ASSERT_TRUE(FitTensor(points, options, &r, &why)) << why;
    scatter_sum += r.attitude_scatter_deg;
    for (int k = 0; k < 6; ++k) {
      within3 += std::fabs(r.components[k].value - kTruth[k]) < 3 * r.components[k].std;
    }
  }
  EXPECT_NEAR(scatter_sum / 100, 0.5, 0.15);
  EXPECT_GT(within3, 0.97 * 600);
}

TEST(Tensor, BootstrapIntervalsCoverTheTruth) {
  // 95 % intervals of 100 campaigns: ~95 of 600 component intervals miss; binomial std 0.9 %.
  std::mt19937_64 rng(11);
  int covered = 0;
  for (int c = 0; c < 100; ++c) {
    TensorOptions options;
    options.bootstrap_replicates = 400;
    options.seed = c + 1;
    TensorResult r;
    std::string why;
    ASSERT_TRUE(FitTensor(Campaign(kTruth, 2, 0.00045, &rng), options, &r, &why)) << why;
    for (int k = 0; k < 6; ++k) {
      covered += r.components[k].ci_lo <= kTruth[k] && kTruth[k] <= r.components[k].ci_hi;
    }
  }
  EXPECT_GT(covered, 0.91 * 600);
  EXPECT_LT(covered, 0.99 * 600);
}

TEST(Tensor, ThreeAxesGiveTheThreeMomentsAndNameTheProducts) {
  std::vector<TensorPoint> points;
  const std::array<std::array<double, 2>, 3> axes = {{{0, -90}, {90, 0}, {0, 0}}};
  const double moments[3] = {15.8e-6, 17.0e-6, 31.2e-6};
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int a = 0; a < 3; ++a) {
    for (int k = 0; k < 4; ++k) {
      TensorPoint p;
      p.direction_in_body = DownInBodyFromAttitude(axes[a][0], axes[a][1]);
      p.inertia_kg_m2 = moments[a] * (1 + 0.002 * normal(rng));
      p.std_kg_m2 = moments[a] * 0.0005;
      points.push_back(p);
    }
  }
  TensorOptions options;
  TensorResult r;
  std::string why;
  ASSERT_TRUE(FitTensor(points, options, &r, &why)) << why;
  EXPECT_EQ(r.rank, 3);
  EXPECT_FALSE(r.full);
  EXPECT_EQ(r.covariance_used, EllipseCovariance::kPointResiduals);  // 3 orientations < 3 + 3
  ASSERT_EQ(r.unobservable.size(), 3u);
  EXPECT_EQ(r.unobservable[0], "Ixy");
  EXPECT_EQ(r.unobservable[1], "Ixz");
  EXPECT_EQ(r.unobservable[2], "Iyz");
  for (int k = 0; k < 3; ++k) {
    // Each moment is the weighted mean of its 4 repeats: within 4 std of the truth, and its std
    // reflects the 0.2 % scatter (not the 0.05 % given): 0.1 % of the moment for 4 repeats.
    EXPECT_NEAR(r.components[k].value, moments[k], 4 * r.components[k].std);
    EXPECT_GT(r.components[k].std, 0.0004 * moments[k]);
    EXPECT_LT(r.components[k].std, 0.0025 * moments[k]);
    EXPECT_FALSE(r.components[3 + k].observable);
    EXPECT_TRUE(std::isnan(r.components[3 + k].value));
  }
  bool named = false;
  for (const std::string& w : r.warnings)
    named |= w.find("not observable") != std::string::npos &&
             w.find("Ixy, Ixz, Iyz") != std::string::npos;
  EXPECT_TRUE(named);
  EXPECT_TRUE(std::isnan(r.principal_moments[0].value));
}

TEST(Tensor, AxesInTheXyPlaneLeaveZUnobservable) {
  std::vector<TensorPoint> points;
  for (double yaw : {0.0, 30.0, 60.0, 90.0, 120.0, 150.0}) {
    TensorPoint p;
    p.direction_in_body = {std::cos(yaw * kRadPerDeg), std::sin(yaw * kRadPerDeg), 0.0};
    p.inertia_kg_m2 = TensorMoment(kTruth, p.direction_in_body);
    points.push_back(p);
    points.back().inertia_kg_m2 *= 1.0001;
    points.push_back(p);
  }
  TensorResult r;
  std::string why;
  TensorOptions options;
  options.bootstrap_replicates = 0;
  ASSERT_TRUE(FitTensor(points, options, &r, &why)) << why;
  EXPECT_EQ(r.rank, 3);
  EXPECT_TRUE(r.components[kIxx].observable && r.components[kIyy].observable &&
              r.components[kIxy].observable);
  EXPECT_FALSE(r.components[kIzz].observable || r.components[kIxz].observable ||
               r.components[kIyz].observable);
  EXPECT_NEAR(r.components[kIxy].value, kTruth[kIxy], 1e-4 * 0.3);
}

TEST(Tensor, ACombinationWithoutItsPartsIsNamed) {
  // Swings about z and about the x-y diagonal: Izz alone, and 0.5 Ixx + 0.5 Iyy - Ixy.
  std::vector<TensorPoint> points;
  for (int k = 0; k < 3; ++k) {
    TensorPoint z, d;
    z.direction_in_body = {0, 0, 1};
    z.inertia_kg_m2 = kTruth[kIzz] * (1 + 1e-4 * k);
    d.direction_in_body = {1, 1, 0};
    d.inertia_kg_m2 = TensorMoment(kTruth, d.direction_in_body) * (1 - 1e-4 * k);
    points.push_back(z);
    points.push_back(d);
  }
  TensorResult r;
  std::string why;
  ASSERT_TRUE(FitTensor(points, TensorOptions(), &r, &why)) << why;
  EXPECT_EQ(r.rank, 2);
  EXPECT_TRUE(r.components[kIzz].observable);
  EXPECT_NEAR(r.components[kIzz].value, kTruth[kIzz], 1e-4 * kTruth[kIzz]);
  ASSERT_EQ(r.unobservable.size(), 5u);
  ASSERT_EQ(r.observable_combinations.size(), 1u);
  EXPECT_NE(r.observable_combinations[0].find("Ixy"), std::string::npos);
  EXPECT_NE(r.observable_combinations[0].find("Ixx"), std::string::npos);
}

TEST(Tensor, NothingObservableIsAnErrorNamingTheComponents) {
  std::vector<TensorPoint> points(4);
  for (auto& p : points) {
    p.direction_in_body = {1, 1, 0};
    p.inertia_kg_m2 = 0.25;
  }
  TensorResult r;
  std::string why;
  EXPECT_FALSE(FitTensor(points, TensorOptions(), &r, &why));
  EXPECT_NE(why.find("none of the six components"), std::string::npos) << why;
  EXPECT_NE(why.find("Ixy"), std::string::npos) << why;
}

TEST(Tensor, PlanarDesignAgreesWithTheEllipse) {
  // Pitch-only swings: the tensor fit's Ixx, Izz, Ixz are the ellipse's I_x, I_z, I_xz.
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<TensorPoint> tp;
  std::vector<EllipsePoint> ep;
  for (int pitch = -80; pitch <= 90; pitch += 10) {
    for (int k = 0; k < 3; ++k) {
      TensorPoint p;
      p.direction_in_body = DownInBodyFromAttitude(0, pitch);
      p.inertia_kg_m2 = TensorMoment(kTruth, p.direction_in_body) + 0.001 * normal(rng);
      tp.push_back(p);
      ep.push_back({static_cast<double>(pitch), p.inertia_kg_m2, 0.0});
    }
  }
  TensorOptions options;
  options.bootstrap_replicates = 0;
  options.covariance = EllipseCovariance::kAngleMeans;  // the ellipse's auto choice here
  TensorResult t;
  std::string why;
  ASSERT_TRUE(FitTensor(tp, options, &t, &why)) << why;
  EllipseOptions eo;
  eo.bootstrap_replicates = 0;
  EllipseResult e;
  ASSERT_TRUE(FitEllipse(ep, eo, &e, &why)) << why;
  EXPECT_EQ(t.rank, 3);
  EXPECT_NEAR(t.components[kIxx].value, e.ix.value, 1e-12);
  EXPECT_NEAR(t.components[kIzz].value, e.iz.value, 1e-12);
  EXPECT_NEAR(t.components[kIxz].value, e.ixz.value, 1e-12);
  EXPECT_NEAR(t.components[kIxz].std, e.ixz.std, 1e-9 * e.ixz.std);
  EXPECT_NEAR(t.components[kIxx].std, e.ix.std, 1e-9 * e.ix.std);
  EXPECT_EQ(t.unobservable, (std::vector<std::string>{"Iyy", "Ixy", "Iyz"}));
}

TEST(Tensor, CommonOffsetEntersTheMomentsNotTheProducts) {
  std::mt19937_64 rng(9);
  const std::vector<TensorPoint> points = Campaign(kTruth, 2, 0.0004, &rng);
  TensorOptions a, b;
  a.bootstrap_replicates = b.bootstrap_replicates = 0;
  b.common_offset_std_kg_m2 = 0.003;
  TensorResult ra, rb;
  std::string why;
  ASSERT_TRUE(FitTensor(points, a, &ra, &why)) << why;
  ASSERT_TRUE(FitTensor(points, b, &rb, &why)) << why;
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(rb.components[k].std * rb.components[k].std,
                ra.components[k].std * ra.components[k].std + 0.003 * 0.003, 1e-12);
    EXPECT_NEAR(rb.components[3 + k].std, ra.components[3 + k].std, 1e-12);
    // Fully correlated between the three moments.
    EXPECT_NEAR(rb.covariance[0][1] - ra.covariance[0][1], 0.003 * 0.003, 1e-12);
  }
}

TEST(Tensor, MeasuredTiltsDoNotMakeProductsObservable) {
  // Three nominal axes, measured 0.3 deg off: the nominal design decides (products unobservable).
  std::vector<TensorPoint> points;
  std::mt19937_64 rng(4);
  std::normal_distribution<double> normal(0.0, 0.3);
  const std::array<std::array<double, 2>, 3> axes = {{{0, -90}, {90, 0}, {0, 0}}};
  for (const auto& a : axes) {
    for (int k = 0; k < 3; ++k) {
      TensorPoint p;
      p.nominal_in_body = DownInBodyFromAttitude(a[0], a[1]);
      p.direction_in_body = DownInBodyFromAttitude(a[0] + normal(rng), a[1] + normal(rng));
      p.inertia_kg_m2 = TensorMoment(kTruth, p.direction_in_body);
      points.push_back(p);
    }
  }
  TensorResult r;
  std::string why;
  ASSERT_TRUE(FitTensor(points, TensorOptions(), &r, &why)) << why;
  EXPECT_EQ(r.rank, 3);
  EXPECT_EQ(r.unobservable.size(), 3u);
}

TEST(Tensor, BadInputSaysWhich) {
  std::vector<TensorPoint> points(7);
  for (auto& p : points) p.inertia_kg_m2 = 1.0;
  points[3].direction_in_body = {0, 0, 0};
  TensorResult r;
  std::string why;
  EXPECT_FALSE(FitTensor(points, TensorOptions(), &r, &why));
  EXPECT_NE(why.find("point 4"), std::string::npos) << why;
  points[3].direction_in_body = {0, 0, 1};
  points[5].inertia_kg_m2 = NAN;
  EXPECT_FALSE(FitTensor(points, TensorOptions(), &r, &why));
  EXPECT_NE(why.find("point 6"), std::string::npos) << why;
  EXPECT_FALSE(FitTensor({}, TensorOptions(), &r, &why));
}

// Issue 23 item 4: (1e308, 0, 1) had norm() = inf, was "normalised" to (0, 0, 0), and six such
// points crashed the SVD (SIGSEGV from Python); beside valid axes it was silently an axis that
// observed nothing. Axes are now scaled by their largest component before normalising: any
// finite non-zero vector is its direction; inf, NaN and zero are errors naming the point.
TEST(Tensor, HugeAndTinyDirectionsAreTheirDirectionsAndNonFiniteOnesAreErrors) {
  std::vector<TensorPoint> huge(6), unit(6);
  for (int i = 0; i < 6; ++i) {
    huge[i].direction_in_body = {1e308, 0, 1};
    huge[i].inertia_kg_m2 = 0.45 + 0.001 * i;
    unit[i] = huge[i];
    unit[i].direction_in_body = {1, 0, 0};
  }
  TensorOptions options;
  options.bootstrap_replicates = 0;
  TensorResult a, b;
  std::string why;
  ASSERT_TRUE(FitTensor(huge, options, &a, &why)) << why;
  ASSERT_TRUE(FitTensor(unit, options, &b, &why)) << why;
  EXPECT_EQ(a.rank, 1);
  EXPECT_NEAR(a.components[kIxx].value, 0.4525, 1e-12);  // the mean of the six moments about x
  EXPECT_EQ(a.unobservable, b.unobservable);

  // Beside valid axes: the huge one counts as the x axis, exactly as (1, 0, 0) would.
  std::mt19937_64 rng(5);
  std::vector<TensorPoint> mixed = Campaign(kTruth, 2, 0.0, &rng);
  std::vector<TensorPoint> plain = mixed;
  mixed[0].direction_in_body = {1e308, 0, 1};
  plain[0].direction_in_body = {1, 0, 0};
  mixed[1].direction_in_body = {0, 1e-300, 0};  // tiny: the y axis
  plain[1].direction_in_body = {0, 1, 0};
  mixed[0].inertia_kg_m2 = plain[0].inertia_kg_m2 = TensorMoment(kTruth, {1, 0, 0});
  mixed[1].inertia_kg_m2 = plain[1].inertia_kg_m2 = TensorMoment(kTruth, {0, 1, 0});
  ASSERT_TRUE(FitTensor(mixed, options, &a, &why)) << why;
  ASSERT_TRUE(FitTensor(plain, options, &b, &why)) << why;
  EXPECT_EQ(a.rank, 6);
  EXPECT_NEAR(a.components[kIxx].value, b.components[kIxx].value, 1e-12);
  EXPECT_NEAR(a.components[kIxx].value, kTruth[0], 1e-9);
  EXPECT_NEAR(TensorMoment(kTruth, {1e308, 0, 1}), kTruth[0], 1e-15);

  // Not finite, or zero: an error naming the point and the vector, never a crash.
  for (const std::array<double, 3>& bad :
       {std::array<double, 3>{INFINITY, 0, 1}, {NAN, 0, 0}, {0, 0, 0}, {1e308, -INFINITY, 0}}) {
    std::vector<TensorPoint> points = plain;
    points[2].direction_in_body = bad;
    EXPECT_FALSE(FitTensor(points, options, &a, &why));
    EXPECT_NE(why.find("point 3: the swing axis must be a finite, non-zero vector"),
              std::string::npos)
        << why;
  }
  std::vector<TensorPoint> points = plain;
  points[4].nominal_in_body = {INFINITY, 0, 0};
  EXPECT_FALSE(FitTensor(points, options, &a, &why));
  EXPECT_NE(why.find("point 5: the nominal swing axis"), std::string::npos) << why;
}

// Every bound of TensorOptions (its own and the ellipse fit's it shares) names the field, the
// value and the bound.
TEST(TensorOptions, CheckNamesFieldValueAndBound) {
  std::string why;
  EXPECT_TRUE(TensorOptions().Check(&why)) << why;
  TensorOptions o;
  o.group_tol_deg = 45;
  EXPECT_FALSE(o.Check(&why));
  EXPECT_EQ(why, "group_tol_deg = 45; must be in [0, 45)");
  o = TensorOptions();
  o.rank_tolerance = 0;
  EXPECT_FALSE(o.Check(&why));
  EXPECT_EQ(why, "rank_tolerance = 0; must be in (0, 1)");
  o = TensorOptions();
  o.confidence = NAN;
  EXPECT_FALSE(o.Check(&why));
  EXPECT_EQ(why, "confidence = nan; must be in (0, 1)");
  o = TensorOptions();
  o.bootstrap_replicates = 50;
  EXPECT_FALSE(o.Check(&why));
  EXPECT_EQ(why, "bootstrap_replicates = 50; must be 0 (off) or in [" +
                     std::to_string(kMinBootstrapReplicates) + ", " +
                     std::to_string(kMaxBootstrapReplicates) + "]");
  o = TensorOptions();
  o.common_offset_std_kg_m2 = INFINITY;
  EXPECT_FALSE(o.Check(&why));
  EXPECT_EQ(why, "common_offset_std_kg_m2 = inf; must be finite and >= 0");
}

}  // namespace
}  // namespace bifilar
