// The campaign configuration (YAML), shared by `bifilar process` and `bifilar fit`. Every key is
// documented in configs/README.md; unknown keys are errors with their dotted path and line
// (pipeline/config/yaml_reader.h), missing required keys are named. Relative paths are resolved
// against the folder of the config file. All values in memory are SI (kg, m, m/s^2, kg m^2, deg for
// pitch angles); `units` only chooses how the console and the report print them.
// Conventions (pitch nose-up positive, swing axis = down vertical): docs/physics.md §2, §3.
#pragma once

#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "base/option_check.h"
#include "base/units.h"
#include "fit/ellipse.h"
#include "fit/glitch.h"
#include "fit/trace_options.h"
#include "pendulum/integrator.h"
#include "pendulum/model.h"
#include "pipeline/logs/imu_format.h"
#include "pipeline/logs/imu_log_options.h"

namespace bifilar {

enum class PitchSource { kNominal, kMeasured };  // "nominal", "measured"

// How the rig's own inertia (subtracted from every total) is known: exactly one of three ways.
struct RigInertiaSpec {
  enum class Kind { kValue, kTable, kTare };
  Kind kind = Kind::kValue;
  double inertia_kg_m2 = 0.0;      // kValue: the rig's inertia about the swing axis (kg m^2)
  double inertia_std_kg_m2 = 0.0;  // kValue/kTable: its standard uncertainty (kg m^2); >= 0
  // kTable: pitch (deg) -> rig inertia (kg m^2); linear interpolation between entries, a pitch
  // outside the table is an error for that trace.
  std::map<double, double> table_kg_m2;
  // kTare: the tare logs (absolute paths after discovery; the patterns as written are kept for
  // the record). Fitted with the rig's own mass; rig inertia = their mean.
  std::vector<std::string> tare_patterns;  // glob-like patterns relative to the config folder
};

// `rig.calibration`: a reference object of known inertia and mass swung on the rig, whose swings
// fix the rig's effective geometry (docs/method.md §15, docs/physics.md §2.6). Absent: the
// configured L and D are used as they are.
struct RigCalibrationSpec {
  bool enabled = false;  // the section is present
  // The reference swings (absolute patterns or files, as rig.inertia.tare.logs); each is fitted
  // with the rig mass + reference_mass_kg and the suspended inertia rig + reference.
  std::vector<std::string> log_patterns;
  double reference_inertia_kg_m2 = 0.0;      // about the swing axis (kg m^2); > 0
  double reference_inertia_std_kg_m2 = 0.0;  // its standard uncertainty (kg m^2); [0, inertia)
  double reference_mass_kg = 0.0;            // (kg); > 0
  // rig.inertia.table only: the rig pitch (deg) at which the reference was swung; default 0.
  double rig_pitch_deg = 0.0;
};

// The effective geometry a calibration found, applied to every fit: the D^2/L of the pendulum is
// `factor` times the configured one. It is realised as an effective separation
// D_eff = D sqrt(factor) with L as configured (docs/physics.md §2.6: to leading order the
// dynamics depend on D^2/L only). Not applied: factor 1, the configured geometry.
struct GeometryCalibration {
  bool applied = false;
  double factor = 1.0;          // k = (D^2/L)_effective / (D^2/L)_configured; > 0
  double factor_rel_std = 0.0;  // std(k) / k: common to every moment of the campaign; >= 0
};

// The assumed 1-sigma of L and D (m) when the config has no `rig.uncertainties`: a tape measure.
constexpr double kAssumedLengthStdM = 0.001;

struct RigUncertainties {
  double filar_length_std_m = 0.0;      // standard uncertainty of L (m); >= 0; default 0
  double filar_separation_std_m = 0.0;  // of D (m); >= 0; default 0
  double mass_std_kg = 0.0;             // of the rig mass (kg); >= 0; default 0
  double gravity_std_mps2 = 0.0;        // of g (m/s^2); >= 0; default 0
  // The config has a `rig.uncertainties` section (zeros included). Without one (Assumed()),
  // InEffect() assumes a tape-measure 1 mm on L and D (kAssumedLengthStdM), labelled.
  bool configured = false;

  // The stds the budget uses: these when configured, else the assumed ones (1 mm on L and D).
  RigUncertainties InEffect() const;
  // Not configured: no section, and no std set in memory either (a config built in code that
  // sets a std has configured it).
  bool Assumed() const {
    return !configured && filar_length_std_m == 0.0 && filar_separation_std_m == 0.0 &&
           mass_std_kg == 0.0 && gravity_std_mps2 == 0.0;
  }
};

// The CSV layout of the logs and how the IMU sits on the aircraft.
struct ImuConfig {
  ImuFormat format;             // columns and units
  double gyro_scale_std = 0.0;  // 1-sigma gyro scale-factor uncertainty (fraction); >= 0
  bool swing_axis_auto = true;  // `swing_axis: auto`
  Eigen::Vector3d swing_axis_in_imu = Eigen::Vector3d::UnitZ();  // fixed axis (unit) otherwise
  // Rotation taking IMU-frame vectors to body axes (x fwd, y right, z down); default identity.
  Eigen::Matrix3d imu_to_body = Eigen::Matrix3d::Identity();
  // `imu.dataflash.instance`: the IMU instance of ArduPilot DataFlash logs (the `I` field; 0, 1,
  // 2 for IMU, IMU2, IMU3 in older logs); [0, 255], default -1: the lowest in the log.
  int dataflash_instance = -1;
};

// Where the aircraft logs are and how their pitch is known.
struct RunsConfig {
  std::string root;  // absolute folder of the logs (resolved from the config folder)
  // Pattern relative to root, '/'-separated; '*' matches any run of characters within one path
  // component, '{pitch_deg}' matches a number (the nominal pitch, deg). Empty when `table` used.
  std::string pattern;
  std::string table;  // absolute path of a CSV table "path,pitch_deg" (paths relative to root)
  PitchSource pitch_source = PitchSource::kNominal;
  // A log whose measured down vector lies farther than this from its nominal one (pitch and
  // roll of the path or table) gets a warning naming it (deg); (0, 180]. Default 3.
  double attitude_tolerance_deg = 3.0;
};

// The fit's quality thresholds, amplitude sweep and glitch detector are the fit's own options
// structs (fit/trace_options.h, fit/glitch.h), held by FitConfig as they are: each has one table
// ({config key, member, bound}, base/option_table.h) from which the loader reads `fit.quality`,
// `fit.amplitude_sweep` and `fit.glitch`, the checks take their bounds and the cache key its text.
struct FitConfig {
  PendulumModel model = PendulumModel::kFull;  // `fit.model`: full | jardin | linear
  // `fit.integrator`: rk853 (default) | cvodes; the fit's ODE solver (pendulum/integrator.h).
  IntegratorMethod integrator = IntegratorMethod::kRungeKutta;
  // Per-file window overrides [t0, t1] (s), keyed by the path as written (relative to runs root
  // or to the config folder for tare logs); the file names are resolved at load time.
  std::map<std::string, std::array<double, 2>> windows_s;
  std::optional<double> max_amplitude_deg;  // amplitude band, upper (deg); default: fit's own
  std::optional<double> min_amplitude_deg;  // amplitude band, lower (deg); default: fit's own
  TraceQualityOptions quality;              // `fit.quality` (fit/trace_options.h)
  AmplitudeSweepOptions sweep;              // `fit.amplitude_sweep` (fit/trace_options.h)
  // `fit.glitch`: isolated gyro glitches (fit/glitch.h), dropped before the swing axis, window
  // and fit, and again on the fit's residuals.
  GlitchOptions glitch;

  // Every bound of the fields above (amplitude band, then quality, sweep and glitch by their own
  // Checks): the first field outside its bound in *failure, named by its YAML key below `fit`
  // ("max_amplitude_deg", "quality.whiteness_lags", "amplitude_sweep.max_bands", ...).
  bool Check(CheckFailure* failure) const;
  // The same; *why = "fit.<YAML key> = <value>; must be <allowed>" (base/option_check.h).
  bool Check(std::string* why) const;
};

// Options of the ellipse fit (fit/ellipse.h EllipseOptions, same defaults).
// Limits of the count-like keys (configs/README.md; fit.quality's in fit/trace_options.h);
// ellipse.bootstrap's are in fit/ellipse.h (kMinBootstrapReplicates, kMaxBootstrapReplicates). One
// set of ranges, checked when the config is loaded (naming the line) and by CampaignConfig::Check
// before any fit runs.
constexpr int kMaxMinAngles = 1000;            // ellipse.min_angles in [3, 1000]
constexpr double kMinMaxAmplitudeDeg = 1;      // fit.max_amplitude_deg in [1, 90]: the trace fit's
constexpr double kMaxMaxAmplitudeDeg = 90;     //   model holds to 90 deg; below 1 deg is noise
constexpr double kMinSwingAxisLength = 1e-3;   // imu.swing_axis: a direction whose length lies
constexpr double kMaxSwingAxisLength = 1e3;    //   in [1e-3, 1e3] (typos and overflow refused)
constexpr double kMaxRigInertiaStdKgM2 = 1e3;  // rig.inertia.inertia_std_kg_m2 below this
// The other std keys (rig.uncertainties.*, aircraft.mass_std_kg, imu.gyro.scale_std) must be
// below the quantity they qualify (L, D, the masses, g; 1 for the scale factor).

struct EllipseConfig {
  int bootstrap = 2000;      // parametric bootstrap replicates (0 = covariance intervals)
  unsigned seed = 1;         // seed of the bootstrap
  double confidence = 0.95;  // confidence level of the intervals, in (0, 1)
  // auto | points | angle_means | absolute (fit/ellipse.h, parsed once when the config is read)
  EllipseCovariance covariance = EllipseCovariance::kAuto;
  int min_angles = 3;  // distinct pitch angles needed to fit the ellipse; [3, 1000]

  // The ranges above: the first field outside them (its name is its key below `ellipse`).
  bool Check(CheckFailure* failure) const;
  bool Check(std::string* why) const;  // *why = "ellipse.<key> = <value>; must be .."
};

// `limits`: size caps of the logs (MB = 1e6 bytes), README "Input size limits". The other
// inputs have fixed caps (base/bounded_read.h).
struct InputLimits {
  double max_log_mb = kDefaultMaxLogMb;  // a log file as stored; [1, kMaxLimitMb]; default 1000
  // its text once a .csv.gz is decompressed; [1, kMaxLimitMb]; default 1000
  double max_decompressed_log_mb = kDefaultMaxDecompressedLogMb;

  ImuLogOptions LogOptions() const;  // the reader's options with these caps (bytes)
};
constexpr double kMaxLimitMb = 1e6;  // 1 TB: the largest limits.* accepted

// `aircraft.cg_m` and `aircraft.cg_std_m` (configs/README.md): read by the loader and, from the
// config text stored in results.json, by `bifilar export`.
struct AircraftCg {
  std::array<double, 3> cg_m = {NAN, NAN, NAN};      // body FRD (m); NaN: not given
  std::array<double, 3> cg_std_m = {NAN, NAN, NAN};  // its std (m); NaN: not given
  bool Given() const { return !std::isnan(cg_m[0]); }
};
// The centre of mass of a config's text (`name` names it in messages): throws UserError naming
// the key and line when aircraft.cg_m or cg_std_m is not a list of 3 finite numbers (std >= 0).
AircraftCg ReadAircraftCgText(const std::string& text, const std::string& name);

struct CampaignConfig {
  std::string file;    // absolute path of the config file
  std::string folder;  // its folder: relative paths are resolved against it
  std::string text;    // the YAML text as read (stored in results.json)

  double filar_length_m = 0.0;      // L (m)
  double filar_separation_m = 0.0;  // D (m)
  double rig_mass_kg = 0.0;         // rig (+ IMU) mass (kg)
  RigInertiaSpec rig_inertia;
  RigCalibrationSpec calibration;  // rig.calibration (enabled = false when absent)
  // The calibration in effect (set by the campaign or `bifilar fit` after the reference swings
  // are fitted, never read from the file). Applied: the geometries below use D_eff, and the
  // L, D and g terms of the budget are replaced by one `calibration` term.
  GeometryCalibration geometry_calibration;
  // false when `process` runs without `rig.inertia` and `aircraft` (a rig of thread only, like
  // the Crazyflie's): rig.mass_kg is everything that hangs and the rig inertia is 0.
  bool rig_inertia_given = true;
  RigUncertainties uncertainties;
  double aircraft_mass_kg = 0.0;         // aircraft mass (kg); 0 when only tare logs are fitted
  double aircraft_mass_std_kg = 0.0;     // its standard uncertainty (kg)
  bool aircraft_mass_std_given = false;  // aircraft.mass_std_kg written in the config
  // aircraft.cg_m: the centre of mass in body axes (x forward, y right, z down; m, from the
  // origin of the simulator model's body/link frame), measured apart from the bifilar; export
  // writes it as the inertial origin. NaN when not given; cg_std_m NaN when not given.
  AircraftCg aircraft_cg;
  // Local gravity (m/s^2); in [9.76, 9.84] (Earth) unless
  double gravity_mps2 = kStandardGravityMps2;
  bool gravity_off_earth = false;  // `gravity_off_earth: true`: then in (0, 100]
  ImuConfig imu;
  RunsConfig runs;  // absent (root empty) for a `fit`-only config
  FitConfig fit;
  EllipseConfig ellipse;
  DisplayUnits units = DisplayUnits::kSi;
  InputLimits limits;

  // Geometry of an aircraft trace (mass = aircraft + rig), of a tare trace (rig alone) and of a
  // reference swing (rig + reference), with the calibrated separation when one is applied.
  RigGeometry AircraftGeometry() const;
  // The log reader's options: limits.LogOptions() and imu.dataflash.instance.
  ImuLogOptions LogOptions() const;
  RigGeometry TareGeometry() const;
  RigGeometry CalibrationGeometry() const;
  double EffectiveSeparationM() const;  // D sqrt(geometry_calibration.factor)

  bool Check(std::string* why) const;
  // Values no lab rig can have (pipeline/config/plausibility.h): L, D, the masses, the rig inertia
  // against the rig's mass and D. Part of Check; *why names the key and the likely unit.
  bool CheckPlausible(std::string* why) const;
};

// Gravity on Earth's surface spans 9.7639 (Huascaran, 6.8 km at the equator) to 9.8337 m/s^2
// (the poles); a config's gravity_mps2 must lie in [9.76, 9.84] unless gravity_off_earth is set,
// which allows (0, 100] (the Moon 1.62, Mars 3.71, Jupiter 24.8). *why names the key and range.
constexpr double kMinEarthGravityMps2 = 9.76, kMaxEarthGravityMps2 = 9.84;
constexpr double kMaxOffEarthGravityMps2 = 100.0;
bool CheckGravity(double gravity_mps2, bool off_earth, std::string* why);

struct ConfigLoadOptions {
  bool require_runs = true;  // `process` needs runs/aircraft; `fit` only geometry + IMU
  // `process --runs-root DIR`: the folder of the aircraft logs, replacing runs.root (which may
  // then be absent). Empty: runs.root as written.
  std::string runs_root;
};

// Reads and validates `path`. Throws UserError naming the file, line and key on any problem.
CampaignConfig LoadCampaignConfig(const std::string& path,
                                  const ConfigLoadOptions& options = ConfigLoadOptions());
// The same checks on YAML text not (yet) in a file, as if it were `path` (relative paths resolve
// against path's folder): `init` loads the config it is about to write, so it writes none that
// `fit` rejects.
CampaignConfig LoadCampaignConfigText(const std::string& text, const std::string& path,
                                      const ConfigLoadOptions& options = ConfigLoadOptions());

const char* ToString(PitchSource source);
bool ParsePitchSource(const std::string& name, PitchSource* source);  // false: no such name
std::string PitchSourceAllowedValues();                               // "nominal or measured"

// `path` resolved against `folder` unless absolute; lexically normalised.
std::string ResolvePath(const std::string& folder, const std::string& path);

}  // namespace bifilar
