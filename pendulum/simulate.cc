// One simulated trace (pendulum/simulate.h): the options' checks, the random inputs, the timeline
// of rest, twist, hold, release and stop, the free swing integrated at the log's own timestamps,
// and the IMU readings synthesized from it (SimulateTrace). The campaign is
// simulate_campaign.cc.
#include "pendulum/simulate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <random>
#include <sstream>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "base/enum_names.h"
#include "base/option_check.h"
#include "base/text_format.h"
#include "base/units.h"
#include "pendulum/simulate_steps.h"

namespace bifilar {
namespace {

// An angle (rad) in degrees as a message shows it: 12 digits, so that 120 deg given reads 120.
double ShownDeg(double rad) { return RoundedToDigits(rad / kRadPerDeg, 12); }

// Quintic smoothstep q(s), s in [0,1]: q(0)=0, q(1)=1, zero slope and curvature at both ends.
void Smoothstep(double s, double* q, double* dq, double* ddq) {
  const double s2 = s * s, s3 = s2 * s;
  *q = s3 * (10.0 - 15.0 * s + 6.0 * s2);
  *dq = 30.0 * s2 * (1.0 - 2.0 * s + s2);
  *ddq = 60.0 * s * (1.0 - 3.0 * s + 2.0 * s2);
}

// psi'' of the truth, including the optional sway-coupling discrepancy term.
struct TruthDynamics {
  PendulumModel model;
  RigGeometry geometry;
  PendulumParams params;
  double sway_k = 0.0;  // per rad^4
  double soft_k = 0.0;  // per rad^p (amplitude softening)
  double soft_p = 2.0;

  double Accel(double angle, double rate) const {
    double acc = AngularAcceleration(model, geometry, params, angle, rate);
    if (sway_k != 0.0 || soft_k != 0.0) {
      const double slope = model == PendulumModel::kLinear
                               ? geometry.filar_separation_m * geometry.filar_separation_m /
                                     (4.0 * geometry.filar_length_m) * angle
                               : RiseSlope(geometry, angle);
      const double inertia = model == PendulumModel::kFull
                                 ? params.inertia_kg_m2 + geometry.mass_kg * slope * slope
                                 : params.inertia_kg_m2;
      const double a2 = angle * angle;
      // Restoring torque m g h' times (1 - sway_k psi^4 - soft_k |psi|^p): adds m g h' (...) / I.
      double weakening = sway_k * a2 * a2;
      if (soft_k != 0.0) weakening += soft_k * std::pow(std::abs(angle), soft_p);
      acc += geometry.mass_kg * geometry.gravity_mps2 * slope * weakening / inertia;
    }
    return acc;
  }
};

// Fixed-step RK4 (steps <= max_step_s) from (t[0], angle0, rate0) through the times t.
bool IntegrateRk4(const TruthDynamics& dyn, double angle0, double rate0,
                  const std::vector<double>& t, std::vector<double>* angle,
                  std::vector<double>* rate, std::string* why) {
  constexpr double kMaxStepS = 1e-3;
  angle->assign(t.size(), 0.0);
  rate->assign(t.size(), 0.0);
  double x = angle0, v = rate0, now = t.empty() ? 0.0 : t[0];
  for (size_t k = 0; k < t.size(); ++k) {
    const double span = t[k] - now;
    const int steps = span > 0 ? static_cast<int>(std::ceil(span / kMaxStepS)) : 0;
    for (int i = 0; i < steps; ++i) {
      const double h = span / steps;
      const double k1x = v, k1v = dyn.Accel(x, v);
      const double k2x = v + 0.5 * h * k1v, k2v = dyn.Accel(x + 0.5 * h * k1x, k2x);
      const double k3x = v + 0.5 * h * k2v, k3v = dyn.Accel(x + 0.5 * h * k2x, k3x);
      const double k4x = v + h * k3v, k4v = dyn.Accel(x + h * k3x, k4x);
      x += h / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x);
      v += h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
    }
    now = t[k];
    if (!std::isfinite(x) || !std::isfinite(v))
      return SetWhy(why, "truth integration (RK4) diverged");
    (*angle)[k] = x;
    (*rate)[k] = v;
  }
  return true;
}

}  // namespace

bool CheckUniformRange(const UniformRange& r, const std::string& field, double lower,
                       bool lower_open, CheckFailure* f) {
  const std::string min = field + ".min", max = field + ".max";
  return CheckFinite(min, r.min, f) && CheckFinite(max, r.max, f) &&
         CheckLe(min, r.min, max, r.max, f) &&
         (lower_open ? CheckGt(min, r.min, lower, f) : CheckGe(min, r.min, lower, f));
}

// ---------------------------------------------------------------------------------------------
constexpr EnumName<SampleSteps> kSampleStepsNames[] = {{SampleSteps::kRegular, "regular"},
                                                       {SampleSteps::kLogNormal, "lognormal"}};

const char* ToString(SampleSteps steps) {
  return EnumToString(kSampleStepsNames, steps, "regular");
}
bool ParseSampleSteps(const std::string& name, SampleSteps* steps) {
  return ParseEnum(kSampleStepsNames, name, steps);
}
std::string SampleStepsAllowedValues() { return EnumAllowedValues(kSampleStepsNames); }

double SofteningHarmonicConstant(double exponent) {
  // <|cos|^(p+2)> / <cos^2> over a cycle: first harmonic of |psi|^p psi for psi = A cos.
  return 2.0 * std::tgamma((exponent + 3.0) / 2.0) /
         (std::sqrt(kPi) * std::tgamma(exponent / 2.0 + 2.0));
}

double SofteningCoefficient(double excess_at_30deg, double exponent) {
  // I_app / I = 1 / (1 - x) = 1 + excess at 30 deg, x = c_p k (30 deg)^p.
  const double x = excess_at_30deg / (1.0 + excess_at_30deg);
  return x / (SofteningHarmonicConstant(exponent) * std::pow(30.0 * kRadPerDeg, exponent));
}

double ApparentInertiaExcess(double k, double exponent, double amplitude_rad) {
  const double x =
      SofteningHarmonicConstant(exponent) * k * std::pow(std::abs(amplitude_rad), exponent);
  return x < 1.0 ? x / (1.0 - x) : std::numeric_limits<double>::infinity();
}

TimelineOptions FixedTimeline(double rest_s, double twist_s, double hold_s, double free_s) {
  TimelineOptions t;
  t.rest_before_s = {rest_s, rest_s};
  t.twist_s = {twist_s, twist_s};
  t.hold_s = {hold_s, hold_s};
  t.free_s = {free_s, free_s};
  t.stop_probability = 0.0;
  return t;
}

bool TimelineOptions::Check(std::string* why) const {
  CheckFailure f;
  const bool ok =
      CheckUniformRange(rest_before_s, "timeline.rest_before_s", 0.0, false, &f) &&
      CheckUniformRange(twist_s, "timeline.twist_s", 0.0, true, &f) &&
      CheckUniformRange(hold_s, "timeline.hold_s", 0.0, false, &f) &&
      CheckIn("timeline.tremor_deg", tremor_deg, 0.0, 5.0, Ends::kClosed, &f) &&
      CheckUniformRange(tremor_hz, "timeline.tremor_hz", 0.0, true, &f) &&
      CheckIn("timeline.release_rate_sigma_deg_per_s", release_rate_sigma_deg_per_s, 0.0, 90.0,
              Ends::kClosed, &f) &&
      CheckUniformRange(free_s, "timeline.free_s", 0.0, true, &f) &&
      CheckIn("timeline.free_s.max", free_s.max, 0.0, 86400.0, Ends::kOpenClosed, &f) &&
      CheckIn("timeline.stop_probability", stop_probability, 0.0, 1.0, Ends::kClosed, &f) &&
      CheckIn("timeline.stop_time_constant_s", stop_time_constant_s, 0.0, 10.0, Ends::kOpenClosed,
              &f) &&
      CheckUniformRange(rest_after_s, "timeline.rest_after_s", 0.0, false, &f);
  return ok || FailWith(f, why);
}

bool SensorOptions::Check(std::string* why) const {
  CheckFailure f;
  const bool ok =
      CheckIn("sensor.sample_rate_hz", sample_rate_hz, 0.0, 100000.0, Ends::kOpenClosed, &f) &&
      // At most one sample period: jitter beyond it would reorder the samples.
      CheckFiniteGe("sensor.time_jitter_sigma_s", time_jitter_sigma_s, 0.0, &f) &&
      CheckLe("sensor.time_jitter_sigma_s", time_jitter_sigma_s,
              "one sample period 1 / sensor.sample_rate_hz", 1.0 / sample_rate_hz, &f) &&
      CheckIn("sensor.step_log_sigma", step_log_sigma, 0.0, 3.0, Ends::kClosed, &f) &&
      CheckUniformRange(step_range_s, "sensor.step_range_s", 0.0, true, &f) &&
      CheckIn("sensor.step_range_s.max", step_range_s.max, 0.0, 3600.0, Ends::kOpenClosed, &f) &&
      CheckIn("sensor.gyro_noise_ar1_phi", gyro_noise_ar1_phi, 0.0, 0.99, Ends::kClosed, &f) &&
      CheckIn("sensor.gyro_bias_walk_deg_per_s_per_sqrt_s", gyro_bias_walk_deg_per_s_per_sqrt_s,
              0.0, 10.0, Ends::kClosed, &f) &&
      CheckIn("sensor.spike_count", spike_count, 0.0, 1000.0, Ends::kClosed, &f) &&
      CheckIn("sensor.spike_rate_rad_per_s", spike_rate_rad_per_s, 0.0, 1e4, Ends::kOpenClosed,
              &f) &&
      CheckUniformRange(gravity_removal_error_deg, "sensor.gravity_removal_error_deg", 0.0, false,
                        &f) &&
      CheckIn("sensor.gravity_removal_error_deg.max", gravity_removal_error_deg.max, 0.0, 30.0,
              Ends::kClosed, &f) &&
      CheckLe("sensor.rocking_frequency_hz", rocking_frequency_hz, "sensor.sample_rate_hz / 4",
              sample_rate_hz / 4.0, &f) &&
      CheckIn("sensor.drop_fraction", drop_fraction, 0.0, 0.5, Ends::kClosed, &f) &&
      CheckIn("sensor.drop_burst_probability", drop_burst_probability, 0.0, 1.0, Ends::kClosed,
              &f) &&
      CheckIn("sensor.drop_burst_max_samples", drop_burst_max_samples, 2.0, 100000.0, Ends::kClosed,
              &f) &&
      CheckUniformRange(start_time_s, "sensor.start_time_s", -1e9, false, &f) &&
      CheckIn("sensor.start_time_s.max", start_time_s.max, -1e9, 1e9, Ends::kClosed, &f) &&
      CheckIn("sensor.gyro_noise_sigma_deg_per_s", gyro_noise_sigma_deg_per_s, 0.0, 100.0,
              Ends::kClosed, &f) &&
      CheckIn("sensor.gyro_bias_sigma_deg_per_s", gyro_bias_sigma_deg_per_s, 0.0, 100.0,
              Ends::kClosed, &f) &&
      CheckIn("sensor.gyro_scale_error_sigma", gyro_scale_error_sigma, 0.0, 0.2, Ends::kClosed,
              &f) &&
      CheckIn("sensor.accel_noise_sigma_mps2", accel_noise_sigma_mps2, 0.0, 10.0, Ends::kClosed,
              &f) &&
      CheckIn("sensor.accel_bias_sigma_mps2", accel_bias_sigma_mps2, 0.0, 10.0, Ends::kClosed,
              &f) &&
      CheckIn("sensor.rocking_max_deg", rocking_max_deg, 0.0, 10.0, Ends::kClosed, &f) &&
      CheckFiniteGe("sensor.rocking_frequency_hz", rocking_frequency_hz, 0.0, &f) &&
      CheckIn("sensor.rocking_decay_s", rocking_decay_s, 0.0, 1e6, Ends::kOpenClosed, &f);
  return ok || FailWith(f, why);
}

bool SimulationOptions::Check(std::string* why) const {
  std::string integrator_why;
  if (!integrator.Check(&integrator_why)) return SetWhy(why, "integrator: " + integrator_why);
  if (!timeline.Check(why) || !sensor.Check(why)) return false;
  CheckFailure f;
  const bool ok =
      CheckIn("negative_amplitude_probability", negative_amplitude_probability, 0.0, 1.0,
              Ends::kClosed, &f) &&
      CheckIn("sway_coupling_at_60deg", sway_coupling_at_60deg, 0.0, 0.5, Ends::kClosed, &f) &&
      CheckIn("swing.softening_percent_at_30deg (fraction)", softening_at_30deg, 0.0, 0.5,
              Ends::kClosed, &f) &&
      CheckIn("swing.softening_exponent", softening_exponent, 1.0, 4.0, Ends::kClosed, &f);
  return ok || FailWith(f, why);
}

bool TraceSetup::Check(std::string* why) const {
  const RigGeometry& g = geometry;
  CheckFailure f;
  const bool in_range =
      CheckIn("filar_length_m (L)", g.filar_length_m, 0.0, 1000.0, Ends::kOpenClosed, &f) &&
      CheckIn("filar_separation_m (D)", g.filar_separation_m, 0.0, 1000.0, Ends::kOpenClosed, &f) &&
      CheckIn("mass_kg (whole suspended mass)", g.mass_kg, 0.0, 1e6, Ends::kOpenClosed, &f) &&
      CheckIn("gravity_mps2", g.gravity_mps2, 0.0, 100.0, Ends::kOpenClosed, &f) &&
      CheckIn("inertia_kg_m2 (whole suspended inertia)", params.inertia_kg_m2, 0.0, 1e9,
              Ends::kOpenClosed, &f) &&
      CheckIn("drag_coeff_kg_m2 (K_D)", params.drag_coeff_kg_m2, 0.0, 1e9, Ends::kClosed, &f) &&
      CheckIn("viscous_coeff_kg_m2_per_s (C)", params.viscous_coeff_kg_m2_per_s, 0.0, 1e9,
              Ends::kClosed, &f);
  if (!in_range) return FailWith(f, why);
  if (!CheckSeparationBelowLength(g.filar_length_m, g.filar_separation_m, why)) return false;
  // The angles are shown in degrees; the bounds hold to 1e-9 rad.
  const double orthogonality =
      (body_from_imu.transpose() * body_from_imu - Eigen::Matrix3d::Identity()).norm();
  const bool ok =
      ((std::isfinite(pitch_rad) && std::abs(pitch_rad) <= kPi / 2 + 1e-9) ||
       CheckFail("pitch_deg", ShownDeg(pitch_rad), "in [-90, 90]", &f)) &&
      ((std::isfinite(roll_rad) && std::abs(roll_rad) <= kPi + 1e-9) ||
       CheckFail("roll_deg", ShownDeg(roll_rad), "in [-180, 180]", &f)) &&
      ((std::isfinite(amplitude_rad) && amplitude_rad != 0.0 &&
        std::abs(amplitude_rad) < 89 * kRadPerDeg) ||
       CheckFail("amplitude_deg", ShownDeg(amplitude_rad), "0 < |amplitude_deg| < 89", &f)) &&
      // A rotation matrix: orthonormal (to 1e-6), determinant +1.
      CheckLe("|body_from_imu^T body_from_imu - I|", orthogonality, 1e-6, &f) &&
      CheckGt("det(body_from_imu)", body_from_imu.determinant(), 0, &f) &&
      CheckLe("|imu_offset_in_body_m|", imu_offset_in_body_m.norm(), 100.0, &f);
  return ok || FailWith(f, why);
}

// ---------------------------------------------------------------------------------------------
namespace {

// Everything random that the main stream draws before the samples, in its fixed order.
struct RandomInputs {
  double start_time = 0.0, rest_before = 0.0, twist = 0.0, hold = 0.0, free = 0.0;
  bool stopped = false;
  double rest_after = 0.0, release_rate = 0.0;
  double tremor_amp[3] = {}, tremor_omega[3] = {}, tremor_phase[3] = {};
  Eigen::Vector3d gyro_bias, gyro_scale, accel_bias;
  double rocking_amp = 0.0, rocking_hz = 0.0, rocking_beta = 0.0;
};

// The phases of the log (s) and its sampling.
struct Timeline {
  double t_twist = 0.0, t_hold = 0.0, t_release = 0.0, t_stop = 0.0, t_end = 0.0;
  double stop_tau = 0.0;  // time constant of the hand's stop
  double dt = 0.0;        // nominal sample step
  bool lognormal = false;
  double samples_real = 0.0;  // nominal samples (or the most irregular steps could give)
};

// The kept samples: times, and which of them lie in the free oscillation.
struct Samples {
  std::vector<double> times;
  int n_nominal = 0, dropped = 0;
  std::vector<size_t> free_index;
  std::vector<double> free_times;  // t_release, the free samples' times, t_stop
};

// The swing axis n and the two horizontal directions in the body frame, and the IMU's view.
struct SwingFrame {
  Eigen::Vector3d n_body, horizontal, lateral, rock_axis;
  Eigen::Matrix3d imu_from_body;
};

// Everything random is drawn here, in a fixed order.
RandomInputs DrawRandomInputs(const TraceSetup& setup, const SimulationOptions& options, Rng& rng) {
  const TimelineOptions& tl = options.timeline;
  const SensorOptions& so = options.sensor;
  RandomInputs in;
  in.start_time = rng.Uniform(so.start_time_s);
  in.rest_before = rng.Uniform(tl.rest_before_s);
  in.twist = rng.Uniform(tl.twist_s);
  in.hold = rng.Uniform(tl.hold_s);
  in.free = rng.Uniform(tl.free_s);
  in.stopped = rng.Uniform() < tl.stop_probability;
  in.rest_after = rng.Uniform(tl.rest_after_s);
  in.release_rate = rng.Normal(tl.release_rate_sigma_deg_per_s * kRadPerDeg);
  for (int i = 0; i < 3; ++i) {
    // Three sinusoids of equal amplitude: RMS of the sum = amp * sqrt(3/2).
    in.tremor_amp[i] = tl.tremor_deg * kRadPerDeg / std::sqrt(1.5) * (0.5 + rng.Uniform());
    in.tremor_omega[i] = 2.0 * kPi * rng.Uniform(tl.tremor_hz);
    in.tremor_phase[i] = 2.0 * kPi * rng.Uniform();
  }
  for (int i = 0; i < 3; ++i) {
    in.gyro_bias[i] = rng.Normal(so.gyro_bias_sigma_deg_per_s * kRadPerDeg);
  }
  for (int i = 0; i < 3; ++i) in.gyro_scale[i] = rng.Normal(so.gyro_scale_error_sigma);
  for (int i = 0; i < 3; ++i) in.accel_bias[i] = rng.Normal(so.accel_bias_sigma_mps2);
  in.rocking_amp = so.rocking_max_deg * kRadPerDeg * rng.Uniform();
  in.rocking_hz = so.rocking_frequency_hz > 0
                      ? so.rocking_frequency_hz
                      : std::sqrt(setup.geometry.gravity_mps2 / setup.geometry.filar_length_m) /
                            (2 * kPi) * (0.9 + 0.2 * rng.Uniform());
  in.rocking_beta = 2.0 * kPi * rng.Uniform();
  return in;
}

// Timeline: rest, twist, hold, free swing, and the hand's stop with the rest after it.
bool MakeTimeline(const RandomInputs& in, const SimulationOptions& options, Timeline* timeline,
                  std::string* why) {
  const TimelineOptions& tl = options.timeline;
  const SensorOptions& so = options.sensor;
  Timeline& tm = *timeline;
  tm.t_twist = in.start_time + in.rest_before;
  tm.t_hold = tm.t_twist + in.twist;
  tm.t_release = tm.t_hold + in.hold;
  tm.t_stop = tm.t_release + in.free;
  tm.stop_tau = tl.stop_time_constant_s;
  tm.t_end = in.stopped ? tm.t_stop + 5.0 * tm.stop_tau + in.rest_after : tm.t_stop;
  tm.dt = 1.0 / so.sample_rate_hz;
  tm.lognormal = so.sample_steps == SampleSteps::kLogNormal;
  tm.samples_real = tm.lognormal
                        ? std::floor((tm.t_end - in.start_time) / so.step_range_s.min) + 1.0
                        : std::floor((tm.t_end - in.start_time) * so.sample_rate_hz) + 1.0;
  if (tm.samples_real > 5e7) {
    return SetWhy(why, "log too long: up to " + Fmt("%g", tm.samples_real) + " samples (" +
                           Fmt("%g", tm.t_end - in.start_time) + " s at " +
                           (tm.lognormal ? "steps down to " + Fmt("%g", so.step_range_s.min) + " s"
                                         : Fmt("%g", so.sample_rate_hz) + " Hz") +
                           "); the limit is 5e7: shorten timeline.free_s or lower "
                           "sensor.sample_rate_hz");
  }
  return true;
}

// Irregular (log-normal) steps come from their own stream: the other draws stay as they are.
std::vector<double> IrregularSteps(uint64_t seed, const SensorOptions& so, double start_time,
                                   const Timeline& tm) {
  std::vector<double> irregular;
  if (!tm.lognormal) return irregular;
  Rng step_rng(DeriveSeed(seed, "sample_steps"));
  for (double t = start_time; t <= tm.t_end;) {
    irregular.push_back(t);
    const double step = tm.dt * std::exp(step_rng.Normal(so.step_log_sigma));
    t += std::clamp(step, so.step_range_s.min, so.step_range_s.max);
  }
  return irregular;
}

// Timestamps: nominal grid + clipped jitter (strictly increasing), or the irregular steps; then
// dropped packets.
bool SampleTimes(const SensorOptions& so, double start_time, const Timeline& tm,
                 const std::vector<double>& irregular, Rng& rng, Samples* samples,
                 std::string* why) {
  const double dt = tm.dt;
  const int n_nominal =
      tm.lognormal ? static_cast<int>(irregular.size()) : static_cast<int>(tm.samples_real);
  samples->n_nominal = n_nominal;
  std::vector<double>& times = samples->times;
  times.reserve(n_nominal);
  const double mean_drop_run = (1.0 - so.drop_burst_probability) +
                               so.drop_burst_probability * (2.0 + so.drop_burst_max_samples) / 2.0;
  const double drop_start_p =
      so.drop_fraction / (mean_drop_run * (1.0 - so.drop_fraction) + so.drop_fraction);
  int drop_left = 0, dropped = 0;
  for (int k = 0; k < n_nominal; ++k) {
    double jitter = rng.Normal(so.time_jitter_sigma_s);
    jitter =
        k == 0 ? 0.0 : std::clamp(jitter, -0.4 * dt, 0.4 * dt);  // the clock starts at sample 0
    const double u = rng.Uniform();
    const double u_burst = rng.Uniform();
    const double u_len = rng.Uniform();
    if (drop_left == 0 && k > 0 && u < drop_start_p) {
      drop_left = u_burst < so.drop_burst_probability
                      ? 2 + static_cast<int>(u_len * (so.drop_burst_max_samples - 1))
                      : 1;
    }
    if (drop_left > 0) {
      --drop_left;
      ++dropped;
      continue;
    }
    times.push_back(tm.lognormal ? irregular[k] : start_time + k * dt + jitter);
  }
  samples->dropped = dropped;
  if (times.size() < 2) return SetWhy(why, "the log would have fewer than 2 samples");
  return true;
}

// The swing angle psi and its derivatives before the release: the hand twists the aircraft to
// the amplitude, then holds it with a tremor. Collects the free oscillation's samples.
bool HandBeforeRelease(const TraceSetup& setup, const RandomInputs& in, const Timeline& tm,
                       Samples* samples, SimulatedTrace* out, std::string* why) {
  const std::vector<double>& times = samples->times;
  const size_t n = times.size();
  std::vector<double>& psi = out->angle_rad;
  std::vector<double>& dpsi = out->rate_rad_per_s;
  std::vector<double>& ddpsi = out->accel_rad_per_s2;
  psi.assign(n, 0.0);
  dpsi.assign(n, 0.0);
  ddpsi.assign(n, 0.0);
  const double amplitude = setup.amplitude_rad;
  const double twist = in.twist, hold = in.hold;
  samples->free_times = {tm.t_release};
  for (size_t k = 0; k < n; ++k) {
    const double t = times[k];
    if (t < tm.t_twist) continue;
    if (t < tm.t_hold) {
      double q, dq, ddq;
      Smoothstep((t - tm.t_twist) / twist, &q, &dq, &ddq);
      psi[k] = amplitude * q;
      dpsi[k] = amplitude * dq / twist;
      ddpsi[k] = amplitude * ddq / (twist * twist);
    } else if (t < tm.t_release) {
      // Tremor, windowed by sin^2 so the hold starts and ends smoothly.
      double tr = 0, dtr = 0, ddtr = 0;
      const double s = t - tm.t_hold;
      for (int i = 0; i < 3; ++i) {
        const double ph = in.tremor_omega[i] * s + in.tremor_phase[i];
        tr += in.tremor_amp[i] * std::sin(ph);
        dtr += in.tremor_amp[i] * in.tremor_omega[i] * std::cos(ph);
        ddtr -= in.tremor_amp[i] * in.tremor_omega[i] * in.tremor_omega[i] * std::sin(ph);
      }
      const double w_arg = kPi * s / hold;
      const double w = std::sin(w_arg) * std::sin(w_arg);
      const double dw = kPi / hold * std::sin(2 * w_arg);
      const double ddw = 2 * kPi * kPi / (hold * hold) * std::cos(2 * w_arg);
      psi[k] = amplitude + tr * w;
      dpsi[k] = dtr * w + tr * dw;
      ddpsi[k] = ddtr * w + 2 * dtr * dw + tr * ddw;
    } else if (t < tm.t_stop) {
      samples->free_index.push_back(k);
      samples->free_times.push_back(t);
    }
  }
  if (samples->free_index.size() < 2) {
    return SetWhy(why, "the free oscillation has fewer than 2 samples");
  }
  samples->free_times.push_back(tm.t_stop);  // the state at the stop starts the hand's deceleration
  return true;
}

// The truth's departures from the fit's models: the sway coupling and the amplitude softening.
bool AddTruthDiscrepancies(const TraceSetup& setup, const SimulationOptions& options,
                           TruthDynamics* dyn_out, std::string* why) {
  TruthDynamics& dyn = *dyn_out;
  if (options.sway_coupling_at_60deg > 0) {
    const double a60 = 60.0 * kRadPerDeg;
    dyn.sway_k = 8.0 / 5.0 * options.sway_coupling_at_60deg / (a60 * a60 * a60 * a60);
  }
  if (options.softening_at_30deg > 0) {
    dyn.soft_p = options.softening_exponent;
    dyn.soft_k = SofteningCoefficient(options.softening_at_30deg, options.softening_exponent);
    // The term must weaken the restoring torque, not reverse it, over the whole swing.
    const double amplitude = setup.amplitude_rad;
    const double weakening = dyn.soft_k * std::pow(std::abs(amplitude), dyn.soft_p);
    if (weakening > 0.5) {
      return SetWhy(
          why, "swing.softening_percent_at_30deg = " + Fmt("%g", 100 * options.softening_at_30deg) +
                   " with swing.softening_exponent = " + Fmt("%g", dyn.soft_p) + " removes " +
                   Fmt("%g", 100 * weakening) + " % of the restoring torque at the amplitude " +
                   Fmt("%g", std::abs(amplitude) / kRadPerDeg) +
                   " deg (at most 50 % allowed); lower the softening or the amplitude");
    }
  }
  return true;
}

// The free oscillation from the release (amplitude, release rate) through free_times: the
// integrator of the fit, or RK4 when the truth has terms the fit's models lack.
bool IntegrateFreeSwing(const TraceSetup& setup, const SimulationOptions& options,
                        const TruthDynamics& dyn, double release_rate,
                        const std::vector<double>& free_times, std::vector<double>* free_angle,
                        std::vector<double>* free_rate, std::string* why) {
  const double amplitude = setup.amplitude_rad;
  if (dyn.sway_k == 0.0 && dyn.soft_k == 0.0) {
    PendulumIntegrator integrator(options.model, setup.geometry, options.integrator);
    Trajectory trajectory;
    std::string integrator_why;
    if (!integrator.Integrate(setup.params, amplitude, release_rate, free_times, false, &trajectory,
                              &integrator_why)) {
      return SetWhy(why, "integration of the free oscillation failed: " + integrator_why);
    }
    *free_angle = trajectory.angle_rad;
    *free_rate = trajectory.rate_rad_per_s;
  } else if (!IntegrateRk4(dyn, amplitude, release_rate, free_times, free_angle, free_rate, why)) {
    return false;
  }
  if (free_angle->size() != free_times.size() || free_rate->size() != free_times.size()) {
    return SetWhy(why, "integrator returned the wrong number of samples");
  }
  return true;
}

// The free swing into psi, and the hand's stop after it: the rate decays exponentially, the
// angle settles rate_stop * tau further on. Returns the envelope over the last period.
double FreeSwingAndStop(const TraceSetup& setup, const TruthDynamics& dyn, const Timeline& tm,
                        const Samples& samples, const std::vector<double>& free_angle,
                        const std::vector<double>& free_rate, SimulatedTrace* out) {
  const std::vector<double>& times = samples.times;
  std::vector<double>& psi = out->angle_rad;
  std::vector<double>& dpsi = out->rate_rad_per_s;
  std::vector<double>& ddpsi = out->accel_rad_per_s2;
  double envelope_at_stop = 0.0;
  const double small_period = SmallAnglePeriod(setup.geometry, setup.params.inertia_kg_m2);
  for (size_t i = 0; i < samples.free_index.size(); ++i) {
    const size_t k = samples.free_index[i];
    psi[k] = free_angle[i + 1];
    dpsi[k] = free_rate[i + 1];
    ddpsi[k] = dyn.Accel(psi[k], dpsi[k]);
    if (times[k] >= tm.t_stop - small_period) {
      envelope_at_stop = std::max(envelope_at_stop, std::abs(psi[k]));
    }
  }
  const double psi_stop = free_angle.back(), rate_stop = free_rate.back();
  const double stop_tau = tm.stop_tau;
  for (size_t k = 0; k < times.size(); ++k) {
    const double t = times[k];
    if (t < tm.t_stop) continue;
    const double e = std::exp(-(t - tm.t_stop) / stop_tau);
    psi[k] = psi_stop + rate_stop * stop_tau * (1.0 - e);
    dpsi[k] = rate_stop * e;
    ddpsi[k] = -rate_stop / stop_tau * e;
  }
  return envelope_at_stop;
}

// The swing axis in the body at the trace's pitch and roll, the rocking axis, the IMU mounting.
SwingFrame SwingFrameFor(const TraceSetup& setup, double rocking_beta) {
  SwingFrame f;
  const double st = std::sin(setup.pitch_rad), ct = std::cos(setup.pitch_rad);
  f.n_body = Eigen::Vector3d(-st, 0.0, ct);
  f.horizontal = Eigen::Vector3d(ct, 0.0, st);  // in the x-z plane, perpendicular to n
  f.lateral = Eigen::Vector3d::UnitY();         // the other horizontal direction
  if (setup.roll_rad != 0.0) {
    // Rolled by phi: n = Rx(-phi) (-sin theta, 0, cos theta) = (-st, sf ct, cf ct), and the two
    // horizontal directions turn with it (docs/physics.md §3.5).
    const double sf = std::sin(setup.roll_rad), cf = std::cos(setup.roll_rad);
    f.n_body = Eigen::Vector3d(-st, sf * ct, cf * ct);
    f.horizontal = Eigen::Vector3d(ct, sf * st, cf * st);
    f.lateral = Eigen::Vector3d(0.0, cf, -sf);
  }
  f.rock_axis =
      (std::cos(rocking_beta) * f.lateral + std::sin(rocking_beta) * f.horizontal).normalized();
  f.imu_from_body = setup.body_from_imu.transpose();
  return f;
}

// Gravity removed by the logger: the firmware's static down, tilted by its attitude error about
// a random horizontal axis (a stream of its own).
Eigen::Vector3d DownEstimateInImu(uint64_t seed, const SensorOptions& so, const SwingFrame& f,
                                  TraceTruth* truth) {
  Rng accel_rng(DeriveSeed(seed, "gravity_removed"));
  truth->gravity_removal_error_rad = accel_rng.Uniform(so.gravity_removal_error_deg) * kRadPerDeg;
  const double beta = 2.0 * kPi * accel_rng.Uniform();
  const Eigen::Vector3d tilt_axis =
      (std::cos(beta) * f.lateral + std::sin(beta) * f.horizontal).normalized();
  return f.imu_from_body *
         (Eigen::AngleAxisd(truth->gravity_removal_error_rad, tilt_axis) * f.n_body);
}

// Rocking of the body about rock_axis after the release: phi and its derivatives at t.
void RockingAt(double t, double t_release, double rocking_amp, double rock_omega, double decay_s,
               double* phi, double* dphi, double* ddphi) {
  if (!(t >= t_release && rocking_amp > 0)) return;
  const double x = t - t_release;
  const double e = rocking_amp * std::exp(-x / decay_s);
  const double c = 1.0 / decay_s;
  const double s = std::sin(rock_omega * x), co = std::cos(rock_omega * x);
  *phi = e * s;
  *dphi = e * (rock_omega * co - c * s);
  *ddphi = e * ((c * c - rock_omega * rock_omega) * s - 2 * c * rock_omega * co);
}

// IMU synthesis: the gyro (scale, bias, optional bias walk, white or AR(1) noise) and the
// accelerometer (lever arm, rocking, gravity, optionally removed) at every sample, with the
// attitude errors and rocking of the rig. Returns the bias walk at the end.
Eigen::Vector3d SynthesizeImu(const TraceSetup& setup, const SensorOptions& so, uint64_t seed,
                              const RandomInputs& in, const Timeline& tm, const SwingFrame& f,
                              const std::vector<double>& times, Rng& rng, SimulatedTrace* out) {
  const size_t n = times.size();
  const std::vector<double>& psi = out->angle_rad;
  const std::vector<double>& dpsi = out->rate_rad_per_s;
  const std::vector<double>& ddpsi = out->accel_rad_per_s2;
  const Eigen::Vector3d& n_body = f.n_body;
  const Eigen::Vector3d& rock_axis = f.rock_axis;
  const Eigen::Matrix3d& imu_from_body = f.imu_from_body;
  const Eigen::Vector3d& r = setup.imu_offset_in_body_m;
  const Eigen::Vector3d r_perp = r - n_body * n_body.dot(r);
  const Eigen::Vector3d n_cross_r = n_body.cross(r);
  const double g = setup.geometry.gravity_mps2;
  const double rock_omega = 2 * kPi * in.rocking_hz;
  const double gyro_noise = so.gyro_noise_sigma_deg_per_s * kRadPerDeg;
  const double phi_ar = so.gyro_noise_ar1_phi;
  const double ar_innovation = std::sqrt(1.0 - phi_ar * phi_ar);
  Eigen::Vector3d ar_state = Eigen::Vector3d::Zero();
  // Optional realism from streams of their own (off: no draws, the log is as before).
  const double walk_rate = so.gyro_bias_walk_deg_per_s_per_sqrt_s * kRadPerDeg;
  Rng walk_rng(DeriveSeed(seed, "gyro_bias_walk"));
  Eigen::Vector3d walk = Eigen::Vector3d::Zero();
  const bool gravity_removed = so.accelerometer && so.accel_gravity_removed;
  Eigen::Vector3d down_estimate_in_imu = Eigen::Vector3d::Zero();
  if (gravity_removed) down_estimate_in_imu = DownEstimateInImu(seed, so, f, &out->truth);

  out->imu.t_s = times;
  out->imu.gyro_in_imu.resize(n);
  if (so.accelerometer) out->imu.accel_in_imu.resize(n);
  for (size_t k = 0; k < n; ++k) {
    double phi = 0, dphi = 0, ddphi = 0;
    RockingAt(times[k], tm.t_release, in.rocking_amp, rock_omega, so.rocking_decay_s, &phi, &dphi,
              &ddphi);
    const Eigen::Vector3d omega_body = dpsi[k] * n_body + dphi * rock_axis;
    Eigen::Vector3d gyro = imu_from_body * omega_body;
    gyro = gyro.cwiseProduct(Eigen::Vector3d::Ones() + in.gyro_scale) + in.gyro_bias;
    if (walk_rate > 0) {
      if (k > 0) {
        const double step = std::sqrt(times[k] - times[k - 1]);
        for (int i = 0; i < 3; ++i) walk[i] += walk_rate * step * walk_rng.Normal();
      }
      gyro += walk;
    }
    for (int i = 0; i < 3; ++i) {
      const double w = rng.Normal(gyro_noise);
      if (phi_ar == 0.0) {
        gyro[i] += w;  // white: exactly the draws of before
      } else {
        ar_state[i] = k == 0 ? w : phi_ar * ar_state[i] + ar_innovation * w;
        gyro[i] += ar_state[i];
      }
    }
    out->imu.gyro_in_imu[k] = gyro;
    if (so.accelerometer) {
      const double hdd = RiseCurvature(setup.geometry, psi[k]) * dpsi[k] * dpsi[k] +
                         RiseSlope(setup.geometry, psi[k]) * ddpsi[k];
      const Eigen::Vector3d a_body = ddpsi[k] * n_cross_r - dpsi[k] * dpsi[k] * r_perp -
                                     hdd * n_body + ddphi * rock_axis.cross(r);
      // The body rocked by phi about rock_axis sees the down vertical rotated by -phi.
      const Eigen::Vector3d down_body = Eigen::AngleAxisd(-phi, rock_axis) * n_body;
      Eigen::Vector3d fs = imu_from_body * (a_body - g * down_body) + in.accel_bias;
      if (gravity_removed) fs += g * down_estimate_in_imu;
      for (int i = 0; i < 3; ++i) fs[i] += rng.Normal(so.accel_noise_sigma_mps2);
      out->imu.accel_in_imu[k] = fs;
    }
  }
  return walk;
}

// Spikes: distinct samples, the first one inside the free oscillation; on the IMU axis that
// carries most of the swing, replaced by +-spike_rate_rad_per_s (a stream of their own).
bool AddSpikes(const SensorOptions& so, uint64_t seed, const SwingFrame& f, const Samples& samples,
               SimulatedTrace* out, std::string* why) {
  if (so.spike_count <= 0) return true;
  const std::vector<double>& times = samples.times;
  const std::vector<size_t>& free_index = samples.free_index;
  const size_t n = times.size();
  if (static_cast<size_t>(so.spike_count) * 2 > n) {
    return SetWhy(why, "sensor.spike_count = " + std::to_string(so.spike_count) +
                           " is more than half the log's " + std::to_string(n) +
                           " samples; lower it");
  }
  TraceTruth& truth = out->truth;
  Rng spike_rng(DeriveSeed(seed, "spikes"));
  const Eigen::Vector3d n_imu = f.imu_from_body * f.n_body;
  int axis = 0;
  n_imu.cwiseAbs().maxCoeff(&axis);
  std::vector<bool> taken(n, false);
  for (int i = 0; i < so.spike_count; ++i) {
    size_t k = 0;
    do {
      k = i == 0 ? free_index[static_cast<size_t>(spike_rng.Uniform() * free_index.size())]
                 : static_cast<size_t>(spike_rng.Uniform() * n);
    } while (taken[k]);
    taken[k] = true;
    const double value = (spike_rng.Uniform() < 0.5 ? -1.0 : 1.0) * so.spike_rate_rad_per_s;
    out->imu.gyro_in_imu[k][axis] = value;
    truth.spikes.push_back({static_cast<int>(k), times[k], axis, value});
  }
  std::sort(
      truth.spikes.begin(), truth.spikes.end(),
      [](const TraceTruth::Spike& a, const TraceTruth::Spike& b) { return a.sample < b.sample; });
  return true;
}

// Every sample finite.
bool CheckFinite(const SensorOptions& so, const SimulatedTrace& out, std::string* why) {
  const std::vector<double>& times = out.imu.t_s;
  for (size_t k = 0; k < times.size(); ++k) {
    if (!out.imu.gyro_in_imu[k].allFinite() ||
        (so.accelerometer && !out.imu.accel_in_imu[k].allFinite()) || !std::isfinite(times[k])) {
      return SetWhy(why, "simulation produced a non-finite value (check the parameters)");
    }
  }
  return true;
}

// The truth the fit is checked against.
void FillTruth(const TraceSetup& setup, const SensorOptions& so, const RandomInputs& in,
               const Timeline& tm, const Samples& samples, const SwingFrame& f,
               const TruthDynamics& dyn, double envelope_at_stop, const Eigen::Vector3d& walk,
               TraceTruth* truth) {
  truth->start_time_s = in.start_time;
  truth->t_twist_s = tm.t_twist;
  truth->t_release_s = tm.t_release;
  truth->stopped = in.stopped;
  truth->t_stop_s = tm.t_stop;
  truth->t_end_s = tm.t_end;
  truth->amplitude_rad = setup.amplitude_rad;
  truth->release_rate_rad_per_s = in.release_rate;
  truth->amplitude_at_stop_rad = envelope_at_stop;
  truth->gyro_bias_rad_per_s = in.gyro_bias;
  truth->gyro_bias_end_rad_per_s = in.gyro_bias + walk;
  truth->softening_k = dyn.soft_k;
  truth->gyro_scale_error = in.gyro_scale;
  truth->accel_bias_mps2 = so.accelerometer ? in.accel_bias : Eigen::Vector3d::Zero();
  truth->swing_axis_in_imu = f.imu_from_body * f.n_body;
  truth->rocking_amplitude_rad = in.rocking_amp;
  truth->rocking_frequency_hz = in.rocking_hz;
  truth->rocking_axis_in_body = f.rock_axis;
  truth->samples_nominal = samples.n_nominal;
  truth->samples_dropped = samples.dropped;
  truth->free_samples = static_cast<int>(samples.free_index.size());
}

}  // namespace

bool SimulateTrace(const TraceSetup& setup, const SimulationOptions& options, uint64_t seed,
                   SimulatedTrace* out, std::string* why) {
  if (!options.Check(why) || !setup.Check(why)) return false;
  const SensorOptions& so = options.sensor;
  Rng rng(seed);
  *out = SimulatedTrace();
  const RandomInputs in = DrawRandomInputs(setup, options, rng);
  Timeline tm;
  if (!MakeTimeline(in, options, &tm, why)) return false;
  const std::vector<double> irregular = IrregularSteps(seed, so, in.start_time, tm);
  Samples samples;
  if (!SampleTimes(so, in.start_time, tm, irregular, rng, &samples, why)) return false;
  if (!HandBeforeRelease(setup, in, tm, &samples, out, why)) return false;
  TruthDynamics dyn{options.model, setup.geometry, setup.params};
  if (!AddTruthDiscrepancies(setup, options, &dyn, why)) return false;
  std::vector<double> free_angle, free_rate;
  if (!IntegrateFreeSwing(setup, options, dyn, in.release_rate, samples.free_times, &free_angle,
                          &free_rate, why)) {
    return false;
  }
  const double envelope_at_stop =
      FreeSwingAndStop(setup, dyn, tm, samples, free_angle, free_rate, out);
  const SwingFrame frame = SwingFrameFor(setup, in.rocking_beta);
  const Eigen::Vector3d walk =
      SynthesizeImu(setup, so, seed, in, tm, frame, samples.times, rng, out);
  if (!AddSpikes(so, seed, frame, samples, out, why)) return false;
  if (!CheckFinite(so, *out, why)) return false;
  FillTruth(setup, so, in, tm, samples, frame, dyn, envelope_at_stop, walk, &out->truth);
  return true;
}

// ---------------------------------------------------------------------------------------------
}  // namespace bifilar
