// `bifilar simulate`: the YAML simulation spec (strict: an unknown key is an error with its path
// and line) and the typed Run functions the CLI calls. The physics lives in pendulum/simulate.h;
// simulate_spec.cc reads specs, simulate_run.cc runs them and writes the logs
// (pipeline/logs/imu_log_writer.h), simulate_truth.cc writes truth.json.
// Key by key documentation: README.md, section "simulate"; example:
// configs/simulate_prandtl_d.yaml.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "base/units.h"
#include "pendulum/simulate.h"
#include "pipeline/logs/imu_format.h"
#include "pipeline/logs/imu_log_writer.h"

namespace bifilar {

// One trace's physical inputs (single-trace mode: the spec's `trace` and `geometry` sections,
// overridden by command-line flags).
struct TraceRequest {
  std::optional<double> inertia_kg_m2;       // whole suspended inertia I (required)
  std::optional<double> mass_kg;             // whole suspended mass m (required)
  std::optional<double> filar_length_m;      // L (required)
  std::optional<double> filar_separation_m;  // D (required)
  double gravity_mps2 = kStandardGravityMps2;
  double pitch_deg = 0.0;                   // true pitch of the body axes
  double amplitude_deg = 20.0;              // psi at release (sign = twist direction)
  double drag_coeff_kg_m2 = 0.04;           // K_D
  double viscous_coeff_kg_m2_per_s = 0.01;  // C
  Eigen::Vector3d imu_offset_m = Eigen::Vector3d(0.15, 0.10, -0.05);  // IMU position, body axes
  Eigen::Vector3d imu_mounting_rpy_deg = Eigen::Vector3d::Zero();     // body_from_imu angles
};

struct SimulateSpec {
  std::string file;                // spec path ("" when built from flags only)
  uint64_t seed = 1;               // spec `seed`, overridable with --seed
  SimulationOptions options;       // model, timeline, sensor, sway coupling
  ImuFormat format;                // CSV columns and units
  ImuLogWriteOptions write;        // significant digits
  bool ulog = false;               // `format.ulog`: campaign logs written as PX4 ULog *.ulg
  bool gzip = false;               // `format.gzip`: campaign logs written as *.csv.gz
  bool footer = false;             // `format.footer`: a Crazyflie-like footer after the data
  bool time_jitter_given = false;  // `sensor.time_jitter_sigma_s` set in the spec
  bool has_campaign = false;       // `aircraft`, `rig`, `campaign` sections present
  CampaignSpec campaign;
  bool has_trace = false;  // `trace` section present
  TraceRequest trace;
};

// The default timestamp jitter (when the spec does not set sensor.time_jitter_sigma_s): 1 ms, but
// at most 10 % of a sample period, so that any sample rate works without touching it.
double DefaultTimeJitterSigmaS(double sample_rate_hz);

// Sets the sample rate from the command line (`--sample-rate-hz`): checks the range, lets a
// default jitter follow the rate (DefaultTimeJitterSigmaS) and, when a setting the spec made no
// longer fits the new rate, throws UserError naming the flag, the spec key and what to change.
void SetSampleRateFromFlag(SimulateSpec* spec, double sample_rate_hz,
                           const std::string& flag = "--sample-rate-hz");

// The settings `bifilar simulate` (flags) and Python's bifilar.simulate (keywords) lay over a
// spec; unset ones keep the spec's value. The callers check the values and name them in their own
// words (a flag or a keyword) before calling ApplySimulateOverrides.
struct SimulateOverrides {
  std::optional<uint64_t> seed;
  std::optional<double> inertia_kg_m2, mass_kg, length_m, separation_m, gravity_mps2, amplitude_deg,
      pitch_deg, duration_s;
  bool no_accel = false;  // write no accelerometer columns
};

// Lays the overrides over the spec: the seed, --no-accel, the free-oscillation duration and the
// geometry (L, D, g), into the campaign (`single_trace` false) or into spec.trace with the
// trace's own inertia, mass, amplitude and pitch (`single_trace` true). Checks nothing.
void ApplySimulateOverrides(const SimulateOverrides& overrides, bool single_trace,
                            SimulateSpec* spec);

// Refuses an output target that `simulate` must not write through: anything but a regular file
// or nothing (a device such as /dev/null, a FIFO, a socket, a folder, also behind a symlink), or
// a path below an existing non-folder. `what` names the option in the message ("--trace").
// Throws UserError.
void CheckOutputFileTarget(const std::string& path, const std::string& what);

// Reads and validates a spec file. Throws UserError "file:line:col: ..." naming the key.
SimulateSpec ReadSimulateSpec(const std::string& file);
// The same from YAML text (`name` stands for the file in messages).
SimulateSpec ParseSimulateSpec(const std::string& yaml_text, const std::string& name);

struct SimulateRunSummary {
  int files_written = 0;     // CSV logs
  long samples_written = 0;  // rows over all logs
  long samples_dropped = 0;  // packets lost over all logs
  std::string truth_path;    // the truth JSON written
  std::string BriefReport() const;
};

// Campaign: simulates every log in memory first (any error -> UserError, nothing written), then
// writes OUT/pitch_{P}/trial_{k}.csv, OUT/tare/tare_{k}.csv and OUT/truth.json, each atomically.
// Every log is marked as simulated, with its seed (pipeline/logs/simulated_log.h).
// Requires spec.has_campaign. Throws UserError, before writing anything, when out_dir exists and
// is not a folder, or one of the files it would write exists and is not a regular file, or
// (unless `force`) exists at all: simulate replaces no file without --force (issue 23).
SimulateRunSummary RunSimulateCampaign(const SimulateSpec& spec, const std::string& out_dir,
                                       bool force = false);

// One trace from spec.trace (flags already merged in): writes `csv_path` and the truth JSON at
// `truth_path` (default: csv_path with ".csv" replaced by ".truth.json"). Throws UserError naming
// the parameter on bad input; nothing is written then. Also refused, before anything is written:
// a target that is not a regular file (CheckOutputFileTarget) and a truth path that is the CSV
// path, however spelled (./a.csv, d/../a.csv, a symlink or a hard link to it), and, unless
// `force`, either path existing (RefuseToReplace, base/atomic_file.h). The log is marked as
// simulated, with its seed (pipeline/logs/simulated_log.h).
SimulateRunSummary RunSimulateTrace(const SimulateSpec& spec, const std::string& csv_path,
                                    const std::string& truth_path = "", bool force = false);

// How the settings are named in RunSimulate's messages: `bifilar simulate`'s flags (the
// defaults), or Python's keywords (python/src/simulate.cc).
struct SimulateSettingNames {
  std::string duration = "--duration-s", sample_rate = "--sample-rate-hz",
              inertia = "--inertia-kg-m2", mass = "--mass-kg", length = "-L/--filar-length-m",
              separation = "-D/--filar-separation-m", gravity = "--gravity-mps2",
              amplitude = "--amplitude-deg", pitch = "--pitch-deg", truth = "--truth",
              model = "--model", trace = "--trace FILE.csv", out = "--out DIR";
};

// `bifilar simulate`: a campaign (spec_file + out_dir) or one trace (trace_csv), with the
// command line's settings over the spec's. Messages name the settings as `names` does.
struct SimulateCommandOptions {
  std::string spec_file;   // "" : the defaults (a trace only)
  std::string out_dir;     // campaign output folder
  std::string trace_csv;   // one trace into this file (CSV; ULog for .ulg; DataFlash for .bin)
  std::string truth_json;  // the trace's truth file ("" : beside it)
  std::string model;       // "" : the spec's
  SimulateOverrides o;     // --seed, --inertia-kg-m2, ..., --duration-s, --no-accel
  std::optional<double> sample_rate;  // --sample-rate-hz (SetSampleRateFromFlag)
  bool force = false;  // replace files that exist (issue 23: never without being told)
  SimulateSettingNames names;
};

struct SimulateCommandResult {
  SimulateRunSummary summary;
  std::string written;  // the trace file or the campaign folder
  ImuFormat format;     // the columns and units the logs were written with
};

// Checks the settings, merges them into the spec and runs RunSimulateTrace or
// RunSimulateCampaign. Throws UserError naming the flag or the spec key.
SimulateCommandResult RunSimulate(const SimulateCommandOptions& options);

// The truth JSON text of a campaign / a single trace (what the Run functions write).
std::string CampaignTruthJson(const SimulateSpec& spec, const std::vector<CampaignTrace>& traces);

}  // namespace bifilar
