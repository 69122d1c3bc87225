// The log simulator (pendulum/simulate.h) against known answers: the free oscillation is the
// integrator's output, the accelerometer at rest points along -down for any pitch and mounting,
// lever-arm terms, dropped-sample statistics, determinism, the campaign's truth, bad input.
#include "pendulum/simulate.h"

#include <cmath>
#include <functional>

#include <gtest/gtest.h>

namespace bifilar {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

TraceSetup PrandtlLikeSetup() {
  TraceSetup s;
  s.geometry.filar_length_m = 2.0;
  s.geometry.filar_separation_m = 1.8;
  s.geometry.mass_kg = 6.75;
  s.params.inertia_kg_m2 = 4.1;
  s.params.drag_coeff_kg_m2 = 0.04;
  s.params.viscous_coeff_kg_m2_per_s = 0.01;
  s.pitch_rad = 20 * kDeg;
  s.amplitude_rad = 25 * kDeg;
  s.imu_offset_in_body_m = Eigen::Vector3d(0.15, 0.10, -0.05);
  return s;
}

// Every noise source off, so the log is the model (the timeline and timestamps stay random).
SimulationOptions Noiseless() {
  SimulationOptions o;
  SensorOptions& s = o.sensor;
  s.gyro_noise_sigma_deg_per_s = s.gyro_bias_sigma_deg_per_s = s.gyro_scale_error_sigma = 0;
  s.accel_noise_sigma_mps2 = s.accel_bias_sigma_mps2 = 0;
  s.rocking_max_deg = 0;
  o.timeline.free_s = {20, 20};
  return o;
}

TEST(Simulate, SameSeedSameTraceDifferentSeedDifferent) {
  SimulatedTrace a, b, c;
  std::string why;
  ASSERT_TRUE(SimulateTrace(PrandtlLikeSetup(), SimulationOptions(), 7, &a, &why)) << why;
  ASSERT_TRUE(SimulateTrace(PrandtlLikeSetup(), SimulationOptions(), 7, &b, &why)) << why;
  ASSERT_TRUE(SimulateTrace(PrandtlLikeSetup(), SimulationOptions(), 8, &c, &why)) << why;
  ASSERT_EQ(a.imu.size(), b.imu.size());
  for (size_t k = 0; k < a.imu.size(); ++k) {
    ASSERT_EQ(a.imu.t_s[k], b.imu.t_s[k]);
    ASSERT_EQ(a.imu.gyro_in_imu[k], b.imu.gyro_in_imu[k]);
    ASSERT_EQ(a.imu.accel_in_imu[k], b.imu.accel_in_imu[k]);
  }
  EXPECT_NE(a.truth.t_release_s, c.truth.t_release_s);
}

TEST(Simulate, FreeOscillationIsTheIntegratorOutput) {
  const TraceSetup setup = PrandtlLikeSetup();
  SimulationOptions options = Noiseless();
  SimulatedTrace trace;
  std::string why;
  ASSERT_TRUE(SimulateTrace(setup, options, 11, &trace, &why)) << why;
  const TraceTruth& truth = trace.truth;
  // Independent integration from the recorded release state at the free samples' times.
  std::vector<double> t{truth.t_release_s};
  std::vector<size_t> index;
  for (size_t k = 0; k < trace.imu.size(); ++k) {
    if (trace.imu.t_s[k] >= truth.t_release_s && trace.imu.t_s[k] < truth.t_stop_s) {
      t.push_back(trace.imu.t_s[k]);
      index.push_back(k);
    }
  }
  ASSERT_EQ(static_cast<int>(index.size()), truth.free_samples);
  ASSERT_GT(index.size(), 1500u);  // 20 s at 100 Hz minus ~1 % drops
  PendulumIntegrator integrator(PendulumModel::kFull, setup.geometry, options.integrator);
  Trajectory trajectory;
  ASSERT_TRUE(integrator.Integrate(setup.params, truth.amplitude_rad, truth.release_rate_rad_per_s,
                                   t, false, &trajectory, &why)) << why;
  // The truth uses CVODES by default; the fit's default Runge-Kutta agrees to the solvers'
  // global error (~1e-9 rad/s at these tolerances; 1e-7 leaves margin, noise is 4e-3 rad/s).
  EXPECT_EQ(options.integrator.method, IntegratorMethod::kCvodes);
  PendulumIntegrator other(PendulumModel::kFull, setup.geometry, IntegratorOptions());
  Trajectory other_trajectory;
  ASSERT_TRUE(other.Integrate(setup.params, truth.amplitude_rad, truth.release_rate_rad_per_s, t,
                              false, &other_trajectory, &why)) << why;
  for (size_t i = 0; i < t.size(); ++i) {
    ASSERT_NEAR(other_trajectory.rate_rad_per_s[i], trajectory.rate_rad_per_s[i], 1e-7);
  }
  const Eigen::Vector3d n(-std::sin(setup.pitch_rad), 0, std::cos(setup.pitch_rad));
  EXPECT_NEAR((truth.swing_axis_in_imu - n).norm(), 0, 1e-15);
  for (size_t i = 0; i < index.size(); ++i) {
    const Eigen::Vector3d& gyro = trace.imu.gyro_in_imu[index[i]];
    // Same computation on the same inputs: agreement to rounding (1e-12 rad/s).
    ASSERT_NEAR(gyro.dot(n), trajectory.rate_rad_per_s[i + 1], 1e-12) << "sample " << i;
    ASSERT_NEAR((gyro - n * gyro.dot(n)).norm(), 0.0, 1e-12);  // nothing off the swing axis
  }
  EXPECT_EQ(truth.amplitude_rad, setup.amplitude_rad);
  // Before the twist the IMU is still.
  EXPECT_EQ(trace.imu.gyro_in_imu[0].norm(), 0.0);
}

TEST(Simulate, AccelerometerAtRestGivesDownForAPitchedTiltedImu) {
  for (double pitch_deg : {-80.0, 0.0, 35.0, 90.0}) {
    TraceSetup setup = PrandtlLikeSetup();
    setup.pitch_rad = pitch_deg * kDeg;
    setup.body_from_imu = MountingFromRollPitchYawDeg(3, -5, 90);
    SimulatedTrace trace;
    std::string why;
    ASSERT_TRUE(SimulateTrace(setup, Noiseless(), 3, &trace, &why)) << why;
    const Eigen::Vector3d n_body(-std::sin(setup.pitch_rad), 0, std::cos(setup.pitch_rad));
    const Eigen::Vector3d n_imu = setup.body_from_imu.transpose() * n_body;
    const Eigen::Vector3d f = trace.imu.accel_in_imu[0];  // at rest, before the twist
    EXPECT_NEAR(f.norm(), setup.geometry.gravity_mps2, 1e-12);
    // docs/physics.md §2: down = -f/|f|.
    EXPECT_NEAR((-f.normalized() - n_imu).norm(), 0.0, 1e-12) << pitch_deg;
    EXPECT_NEAR((trace.truth.swing_axis_in_imu - n_imu).norm(), 0.0, 1e-12);
  }
  // Sanity of the convention: at 90 deg nose-up the swing shows on -x of an aligned IMU.
  TraceSetup up = PrandtlLikeSetup();
  up.pitch_rad = 90 * kDeg;
  SimulatedTrace trace;
  std::string why;
  ASSERT_TRUE(SimulateTrace(up, Noiseless(), 3, &trace, &why)) << why;
  EXPECT_NEAR(trace.truth.swing_axis_in_imu.x(), -1.0, 1e-12);
}

TEST(Simulate, LeverArmAccelerations) {
  // IMU 0.2 m forward of the CG at zero pitch: n = z, so f_x = -0.2 psi'^2 (centripetal) and
  // f_y = 0.2 psi'' (tangential); f_z = -g - d^2h/dt^2.
  TraceSetup setup = PrandtlLikeSetup();
  setup.pitch_rad = 0;
  setup.imu_offset_in_body_m = Eigen::Vector3d(0.2, 0, 0);
  SimulatedTrace trace;
  std::string why;
  ASSERT_TRUE(SimulateTrace(setup, Noiseless(), 5, &trace, &why)) << why;
  double max_centripetal = 0;
  for (size_t k = 0; k < trace.imu.size(); ++k) {
    const Eigen::Vector3d& f = trace.imu.accel_in_imu[k];
    const double rate = trace.rate_rad_per_s[k], acc = trace.accel_rad_per_s2[k];
    ASSERT_NEAR(f.x(), -0.2 * rate * rate, 1e-12);
    ASSERT_NEAR(f.y(), 0.2 * acc, 1e-12);
    const double hdd = RiseCurvature(setup.geometry, trace.angle_rad[k]) * rate * rate +
                       RiseSlope(setup.geometry, trace.angle_rad[k]) * acc;
    ASSERT_NEAR(f.z(), -setup.geometry.gravity_mps2 - hdd, 1e-12);
    max_centripetal = std::max(max_centripetal, -f.x());
  }
  EXPECT_GT(max_centripetal, 0.05);  // the swing really moved the IMU
}

TEST(Simulate, TimestampsIncreaseAndDropFractionMatches) {
  SimulationOptions options;
  options.timeline.free_s = {600, 600};
  options.sensor.drop_fraction = 0.01;
  SimulatedTrace trace;
  std::string why;
  ASSERT_TRUE(SimulateTrace(PrandtlLikeSetup(), options, 21, &trace, &why)) << why;
  const double dt = 1.0 / options.sensor.sample_rate_hz;
  int gaps = 0;
  for (size_t k = 1; k < trace.imu.size(); ++k) {
    ASSERT_GT(trace.imu.t_s[k], trace.imu.t_s[k - 1]);
    if (trace.imu.t_s[k] - trace.imu.t_s[k - 1] > 1.9 * dt) ++gaps;
  }
  const double fraction =
      static_cast<double>(trace.truth.samples_dropped) / trace.truth.samples_nominal;
  EXPECT_EQ(trace.truth.samples_nominal - trace.truth.samples_dropped,
            static_cast<int>(trace.imu.size()));
  // ~60000 samples, ~270 loss events of mean length 2.25: sigma of the fraction ~0.0013
  // (bursts of up to 25 dominate); 0.004 is 3 sigma.
  EXPECT_NEAR(fraction, 0.01, 0.004);
  EXPECT_GT(gaps, 100);
}

TEST(Simulate, SwayCouplingRaisesTheApparentInertiaAsAToTheFourth) {
  // Undamped, at 60 deg: the period with the discrepancy is longer; T^2 ratio ~ 1 + delta
  // (first-order harmonic balance; tolerance 20 % of delta for the higher orders).
  TraceSetup setup = PrandtlLikeSetup();
  setup.params.drag_coeff_kg_m2 = setup.params.viscous_coeff_kg_m2_per_s = 0;
  setup.amplitude_rad = 60 * kDeg;
  auto period = [&](double delta) {
    SimulationOptions options = Noiseless();
    options.sway_coupling_at_60deg = delta;
    options.timeline.release_rate_sigma_deg_per_s = 0;
    options.sensor.time_jitter_sigma_s = 0;
    options.sensor.drop_fraction = 0;
    SimulatedTrace trace;
    std::string why;
    EXPECT_TRUE(SimulateTrace(setup, options, 9, &trace, &why)) << why;
    std::vector<double> crossings;  // downward zero crossings of psi after the release
    for (size_t k = 1; k < trace.imu.size(); ++k) {
      const double a = trace.angle_rad[k - 1], b = trace.angle_rad[k];
      if (trace.imu.t_s[k - 1] > trace.truth.t_release_s && a > 0 && b <= 0) {
        crossings.push_back(trace.imu.t_s[k - 1] + a / (a - b) * (trace.imu.t_s[k] - trace.imu.t_s[k - 1]));
      }
    }
    return (crossings.back() - crossings.front()) / (crossings.size() - 1);
  };
  const double delta = 0.02;
  const double ratio = std::pow(period(delta) / period(0.0), 2);
  EXPECT_NEAR(ratio - 1, delta, 0.2 * delta);
  // A^4 below 60 deg: at 30 deg the excess is delta / 16.
  setup.amplitude_rad = 30 * kDeg;
  const double ratio30 = std::pow(period(delta) / period(0.0), 2);
  EXPECT_NEAR(ratio30 - 1, delta / 16, 0.2 * delta / 16);
}

TEST(Simulate, CampaignTruthAndLayout) {
  CampaignSpec spec;
  constexpr double kSlug = 1.35581795;
  spec.aircraft = {5.5, 2.3596 * kSlug, 2.8477 * kSlug, 0.0178 * kSlug};
  spec.rig.mass_kg = 1.2;
  spec.rig.imu_mass_kg = 0.05;
  spec.rig.inertia_kg_m2 = 0.25;
  spec.filar_length_m = 2.0;
  spec.filar_separation_m = 1.8;
  spec.pitch_deg = {-80, 0, 45};
  spec.trials_per_pitch = 2;
  spec.tare_logs = 2;
  SimulationOptions options;
  options.timeline.free_s = {5, 5};
  std::vector<CampaignTrace> traces;
  std::string why;
  ASSERT_TRUE(SimulateCampaign(spec, options, 42, &traces, &why)) << why;
  ASSERT_EQ(traces.size(), 8u);
  EXPECT_EQ(traces[0].relative_path, "pitch_-80/trial_1.csv");
  EXPECT_EQ(traces[2].relative_path, "pitch_0/trial_1.csv");
  EXPECT_EQ(traces[7].relative_path, "tare/tare_2.csv");
  // Paper Table 2: tau = 0.5 atan2(2 I_xz, I_z - I_x) = 2.0858 deg (the paper prints 2.0875).
  EXPECT_NEAR(spec.aircraft.PrincipalInclinationRad() / kDeg, 2.0858, 1e-4);
  for (const auto& t : traces) {
    const double theta = t.true_pitch_deg * kDeg;
    if (t.is_tare) {
      EXPECT_EQ(t.inertia_aircraft_kg_m2, 0.0);
      EXPECT_NEAR(t.setup.geometry.mass_kg, 1.25, 1e-12);
    } else {
      const double c = std::cos(theta), s = std::sin(theta);
      EXPECT_NEAR(t.inertia_aircraft_kg_m2,
                  spec.aircraft.iz_kg_m2 * c * c + spec.aircraft.ix_kg_m2 * s * s +
                      spec.aircraft.ixz_kg_m2 * 2 * s * c, 1e-12);
      EXPECT_NEAR(t.setup.geometry.mass_kg, 6.75, 1e-12);
      EXPECT_LT(std::abs(t.true_pitch_deg - t.nominal_pitch_deg), 5 * 0.5);  // 5 sigma
    }
    EXPECT_NEAR(t.setup.params.inertia_kg_m2, t.inertia_aircraft_kg_m2 + 0.25, 1e-12);
    EXPECT_NEAR(t.setup.pitch_rad, theta, 1e-15);
    const double amplitude = std::abs(t.setup.amplitude_rad) / kDeg;
    EXPECT_GE(amplitude, 5.0);
    EXPECT_LE(amplitude, 30.0);
  }
  // A log's randomness depends only on (seed, its path): fewer tare logs change no pitch log.
  spec.tare_logs = 0;
  std::vector<CampaignTrace> fewer;
  ASSERT_TRUE(SimulateCampaign(spec, options, 42, &fewer, &why)) << why;
  ASSERT_EQ(fewer.size(), 6u);
  EXPECT_EQ(fewer[3].trace.imu.gyro_in_imu.back(), traces[3].trace.imu.gyro_in_imu.back());
  EXPECT_EQ(FormatPitchDeg(-0.0), "0");
  EXPECT_EQ(FormatPitchDeg(12.5), "12.5");
}

TEST(Simulate, BadInputNamesTheParameter) {
  struct Case {
    const char* expect;
    std::function<void(TraceSetup*, SimulationOptions*)> edit;
  };
  const std::vector<Case> cases = {
      {"filar_length_m", [](TraceSetup* s, SimulationOptions*) { s->geometry.filar_length_m = -1; }},
      {"filar_length_m (L) = 1.5 must be greater than filar_separation_m",
       [](TraceSetup* s, SimulationOptions*) { s->geometry.filar_length_m = 1.5; }},
      {"filar_separation_m", [](TraceSetup* s, SimulationOptions*) { s->geometry.filar_separation_m = 0; }},
      {"mass_kg", [](TraceSetup* s, SimulationOptions*) { s->geometry.mass_kg = 0; }},
      {"inertia_kg_m2", [](TraceSetup* s, SimulationOptions*) { s->params.inertia_kg_m2 = -2; }},
      {"inertia_kg_m2", [](TraceSetup* s, SimulationOptions*) { s->params.inertia_kg_m2 = NAN; }},
      {"amplitude", [](TraceSetup* s, SimulationOptions*) { s->amplitude_rad = 0; }},
      {"sensor.sample_rate_hz", [](TraceSetup*, SimulationOptions* o) { o->sensor.sample_rate_hz = 0; }},
      {"timeline.free_s", [](TraceSetup*, SimulationOptions* o) { o->timeline.free_s = {0, 0}; }},
      {"timeline.free_s", [](TraceSetup*, SimulationOptions* o) { o->timeline.free_s = {-5, 10}; }},
      {"sensor.drop_fraction", [](TraceSetup*, SimulationOptions* o) { o->sensor.drop_fraction = 0.9; }},
      {"timeline.stop_probability", [](TraceSetup*, SimulationOptions* o) { o->timeline.stop_probability = 2; }},
  };
  for (const Case& c : cases) {
    TraceSetup setup = PrandtlLikeSetup();
    SimulationOptions options;
    c.edit(&setup, &options);
    SimulatedTrace trace;
    std::string why;
    EXPECT_FALSE(SimulateTrace(setup, options, 1, &trace, &why)) << c.expect;
    EXPECT_NE(why.find(c.expect), std::string::npos) << "message: " << why;
    EXPECT_TRUE(trace.imu.t_s.empty());
  }
}

}  // namespace
}  // namespace bifilar
