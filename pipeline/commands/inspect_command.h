// The use cases behind `bifilar inspect LOG...` (a look at logs before fitting them,
// pipeline/commands/log_inspect.h) and `bifilar init [PATH]` (a commented starting config,
// pipeline/config/config_template.h). The CLI (pipeline/cli/cli_inspect.cc) parses and prints.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/units.h"
#include "pipeline/commands/log_inspect.h"
#include "pipeline/config/config_template.h"

namespace bifilar {

struct InspectCommandOptions {
  std::vector<std::string> logs;  // CSV (.csv, .csv.gz) or PX4 ULog (.ulg)
  std::string config_path;        // "": guess the format (and print the guesses)
  std::function<void(const InspectReport&)> on_report;  // each report once made; may be empty
};

struct InspectCommandResult {
  std::vector<InspectReport> reports;  // one per log, in order
  int n_bad = 0;                       // not a log, or an error
  nlohmann::json json;                 // what `inspect --json` prints: an array of reports
  int ExitCode() const { return n_bad > 0 ? 1 : 0; }
};

// Throws UserError for a bad config; a bad log is a report with its error.
InspectCommandResult RunInspect(const InspectCommandOptions& options);

struct InitCommandOptions {
  std::string path = "bifilar.yaml";  // config file to write
  std::string log;                    // "" or a log whose format is filled in (as inspect guesses)
  ColumnChoice columns;               // with `log`: its time and gyro columns, named (not guessed)
  std::string rig;                    // "L,D,MASS" (m, m, kg); "": ask_rig
  double gravity_mps2 = kStandardGravityMps2;
  bool force = false;  // overwrite `path` if it exists
  // Without `rig`: fills L, D and the mass (the CLI asks on a terminal); returns false when it
  // cannot ask (then RunInit throws UserError saying to give --rig).
  std::function<bool(StartingConfigOptions*)> ask_rig;
  std::function<void(const std::string&)> on_guess;  // each format guess from `log`
};

// Refuses to replace `path` without `force`, checks the gravity and the rig, fills the format
// from `log`, and writes the config atomically. Returns the path written; throws UserError.
std::string RunInit(const InitCommandOptions& options);

}  // namespace bifilar
