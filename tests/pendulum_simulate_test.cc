// The log simulator (pendulum/simulate.h) against known answers: the free oscillation is the
// integrator's output, the accelerometer at rest points along -down for any pitch and mounting,
// lever-arm terms, dropped-sample statistics, determinism, the campaign's truth, bad input.
#include "pendulum/simulate.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include <gtest/gtest.h>

#include "base/units.h"

namespace bifilar {
namespace {

TraceSetup PrandtlLikeSetup() {
  TraceSetup s;
  s.geometry.filar_length_m = 2.0;
  s.geometry.filar_separation_m = 1.8;
  s.geometry.mass_kg = 6.75;
  s.params.inertia_kg_m2 = 4.1;
  s.params.drag_coeff_kg_m2 = 0.04;
  s.params.viscous_coeff_kg_m2_per_s = 0.01;
  s.pitch_rad = 20 * kRadPerDeg;
  s.amplitude_rad = 25 * kRadPerDeg;
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
                                   t, false, &trajectory, &why))
      << why;
  // The truth uses CVODES by default; the fit's default Runge-Kutta agrees to the solvers'
  // global error (~1e-9 rad/s at these tolerances; 1e-7 leaves margin, noise is 4e-3 rad/s).
  EXPECT_EQ(options.integrator.method, IntegratorMethod::kCvodes);
  PendulumIntegrator other(PendulumModel::kFull, setup.geometry, IntegratorOptions());
  Trajectory other_trajectory;
  ASSERT_TRUE(other.Integrate(setup.params, truth.amplitude_rad, truth.release_rate_rad_per_s, t,
                              false, &other_trajectory, &why))
      << why;
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
    setup.pitch_rad = pitch_deg * kRadPerDeg;
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
  up.pitch_rad = 90 * kRadPerDeg;
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
  setup.amplitude_rad = 60 * kRadPerDeg;
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
        crossings.push_back(trace.imu.t_s[k - 1] +
                            a / (a - b) * (trace.imu.t_s[k] - trace.imu.t_s[k - 1]));
      }
    }
    return (crossings.back() - crossings.front()) / (crossings.size() - 1);
  };
  const double delta = 0.02;
  const double ratio = std::pow(period(delta) / period(0.0), 2);
  EXPECT_NEAR(ratio - 1, delta, 0.2 * delta);
  // A^4 below 60 deg: at 30 deg the excess is delta / 16.
  setup.amplitude_rad = 30 * kRadPerDeg;
  const double ratio30 = std::pow(period(delta) / period(0.0), 2);
  EXPECT_NEAR(ratio30 - 1, delta / 16, 0.2 * delta / 16);
}

TEST(Simulate, CampaignTruthAndLayout) {
  CampaignSpec spec;
  constexpr double kSlug = kKgM2PerSlugFt2;
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
  EXPECT_NEAR(spec.aircraft.PrincipalInclinationRad() / kRadPerDeg, 2.0858, 1e-4);
  for (const auto& t : traces) {
    const double theta = t.true_pitch_deg * kRadPerDeg;
    if (t.is_tare) {
      EXPECT_EQ(t.inertia_aircraft_kg_m2, 0.0);
      EXPECT_NEAR(t.setup.geometry.mass_kg, 1.25, 1e-12);
    } else {
      const double c = std::cos(theta), s = std::sin(theta);
      EXPECT_NEAR(t.inertia_aircraft_kg_m2,
                  spec.aircraft.iz_kg_m2 * c * c + spec.aircraft.ix_kg_m2 * s * s +
                      spec.aircraft.ixz_kg_m2 * 2 * s * c,
                  1e-12);
      EXPECT_NEAR(t.setup.geometry.mass_kg, 6.75, 1e-12);
      EXPECT_LT(std::abs(t.true_pitch_deg - t.nominal_pitch_deg), 5 * 0.5);  // 5 sigma
    }
    EXPECT_NEAR(t.setup.params.inertia_kg_m2, t.inertia_aircraft_kg_m2 + 0.25, 1e-12);
    EXPECT_NEAR(t.setup.pitch_rad, theta, 1e-15);
    const double amplitude = std::abs(t.setup.amplitude_rad) / kRadPerDeg;
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
      {"filar_length_m (L) = -1; must be in (0, 1000]",
       [](TraceSetup* s, SimulationOptions*) { s->geometry.filar_length_m = -1; }},
      {"filar_separation_m (D) = 1.8; must be < filar_length_m (L) = 1.5 (the wires would go "
       "slack)",
       [](TraceSetup* s, SimulationOptions*) { s->geometry.filar_length_m = 1.5; }},
      {"filar_separation_m (D) = 0; must be in (0, 1000]",
       [](TraceSetup* s, SimulationOptions*) { s->geometry.filar_separation_m = 0; }},
      {"mass_kg (whole suspended mass) = 0; must be in (0, 1000000]",
       [](TraceSetup* s, SimulationOptions*) { s->geometry.mass_kg = 0; }},
      {"inertia_kg_m2 (whole suspended inertia) = -2; must be in (0, 1000000000]",
       [](TraceSetup* s, SimulationOptions*) { s->params.inertia_kg_m2 = -2; }},
      {"inertia_kg_m2 (whole suspended inertia) = nan; must be in (0, 1000000000]",
       [](TraceSetup* s, SimulationOptions*) { s->params.inertia_kg_m2 = NAN; }},
      {"amplitude_deg = 0; must be 0 < |amplitude_deg| < 89",
       [](TraceSetup* s, SimulationOptions*) { s->amplitude_rad = 0; }},
      {"pitch_deg = 100; must be in [-90, 90]",
       [](TraceSetup* s, SimulationOptions*) { s->pitch_rad = 100 * kRadPerDeg; }},
      {"|imu_offset_in_body_m| = 200; must be <= 100",
       [](TraceSetup* s, SimulationOptions*) {
         s->imu_offset_in_body_m = {200, 0, 0};
       }},
      {"det(body_from_imu) = -1; must be > 0",
       [](TraceSetup* s, SimulationOptions*) { s->body_from_imu = -Eigen::Matrix3d::Identity(); }},
      {"sensor.sample_rate_hz = 0; must be in (0, 100000]",
       [](TraceSetup*, SimulationOptions* o) { o->sensor.sample_rate_hz = 0; }},
      {"timeline.free_s.min = 0; must be > 0",
       [](TraceSetup*, SimulationOptions* o) {
         o->timeline.free_s = {0, 0};
       }},
      {"timeline.free_s.min = -5; must be > 0",
       [](TraceSetup*, SimulationOptions* o) {
         o->timeline.free_s = {-5, 10};
       }},
      {"timeline.free_s.min = 20; must be <= timeline.free_s.max = 10",
       [](TraceSetup*, SimulationOptions* o) {
         o->timeline.free_s = {20, 10};
       }},
      {"integrator: rel_tol = 0.1; must be in (0, 0.01]",
       [](TraceSetup*, SimulationOptions* o) { o->integrator.rel_tol = 0.1; }},
      {"sensor.drop_fraction = 0.9; must be in [0, 0.5]",
       [](TraceSetup*, SimulationOptions* o) { o->sensor.drop_fraction = 0.9; }},
      {"timeline.stop_probability = 2; must be in [0, 1]",
       [](TraceSetup*, SimulationOptions* o) { o->timeline.stop_probability = 2; }},
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

// ---- Realism options (issue 8): each one against its setting --------------------------------

// Gyro minus the noise-free rate psi' n (IMU axes = body axes, no rocking): the sensor errors.
std::vector<Eigen::Vector3d> GyroErrors(const SimulatedTrace& trace, const TraceSetup& setup) {
  const Eigen::Vector3d n(-std::sin(setup.pitch_rad), 0, std::cos(setup.pitch_rad));
  std::vector<Eigen::Vector3d> e(trace.imu.size());
  for (size_t k = 0; k < e.size(); ++k)
    e[k] = trace.imu.gyro_in_imu[k] - trace.rate_rad_per_s[k] * n;
  return e;
}

double Lag1Autocorrelation(const std::vector<double>& x) {
  double mean = 0;
  for (double v : x) mean += v;
  mean /= x.size();
  double c0 = 0, c1 = 0;
  for (size_t k = 0; k < x.size(); ++k) {
    c0 += (x[k] - mean) * (x[k] - mean);
    if (k > 0) c1 += (x[k] - mean) * (x[k - 1] - mean);
  }
  return c1 / c0;
}

TEST(SimulateRealism, Ar1GyroNoiseHasItsPhiAndSigma) {
  const TraceSetup setup = PrandtlLikeSetup();
  for (double phi : {0.0, 0.5, 0.9}) {
    SimulationOptions options = Noiseless();
    options.timeline.free_s = {100, 100};
    options.sensor.gyro_noise_sigma_deg_per_s = 0.5;
    options.sensor.gyro_noise_ar1_phi = phi;
    SimulatedTrace trace;
    std::string why;
    ASSERT_TRUE(SimulateTrace(setup, options, 31, &trace, &why)) << why;
    const std::vector<Eigen::Vector3d> e = GyroErrors(trace, setup);
    const double n = static_cast<double>(e.size());  // ~10 000 samples
    for (int axis = 0; axis < 3; ++axis) {
      std::vector<double> x(e.size());
      double sum2 = 0;
      for (size_t k = 0; k < e.size(); ++k) {
        x[k] = e[k][axis];
        sum2 += x[k] * x[k];
      }
      // Lag-1 estimate: std sqrt((1 - phi^2) / n) <= 0.01; 0.04 is > 4 sigma.
      EXPECT_NEAR(Lag1Autocorrelation(x), phi, 0.04) << "phi " << phi << " axis " << axis;
      // Marginal std: relative std of the estimate ~ sqrt((1 + phi^2) / (2 n (1 - phi^2))), 2.3 %
      // at phi 0.9; 12 % is > 5 sigma.
      const double sigma = std::sqrt(sum2 / n) / kRadPerDeg;
      EXPECT_NEAR(sigma, 0.5, 0.5 * 0.12) << "phi " << phi << " axis " << axis;
    }
  }
}

TEST(SimulateRealism, BiasRandomWalkIncrementsScaleWithSqrtDt) {
  const TraceSetup setup = PrandtlLikeSetup();
  SimulationOptions options = Noiseless();
  options.timeline.free_s = {60, 60};
  options.sensor.gyro_bias_walk_deg_per_s_per_sqrt_s = 0.05;
  SimulatedTrace trace;
  std::string why;
  ASSERT_TRUE(SimulateTrace(setup, options, 17, &trace, &why)) << why;
  const std::vector<Eigen::Vector3d> e = GyroErrors(trace, setup);  // = the walk (no other error)
  EXPECT_NEAR(e[0].norm(), 0.0, 1e-15);                             // starts at the bias (0)
  double sum2 = 0;
  int count = 0;
  for (size_t k = 1; k < e.size(); ++k) {
    const Eigen::Vector3d z =
        (e[k] - e[k - 1]) / std::sqrt(trace.imu.t_s[k] - trace.imu.t_s[k - 1]);
    sum2 += z.squaredNorm();
    count += 3;
  }
  // ~19 000 normalised increments: relative std of the std estimate 0.5 %; 3 % is 6 sigma.
  EXPECT_NEAR(std::sqrt(sum2 / count) / kRadPerDeg, 0.05, 0.05 * 0.03);
  EXPECT_NEAR((trace.truth.gyro_bias_end_rad_per_s - e.back()).norm(), 0.0, 1e-12);
}

TEST(SimulateRealism, LogNormalStepsLikeACrazyflieLog) {
  SimulationOptions options = Noiseless();
  options.timeline.free_s = {300, 300};
  options.sensor.sample_rate_hz = 32;
  options.sensor.sample_steps = SampleSteps::kLogNormal;
  options.sensor.step_log_sigma = 0.75;
  options.sensor.step_range_s = {0.008, 0.160};
  options.sensor.drop_fraction = 0;
  SimulatedTrace trace;
  std::string why;
  ASSERT_TRUE(SimulateTrace(PrandtlLikeSetup(), options, 5, &trace, &why)) << why;
  std::vector<double> steps;
  for (size_t k = 1; k < trace.imu.size(); ++k)
    steps.push_back(trace.imu.t_s[k] - trace.imu.t_s[k - 1]);
  ASSERT_GT(steps.size(), 7000u);
  double sum = 0;
  for (double s : steps) {
    ASSERT_GE(s, 0.008 - 1e-12);
    ASSERT_LE(s, 0.160 + 1e-12);
    sum += s;
  }
  std::sort(steps.begin(), steps.end());
  // Median 1/32 s (std of the sample median ~ 1.25 sigma_ln median / sqrt(n) ~ 1 %); mean of the
  // clipped log-normal exp(mu + s^2/2) = 41.3 ms less the clipped tail ~ 40.4 ms (the real
  // Crazyflie logs: 37.4-43.6 ms).
  EXPECT_NEAR(steps[steps.size() / 2], 1.0 / 32, 0.05 / 32);
  EXPECT_NEAR(sum / steps.size(), 0.0404, 0.0015);
  EXPECT_EQ(trace.truth.samples_nominal, static_cast<int>(trace.imu.size()));
  // The swing is still evaluated at the stamped times: the rate is the integrator's there.
  EXPECT_EQ(trace.truth.free_samples > 0, true);
}

TEST(SimulateRealism, GravityRemovedAccelerometerMeanIsNearZero) {
  TraceSetup setup = PrandtlLikeSetup();
  setup.imu_offset_in_body_m.setZero();  // no lever arm: only gravity and the rise remain
  SimulationOptions options = Noiseless();
  options.sensor.accel_gravity_removed = true;
  auto mean_g = [&](const SimulatedTrace& trace) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& f : trace.imu.accel_in_imu) mean += f;
    return (mean / trace.imu.size()).norm() / setup.geometry.gravity_mps2;
  };
  SimulatedTrace exact, tilted, plain;
  std::string why;
  ASSERT_TRUE(SimulateTrace(setup, options, 8, &exact, &why)) << why;
  EXPECT_LT(mean_g(exact), 1e-3);  // only the rise d^2h/dt^2 (~1e-4 g) is left
  options.sensor.gravity_removal_error_deg = {10, 10};
  ASSERT_TRUE(SimulateTrace(setup, options, 8, &tilted, &why)) << why;
  // A 10 deg attitude error leaves |g (down_est - down)| = 2 g sin(5 deg) = 0.174 g.
  EXPECT_NEAR(mean_g(tilted), 2 * std::sin(5 * kRadPerDeg), 2e-3);
  EXPECT_NEAR(tilted.truth.gravity_removal_error_rad, 10 * kRadPerDeg, 1e-15);
  // The gyro and the timestamps are those of the same log with gravity kept.
  options.sensor.accel_gravity_removed = false;
  ASSERT_TRUE(SimulateTrace(setup, options, 8, &plain, &why)) << why;
  EXPECT_NEAR(mean_g(plain), 1.0, 1e-3);
  ASSERT_EQ(plain.imu.size(), tilted.imu.size());
  for (size_t k = 0; k < plain.imu.size(); ++k) {
    ASSERT_EQ(plain.imu.t_s[k], tilted.imu.t_s[k]);
    ASSERT_EQ(plain.imu.gyro_in_imu[k], tilted.imu.gyro_in_imu[k]);
  }
}

TEST(SimulateRealism, SpikesHaveTheirCountAndSizeAndChangeNothingElse) {
  const TraceSetup setup = PrandtlLikeSetup();  // pitch 20 deg: the swing is mostly on IMU z
  SimulationOptions options;                    // default noise, drops, jitter
  options.timeline.free_s = {30, 30};
  SimulatedTrace clean, spiked;
  std::string why;
  ASSERT_TRUE(SimulateTrace(setup, options, 12, &clean, &why)) << why;
  options.sensor.spike_count = 5;
  options.sensor.spike_rate_rad_per_s = 50;
  ASSERT_TRUE(SimulateTrace(setup, options, 12, &spiked, &why)) << why;
  const auto& spikes = spiked.truth.spikes;
  ASSERT_EQ(spikes.size(), 5u);
  ASSERT_EQ(clean.imu.size(), spiked.imu.size());
  int changed = 0;
  for (size_t k = 0; k < clean.imu.size(); ++k) {
    if (clean.imu.gyro_in_imu[k] == spiked.imu.gyro_in_imu[k]) continue;
    ++changed;
    const auto it = std::find_if(spikes.begin(), spikes.end(), [k](const TraceTruth::Spike& s) {
      return s.sample == static_cast<int>(k);
    });
    ASSERT_NE(it, spikes.end()) << "sample " << k << " changed but is not a spike";
    EXPECT_EQ(it->axis, 2);  // the IMU axis most aligned with the swing axis
    EXPECT_EQ(std::abs(spiked.imu.gyro_in_imu[k][2]), 50.0);
    EXPECT_EQ(spiked.imu.gyro_in_imu[k][2], it->rate_rad_per_s);
    EXPECT_EQ(it->t_s, spiked.imu.t_s[k]);
    EXPECT_EQ(spiked.imu.gyro_in_imu[k].head<2>(), clean.imu.gyro_in_imu[k].head<2>());
  }
  EXPECT_EQ(changed, 5);
  // Distinct, in sample order, at least one inside the free oscillation.
  int inside = 0;
  for (size_t i = 0; i < spikes.size(); ++i) {
    if (i > 0) {
      EXPECT_GT(spikes[i].sample, spikes[i - 1].sample);
    }
    inside += spikes[i].t_s >= spiked.truth.t_release_s && spikes[i].t_s < spiked.truth.t_stop_s;
  }
  EXPECT_GE(inside, 1);
}

// Period of an undamped swing at a fixed amplitude, from the downward zero crossings of psi.
double UndampedPeriod(TraceSetup setup, SimulationOptions options, double amplitude_deg) {
  setup.params.drag_coeff_kg_m2 = setup.params.viscous_coeff_kg_m2_per_s = 0;
  setup.amplitude_rad = amplitude_deg * kRadPerDeg;
  options.timeline.release_rate_sigma_deg_per_s = 0;
  options.timeline.stop_probability = 0;
  options.sensor.time_jitter_sigma_s = 0;
  options.sensor.drop_fraction = 0;
  options.sensor.sample_rate_hz = 1000;
  SimulatedTrace trace;
  std::string why;
  EXPECT_TRUE(SimulateTrace(setup, options, 9, &trace, &why)) << why;
  std::vector<double> crossings;
  for (size_t k = 1; k < trace.imu.size(); ++k) {
    const double a = trace.angle_rad[k - 1], b = trace.angle_rad[k];
    if (trace.imu.t_s[k - 1] > trace.truth.t_release_s && a > 0 && b <= 0) {
      crossings.push_back(trace.imu.t_s[k - 1] +
                          a / (a - b) * (trace.imu.t_s[k] - trace.imu.t_s[k - 1]));
    }
  }
  EXPECT_GE(crossings.size(), 5u);
  return (crossings.back() - crossings.front()) / (crossings.size() - 1);
}

TEST(SimulateRealism, SofteningRaisesTheApparentInertiaAsStated) {
  // The fixed-wing rig of issue 8 (m 3.34 kg, D 0.16 m, L 0.74 m, I 0.05 kg m^2), undamped, with
  // the `jardin` model: its period at amplitude A is a function of I alone, T ~ sqrt(I), so a fit
  // of the ideal model to the softened swing finds I_app / I = (T_soft / T_ideal)^2 exactly.
  // Harmonic balance predicts I_app / I = 1 / (1 - c_p k A^p) (c_2 = 3/4). Measured: 0.02881
  // against 0.02881 at 30 deg (the first-order form I (1 + c_p k A^p) would give 0.0280), 0.01260
  // against 0.01260 at 20 deg; 1 % of the excess leaves room for the neglected harmonics.
  TraceSetup setup;
  setup.geometry = {0.74, 0.16, 3.34, kStandardGravityMps2};
  setup.params.inertia_kg_m2 = 0.05;
  SimulationOptions options = Noiseless();
  options.model = PendulumModel::kJardin;
  options.timeline.free_s = {20, 20};
  EXPECT_NEAR(SofteningHarmonicConstant(2.0), 0.75, 1e-14);
  EXPECT_NEAR(SofteningHarmonicConstant(4.0), 0.625, 1e-14);
  EXPECT_NEAR(SofteningHarmonicConstant(1.0), 8.0 / (3.0 * kPi), 1e-14);
  for (double exponent : {2.0, 1.0}) {
    SimulationOptions soft = options;
    soft.softening_at_30deg = 0.028;
    soft.softening_exponent = exponent;
    const double k = SofteningCoefficient(0.028, exponent);
    EXPECT_NEAR(ApparentInertiaExcess(k, exponent, 30 * kRadPerDeg), 0.028, 1e-15);
    for (double amplitude_deg : {8.0, 20.0, 30.0}) {
      const double ratio = std::pow(UndampedPeriod(setup, soft, amplitude_deg) /
                                        UndampedPeriod(setup, options, amplitude_deg),
                                    2);
      const double predicted = ApparentInertiaExcess(k, exponent, amplitude_deg * kRadPerDeg);
      EXPECT_NEAR(ratio - 1, predicted, 0.01 * predicted)
          << "p " << exponent << " at " << amplitude_deg << " deg";
    }
  }
  // With the `full` model (the default truth) the m h'^2 term adds < 0.1 % of I: the same excess
  // to 2 %.
  SimulationOptions full = options, full_soft = options;
  full.model = full_soft.model = PendulumModel::kFull;
  full_soft.softening_at_30deg = 0.028;
  const double ratio =
      std::pow(UndampedPeriod(setup, full_soft, 30) / UndampedPeriod(setup, full, 30), 2);
  EXPECT_NEAR(ratio - 1, 0.028, 0.02 * 0.028);
  // The truth records k; the true inertia is untouched.
  SimulatedTrace trace;
  std::string why;
  ASSERT_TRUE(SimulateTrace(setup, full_soft, 1, &trace, &why)) << why;
  EXPECT_EQ(trace.truth.softening_k, SofteningCoefficient(0.028, 2.0));
}

TEST(SimulateRealism, EverythingOnIsStillDeterministic) {
  SimulationOptions options;
  options.timeline.free_s = {20, 20};
  options.sensor.sample_steps = SampleSteps::kLogNormal;
  options.sensor.sample_rate_hz = 32;
  options.sensor.gyro_noise_ar1_phi = 0.8;
  options.sensor.gyro_bias_walk_deg_per_s_per_sqrt_s = 0.02;
  options.sensor.accel_gravity_removed = true;
  options.sensor.gravity_removal_error_deg = {4, 15};
  options.sensor.spike_count = 3;
  options.softening_at_30deg = 0.028;
  SimulatedTrace a, b, c;
  std::string why;
  ASSERT_TRUE(SimulateTrace(PrandtlLikeSetup(), options, 77, &a, &why)) << why;
  ASSERT_TRUE(SimulateTrace(PrandtlLikeSetup(), options, 77, &b, &why)) << why;
  ASSERT_TRUE(SimulateTrace(PrandtlLikeSetup(), options, 78, &c, &why)) << why;
  ASSERT_EQ(a.imu.size(), b.imu.size());
  for (size_t k = 0; k < a.imu.size(); ++k) {
    ASSERT_EQ(a.imu.t_s[k], b.imu.t_s[k]);
    ASSERT_EQ(a.imu.gyro_in_imu[k], b.imu.gyro_in_imu[k]);
    ASSERT_EQ(a.imu.accel_in_imu[k], b.imu.accel_in_imu[k]);
  }
  EXPECT_NE(a.imu.t_s[1], c.imu.t_s[1]);
  EXPECT_NE(a.truth.spikes[0].sample, c.truth.spikes[0].sample);
}

TEST(SimulateRealism, BadSettingsNameTheKey) {
  struct Case {
    const char* expect;
    std::function<void(SimulationOptions*)> edit;
  };
  const std::vector<Case> cases = {
      {"sensor.gyro_noise_ar1_phi = 1; must be in [0, 0.99]",
       [](SimulationOptions* o) { o->sensor.gyro_noise_ar1_phi = 1.0; }},
      {"sensor.gyro_bias_walk_deg_per_s_per_sqrt_s",
       [](SimulationOptions* o) { o->sensor.gyro_bias_walk_deg_per_s_per_sqrt_s = -1; }},
      {"sensor.spike_count", [](SimulationOptions* o) { o->sensor.spike_count = -1; }},
      {"sensor.spike_rate_rad_per_s = 0; must be in (0, 10000]",
       [](SimulationOptions* o) { o->sensor.spike_rate_rad_per_s = 0; }},
      {"sensor.step_range_s",
       [](SimulationOptions* o) {
         o->sensor.step_range_s = {0, 0.1};
       }},
      {"sensor.step_log_sigma = nan; must be in [0, 3]",
       [](SimulationOptions* o) { o->sensor.step_log_sigma = NAN; }},
      {"sensor.gravity_removal_error_deg",
       [](SimulationOptions* o) {
         o->sensor.gravity_removal_error_deg = {0, 45};
       }},
      {"swing.softening_percent_at_30deg",
       [](SimulationOptions* o) { o->softening_at_30deg = 0.9; }},
      {"swing.softening_exponent = 0.5; must be in [1, 4]",
       [](SimulationOptions* o) { o->softening_exponent = 0.5; }},
      {"sensor.time_jitter_sigma_s = 0.001; must be <= one sample period 1 / sensor.sample_rate_hz "
       "= 5e-04",
       [](SimulationOptions* o) { o->sensor.sample_rate_hz = 2000; }},
  };
  for (const Case& c : cases) {
    SimulationOptions options;
    c.edit(&options);
    SimulatedTrace trace;
    std::string why;
    EXPECT_FALSE(SimulateTrace(PrandtlLikeSetup(), options, 1, &trace, &why)) << c.expect;
    EXPECT_NE(why.find(c.expect), std::string::npos) << "message: " << why;
  }
  // Softening that would reverse the restoring torque: +50 % at 30 deg with p = 4 removes
  // (1/3) / 0.625 * 1.5^4 = 270 % of it at 45 deg.
  {
    SimulationOptions options;
    options.softening_at_30deg = 0.5;
    options.softening_exponent = 4;
    TraceSetup setup = PrandtlLikeSetup();
    setup.amplitude_rad = 45 * kRadPerDeg;
    SimulatedTrace trace;
    std::string why;
    EXPECT_FALSE(SimulateTrace(setup, options, 1, &trace, &why));
    EXPECT_NE(why.find("removes 270 % of the restoring torque at the amplitude 45 deg"),
              std::string::npos)
        << why;
  }
  // More spikes than half the log is refused, not looped on.
  SimulationOptions options;
  options.timeline.free_s = {1, 1};
  options.timeline.rest_before_s = options.timeline.hold_s = options.timeline.rest_after_s = {0, 0};
  options.sensor.spike_count = 1000;
  SimulatedTrace trace;
  std::string why;
  EXPECT_FALSE(SimulateTrace(PrandtlLikeSetup(), options, 1, &trace, &why));
  EXPECT_NE(why.find("sensor.spike_count = 1000"), std::string::npos) << why;
}

}  // namespace
}  // namespace bifilar
