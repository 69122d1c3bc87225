// The use cases of `bifilar inspect` and `bifilar init` (pipeline/commands/inspect_command.h).
#include "pipeline/commands/inspect_command.h"

#include <optional>

#include "base/atomic_file.h"
#include "base/user_error.h"
#include "pipeline/config/config.h"
#include "pipeline/logs/imu_log.h"

namespace bifilar {

InspectCommandResult RunInspect(const InspectCommandOptions& options) {
  InspectCommandResult result;
  std::optional<CampaignConfig> config;
  if (!options.config_path.empty()) {
    ConfigLoadOptions load;
    load.require_runs = false;
    config = LoadCampaignConfig(options.config_path, load);
  }
  result.json = nlohmann::json::array();
  for (const std::string& log : options.logs) {
    result.reports.push_back(InspectLog(log, config ? &*config : nullptr));
    const InspectReport& report = result.reports.back();
    if (!report.is_log() || !report.error.empty()) ++result.n_bad;
    result.json.push_back(InspectReportToJson(report));
    if (options.on_report) options.on_report(report);
  }
  return result;
}

std::string RunInit(const InitCommandOptions& o) {
  RefuseToReplace(o.path, "init", o.force);  // base/atomic_file.h
  StartingConfigOptions options;
  options.gravity_mps2 = o.gravity_mps2;
  {
    std::string why;  // the config's own bound and message (pipeline/config/config.h)
    if (!CheckGravity(o.gravity_mps2, false, &why)) throw UserError("init: --gravity: " + why);
  }
  if (!o.rig.empty()) {
    std::string why;
    if (!ParseRigSpec(o.rig, &options, &why)) throw UserError(why);
  } else if (o.ask_rig && o.ask_rig(&options)) {
    std::string why;
    if (!options.Check(&why)) throw UserError("init: " + why);
  } else {
    throw UserError(
        "init: give the rig with --rig L,D,MASS (m, m, kg), e.g. --rig "
        "0.594,0.030,0.0343, or run it on a terminal to be asked");
  }
  const bool columns_named = !o.columns.time.empty() || !o.columns.gyro[0].empty();
  if (columns_named && o.log.empty()) {
    throw UserError("init: --time and --gyro name columns of a log: give the log with --log");
  }
  if (!o.log.empty()) {
    const InspectReport report = InspectLog(o.log, nullptr, o.columns);
    if (!report.is_log()) {
      throw UserError("init: --log " +
                      EchoedName(report.error.empty() ? o.log : report.error, 4000));
    }
    // A log whose series could not be read (a .bin without messages, a header with the same
    // name twice) would give a config `bifilar fit` cannot use with it: refused, with the reason.
    if (report.samples < 2 && !report.error.empty()) {
      throw UserError("init: --log " + EchoedName(o.log) +
                      ": no config written, the log cannot be "
                      "read with the format " +
                      (report.format_from_config ? "given" : "guessed") + ": " +
                      EchoedName(report.error, 4000));
    }
    if (!report.format_problem.empty()) {
      throw UserError("init: --log " + EchoedName(o.log) +
                      ": no config written: " + EchoedName(report.format_problem, 4000));
    }
    options.format = report.format;
    options.ulog = report.kind == "ulog";
    options.format_source = o.log;
    if (o.on_guess) {
      for (const std::string& g : report.guesses) o.on_guess(EchoedName(g, 4000));
      for (const std::string& w : report.warnings) {
        if (w.rfind("no unit makes", 0) == 0) o.on_guess("warning: " + EchoedName(w, 4000));
      }
    }
  }
  CampaignConfig loaded;
  const std::string text = CheckedStartingConfigText(options, o.path, &loaded);
  if (!o.log.empty()) {
    // The config read back reads the log as `bifilar fit` will (the same reader, the same
    // names): a config init writes is never one fit rejects with this log.
    ImuData data;
    std::string why;
    if (!TryReadImuLog(o.log, loaded.imu.format, loaded.LogOptions(), &data, &why)) {
      throw UserError("init: " + o.path + ": not written: `bifilar fit` would not read " +
                      EchoedName(o.log) + " with it: " + EchoedName(why, 4000));
    }
  }
  WriteFileAtomically(o.path, text);
  return o.path;
}

}  // namespace bifilar
