// Swing axis, measured pitch and secondary motion against known truth: synthetic rotated IMU data
// built here and the simulator's logs (pendulum/simulate.h), whose truth records the axis.
#include "fit/swing_axis.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "base/units.h"
#include "pendulum/simulate.h"

namespace bifilar {
namespace {

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) / kRadPerDeg;
}

Eigen::Vector3d DownInBody(double pitch_deg) {
  return Eigen::Vector3d(-std::sin(pitch_deg * kRadPerDeg), 0.0, std::cos(pitch_deg * kRadPerDeg));
}

TEST(SwingAxis, PitchSignConvention) {
  // docs/physics.md §3: n_body = (-sin theta, 0, cos theta), nose-up positive.
  for (double pitch : {-80.0, -30.0, 0.0, 12.5, 45.0, 89.0, 90.0}) {
    EXPECT_NEAR(PitchFromDownDeg(DownInBody(pitch)), pitch, 1e-12) << pitch;
    EXPECT_NEAR(RollFromDownDeg(DownInBody(pitch)), 0.0, 1e-9) << pitch;
  }
  // Nose up by 30 deg: gravity pulls toward the tail, so the down vector has a negative x.
  EXPECT_LT(DownInBody(30).x(), 0.0);
  EXPECT_NEAR(PitchFromDownDeg(Eigen::Vector3d(-0.5, 0.0, std::sqrt(0.75))), 30.0, 1e-12);
  // A small roll does not change the pitch (Euler pitch = asin(-n_x)).
  const double th = 20 * kRadPerDeg, ph = 3 * kRadPerDeg;
  const Eigen::Vector3d rolled(-std::sin(th), std::sin(ph) * std::cos(th),
                               std::cos(ph) * std::cos(th));
  EXPECT_NEAR(PitchFromDownDeg(rolled), 20.0, 1e-12);
  EXPECT_NEAR(RollFromDownDeg(rolled), 3.0, 1e-12);
}

// Rest, then a swing about the down vertical with a small rocking about a horizontal axis.
struct Synthetic {
  ImuData data;
  Eigen::Vector3d down_in_imu;
  Eigen::Matrix3d imu_to_body;
};

Synthetic MakeSynthetic(double pitch_deg, const Eigen::Matrix3d& imu_to_body, bool rest,
                        uint64_t seed, double rocking = 0.02) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Synthetic s;
  s.imu_to_body = imu_to_body;
  s.down_in_imu = imu_to_body.transpose() * DownInBody(pitch_deg);
  const Eigen::Vector3d horiz_in_imu = imu_to_body.transpose() * Eigen::Vector3d::UnitY();
  const Eigen::Vector3d bias(0.008, -0.005, 0.006);
  const double gyro_sigma = 0.25 * kRadPerDeg, accel_sigma = 0.02;
  const double t_release = rest ? 3.0 : 0.0, w = 2 * kPi / 1.8;
  for (int k = 0; k < 4000; ++k) {
    const double t = 0.01 * k;
    double rate = 0.0, rock = 0.0;
    if (t >= t_release) {
      rate = 0.4 * std::exp(-0.02 * (t - t_release)) * std::sin(w * (t - t_release));
      rock = rocking * std::sin(2 * kPi * 0.35 * (t - t_release));
    }
    const Eigen::Vector3d noise_g(normal(rng), normal(rng), normal(rng));
    const Eigen::Vector3d noise_a(normal(rng), normal(rng), normal(rng));
    s.data.t_s.push_back(t);
    s.data.gyro_in_imu.push_back(rate * s.down_in_imu + rock * horiz_in_imu + bias +
                                 gyro_sigma * noise_g);
    s.data.accel_in_imu.push_back(-kStandardGravityMps2 * s.down_in_imu + accel_sigma * noise_a);
  }
  return s;
}

TEST(SwingAxis, RotatedImuAccelerometerAtRest) {
  // Tolerances: 0.02 m/s^2 accelerometer noise averaged over ~250 rest samples tilts the down
  // vector by ~0.02/9.8/sqrt(250) rad = 0.007 deg; 0.1 deg (pitch) is > 10 sigma.
  for (double pitch : {-70.0, -20.0, 0.0, 35.0, 80.0}) {
    const Eigen::Matrix3d mount = MountingFromRollPitchYawDeg(4.0, -9.0, 125.0);
    const Synthetic s = MakeSynthetic(pitch, mount, true, 11);
    SwingAxisOptions o;
    o.imu_to_body = mount;
    SwingAxis axis;
    std::string why;
    ASSERT_TRUE(EstimateSwingAxis(s.data, o, std::nullopt, &axis, &why)) << why;
    EXPECT_EQ(axis.source, SwingAxisSource::kAccelAtRest);
    EXPECT_GT(axis.rest_samples, 200);
    EXPECT_LT(AngleDeg(axis.axis_in_imu, s.down_in_imu), 0.05) << pitch;
    ASSERT_TRUE(axis.pitch_measured_deg.has_value());
    EXPECT_NEAR(*axis.pitch_measured_deg, pitch, 0.1);
    EXPECT_NEAR(*axis.roll_measured_deg, 0.0, 0.1);
    EXPECT_NEAR(axis.rest_accel_mps2, kStandardGravityMps2, 0.01);
    ASSERT_EQ(axis.rate_rad_per_s.size(), s.data.size());
    EXPECT_NEAR(axis.rate_rad_per_s[100], s.data.gyro_in_imu[100].dot(axis.axis_in_imu), 1e-15);
  }
}

TEST(SwingAxis, WithoutRestUsesWindowAverage) {
  const Eigen::Matrix3d mount = MountingFromRollPitchYawDeg(0.0, 0.0, 0.0);
  const Synthetic s = MakeSynthetic(15.0, mount, false, 12);
  SwingAxisOptions o;
  SwingAxis axis;
  std::string why;
  ASSERT_TRUE(EstimateSwingAxis(s.data, o, std::make_pair(5.0, 35.0), &axis, &why)) << why;
  EXPECT_EQ(axis.source, SwingAxisSource::kAccelOverWindow);
  EXPECT_FALSE(axis.notes.empty());
  // No lever arm in this synthetic data, so the window average is as good as rest.
  EXPECT_NEAR(*axis.pitch_measured_deg, 15.0, 0.1);
}

TEST(SwingAxis, GyroOnlyPrincipalDirection) {
  // Gyro noise 0.25 deg/s against a 0.4 rad/s swing over 37 s: the principal direction is good to
  // ~0.01 deg; the 0.02 rad/s rocking is orthogonal and smaller, so it does not tilt it.
  const Eigen::Matrix3d mount = MountingFromRollPitchYawDeg(-3.0, 6.0, -50.0);
  for (double pitch : {-60.0, 10.0, 70.0}) {
    Synthetic s = MakeSynthetic(pitch, mount, true, 13);
    s.data.accel_in_imu.clear();
    SwingAxisOptions o;
    o.imu_to_body = mount;
    SwingAxis axis;
    std::string why;
    ASSERT_TRUE(EstimateSwingAxis(s.data, o, std::nullopt, &axis, &why)) << why;
    EXPECT_EQ(axis.source, SwingAxisSource::kGyroPrincipal);
    EXPECT_FALSE(axis.pitch_measured_deg.has_value());
    // Sign rule: z >= 0 in body axes, which is the down vertical's sign for |pitch| < 90 deg.
    EXPECT_LT(AngleDeg(axis.axis_in_imu, s.down_in_imu), 0.5) << pitch;
    EXPECT_GE(axis.axis_in_body.z(), 0.0);
  }
}

TEST(SwingAxis, FixedAxis) {
  const Synthetic s = MakeSynthetic(0.0, Eigen::Matrix3d::Identity(), true, 14);
  SwingAxisOptions o;
  o.mode = SwingAxisMode::kFixed;
  o.fixed_axis_in_imu = Eigen::Vector3d(0, 0, 2);
  SwingAxis axis;
  std::string why;
  ASSERT_TRUE(EstimateSwingAxis(s.data, o, std::nullopt, &axis, &why)) << why;
  EXPECT_EQ(axis.source, SwingAxisSource::kFixed);
  EXPECT_DOUBLE_EQ(axis.axis_in_imu.z(), 1.0);
  EXPECT_DOUBLE_EQ(axis.rate_rad_per_s[500], s.data.gyro_in_imu[500].z());
  ASSERT_TRUE(axis.pitch_measured_deg.has_value());  // still measured from the accelerometer
  EXPECT_NEAR(*axis.pitch_measured_deg, 0.0, 0.1);
  o.fixed_axis_in_imu.setZero();
  EXPECT_FALSE(EstimateSwingAxis(s.data, o, std::nullopt, &axis, &why));
  EXPECT_NE(why.find("swing axis: |fixed_axis_in_imu| = 0; must be finite and > 1e-09"),
            std::string::npos)
      << why;
}

TEST(SwingAxis, Rejects) {
  Synthetic s = MakeSynthetic(0.0, Eigen::Matrix3d::Identity(), true, 15);
  SwingAxis axis;
  std::string why;
  // Accelerometer in g read as m/s^2: |f| = 1, not gravity. An error when the caller needs the
  // accelerometer, naming the unit key.
  ImuData wrong_unit = s.data;
  for (auto& f : wrong_unit.accel_in_imu) f /= kStandardGravityMps2;
  SwingAxisOptions required;
  required.accel_required = true;
  EXPECT_FALSE(EstimateSwingAxis(wrong_unit, required, std::nullopt, &axis, &why));
  EXPECT_NE(why.find("set imu.accel.unit: g"), std::string::npos) << why;
  // Constant gyro, no accelerometer: no axis to find.
  ImuData flat = s.data;
  flat.accel_in_imu.clear();
  for (auto& g : flat.gyro_in_imu) g = Eigen::Vector3d(0.01, 0.0, 0.0);
  EXPECT_FALSE(EstimateSwingAxis(flat, SwingAxisOptions(), std::nullopt, &axis, &why));
  EXPECT_NE(why.find("constant"), std::string::npos) << why;
  // Not a rotation.
  SwingAxisOptions bad;
  bad.imu_to_body = 2.0 * Eigen::Matrix3d::Identity();
  EXPECT_FALSE(bad.Check(&why));
  EXPECT_FALSE(EstimateSwingAxis(ImuData(), SwingAxisOptions(), std::nullopt, &axis, &why));
}

// A logger that removes gravity leaves g (n_est - n): ~0.1-0.3 g, nearly perpendicular to the
// down vertical (the swing axis). It is ignored with a warning, the axis comes from the gyro; the
// same small reading along the swing axis (g read as m/s^2) stays an error (test above).
TEST(SwingAxis, GravityRemovedAccelerometerIsIgnoredWithAWarning) {
  const Eigen::Matrix3d mount = MountingFromRollPitchYawDeg(0, 0, 30);
  Synthetic s = MakeSynthetic(15.0, mount, true, 21);
  const Eigen::Vector3d across = s.down_in_imu.unitOrthogonal();
  for (double tilt_deg : {4.0, 15.0}) {
    // Residual of a tilt error of tilt_deg about `across x n`: 2 g sin(tilt/2), at 90 - tilt/2
    // deg from n.
    const Eigen::Vector3d n_est =
        Eigen::AngleAxisd(tilt_deg * kRadPerDeg, across.cross(s.down_in_imu).normalized()) *
        s.down_in_imu;
    ImuData removed = s.data;
    for (auto& f : removed.accel_in_imu)
      f += kStandardGravityMps2 * n_est;  // f + g n_est: gravity removed
    SwingAxis axis;
    std::string why;
    ASSERT_TRUE(EstimateSwingAxis(removed, SwingAxisOptions(), std::nullopt, &axis, &why)) << why;
    EXPECT_TRUE(axis.accel_ignored);
    EXPECT_EQ(axis.source, SwingAxisSource::kGyroPrincipal);
    EXPECT_FALSE(axis.pitch_measured_deg.has_value());
    ASSERT_EQ(axis.warnings.size(), 1u);
    EXPECT_NE(axis.warnings[0].find("gravity removed"), std::string::npos) << axis.warnings[0];
    EXPECT_NE(axis.warnings[0].find("imu.accel: null"), std::string::npos) << axis.warnings[0];
    // The axis is the swing's, within the rocking's pull on the principal direction (~0.5 deg).
    EXPECT_LT(std::min(AngleDeg(axis.axis_in_imu, s.down_in_imu),
                       AngleDeg(-axis.axis_in_imu, s.down_in_imu)),
              1.0);
  }
  // With the diagnosis off (0), still ignored, but not called "gravity removed".
  SwingAxisOptions off;
  off.gravity_removed_below_g = 0.0;
  ImuData removed = s.data;
  for (auto& f : removed.accel_in_imu)
    f += kStandardGravityMps2 * (s.down_in_imu + 0.2 * s.down_in_imu.unitOrthogonal()).normalized();
  SwingAxis axis;
  std::string why;
  ASSERT_TRUE(EstimateSwingAxis(removed, off, std::nullopt, &axis, &why)) << why;
  EXPECT_TRUE(axis.accel_ignored);
  ASSERT_EQ(axis.warnings.size(), 1u);
  EXPECT_EQ(axis.warnings[0].find("gravity removed"), std::string::npos) << axis.warnings[0];
  EXPECT_NE(axis.warnings[0].find("neither gravity"), std::string::npos) << axis.warnings[0];
}

// issue 16 item 4: an accelerometer that reads neither gravity nor zero (the fixed-wing rig's
// 0.27 g, along the vertical), or gravity in a wrong unit, is ignored with a warning that says
// what the reading looks like; the axis comes from the gyro. Only accel_required makes it an
// error.
TEST(SwingAxis, AccelerometerThatDoesNotReadGravityIsIgnored) {
  const Eigen::Matrix3d mount = MountingFromRollPitchYawDeg(0, 10, 30);
  Synthetic s = MakeSynthetic(15.0, mount, true, 33);
  // The advice names the other unit than the one declared (accel_unit_si), never the same.
  const struct {
    double scale;
    const char* says;
    double declared_unit_si;
  } cases[] = {{0.27, "neither gravity", 1.0},
               {1.0 / kStandardGravityMps2, "set imu.accel.unit: g", 1.0},
               {kStandardGravityMps2, "set imu.accel.unit: m/s^2", kStandardGravityMps2},
               {1.0 / kStandardGravityMps2, "neither gravity", kStandardGravityMps2},
               {kStandardGravityMps2, "neither gravity", 1.0}};
  for (const auto& c : cases) {
    ImuData odd = s.data;
    for (auto& f : odd.accel_in_imu) f *= c.scale;
    SwingAxis axis;
    std::string why;
    SwingAxisOptions declared;
    declared.accel_unit_si = c.declared_unit_si;
    ASSERT_TRUE(EstimateSwingAxis(odd, declared, std::nullopt, &axis, &why)) << why;
    EXPECT_TRUE(axis.accel_ignored) << c.says;
    EXPECT_EQ(axis.source, SwingAxisSource::kGyroPrincipal) << c.says;
    EXPECT_FALSE(axis.pitch_measured_deg.has_value()) << c.says;
    ASSERT_EQ(axis.warnings.size(), 1u) << c.says;
    EXPECT_NE(axis.warnings[0].find(c.says), std::string::npos) << axis.warnings[0];
    EXPECT_NE(axis.warnings[0].find(kAccelIgnoredSentence), std::string::npos) << axis.warnings[0];
    // The gyro's axis is the swing's, within the rocking's pull on the principal direction.
    EXPECT_LT(std::min(AngleDeg(axis.axis_in_imu, s.down_in_imu),
                       AngleDeg(-axis.axis_in_imu, s.down_in_imu)),
              1.0)
        << c.says;
    SwingAxisOptions required = declared;
    required.accel_required = true;
    EXPECT_FALSE(EstimateSwingAxis(odd, required, std::nullopt, &axis, &why)) << c.says;
    EXPECT_NE(why.find(c.says), std::string::npos) << why;
  }
}

TEST(SwingAxis, SecondaryMotionRatio) {
  // Exact: gyro = w(t) n + eps w(t) m + constant bias, m orthogonal to n -> ratio eps.
  ImuData d;
  const Eigen::Vector3d n = Eigen::Vector3d(0.2, -0.3, 0.9).normalized();
  const Eigen::Vector3d m = n.cross(Eigen::Vector3d::UnitX()).normalized();
  for (int k = 0; k < 3000; ++k) {
    const double t = 0.01 * k, w = std::sin(3.0 * t);
    d.t_s.push_back(t);
    d.gyro_in_imu.push_back(w * n + 0.07 * w * m + Eigen::Vector3d(0.01, 0.02, -0.01));
  }
  EXPECT_NEAR(SecondaryMotionRatio(d, n, 2.0, 25.0), 0.07, 1e-12);
  EXPECT_NEAR(SecondaryMotionRatio(d, -n, 2.0, 25.0), 0.07, 1e-12);
  EXPECT_DOUBLE_EQ(SecondaryMotionRatio(d, n, 50.0, 60.0), 0.0);  // empty range
  ImuData still = d;
  for (auto& g : still.gyro_in_imu) g.setConstant(0.01);
  EXPECT_DOUBLE_EQ(SecondaryMotionRatio(still, n, 2.0, 25.0), 0.0);
}

// The rig of the simulated-log tests: L = 2 m, D = 0.7 m, 10 kg, 0.8 kg m^2, light damping.
TraceSetup SimulatedRig() {
  TraceSetup setup;
  setup.geometry.filar_length_m = 2.0;
  setup.geometry.filar_separation_m = 0.7;
  setup.geometry.mass_kg = 10.0;
  setup.params.inertia_kg_m2 = 0.8;
  setup.params.drag_coeff_kg_m2 = 0.005;
  setup.params.viscous_coeff_kg_m2_per_s = 0.001;
  return setup;
}

// Simulated logs: tilted IMU at many pitches; the axis against the simulator's truth, the pitch
// against the true pitch. Accelerometer bias is what limits the pitch: with the simulator's
// default 0.05 m/s^2 per axis it tilts the down vector by up to ~0.5 deg, so the 0.1 deg check
// runs with the bias off and a 4-sigma bound (4 * 0.05 / 9.8 rad = 1.2 deg) with it on.
TEST(SwingAxis, SimulatedLogs) {
  for (bool accel_bias : {false, true}) {
    SimulationOptions options;
    options.timeline.free_s = {15.0, 20.0};
    if (!accel_bias) options.sensor.accel_bias_sigma_mps2 = 0.0;
    for (int i = 0; i < 8; ++i) {
      TraceSetup setup = SimulatedRig();
      setup.pitch_rad = (-75.0 + 21.0 * i) * kRadPerDeg;
      setup.amplitude_rad = (8.0 + 3.0 * i) * kRadPerDeg;
      setup.body_from_imu = MountingFromRollPitchYawDeg(3.0 - i, 2.0 * i - 7.0, 45.0 * i);
      setup.imu_offset_in_body_m = Eigen::Vector3d(0.25, 0.1, -0.05);
      SimulatedTrace trace;
      std::string why;
      ASSERT_TRUE(SimulateTrace(setup, options, 500 + i, &trace, &why)) << why;
      SwingAxisOptions o;
      o.imu_to_body = setup.body_from_imu;
      SwingAxis axis;
      ASSERT_TRUE(EstimateSwingAxis(trace.imu, o, std::nullopt, &axis, &why)) << why;
      SCOPED_TRACE("sim " + std::to_string(i) + (accel_bias ? " with accel bias" : ""));
      EXPECT_EQ(axis.source, SwingAxisSource::kAccelAtRest);
      EXPECT_LT(AngleDeg(axis.axis_in_imu, trace.truth.swing_axis_in_imu), accel_bias ? 1.2 : 0.1);
      ASSERT_TRUE(axis.pitch_measured_deg.has_value());
      EXPECT_NEAR(*axis.pitch_measured_deg, setup.pitch_rad / kRadPerDeg, accel_bias ? 1.2 : 0.1);
      // Gyro only: the principal direction of the same log, within 0.5 deg of the truth.
      ImuData gyro_only = trace.imu;
      gyro_only.accel_in_imu.clear();
      SwingAxis principal;
      ASSERT_TRUE(EstimateSwingAxis(gyro_only, o, std::nullopt, &principal, &why)) << why;
      EXPECT_LT(AngleDeg(principal.axis_in_imu, trace.truth.swing_axis_in_imu), 0.5);
      // Secondary motion: the simulator's rocking (<= 0.3 deg) is small against the swing.
      const double ratio =
          SecondaryMotionRatio(trace.imu, axis.axis_in_imu, trace.truth.t_release_s + 2.0,
                               trace.truth.t_release_s + 12.0);
      EXPECT_LT(ratio, 0.2);
      EXPECT_GT(ratio, 0.0);
    }
  }
}

// A log without rest (logging started during the hold): the pitch comes from the window's turning
// points. The IMU sits 0.35 m off the swing axis on a 30 deg swing, where a plain average of the
// accelerometer over the window would be tilted by ~<psi'^2> r / g ~ 1 deg by the centripetal
// term; at the turning points the residual tilt is < 0.1 deg (no accelerometer bias here).
TEST(SwingAxis, NoRestPitchFromTurningPoints) {
  SimulationOptions options;
  options.timeline.rest_before_s = {0.0, 0.0};
  options.timeline.stop_probability = 0.0;
  options.timeline.free_s = {30.0, 30.0};
  options.sensor.accel_bias_sigma_mps2 = 0.0;
  for (int i = 0; i < 4; ++i) {
    TraceSetup setup = SimulatedRig();
    setup.pitch_rad = (-40.0 + 25.0 * i) * kRadPerDeg;
    setup.amplitude_rad = 30.0 * kRadPerDeg;
    setup.body_from_imu = MountingFromRollPitchYawDeg(2.0, -4.0, 60.0 * i);
    setup.imu_offset_in_body_m = Eigen::Vector3d(0.35, 0.0, 0.0);
    SimulatedTrace trace;
    std::string why;
    ASSERT_TRUE(SimulateTrace(setup, options, 800 + i, &trace, &why)) << why;
    SCOPED_TRACE("sim " + std::to_string(i));
    SwingAxisOptions o;
    o.imu_to_body = setup.body_from_imu;
    SwingAxis axis;
    ASSERT_TRUE(EstimateSwingAxis(trace.imu, o, std::nullopt, &axis, &why)) << why;
    EXPECT_EQ(axis.source, SwingAxisSource::kAccelOverWindow);
    EXPECT_FALSE(axis.pitch_measured_deg.has_value());  // no rest, no window: no pitch
    const double t0 = trace.truth.t_release_s + 1.0, t1 = trace.truth.t_release_s + 25.0;
    ASSERT_TRUE(EstimateSwingAxis(trace.imu, o, std::make_pair(t0, t1), &axis, &why)) << why;
    ASSERT_TRUE(axis.pitch_measured_deg.has_value());
    EXPECT_NEAR(*axis.pitch_measured_deg, setup.pitch_rad / kRadPerDeg, 0.1);
    EXPECT_LT(AngleDeg(axis.axis_in_imu, trace.truth.swing_axis_in_imu), 0.1);
    // The plain window average is visibly worse (this is what the turning points fix).
    Eigen::Vector3d f = Eigen::Vector3d::Zero();
    for (size_t k = 0; k < trace.imu.size(); ++k) {
      if (trace.imu.t_s[k] >= t0 && trace.imu.t_s[k] <= t1) f += trace.imu.accel_in_imu[k];
    }
    EXPECT_GT(AngleDeg(-f.normalized(), trace.truth.swing_axis_in_imu), 0.3);
  }
}

}  // namespace
}  // namespace bifilar
