// The use case behind `bifilar fit CONFIG LOG...`: fits single logs with the campaign's trace
// processing (pipeline/trace/trace_process.h), optionally calibrating the rig first and combining
// repeats. The CLI (pipeline/cli/cli_fit.cc) parses options and prints; tests and Python call
// RunFit directly.
#pragma once

#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/config/config.h"
#include "pipeline/records/calibration_result.h"
#include "pipeline/records/trace_record.h"
#include "pipeline/trace/repeats.h"

namespace bifilar {

struct FitCommandOptions {
  std::string config_path;        // YAML: rig geometry, masses, IMU format (configs/README.md)
  std::vector<std::string> logs;  // CSV (optionally .gz) or PX4 ULog (.ulg)
  bool repeats = false;           // combine repeats (GroupRepeats, CombineRepeats)
  // --repeats: the part of each file name that names the set-up (a regular expression, case
  // ignored; RepeatGroupingOptions::group_by); "" groups by file name.
  std::string group_by;
  // --repeats: a runs table naming each log's group (its `group` column, else its attitude;
  // pipeline/campaign/run_discovery.h ReadRunsTableGroups); "" none. Not with group_by.
  std::string runs_table;
  std::string model;       // "" (the config's), "full", "jardin" or "linear"
  std::string integrator;  // "" (the config's), "rk853" or "cvodes"
  std::string window;      // "" or "T0:T1" (s, the log's own time)
  std::string plot_dir;    // write DIR/<log>.svg|.png (+ _sweep) when non-empty
  // --force: with plot_dir, replace files of the figures' names bifilar did not write there
  // (never a link; base/plot_folder.h). Without it they are refused before any fit.
  bool force = false;
  double max_amplitude_deg = NAN;  // upper end of the amplitude band; NaN: the config's
  // Install the Ctrl-C handler before the first fit (base/interrupt.h); an interrupt then stops
  // the run between logs or between solver iterations, and the result says so.
  bool handle_interrupt = false;
  // Told as the run goes (the CLI prints them at once); any may be empty.
  std::function<void(const RigCalibrationResult&)> on_calibration;  // before any fit
  std::function<void(const std::string&)> on_identical_log;         // a dropped copy (--repeats)
  // --repeats: the groups made (RepeatGroupsText), before any fit.
  std::function<void(const std::string&)> on_groups;
  // Each record once fitted, with the config it was fitted with (its display units).
  std::function<void(const TraceRecord&, const CampaignConfig&)> on_record;
};

struct FitCommandResult {
  CampaignConfig config;                            // as run (calibrated geometry applied)
  std::optional<RigCalibrationResult> calibration;  // when rig.calibration is enabled
  DistinctLogs distinct;                            // the logs fitted, and dropped copies
  std::vector<TraceRecord> records;                 // one per fitted log, in order
  std::vector<RepeatGroup> groups;                  // --repeats (members index distinct.kept)
  RepeatGroupingOptions grouping;                   // --repeats: how they were made
  RepeatsAmplitudeCorrection correction;            // --repeats
  int n_failed = 0;                                 // records not ok
  // Ctrl-C: `records` holds the logs fitted before it; groups, correction and json are empty.
  bool interrupted = false;
  // What `fit --json` prints: an array of records, or {traces, repeats, amplitude_correction,
  // identical_logs_dropped, calibration} with --repeats or a calibration.
  nlohmann::json json;
  // The exit code of `bifilar fit`: 130 interrupted, 1 when a log failed, else 0.
  int ExitCode() const;
};

// Loads the config, applies the overrides, calibrates if configured, fits each log (Ctrl-C
// aware), combines repeats and builds the JSON. Throws UserError on bad input before any fit
// (config, --window, --max-amplitude against fit.min_amplitude_deg, an unmakeable --plot folder).
FitCommandResult RunFit(const FitCommandOptions& options);

// The figure name of each log: DIR/<stem>.svg, unique among the logs and one per log.
std::vector<std::string> FigureStems(const std::vector<std::string>& logs);

}  // namespace bifilar
