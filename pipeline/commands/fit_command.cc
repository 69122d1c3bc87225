// The use case of `bifilar fit` (pipeline/commands/fit_command.h).
#include "pipeline/commands/fit_command.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <filesystem>
#include <map>
#include <set>
#include <system_error>

#include "base/hash.h"
#include "base/interrupt.h"
#include "base/json_number.h"
#include "base/plot_folder.h"
#include "base/user_error.h"
#include "fit/window.h"
#include "pipeline/campaign/calibration.h"
#include "pipeline/campaign/campaign_inputs.h"
#include "pipeline/campaign/run_discovery.h"
#include "pipeline/records/results_json.h"
#include "pipeline/trace/trace_process.h"

namespace bifilar {
namespace {

// A log's name without its folder and extensions ("BaseModel_Ixx_Log-1.csv" ->
// "BaseModel_Ixx_Log-1", "trial_1.csv.gz" -> "trial_1").
std::string LogStem(const std::string& log) {
  std::filesystem::path name = std::filesystem::path(log).filename();
  if (name.extension() == ".gz") name = name.stem();
  const std::string ext = name.extension().string();
  if (ext == ".csv" || ext == ".ulg" || ext == ".txt" || ext == ".tsv") name = name.stem();
  std::string stem = name.string();
  for (char& c : stem) {
    if (c == ' ' || c == ':') c = '_';
  }
  while (!stem.empty() && stem[0] == '.') stem.erase(stem.begin());
  return stem.empty() ? "trace" : stem;
}

// The figure name of each log: DIR/<log>.svg, as the docs say. Names are unique among the
// logs of the run, and one log (the same canonical path, however it is written) has one name:
// logs of the same name in different folders ("pitch_10/trial_1.csv", "pitch_20/trial_1.csv")
// get their folder in front ("pitch_10_trial_1"); a name still shared by different logs (with
// its "_sweep" figure too: "x/t.csv", "x_t.csv", or "a.csv" and "a_sweep.csv") gets 8 hex
// digits of the hash of the log's canonical path ("x_t-1f0c9a3e"), and, should even those
// meet, the log's position in the command line.
}  // namespace

std::vector<std::string> FigureStems(const std::vector<std::string>& logs) {
  const size_t n = logs.size();
  std::vector<std::string> key(n), stems(n);
  std::map<std::string, std::set<std::string>> logs_of_stem;  // stem -> canonical paths
  for (size_t i = 0; i < n; ++i) {
    key[i] = CanonicalLogPath(logs[i]);
    stems[i] = LogStem(logs[i]);
    logs_of_stem[stems[i]].insert(key[i]);
  }
  for (size_t i = 0; i < n; ++i) {
    if (logs_of_stem[LogStem(logs[i])].size() < 2) continue;
    const std::string folder =
        std::filesystem::path(logs[i]).lexically_normal().parent_path().filename().string();
    if (!folder.empty() && folder != "." && folder != "..") stems[i] = folder + "_" + stems[i];
  }
  // Each file name a log's figures take (<stem> and <stem>_sweep), and the logs taking it.
  const auto clashes = [&]() {
    std::map<std::string, std::set<std::string>> users;
    for (size_t i = 0; i < n; ++i) {
      users[stems[i]].insert(key[i]);
      users[stems[i] + "_sweep"].insert(key[i]);
    }
    std::vector<bool> clash(n, false);
    for (size_t i = 0; i < n; ++i) {
      clash[i] = users[stems[i]].size() > 1 || users[stems[i] + "_sweep"].size() > 1;
    }
    return clash;
  };
  std::vector<bool> clash = clashes();
  for (size_t i = 0; i < n; ++i) {
    if (clash[i]) stems[i] += "-" + HashToHex(Fnv1a64(key[i])).substr(0, 8);
  }
  clash = clashes();
  std::map<std::string, size_t> first_of_key;
  for (size_t i = 0; i < n; ++i) {
    const size_t first = first_of_key.emplace(key[i], i).first->second;  // one name per log
    if (clash[i]) stems[i] += "-" + std::to_string(first + 1);
  }
  return stems;
}

namespace {

nlohmann::json SetupSplitToJson(const SetupSplit& s, const std::string& text) {
  nlohmann::json j = {{"tested", s.tested},
                      {"two_setups", s.two_setups},
                      {"note", s.note},
                      {"q", JsonNumber(s.q)},
                      {"q_z", JsonNumber(s.q_z)}};
  if (!s.tested) return j;
  j["clusters"] = {s.clusters[0], s.clusters[1]};
  j["mean_kg_m2"] = {JsonNumber(s.mean_kg_m2[0]), JsonNumber(s.mean_kg_m2[1])};
  j["mean_std_kg_m2"] = {JsonNumber(s.mean_std_kg_m2[0]), JsonNumber(s.mean_std_kg_m2[1])};
  j["amplitude_rms_deg"] = {JsonNumber(s.amplitude_rms_deg[0]), JsonNumber(s.amplitude_rms_deg[1])};
  j["gap_percent"] = JsonNumber(s.gap_percent);
  j["gap_z"] = JsonNumber(s.gap_z);
  j["separation"] = JsonNumber(s.separation);
  j["amplitudes_interleave"] = s.amplitudes_interleave;
  j["own_trend_logs"] = s.n_own;
  j["own_coeff_per_deg2"] = JsonNumber(s.own_coeff_per_deg2);
  j["own_coeff_std_per_deg2"] = JsonNumber(s.own_coeff_std_per_deg2);
  j["amplitude_allows_percent"] = JsonNumber(s.amplitude_allows_percent);
  j["gap_z_beyond_amplitude"] = JsonNumber(s.gap_z_beyond_amplitude);
  j["axis_angle_deg"] = JsonNumber(s.axis_angle_deg);
  j["axis_spread_deg"] = JsonNumber(s.axis_spread_deg);
  j["axes_differ"] = s.axes_differ;
  j["text"] = text;
  return j;
}

nlohmann::json RepeatGroupsToJson(const std::vector<RepeatGroup>& groups) {
  nlohmann::json out = nlohmann::json::array();
  for (const RepeatGroup& g : groups) {
    out.push_back(
        {{"name", g.name},
         {"members", g.members},
         {"n_used", g.n_used},
         {"mean_kg_m2", JsonNumber(g.mean_kg_m2)},
         {"mean_std_kg_m2", JsonNumber(g.mean_std_kg_m2)},
         {"plain_mean_kg_m2", JsonNumber(g.plain_mean_kg_m2)},
         {"q", JsonNumber(g.q)},
         {"tau_kg_m2", JsonNumber(g.tau_kg_m2)},
         {"max_abs_z", JsonNumber(g.max_abs_z)},
         {"amplitude_trend_percent_per_10deg", JsonNumber(g.amplitude_trend_percent_per_10deg)},
         {"amplitude_trend_z", JsonNumber(g.amplitude_trend_z)},
         {"spread_before_percent", JsonNumber(g.spread_before_percent)},
         {"spread_after_percent", JsonNumber(g.spread_after_percent)},
         {"q_before", JsonNumber(g.q_before)},
         {"max_abs_z_before", JsonNumber(g.max_abs_z_before)},
         {"correction_std_kg_m2", JsonNumber(g.correction_std_kg_m2)},
         {"common_mode_std_kg_m2", JsonNumber(g.common_mode_std_kg_m2)},
         {"total_std_kg_m2", JsonNumber(g.total_std_kg_m2)},
         {"note", g.note},
         {"max_abs_z_own", JsonNumber(g.max_abs_z_own)},
         {"alone", g.alone},
         {"trend_contradicts_own_trends", g.trend_contradicts_own},
         {"setups", SetupSplitToJson(g.setups, g.setups_text)}});
  }
  return out;
}

nlohmann::json AmplitudeCorrectionToJson(const RepeatsAmplitudeCorrection& c) {
  return {
      {"applied", c.applied},
      {"model", "I_0 (1 + c A^2)"},
      {"to_amplitude_deg", 0.0},
      {"coeff_per_deg2", JsonNumber(c.coeff_per_deg2)},
      {"coeff_std_per_deg2", JsonNumber(c.coeff_std_per_deg2)},
      {"z", JsonNumber(c.z)},
      {"birge", JsonNumber(c.birge)},
      {"scatter_percent", JsonNumber(c.scatter_percent)},
      {"dof", c.dof},
      {"n_logs", c.n_logs},
      {"n_groups", c.n_groups},
      {"n_corrected", c.n_corrected},
      {"n_low_band_kept", c.n_low_band_kept},
      {"amplitude_range_deg", {JsonNumber(c.amplitude_min_deg), JsonNumber(c.amplitude_max_deg)}},
      {"note", c.note},
      {"own_coeff_per_deg2", JsonNumber(c.own_coeff_per_deg2)},
      {"own_coeff_std_per_deg2", JsonNumber(c.own_coeff_std_per_deg2)},
      {"own_trend_logs", c.n_own},
      {"own_z", JsonNumber(c.own_z)},
      {"contradicts_own_trends", c.contradicts_own},
      {"groups_two_setups", c.n_groups_two_setups}};
}

// The config with the command line's overrides; checks them and fit.windows before any fit.
CampaignConfig LoadFitConfig(const FitCommandOptions& o) {
  ConfigLoadOptions load;
  load.require_runs = false;
  CampaignConfig config = LoadCampaignConfig(o.config_path, load);
  if (!o.model.empty()) ParsePendulumModel(o.model, &config.fit.model);
  if (!o.integrator.empty()) ParseIntegratorMethod(o.integrator, &config.fit.integrator);
  if (std::isfinite(o.max_amplitude_deg)) {
    config.fit.max_amplitude_deg = o.max_amplitude_deg;
    if (config.fit.min_amplitude_deg && *config.fit.min_amplitude_deg >= o.max_amplitude_deg) {
      throw UserError("--max-amplitude must exceed fit.min_amplitude_deg of the config");
    }
  }
  // fit.windows as `process` reads it: an entry naming no log is an error before any fit, and
  // each log finds its entry however its path is written (ConfigWindowFor).
  CheckWindowEntriesExist(config);
  return config;
}

// --window and --plot: the options every log's processing starts from.
TraceProcessOptions BaseTraceOptions(const FitCommandOptions& o) {
  TraceProcessOptions options;
  if (!o.window.empty()) {
    double t0 = 0, t1 = 0;
    std::string why;
    if (!ParseWindowSpec(o.window, &t0, &t1, &why)) throw UserError(why);
    options.window_s = std::array<double, 2>{t0, t1};
  }
  if (!o.plot_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(o.plot_dir, ec);
    if (!std::filesystem::is_directory(o.plot_dir)) {
      throw UserError("--plot " + o.plot_dir + ": cannot create folder");
    }
  }
  return options;
}

// --plot DIR: the figures' names, claimed before any fit: a file there that bifilar did not write
// is refused without --force, a link always (base/plot_folder.h).
void ClaimFitFigures(const FitCommandOptions& o, const std::vector<std::string>& logs) {
  std::vector<std::string> names;
  for (const std::string& stem : FigureStems(logs)) {
    for (const char* suffix : {".svg", ".png", "_sweep.svg", "_sweep.png"}) {
      names.push_back(stem + suffix);
    }
  }
  PlotFolder(o.plot_dir, "fit --plot", o.force).Claim(names);
}

// rig.calibration: the reference swings fix the geometry first (pipeline/campaign/calibration.h).
void CalibrateIfConfigured(const FitCommandOptions& o, FitCommandResult* result) {
  if (!result->config.calibration.enabled) return;
  result->calibration = CalibrateRigFromLogs(result->config);
  result->config.geometry_calibration = result->calibration->Applied();
  if (o.on_calibration) o.on_calibration(*result->calibration);
}

// Fits each kept log in order. Ctrl-C, between logs or inside a fit (which then stops between
// solver iterations, and its log counts as not fitted): what was fitted, and `interrupted`.
void FitLogs(const FitCommandOptions& o, const TraceProcessOptions& options,
             FitCommandResult* result) {
  const std::vector<std::string>& logs = result->distinct.kept;
  std::vector<TraceRecord>& records = result->records;
  if (o.handle_interrupt) InstallInterruptHandler();
  const std::vector<std::string> stems = FigureStems(logs);
  bool mid_fit = false;  // the last fit was stopped by Ctrl-C: its log is not fitted
  for (size_t k = 0; k <= logs.size(); ++k) {
    if (ProcessInterruptFlag().load()) {
      if (mid_fit) records.pop_back();
      result->interrupted = true;
      return;
    }
    if (k == logs.size()) break;
    const std::string& log = logs[k];
    TraceProcessOptions trace = options;
    trace.display_name = log;
    trace.interrupt = &ProcessInterruptFlag();
    if (!o.plot_dir.empty()) {
      const std::string base = (std::filesystem::path(o.plot_dir) / stems[k]).string();
      trace.figure_paths = {base + ".svg", base + ".png"};
      trace.sweep_figure_paths = {base + "_sweep.svg", base + "_sweep.png"};
    }
    records.push_back(ProcessTrace(result->config, log, trace));
    if (ProcessInterruptFlag().load()) {  // handled at the loop's top
      mid_fit = true;
      continue;
    }
    if (!records.back().ok()) ++result->n_failed;
    if (o.on_record) o.on_record(records.back(), result->config);
  }
}

// What `fit --json` prints.
nlohmann::json FitResultJson(const FitCommandOptions& o, const FitCommandResult& r) {
  nlohmann::json traces = nlohmann::json::array();
  for (const TraceRecord& record : r.records) traces.push_back(TraceRecordToJson(record, false));
  nlohmann::json out = traces;
  if (o.repeats || r.calibration) out = {{"traces", traces}};
  if (o.repeats) {
    out["repeats"] = RepeatGroupsToJson(r.groups);
    out["amplitude_correction"] = AmplitudeCorrectionToJson(r.correction);
    nlohmann::json dropped = nlohmann::json::array();
    for (size_t i = 0; i < r.distinct.dropped.size(); ++i) {
      dropped.push_back({{"file", r.distinct.dropped[i].first},
                         {"same_as", r.distinct.dropped[i].second},
                         {"warning", r.distinct.warnings[i]}});
    }
    out["identical_logs_dropped"] = dropped;
  }
  if (r.calibration) out["calibration"] = CalibrationToJson(*r.calibration);
  return out;
}

// --group-by and --runs-table (with --repeats, not both): how the logs are grouped.
RepeatGroupingOptions GroupingOptions(const FitCommandOptions& o,
                                      const std::vector<std::string>& logs) {
  if (!o.repeats && (!o.group_by.empty() || !o.runs_table.empty())) {
    throw UserError(std::string(o.group_by.empty() ? "--runs-table" : "--group-by") +
                    " groups repeats: it needs --repeats");
  }
  if (!o.group_by.empty() && !o.runs_table.empty()) {
    throw UserError("--group-by and --runs-table both say how to group the repeats: give one");
  }
  RepeatGroupingOptions grouping;
  grouping.group_by = o.group_by;
  if (!o.runs_table.empty()) {
    const RunsTableGroups table = ReadRunsTableGroups(o.runs_table);
    grouping.named = GroupsOfLogs(logs, table);
    grouping.named_source = table.source;
    grouping.named_rows = table.paths;
  }
  return grouping;
}

}  // namespace

int FitCommandResult::ExitCode() const {
  if (interrupted) return kInterruptedExitCode;
  return n_failed > 0 ? 1 : 0;
}

FitCommandResult RunFit(const FitCommandOptions& options) {
  FitCommandResult result;
  result.config = LoadFitConfig(options);
  if (!options.repeats) GroupingOptions(options, {});  // --group-by without --repeats: refused
  const TraceProcessOptions trace_options = BaseTraceOptions(options);
  CalibrateIfConfigured(options, &result);
  // --repeats: identical data is one repeat; the copies are named and dropped before fitting.
  if (options.repeats) {
    result.distinct =
        DropIdenticalLogs(options.logs, result.config.imu.format, result.config.LogOptions());
  } else {
    result.distinct.kept = options.logs;
  }
  if (options.on_identical_log) {
    for (const std::string& w : result.distinct.warnings) options.on_identical_log(w);
  }
  if (options.repeats) {  // the groups before any fit: a wrong grouping is seen at once
    result.grouping = GroupingOptions(options, result.distinct.kept);
    result.groups = GroupRepeats(result.distinct.kept, result.grouping);
    if (options.on_groups) {
      options.on_groups(RepeatGroupsText(result.groups, result.distinct.kept, result.grouping));
    }
  }
  if (!options.plot_dir.empty()) ClaimFitFigures(options, result.distinct.kept);
  FitLogs(options, trace_options, &result);
  if (result.interrupted) {
    result.groups.clear();
    return result;
  }
  if (options.repeats) {
    result.correction = CombineRepeats(&result.groups, &result.records);
  }
  result.json = FitResultJson(options, result);
  return result;
}

}  // namespace bifilar
