// `bifilar inspect`: a look at a log before fitting it. What the file is (CSV, ULog, or what it
// looks like instead), its columns or ULog topics, the sample rate, the free-oscillation window,
// the swing axis, the amplitude range and the period; with a config, the small-angle inertia
// (docs/physics.md §2.3, the classical formula) beside it.
//
// Without a config the time and gyro columns and their units are guessed from the column names
// and the data (GuessCsvFormat, pipeline/logs/format_guess.h); every guess is stated in
// InspectReport::guesses, and the same guess is what `bifilar init --log` writes into a starting
// config. Nothing here fits the model: it is the data, the window search (fit/window.h) and the
// swing axis (fit/swing_axis.h) only.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/config/config.h"
#include "pipeline/logs/dataflash.h"
#include "pipeline/logs/format_guess.h"
#include "pipeline/logs/imu_format.h"

namespace bifilar {

// One ULog subscription as listed by inspect.
struct UlogTopicInfo {
  std::string topic;
  int multi_id = 0;
  long samples = 0;
  double rate_hz = 0.0;  // samples over the span of their timestamps; 0 when unknown
};

// What `inspect` found in one file. Numbers that do not apply are NaN (null in JSON).
struct InspectReport {
  std::string file;
  // "csv", "ulog", "dataflash" (ArduPilot .bin), or what the file is instead: "missing", "folder",
  // "empty", "binary", "config" (a YAML config), "text" (text that is not a table of numbers).
  std::string kind;
  bool is_log() const { return kind == "csv" || kind == "ulog" || kind == "dataflash"; }
  bool compressed = false;                     // gzip around the log
  std::vector<std::string> columns;            // CSV header
  std::vector<UlogTopicInfo> topics;           // ULog subscriptions
  std::vector<DataflashMessageInfo> messages;  // DataFlash messages: counts, rates, instances
  bool format_from_config = false;             // the format came from --config, not a guess
  std::vector<std::string> guesses;            // what was guessed without a config, and why
  // The guessed format cannot be used as it is (the "rate" columns hold angles): why. `init`
  // refuses to write it; `inspect` reports it as the error.
  std::string format_problem;
  ImuFormat format;  // the format used to read the series

  // Series (when read).
  long samples = 0;
  double duration_s = NAN;
  double rate_mean_hz = NAN;  // (samples - 1) / duration
  double step_median_s = NAN;
  double step_jitter_s = NAN;  // std of the steps that are not dropouts
  int dropouts = 0;            // steps longer than 2.5 median steps
  double longest_gap_s = NAN;
  bool has_accel = false;

  // Swing (when found).
  std::array<double, 3> swing_axis_in_imu = {NAN, NAN, NAN};
  std::string swing_axis_source;             // "accel_rest", "gyro_principal", ...
  std::optional<double> pitch_measured_deg;  // from the accelerometer
  std::string window_status;                 // "ok", "rejected", "error", "" when not searched
  std::array<double, 2> window_s = {NAN, NAN};
  std::string window_end;  // "log_end", "noise_floor", "stopped"
  double release_s = NAN;
  double period_s = NAN;
  double frequency_hz = NAN;
  double cycles = NAN;
  std::array<double, 2> amplitude_deg = {NAN, NAN};  // largest and smallest in the window
  double noise_rad_per_s = NAN;

  // With a config: I = m g D² T² / (16 π² L), m the aircraft trace's suspended mass.
  double small_angle_inertia_kg_m2 = NAN;
  double mass_used_kg = NAN;

  std::vector<std::string> warnings;  // reader warnings, window and axis notes
  std::string error;                  // why the series could not be read or searched; "" if fine
};

// Reads and looks at `path`. `config` (optional) gives the format and the rig for the
// small-angle inertia; `choice` names CSV columns instead of guessing them. Never throws on bad
// input: what went wrong is in kind/error.
InspectReport InspectLog(const std::string& path, const CampaignConfig* config,
                         const ColumnChoice& choice = {});

// The console form (several lines) and the JSON form of a report.
std::string InspectReportText(const InspectReport& report);
nlohmann::json InspectReportToJson(const InspectReport& report);

}  // namespace bifilar
