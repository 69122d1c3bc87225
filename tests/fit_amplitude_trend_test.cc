// The trend of I against amplitude (fit/amplitude_trend.h): the power law chosen by the data, the
// Birge scale taken about the chosen curve, and the coefficient pooled over several set-ups, each
// against points drawn from a known curve with known stds (fixed seeds).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "fit/amplitude_trend.h"

namespace bifilar {
namespace {

// Six bands from 60 to 4.5 deg, like a large release, on I_0 (1 + c A^p), relative std s.
std::vector<AmplitudePoint> Bands(double p, double c, double s, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<AmplitudePoint> points;
  for (double a : {60.0, 38.0, 24.0, 15.0, 9.0, 4.5}) {
    const double i = 0.05 * (1.0 + c * std::pow(a, p));
    points.push_back({a, i * (1.0 + s * normal(rng)), i * s});
  }
  return points;
}

// I linear in A (1 % per 10 deg): the A^2 line misfits it (its Birge scale inflates the std and
// the z falls), the data choose p = 1, and its coefficient comes back within 3 sigma.
TEST(AmplitudeTrend, ChoosesTheExponentOfTheData) {
  int chosen_linear = 0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const std::vector<AmplitudePoint> points = Bands(1.0, 0.001, 0.001, seed);
    AmplitudePowerFit shape, square;
    ASSERT_TRUE(FitAmplitudeShape(points, 0.05, &shape));
    ASSERT_TRUE(FitAmplitudePower(points, 0.05, 2.0, &square));
    if (shape.exponent == 1.0) ++chosen_linear;
    EXPECT_GT(square.birge, 3.0) << seed;  // the A^2 line does not describe the bands
    EXPECT_GT(std::abs(shape.z), 2.0 * std::abs(square.z)) << seed;
    if (shape.exponent == 1.0) {
      EXPECT_NEAR(shape.coeff, 0.001, 3.0 * shape.coeff_std) << seed;
      EXPECT_NEAR(shape.inertia_zero_amplitude_kg_m2, 0.05, 0.05 * 3.0 * 0.001) << seed;
      EXPECT_NEAR(shape.percent_per_10deg, 1.0, 0.1) << seed;
    }
  }
  // The 0.1 % noise cannot confuse 1 % per 10 deg with A^2 on these amplitudes.
  EXPECT_EQ(chosen_linear, 20);
  // And an A^2 rig is taken as A^2.
  AmplitudePowerFit shape;
  ASSERT_TRUE(FitAmplitudeShape(Bands(2.0, 2e-5, 0.001, 3), 0.05, &shape));
  EXPECT_EQ(shape.exponent, 2.0);
}

// With two points every curve passes through both: p = 2, the leading analytic term, stays.
TEST(AmplitudeTrend, TwoPointsKeepTheSquare) {
  AmplitudePowerFit shape;
  ASSERT_TRUE(FitAmplitudeShape({{20.0, 1.01, 0.001}, {5.0, 1.0, 0.001}}, 1.0, &shape));
  EXPECT_EQ(shape.exponent, 2.0);
  EXPECT_EQ(shape.dof, 0);
  EXPECT_EQ(shape.birge, 1.0);
  EXPECT_NEAR(shape.InertiaAt(20.0), 1.01, 1e-12);
  EXPECT_NEAR(shape.InertiaAt(5.0), 1.0, 1e-12);
}

TEST(AmplitudeTrend, NoRangeOfAmplitudesIsNoFit) {
  AmplitudePowerFit shape;
  EXPECT_FALSE(FitAmplitudeShape({{20.0, 1.01, 0.001}, {20.0, 1.0, 0.001}}, 1.0, &shape));
}

// Six set-ups with their own I_0 (1e-5 ... 0.05 kg m^2), 4 repeats each at 10-25 deg, one c:
// the pooled fit recovers it within 3 sigma, and its std is the textbook one when the points
// scatter as their stds say (Birge ~1).
TEST(AmplitudeTrend, PooledCoefficientOverSetUps) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> amplitude(10.0, 25.0);
  const double c = 2e-5, s = 0.001;
  int within = 0, trials = 50;
  for (int t = 0; t < trials; ++t) {
    std::vector<std::vector<AmplitudePoint>> groups;
    for (double i0 : {1.6e-5, 3.2e-5, 2.7e-5, 4.4e-5, 0.05, 0.027}) {
      std::vector<AmplitudePoint> g;
      for (int k = 0; k < 4; ++k) {
        const double a = amplitude(rng);
        const double i = i0 * (1.0 + c * a * a);
        g.push_back({a, i * (1.0 + s * normal(rng)), i * s});
      }
      groups.push_back(g);
    }
    PooledAmplitudeTrend pooled;
    ASSERT_TRUE(FitPooledAmplitudeTrend(groups, &pooled));
    EXPECT_EQ(pooled.n_groups, 6);
    EXPECT_EQ(pooled.n_points, 24);
    EXPECT_EQ(pooled.dof, 17);
    if (std::abs(pooled.coeff_per_deg2 - c) <= 1.96 * pooled.coeff_std_per_deg2) ++within;
  }
  // 95 % coverage; 50 trials: binomial sd 3 %, the bound ~3 sd below.
  EXPECT_GE(within, 43);
}

TEST(AmplitudeTrend, PooledNeedsAmplitudesThatVaryAndADegreeOfFreedom) {
  PooledAmplitudeTrend pooled;
  // One group of two: no degree of freedom left.
  EXPECT_FALSE(FitPooledAmplitudeTrend({{{10.0, 1.0, 0.01}, {20.0, 1.01, 0.01}}}, &pooled));
  // Equal amplitudes within every group.
  EXPECT_FALSE(FitPooledAmplitudeTrend(
      {{{10.0, 1.0, 0.01}, {10.0, 1.01, 0.01}}, {{15.0, 2.0, 0.01}, {15.0, 2.01, 0.01}}}, &pooled));
  // Single-point groups are left out.
  EXPECT_TRUE(FitPooledAmplitudeTrend(
      {{{10.0, 1.0, 0.01}, {20.0, 1.01, 0.01}, {15.0, 1.004, 0.01}}, {{5.0, 3.0, 0.01}}}, &pooled));
  EXPECT_EQ(pooled.n_groups, 1);
}

}  // namespace
}  // namespace bifilar
