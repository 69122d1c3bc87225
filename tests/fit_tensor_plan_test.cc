// Planning a tensor campaign (fit/tensor_plan.h) against known truth: the planned stds against a
// Monte-Carlo of simulated noisy swings on the planned design, fitted by weighted least squares;
// full rank; D-optimality against random designs; rigs that cannot observe some components; the
// trials needed for a target; bad options.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "base/option_check.h"
#include "base/units.h"
#include "fit/tensor.h"
#include "fit/tensor_plan.h"

namespace bifilar {
namespace {

using Components = std::array<double, kTensorComponents>;

// A tensor with products of 2-4 % of the moments (the hidden campaign kind), kg m^2.
const Components kTruth = {2.0, 3.0, 4.5, 0.08, 0.12, -0.06};

Eigen::Matrix3d Tensor(const Components& c) {
  Eigen::Matrix3d j;
  j << c[0], -c[3], -c[4], -c[3], c[1], -c[5], -c[4], -c[5], c[2];
  return j;
}

double Moment(const Components& c, const Eigen::Vector3d& n) {
  return n.normalized().dot(Tensor(c) * n.normalized());
}

Eigen::Vector3d Axis(const TensorPlanOrientation& o) {
  return Eigen::Vector3d(o.axis_in_body[0], o.axis_in_body[1], o.axis_in_body[2]);
}

// Sample std of each component of the WLS estimates over `replicates` simulated campaigns on the
// planned design: each orientation's axis tilted once by an isotropic error of `tilt_std_rad` per
// axis (shared by its trials), each swing with its own noise, the orientation means fitted with
// the plan's weights 1 / (swing_std^2 / trials + tilt variance) about the nominal axes.
Components MonteCarloStd(const TensorPlan& plan, int trials, double tilt_std_rad, int replicates,
                         std::uint64_t seed) {
  const int n = static_cast<int>(plan.orientations.size());
  Eigen::MatrixXd a(n, kTensorComponents);
  Eigen::VectorXd w(n);
  for (int i = 0; i < n; ++i) {
    const auto row = TensorDesignRow(plan.orientations[i].axis_in_body);
    for (int k = 0; k < kTensorComponents; ++k) a(i, k) = row[k];
    w[i] = 1.0 / std::pow(plan.orientations[i].mean_std_kg_m2, 2);
  }
  // theta = (A^T W A)^-1 A^T W y: one estimator matrix for every replicate.
  const Eigen::MatrixXd k =
      (a.transpose() * w.asDiagonal() * a).ldlt().solve(a.transpose() * w.asDiagonal());
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(6), sum2 = Eigen::VectorXd::Zero(6);
  for (int r = 0; r < replicates; ++r) {
    Eigen::VectorXd y(n);
    for (int i = 0; i < n; ++i) {
      const TensorPlanOrientation& o = plan.orientations[i];
      const Eigen::Vector3d nominal = Axis(o);
      Eigen::Vector3d u1 = nominal.unitOrthogonal(), u2 = nominal.cross(u1);
      const Eigen::Vector3d actual = nominal + tilt_std_rad * (normal(rng) * u1 + normal(rng) * u2);
      const double moment = Moment(kTruth, actual);
      double mean = 0.0;
      for (int t = 0; t < trials; ++t) mean += moment + o.swing_std_kg_m2 * normal(rng);
      y[i] = mean / trials;
    }
    const Eigen::VectorXd theta = k * y;
    sum += theta;
    sum2 += theta.cwiseProduct(theta);
  }
  Components s;
  for (int c = 0; c < 6; ++c) {
    const double mean = sum[c] / replicates;
    s[c] = std::sqrt((sum2[c] - replicates * mean * mean) / (replicates - 1));
  }
  return s;
}

TensorPlanOptions FullRig() {
  TensorPlanOptions o;
  o.roll_min_deg = -90;
  o.roll_max_deg = 90;
  o.pitch_min_deg = -90;
  o.pitch_max_deg = 90;
  o.grid_step_deg = 5;
  o.n_orientations = 12;
  o.trials_per_orientation = 2;
  o.sigma_kg_m2 = 0.005;
  return o;
}

TEST(TensorPlanGeometry, AxesAndRowsFollowTheConvention) {
  const auto near = [](const std::array<double, 3>& a, double x, double y, double z) {
    return std::fabs(a[0] - x) < 1e-15 && std::fabs(a[1] - y) < 1e-15 &&
           std::fabs(a[2] - z) < 1e-15;
  };
  EXPECT_TRUE(near(DownInBodyFromAttitude(0, 0), 0, 0, 1));    // level: swings about body z
  EXPECT_TRUE(near(DownInBodyFromAttitude(0, 90), -1, 0, 0));  // nose up 90: about -x (= x)
  EXPECT_TRUE(near(DownInBodyFromAttitude(90, 0), 0, 1, 0));   // right wing down 90: about y
  // The row reproduces n^T J n for an oblique axis (roll 30, pitch -20).
  const auto n = DownInBodyFromAttitude(30, -20);
  const auto row = TensorDesignRow(n);
  double dot = 0;
  for (int k = 0; k < 6; ++k) dot += row[k] * kTruth[k];
  EXPECT_NEAR(dot, Moment(kTruth, Eigen::Vector3d(n[0], n[1], n[2])), 1e-14);
}

TEST(TensorPlan, FullRigGivesAFullRankDesignWhoseStdsMatchAMonteCarlo) {
  TensorPlan plan;
  std::string why;
  ASSERT_TRUE(PlanTensor(FullRig(), &plan, &why)) << why;
  EXPECT_EQ(plan.rank, 6);
  EXPECT_TRUE(plan.unobservable.empty());
  ASSERT_EQ(plan.orientations.size(), 12u);
  EXPECT_EQ(plan.n_points, 24);
  EXPECT_TRUE(plan.warnings.empty());
  // Full rank: the chosen unit-axis rows have 6 non-zero singular values, and a finite
  // condition number.
  Eigen::MatrixXd a(12, 6);
  for (int i = 0; i < 12; ++i) {
    const auto row = TensorDesignRow(plan.orientations[i].axis_in_body);
    for (int k = 0; k < 6; ++k) a(i, k) = row[k];
  }
  const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(a).singularValues();
  EXPECT_GT(sv[5], 0.05 * sv[0]);
  EXPECT_NEAR(plan.condition_number, sv[0] / sv[5], 1e-9 * plan.condition_number);
  // Distinct axes, each inside the rig's range.
  for (int i = 0; i < 12; ++i) {
    EXPECT_LE(std::fabs(plan.orientations[i].roll_deg), 90);
    EXPECT_LE(std::fabs(plan.orientations[i].pitch_deg), 90);
    for (int j = 0; j < i; ++j) {
      EXPECT_LT(std::fabs(Axis(plan.orientations[i]).dot(Axis(plan.orientations[j]))), 1 - 1e-9);
    }
  }
  // With swing noise only the plan's covariance is exact for WLS, so the Monte-Carlo std of 4000
  // campaigns matches it up to the sampling error of a std, 1/sqrt(2 (R - 1)) = 1.1 %:
  constexpr double kRelTol = 0.06;  // 5 sigma of that sampling error
  const Components mc = MonteCarloStd(plan, 2, 0.0, 4000, 17);
  for (int k = 0; k < 6; ++k) {
    SCOPED_TRACE(TensorComponentName(k));
    EXPECT_GT(plan.std_kg_m2[k], 0);
    EXPECT_NEAR(mc[k] / plan.std_kg_m2[k], 1.0, kRelTol);
  }
}

TEST(TensorPlan, RelativeSwingNoiseAndAttitudeErrorMatchAMonteCarlo) {
  TensorPlanOptions o = FullRig();
  o.sigma_kg_m2 = 0.0;
  o.sigma_relative = 0.002;  // 0.2 % of the moment per swing
  o.attitude_std_deg = 0.5;  // per tilt axis, shared by an orientation's trials
  o.trials_per_orientation = 3;
  o.guess_kg_m2 = kTruth;
  o.guess_given = true;
  TensorPlan plan;
  std::string why;
  ASSERT_TRUE(PlanTensor(o, &plan, &why)) << why;
  EXPECT_EQ(plan.rank, 6);
  // The plan linearises the moment in the tilt; the Monte-Carlo tilts the real axis. The second-
  // order term (about tilt^2 (I_max - I_min) = 7.6e-5 x 2.5 kg m^2, 2e-4) is a tenth of the
  // first-order spread (2 tilt |(1 - n n^T) J n| up to ~2e-2), so it moves a std by well under
  // 1 %; the tolerance is the 5-sigma sampling error of 4000 replicates (5.6 %) plus that.
  constexpr double kRelTol = 0.07;
  const Components mc = MonteCarloStd(plan, 3, 0.5 * kRadPerDeg, 4000, 23);
  for (int k = 0; k < 6; ++k) {
    SCOPED_TRACE(TensorComponentName(k));
    EXPECT_NEAR(mc[k] / plan.std_kg_m2[k], 1.0, kRelTol);
    // The attitude error is a floor that more trials cannot lower.
    EXPECT_GT(plan.floor_std_kg_m2[k], 0);
    EXPECT_LT(plan.floor_std_kg_m2[k], plan.std_kg_m2[k]);
  }
}

TEST(TensorPlan, ChosenDesignBeatsRandomDesignsFromTheSameGrid) {
  const TensorPlanOptions o = FullRig();
  TensorPlan plan;
  std::string why;
  ASSERT_TRUE(PlanTensor(o, &plan, &why)) << why;
  // log det of the information matrix of 12 random distinct grid attitudes (2 trials each, same
  // sigma): the exchange must do at least as well as every one of 300 of them.
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<int> grid(-18, 18);  // 5 deg steps in [-90, 90]
  const double w = 2.0 / (o.sigma_kg_m2 * o.sigma_kg_m2);
  for (int r = 0; r < 300; ++r) {
    Eigen::MatrixXd info = Eigen::MatrixXd::Zero(6, 6);
    for (int i = 0; i < 12; ++i) {
      const auto row = TensorDesignRow(DownInBodyFromAttitude(5.0 * grid(rng), 5.0 * grid(rng)));
      const Eigen::Map<const Eigen::Matrix<double, 6, 1>> b(row.data());
      info += w * b * b.transpose();
    }
    const Eigen::VectorXd eig = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(info).eigenvalues();
    if (eig[0] <= 0) continue;  // a singular random design
    EXPECT_GE(plan.log_det_information, eig.array().log().sum());
  }
}

TEST(TensorPlan, RollHeldAtZeroCannotObserveIyyIxyIyz) {
  TensorPlanOptions o = FullRig();
  o.roll_min_deg = o.roll_max_deg = 0;
  TensorPlan plan;
  std::string why;
  ASSERT_TRUE(PlanTensor(o, &plan, &why)) << why;
  EXPECT_EQ(plan.rank, 3);
  EXPECT_EQ(plan.unobservable, (std::vector<std::string>{"Iyy", "Ixy", "Iyz"}));
  EXPECT_EQ(plan.n_combinations, 0);
  ASSERT_FALSE(plan.warnings.empty());
  EXPECT_NE(plan.warnings[0].find("cannot observe Iyy, Ixy, Iyz"), std::string::npos)
      << plan.warnings[0];
  for (int k : {0, 2, 4}) {  // Ixx, Izz, Ixz: the ellipse
    EXPECT_TRUE(plan.observable[k]);
    EXPECT_GT(plan.std_kg_m2[k], 0);
  }
  for (int k : {1, 3, 5}) EXPECT_TRUE(std::isnan(plan.std_kg_m2[k]));
  // Every planned axis is in the x-z plane.
  for (const auto& or_ : plan.orientations) EXPECT_EQ(or_.axis_in_body[1], 0.0);
}

TEST(TensorPlan, PitchHeldAtZeroCannotObserveIxxIxyIxz) {
  TensorPlanOptions o = FullRig();
  o.pitch_min_deg = o.pitch_max_deg = 0;
  TensorPlan plan;
  std::string why;
  ASSERT_TRUE(PlanTensor(o, &plan, &why)) << why;
  EXPECT_EQ(plan.unobservable, (std::vector<std::string>{"Ixx", "Ixy", "Ixz"}));
}

TEST(TensorPlan, AFixedAttitudeObservesOneMomentAndPlansOneOrientation) {
  TensorPlanOptions o = FullRig();
  o.roll_min_deg = o.roll_max_deg = 0;
  o.pitch_min_deg = o.pitch_max_deg = 0;
  TensorPlan plan;
  std::string why;
  ASSERT_TRUE(PlanTensor(o, &plan, &why)) << why;
  EXPECT_EQ(plan.rank, 1);
  EXPECT_EQ(plan.orientations.size(), 1u);
  EXPECT_TRUE(plan.observable[2]);  // Izz only
  EXPECT_NEAR(plan.std_kg_m2[2], 0.005 / std::sqrt(2.0), 1e-15);
  EXPECT_EQ(plan.unobservable.size(), 5u);
}

TEST(TensorPlan, TrialsNeededScaleAsOneOverSqrtTrialsAndStopAtTheAttitudeFloor) {
  TensorPlanOptions o = FullRig();
  TensorPlan plan;
  std::string why;
  ASSERT_TRUE(PlanTensor(o, &plan, &why)) << why;
  double worst = 0;
  for (double s : plan.std_kg_m2) worst = std::max(worst, s);
  // Swing noise only: std(t) = std(2) sqrt(2 / t), so halving the worst std needs 8 trials.
  o.target_std_kg_m2 = worst / 2 * (1 + 1e-9);
  ASSERT_TRUE(PlanTensor(o, &plan, &why)) << why;
  EXPECT_EQ(plan.trials_needed_all, 8);
  for (int k = 0; k < 6; ++k) {
    const double exact = 2 * std::pow(plan.std_kg_m2[k] / o.target_std_kg_m2, 2);
    EXPECT_EQ(plan.trials_needed[k], std::max(1, static_cast<int>(std::ceil(exact - 1e-9))));
  }
  // With an attitude error, a target below its floor cannot be reached by trials.
  o.attitude_std_deg = 1.0;
  o.guess_kg_m2 = kTruth;
  o.guess_given = true;
  o.target_std_kg_m2 = 1e-5;
  ASSERT_TRUE(PlanTensor(o, &plan, &why)) << why;
  EXPECT_EQ(plan.trials_needed_all, -1);
  for (int k = 0; k < 6; ++k) EXPECT_EQ(plan.trials_needed[k], -1);
}

TEST(TensorPlan, BadOptionsSayWhatIsWrong) {
  TensorPlan plan;
  std::string why;
  TensorPlanOptions o = FullRig();
  o.roll_max_deg = 200;
  EXPECT_FALSE(PlanTensor(o, &plan, &why));
  EXPECT_EQ(why, "roll_max_deg = 200; must be in [-180, 180]");
  o = FullRig();
  o.sigma_kg_m2 = 0;
  EXPECT_FALSE(PlanTensor(o, &plan, &why));
  EXPECT_EQ(why,
            "sigma_kg_m2 = 0; must be > 0 when sigma_relative = 0 (a per-swing std, "
            "absolute or relative)");
  o = FullRig();
  o.sigma_relative = 0.01;
  EXPECT_FALSE(PlanTensor(o, &plan, &why));
  EXPECT_EQ(why,
            "guess_kg_m2 = \"not given\"; must be given (at least Ixx, Iyy, Izz) with a "
            "relative swing std or an attitude error");
  o.guess_given = true;
  o.guess_kg_m2 = {1, 1, 1, 2, 0, 0};  // |Ixy| > the moments: not positive definite
  EXPECT_FALSE(PlanTensor(o, &plan, &why));
  // The eigenvalue -1 to rounding: the field, the value, the bound.
  EXPECT_EQ(why.rfind("smallest principal moment of guess_kg_m2 = -1; must be > 0", 0), 0u) << why;
  EXPECT_NE(why.find("; must be > 0 (check the products' signs and sizes)"), std::string::npos)
      << why;
  o = FullRig();
  o.n_orientations = 4;  // fewer than the 6 components the rig can observe
  EXPECT_FALSE(PlanTensor(o, &plan, &why));
  EXPECT_NE(why.find("plan at least 6"), std::string::npos) << why;
}

// Issue 23 item 4: --sigma 1e-160 (or --sigma-rel 1e-170) squared to a subnormal, the weights
// became infinite, no candidate added information and in_design[-1] was written (a heap
// corruption). Item 6: --sigma 1e200 squared to inf, NaN stds and 12 near-identical attitudes.
// The plan is computed in units of the largest std, so the choice is the same at any scale and
// the stds scale with sigma; a sigma above 1e100 kg m^2 is refused by name.
TEST(TensorPlan, TinyAndHugeSigmasGiveTheSameDesignScaled) {
  TensorPlanOptions base = FullRig();
  base.roll_min_deg = -45;
  base.roll_max_deg = 45;
  base.sigma_kg_m2 = 1.0;
  TensorPlan reference;
  std::string why;
  ASSERT_TRUE(PlanTensor(base, &reference, &why)) << why;
  // Equal designs give equal stds to rounding: 1e-12 relative is ~5000 ulp.
  constexpr double kRelTol = 1e-12;
  for (double sigma : {1e-160, 1e-300, 1e-100, 1e99}) {
    SCOPED_TRACE(sigma);
    TensorPlanOptions o = base;
    o.sigma_kg_m2 = sigma;
    TensorPlan plan;
    ASSERT_TRUE(PlanTensor(o, &plan, &why)) << why;
    ASSERT_EQ(plan.orientations.size(), reference.orientations.size());
    for (size_t i = 0; i < plan.orientations.size(); ++i) {
      EXPECT_EQ(plan.orientations[i].roll_deg, reference.orientations[i].roll_deg);
      EXPECT_EQ(plan.orientations[i].pitch_deg, reference.orientations[i].pitch_deg);
      EXPECT_NEAR(plan.orientations[i].mean_std_kg_m2 / sigma,
                  reference.orientations[i].mean_std_kg_m2, kRelTol);
    }
    for (int k = 0; k < 6; ++k) {
      ASSERT_TRUE(std::isfinite(plan.std_kg_m2[k]));
      EXPECT_NEAR(plan.std_kg_m2[k] / sigma / reference.std_kg_m2[k], 1.0, kRelTol);
    }
  }
  // Relative std only, 1e-170 of the moment: the same design as 1e-2, stds 1e-168 of them.
  TensorPlanOptions rel = base;
  rel.sigma_kg_m2 = 0;
  rel.guess_given = true;
  rel.guess_kg_m2 = kTruth;
  rel.sigma_relative = 1e-2;
  ASSERT_TRUE(PlanTensor(rel, &reference, &why)) << why;
  rel.sigma_relative = 1e-170;
  TensorPlan tiny;
  ASSERT_TRUE(PlanTensor(rel, &tiny, &why)) << why;
  ASSERT_EQ(tiny.orientations.size(), reference.orientations.size());
  for (size_t i = 0; i < tiny.orientations.size(); ++i) {
    EXPECT_EQ(tiny.orientations[i].roll_deg, reference.orientations[i].roll_deg);
    EXPECT_EQ(tiny.orientations[i].pitch_deg, reference.orientations[i].pitch_deg);
  }
  for (int k = 0; k < 6; ++k) {
    EXPECT_NEAR(tiny.std_kg_m2[k] / 1e-168 / reference.std_kg_m2[k], 1.0, kRelTol);
  }
  // A relative std of 1e-170 beside an attitude error of 0.5 deg: the tilt dominates every
  // variance, the swing std is still reported as what it is (1e-170 of the moment).
  rel.attitude_std_deg = 0.5;
  TensorPlan tilted;
  ASSERT_TRUE(PlanTensor(rel, &tilted, &why)) << why;
  for (const TensorPlanOrientation& o : tilted.orientations) {
    EXPECT_NEAR(o.swing_std_kg_m2 / (1e-170 * o.inertia_kg_m2), 1.0, kRelTol);
    EXPECT_TRUE(std::isfinite(o.mean_std_kg_m2) && o.mean_std_kg_m2 > 0);
  }
  for (int k = 0; k < 6; ++k) {
    EXPECT_TRUE(std::isfinite(tilted.std_kg_m2[k]) && tilted.std_kg_m2[k] > 0) << k;
    EXPECT_NEAR(tilted.floor_std_kg_m2[k] / tilted.std_kg_m2[k], 1.0, 1e-6) << k;  // all tilt
  }
  // Below 1e-300 kg m^2 the stds would be subnormal: refused, as too small to compute with.
  for (double sigma : {1e-301, 4.9e-324}) {
    TensorPlanOptions o = base;
    o.sigma_kg_m2 = sigma;
    TensorPlan plan;
    EXPECT_FALSE(PlanTensor(o, &plan, &why));
    EXPECT_NE(why.find("too small to compute with"), std::string::npos) << why;
  }
  // Above 1e100 kg m^2 (its square would overflow the covariance): refused, naming the value.
  for (double sigma : {1e101, 1e200, 1.7e308}) {
    TensorPlanOptions o = base;
    o.sigma_kg_m2 = sigma;
    TensorPlan plan;
    EXPECT_FALSE(PlanTensor(o, &plan, &why));
    EXPECT_EQ(why, "sigma_kg_m2 = " + FormatCheckValue(sigma) + "; must be in [0, 1e+100]");
  }
  TensorPlanOptions huge_guess = rel;
  huge_guess.guess_kg_m2 = {1e300, 1e300, 1e300, 0, 0, 0};
  TensorPlan plan;
  EXPECT_FALSE(PlanTensor(huge_guess, &plan, &why));
  EXPECT_EQ(why, "guess_kg_m2 Ixx = 1e+300; must be in [-1e+100, 1e+100]");
}

}  // namespace
}  // namespace bifilar
