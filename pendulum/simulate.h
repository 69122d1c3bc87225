// Realistic bifilar-pendulum IMU logs with known truth: one trace (simulate.cc) or a whole
// campaign (simulate_campaign.cc).
// Physics and IMU synthesis only (no files, no YAML): pipeline/commands/simulate_spec.h reads the
// spec and writes the files.
//
// Conventions (docs/physics.md §2, §3): body axes x forward, y right wing, z down, origin at
// the CG; pitch theta nose-up positive; the swing axis (down vertical) in body axes is
// n_body = (-sin theta, 0, cos theta); psi is the yaw angle about n (right-handed about down), so
// the body's angular velocity is psi' n_body: the swing shows on body z at small pitch and on -x at
// large nose-up pitch. The IMU is mounted on the rig with rotation body_from_imu
// (v_body = body_from_imu * v_imu; identity by default), at imu_offset_in_body_m from the CG. The
// accelerometer measures specific force f = a - g_vec: at rest f = -g n (pointing up), so
// down = -f/|f| as docs/physics.md says. Lever-arm terms at offset r: a = psi'' n x r
// - psi'^2 r_perp - (d^2 h/dt^2) n, with h the rise of the body (docs/physics.md §2).
//
// One trace, in time order: rest, the hand twisting to the amplitude A (smooth quintic ramp),
// holding with hand tremor, release (psi(t_release) = A, psi'(t_release) = a small random rate),
// free oscillation integrated with PendulumIntegrator (model `full` by default) at the log's own
// timestamps, and with some probability a hand stopping it (rate decays exponentially) followed by
// a little rest. A small decaying rocking mode about a horizontal axis perpendicular to n starts at
// release. Timestamps have jitter and dropped samples (single and in bursts), or irregular
// log-normal steps. Optional realism, all off by default (and then the log is bit for bit what it
// was before these options existed): AR(1) coloured gyro noise, a gyro bias random walk,
// single-sample spikes, a gravity-removed accelerometer, amplitude softening. Each draws from its
// own random stream (AR(1) reuses the white-noise draws), so turning one on changes only what it
// models: the timestamps for the steps, the swing for the softening, one channel for the others.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "base/units.h"
#include "pendulum/imu_data.h"
#include "pendulum/integrator.h"
#include "pendulum/model.h"

namespace bifilar {

// A closed range [min, max] sampled uniformly; min == max is a fixed value.
struct UniformRange {
  double min = 0.0;
  double max = 0.0;
  bool Valid() const { return min <= max; }
};

// What happens in a log, besides the free oscillation. Durations in seconds.
struct TimelineOptions {
  UniformRange rest_before_s = {2.0, 5.0};    // still on the wires before the twist; >= 0
  UniformRange twist_s = {0.8, 1.2};          // hand twisting to the amplitude; > 0
  UniformRange hold_s = {1.0, 2.0};           // hand holding at the amplitude; >= 0
  double tremor_deg = 0.08;                   // hand tremor while holding, RMS angle (deg); >= 0
  UniformRange tremor_hz = {4.0, 9.0};        // tremor frequencies (Hz); > 0
  double release_rate_sigma_deg_per_s = 0.5;  // psi'(t_release) ~ N(0, sigma) (deg/s); >= 0
  UniformRange free_s = {40.0, 90.0};      // free oscillation until the log ends or the stop; > 0
  double stop_probability = 0.5;           // chance a hand stops the swing at the end; [0, 1]
  double stop_time_constant_s = 0.1;       // rate decays as exp(-t/tau) when stopped; > 0
  UniformRange rest_after_s = {1.0, 3.0};  // logging continues after the stop; >= 0

  bool Check(std::string* why) const;
};

// A timeline of fixed phase durations (s) that is never stopped by hand: a trace of known
// length, as tests and benchmarks use.
TimelineOptions FixedTimeline(double rest_s, double twist_s, double hold_s, double free_s);

// The sensor and the radio link.
// How timestamps are spaced.
//   kRegular: a grid at 1/sample_rate_hz with Gaussian jitter (time_jitter_sigma_s), as before.
//   kLogNormal: steps drawn independently, ln(step) ~ N(ln(1/sample_rate_hz), step_log_sigma),
//     clipped to step_range_s, like a radio link that batches packets (a Crazyflie log at
//     "30 Hz": median 31 ms, ln-std 0.75, 8-160 ms). No jitter; drops still apply on top.
enum class SampleSteps { kRegular, kLogNormal };
// "regular", "lognormal".
const char* ToString(SampleSteps steps);
bool ParseSampleSteps(const std::string& name, SampleSteps* steps);
std::string SampleStepsAllowedValues();  // "regular or lognormal"

struct SensorOptions {
  double sample_rate_hz = 100.0;  // nominal sample rate (Hz); > 0
  SampleSteps sample_steps = SampleSteps::kRegular;
  double step_log_sigma = 0.75;                // kLogNormal: std of ln(step) (-); [0, 3]
  UniformRange step_range_s = {0.008, 0.160};  // kLogNormal: steps clipped to [min, max] (s); > 0
  double time_jitter_sigma_s = 0.001;          // timestamp jitter, clipped to +-0.4/rate (s); >= 0
  double drop_fraction = 0.01;                 // fraction of samples lost; [0, 0.5]
  double drop_burst_probability = 0.1;     // chance a loss is a burst rather than one sample; [0,1]
  int drop_burst_max_samples = 25;         // bursts are 2..max samples long; >= 2
  UniformRange start_time_s = {0.0, 0.0};  // time stamp of the first sample (s), e.g. uptime
  double gyro_noise_sigma_deg_per_s = 0.25;  // noise std per sample per axis (deg/s); >= 0
  // Coloured gyro noise: AR(1) over the logged samples, e_k = phi e_(k-1) + sqrt(1 - phi^2) w_k,
  // w_k ~ N(0, gyro_noise_sigma), e_0 = w_0, so the marginal std stays gyro_noise_sigma and the
  // lag-1 autocorrelation is phi. 0 = white (default); [0, 0.99].
  double gyro_noise_ar1_phi = 0.0;
  // Gyro bias random walk (deg/s per sqrt(s)): per axis, b(t_(k+1)) = b(t_k) + rate sqrt(dt)
  // N(0,1), starting at the constant bias; 0 = off (default); [0, 10].
  double gyro_bias_walk_deg_per_s_per_sqrt_s = 0.0;
  // Single-sample gyro glitches: spike_count samples (distinct; the first one inside the free
  // oscillation, the others anywhere in the log) whose value on the IMU axis most aligned with
  // the swing axis is replaced by +-spike_rate_rad_per_s (sign random). Count in [0, 1000]
  // (default 0), rate (rad/s) in (0, 1e4] (default 50).
  int spike_count = 0;
  double spike_rate_rad_per_s = 50.0;
  double gyro_bias_sigma_deg_per_s = 0.5;  // constant bias per axis ~ N(0, sigma) (deg/s); >= 0
  double gyro_scale_error_sigma = 0.0;     // scale factor error per axis ~ N(0, sigma) (-); >= 0
  bool accelerometer = true;               // false: the log has no accelerometer
  // The accelerometer logs specific force with gravity removed (f + g down_est, as some IMU
  // firmwares do: the mean is near 0 g), where down_est is the static down (no rocking) tilted
  // by an attitude-estimate error of gravity_removal_error_deg about a random horizontal axis
  // (residual ~ g * error). Only with accelerometer = true; default false.
  bool accel_gravity_removed = false;
  UniformRange gravity_removal_error_deg = {0.0, 0.0};  // per log ~ U(min, max) (deg); [0, 30]
  double accel_noise_sigma_mps2 = 0.02;  // white noise per sample per axis (m/s^2); >= 0
  double accel_bias_sigma_mps2 = 0.05;   // constant bias per axis ~ N(0, sigma) (m/s^2); >= 0
  double rocking_max_deg = 0.3;          // rocking amplitude ~ U(0, max) at release (deg); >= 0
  double rocking_frequency_hz = 0.0;     // 0: sqrt(g/L)/(2 pi) +-10 %; else this (Hz); >= 0
  double rocking_decay_s = 15.0;         // rocking amplitude time constant (s); > 0

  bool Check(std::string* why) const;
};

// Randomness and model options shared by every trace of a run.
struct SimulationOptions {
  PendulumModel model = PendulumModel::kFull;  // the truth's equation of motion
  TimelineOptions timeline;
  SensorOptions sensor;
  double negative_amplitude_probability = 0.5;  // twist direction: chance of psi(t_release) < 0
  // Deliberate model discrepancy ("sway coupling"), off by default: a conservative extra term that
  // weakens the restoring torque, m g h'(psi) (1 - k psi^4), with k chosen so that a fit with the
  // exact model at 60 deg amplitude finds an inertia this fraction too large; the bias scales as
  // A^4 below (harmonic balance: I_apparent ~ I (1 + (5/8) k A^4)). Integrated with a fixed-step
  // RK4 (<= 1 ms steps) instead of PendulumIntegrator when non-zero. Fraction, e.g. 0.01 = +1 %
  // at 60 deg; in [0, 0.5].
  double sway_coupling_at_60deg = 0.0;
  // Amplitude softening ("non-ideal rig"), off by default: the restoring torque becomes
  // m g h'(psi) (1 - k |psi|^p), p = softening_exponent, so the period grows with amplitude faster
  // than the ideal model's, and a fit of the ideal model at amplitude A finds
  // I_app = I / (1 - c_p k A^p) ~ I (1 + c_p k A^p) (harmonic balance, c_p = 2 Gamma((p+3)/2) /
  // (sqrt(pi) Gamma(p/2+2)): 3/4 for p = 2, 8/(3 pi) for p = 1), i.e. roughly like A^p. k is
  // chosen so that I_app / I - 1 = softening_at_30deg at A = 30 deg (SofteningCoefficient).
  // Real rigs (pendulum sway, wire stretch, hooks) show a few percent at 30 deg. The term may
  // remove at most half the restoring torque at the release amplitude. Integrated with a
  // fixed-step RK4 (<= 1 ms steps) when non-zero. Fraction, e.g. 0.028 = +2.8 % at 30 deg; in
  // [0, 0.5]; exponent in [1, 4], default 2.
  double softening_at_30deg = 0.0;
  double softening_exponent = 2.0;
  // The truth's integrator. Default: CVODE (kCvodes), a different solver from the fit's default
  // (Runge-Kutta), so that the fit is judged against an independent integration.
  IntegratorOptions integrator = [] {
    IntegratorOptions options;
    options.method = IntegratorMethod::kCvodes;
    return options;
  }();

  bool Check(std::string* why) const;
};

// c_p of the softening term (harmonic balance constant, see softening_at_30deg) and k such that
// the apparent-inertia excess at 30 deg is `excess_at_30deg`. ApparentInertiaExcess(k, p, A) =
// x / (1 - x), x = c_p k |A|^p: the relative excess I_app / I - 1 of the inertia a fit of the
// ideal model finds at amplitude A (tests/pendulum_simulate_test.cc checks it against measured
// periods to 1 %).
double SofteningHarmonicConstant(double exponent);
double SofteningCoefficient(double excess_at_30deg, double exponent);
double ApparentInertiaExcess(double k, double exponent, double amplitude_rad);

// The physical truth of one trace (everything deterministic; the noise comes from the seed).
struct TraceSetup {
  RigGeometry geometry;    // L, D, whole suspended mass, g
  PendulumParams params;   // I, K_D, C of the whole suspended body
  double pitch_rad = 0.0;  // TRUE pitch of the body axes (nose-up +)
  // TRUE roll (right wing down +, rad), |roll| <= pi: the swing axis in body axes is then
  // (-sin theta, sin phi cos theta, cos phi cos theta) (docs/physics.md §3.5). Default 0.
  double roll_rad = 0.0;
  double amplitude_rad = 0.3;  // psi at release (sign = twist direction); 0 < |A| < 89 deg
  Eigen::Matrix3d body_from_imu = Eigen::Matrix3d::Identity();     // IMU mounting (rotation)
  Eigen::Vector3d imu_offset_in_body_m = Eigen::Vector3d::Zero();  // IMU position from the CG

  bool Check(std::string* why) const;
};

// What the simulator drew for one trace: the truth a fitter should recover.
struct TraceTruth {
  double start_time_s = 0.0;            // first nominal sample time
  double t_twist_s = 0.0;               // hand starts twisting
  double t_release_s = 0.0;             // free oscillation starts
  bool stopped = false;                 // a hand stopped the swing
  double t_stop_s = 0.0;                // hand grabs (valid when stopped)
  double t_end_s = 0.0;                 // last nominal sample time
  double amplitude_rad = 0.0;           // psi(t_release)
  double release_rate_rad_per_s = 0.0;  // psi'(t_release)
  double amplitude_at_stop_rad = 0.0;   // |psi| envelope estimate at the end of the free part
  Eigen::Vector3d gyro_bias_rad_per_s = Eigen::Vector3d::Zero();  // IMU axes
  Eigen::Vector3d gyro_scale_error = Eigen::Vector3d::Zero();     // measured = (1+e) true
  Eigen::Vector3d accel_bias_mps2 = Eigen::Vector3d::Zero();      // IMU axes
  Eigen::Vector3d swing_axis_in_imu = Eigen::Vector3d::UnitZ();   // n in IMU axes (down)
  double rocking_amplitude_rad = 0.0;
  double rocking_frequency_hz = 0.0;
  Eigen::Vector3d rocking_axis_in_body = Eigen::Vector3d::UnitY();
  Eigen::Vector3d gyro_bias_end_rad_per_s = Eigen::Vector3d::Zero();  // bias at the last sample
  double gravity_removal_error_rad = 0.0;  // attitude error of a gravity-removed accelerometer
  double softening_k = 0.0;                // k of the softening term (per rad^p); 0 = off
  struct Spike {
    int sample = 0;  // index into the kept samples
    double t_s = 0.0;
    int axis = 0;                 // IMU axis 0..2
    double rate_rad_per_s = 0.0;  // the value written on that axis
  };
  std::vector<Spike> spikes;  // in sample order
  int samples_nominal = 0;    // samples the IMU would have sent
  int samples_dropped = 0;
  int free_samples = 0;  // samples in [t_release, t_stop) (or to the end)
};

struct SimulatedTrace {
  ImuData imu;  // SI, IMU axes (accel empty when the sensor has none)
  TraceTruth truth;
  // Noise-free swing state at each kept sample (for tests and plots): psi, psi', psi''.
  std::vector<double> angle_rad, rate_rad_per_s, accel_rad_per_s2;
};

// Simulates one trace. Same (setup, options, seed) -> same output, bit for bit. Returns false
// with *why naming the parameter and its allowed range on bad input or a solver failure; never
// produces NaN.
bool SimulateTrace(const TraceSetup& setup, const SimulationOptions& options, uint64_t seed,
                   SimulatedTrace* out, std::string* why);

// ---- Campaign: an aircraft tested at many pitch angles in a rig, plus tare logs of the rig ----

struct AircraftTruth {
  double mass_kg = 0.0;    // > 0
  double ix_kg_m2 = 0.0;   // I_x, body axes about the CG; > 0
  double iz_kg_m2 = 0.0;   // I_z; > 0
  double ixz_kg_m2 = 0.0;  // I_xz = integral x z dm (docs/physics.md §3)
  // The rest of the tensor (docs/physics.md §3.5), for campaigns that roll: I_y > 0 turns it on
  // (0: a pitch-only aircraft, as before); products positive, I_xy = integral x y dm.
  double iy_kg_m2 = 0.0;
  double ixy_kg_m2 = 0.0;
  double iyz_kg_m2 = 0.0;
  bool HasTensor() const { return iy_kg_m2 > 0.0; }
  // [[Ix, -Ixy, -Ixz], [-Ixy, Iy, -Iyz], [-Ixz, -Iyz, Iz]].
  Eigen::Matrix3d Tensor() const;
  // n^T J n about n = (-sin theta, sin phi cos theta, cos phi cos theta); InertiaAtPitch when the
  // roll is 0 and there is no tensor (bit for bit as before).
  double InertiaAtAttitude(double roll_rad, double pitch_rad) const;

  // I(theta) = I_z cos^2 + I_x sin^2 + I_xz sin 2theta (docs/physics.md §3, paper Eq. 4).
  double InertiaAtPitch(double pitch_rad) const;
  // Principal inclination tau = 0.5 atan2(2 I_xz, I_z - I_x), in (-pi/4, pi/4].
  double PrincipalInclinationRad() const;
  bool Check(std::string* why) const;  // positive, and I(theta) > 0 for every theta
};

struct RigTruth {
  double mass_kg = 0.0;        // rig structure (kg); > 0
  double imu_mass_kg = 0.0;    // the IMU (kg), carried in every log; >= 0
  double inertia_kg_m2 = 0.0;  // rig (+ IMU) inertia about the swing axis when constant; > 0
  // Optional per-pitch table (nominal pitch deg -> kg m^2), used instead of the constant when set;
  // must cover every nominal pitch simulated (and the tare pitch).
  std::vector<std::pair<double, double>> inertia_by_pitch_kg_m2;
  Eigen::Vector3d imu_offset_in_body_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d body_from_imu = Eigen::Matrix3d::Identity();

  // Rig inertia at a nominal pitch; false when the table lacks it.
  bool InertiaAtPitch(double nominal_pitch_deg, double* inertia_kg_m2) const;
  bool Check(std::string* why) const;
};

// Logs of one attitude made otherwise than the rest (a survey's faulty campaign): on another
// rig (true L, D; 0 = the campaign's), and/or with a per-log scatter of the true moment beyond
// what the logs' fits see (a relative std: a hanging that changes between repeats).
struct AttitudeOverride {
  std::array<double, 2> attitude_deg = {0, 0};  // [roll, pitch], one of attitudes_deg
  double true_filar_length_m = 0.0;             // 0: the campaign's
  double true_filar_separation_m = 0.0;         // 0: the campaign's
  std::vector<int> trials;                      // 1-based trials it applies to; empty: all
  double inertia_scatter = 0.0;                 // relative std of the true moment per log, >= 0
};

struct CampaignSpec {
  AircraftTruth aircraft;
  RigTruth rig;
  double filar_length_m = 0.0;                 // L; > D
  double filar_separation_m = 0.0;             // D; > 0
  double gravity_mps2 = kStandardGravityMps2;  // > 0
  std::vector<double> pitch_deg;               // nominal pitch angles (deg), distinct, in [-90, 90]
  // Attitudes (roll, pitch) in deg instead of pitch_deg (a tensor campaign): folders
  // roll_{R}_pitch_{P}; roll in [-180, 180], pitch in [-90, 90]; needs aircraft.iy_kg_m2.
  std::vector<std::array<double, 2>> attitudes_deg;
  double roll_error_sigma_deg = 0.5;         // true roll = nominal + N(0, sigma), per log; >= 0
  int trials_per_pitch = 3;                  // >= 1
  int tare_logs = 0;                         // logs of the rig alone; >= 0
  double tare_pitch_deg = 0.0;               // rig pitch for the tare logs (nominal)
  double pitch_error_sigma_deg = 0.5;        // true pitch = nominal + N(0, sigma), per log; >= 0
  UniformRange amplitude_deg = {5.0, 30.0};  // |psi(t_release)| (deg); 0 < min, max <= 85
  UniformRange drag_coeff_kg_m2 = {0.02, 0.08};            // K_D per log
  UniformRange viscous_coeff_kg_m2_per_s = {0.005, 0.02};  // C per log
  // Tare logs (rig alone, far less aerodynamic area) draw K_D and C from the ranges above times
  // this factor; in [0, 1], default 0.25. Reference swings (calibration) too.
  double tare_damping_scale = 0.25;
  // A mis-measured rig: the geometry the logs are simulated with, when it differs from the one a
  // user measured (filar_length_m, filar_separation_m, which truth.json reports as configured).
  // 0 = as configured. With them, L_true > D_true > 0 is required.
  double true_filar_length_m = 0.0;
  double true_filar_separation_m = 0.0;
  // Reference swings for rig.calibration: a reference object of known inertia (about the swing
  // axis) and mass hung on the rig at tare_pitch_deg, swung calibration_logs times
  // (calibration/reference_{k}.csv), each at an amplitude from calibration_amplitude_deg
  // (default {0, 0}: amplitude_deg).
  int calibration_logs = 0;              // [0, 1000]
  double reference_inertia_kg_m2 = 0.0;  // > 0 when calibration_logs > 0
  double reference_mass_kg = 0.0;        // > 0 when calibration_logs > 0
  UniformRange calibration_amplitude_deg = {0.0, 0.0};
  // Attitudes whose logs were made otherwise (AttitudeOverride); each names one of attitudes_deg.
  std::vector<AttitudeOverride> attitude_overrides;

  double TrueLengthM() const {
    return true_filar_length_m > 0 ? true_filar_length_m : filar_length_m;
  }
  double TrueSeparationM() const {
    return true_filar_separation_m > 0 ? true_filar_separation_m : filar_separation_m;
  }

  bool Check(std::string* why) const;
};

// One log of a campaign with its truth.
struct CampaignTrace {
  std::string relative_path;  // "pitch_-80/trial_1.csv", "tare/tare_1.csv",
                              // "calibration/reference_1.csv"
  bool is_tare = false;
  bool is_calibration = false;           // a reference swing (rig + reference object)
  double inertia_reference_kg_m2 = 0.0;  // the reference object's, for a reference swing
  int trial = 0;                         // 1-based
  double nominal_pitch_deg = 0.0;
  double true_pitch_deg = 0.0;
  double nominal_roll_deg = 0.0;  // attitude campaigns (0 otherwise)
  double true_roll_deg = 0.0;
  double inertia_aircraft_kg_m2 = 0.0;  // 0 for tare logs
  double inertia_rig_kg_m2 = 0.0;
  TraceSetup setup;  // setup.params.inertia_kg_m2 = I_total, geometry.mass_kg = m
  SimulatedTrace trace;
};

// Simulates every log (pitch folders in the order given, then tare, then the reference swings),
// with the true geometry (TrueLengthM, TrueSeparationM). Each log's random stream is
// derived from (seed, its relative path), so a log does not change when others are added.
bool SimulateCampaign(const CampaignSpec& spec, const SimulationOptions& options, uint64_t seed,
                      std::vector<CampaignTrace>* out, std::string* why);

// "roll_-45_pitch_30": the folder of an attitude (roll, pitch in deg) of a tensor campaign.
std::string AttitudeFolder(const std::array<double, 2>& roll_pitch_deg);

// "-80", "0", "10", "12.5": the folder name part of a nominal pitch.
std::string FormatPitchDeg(double pitch_deg);

// Deterministic per-stream seed from a campaign seed and a name (SplitMix64 over FNV-1a).
uint64_t DeriveSeed(uint64_t seed, const std::string& name);

// Rotation body_from_imu from roll, pitch, yaw mounting angles (deg), Z-Y-X (yaw first).
Eigen::Matrix3d MountingFromRollPitchYawDeg(double roll_deg, double pitch_deg, double yaw_deg);

}  // namespace bifilar
