// `bifilar fit CONFIG LOG... [--json] [--model M] [--window T0:T1] [--max-amplitude DEG]
// [--plot DIR]`: fits single logs with the campaign's trace processing
// (pipeline/trace/trace_process.h). The config needs only the rig geometry, the masses and the IMU
// format (configs/README.md).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>
#include <set>

#include <nlohmann/json.hpp>

#include "base/interrupt.h"
#include "fit/window.h"
#include "base/hash.h"
#include "pipeline/campaign/calibration.h"
#include "pipeline/campaign/campaign_inputs.h"
#include "pipeline/cli/cli_commands.h"
#include "pipeline/config/config.h"
#include "pipeline/records/results_json.h"
#include "pipeline/records/total_uncertainty.h"
#include "pipeline/trace/repeats.h"
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

// The record's console line, inertias (I, K_D, C and the small-angle I) in the config's units.
std::string HumanLine(const TraceRecord& r, DisplayUnits units) {
  char buffer[1024];
  // Messages name the file already; say it once at the start of the line.
  const std::string prefix = r.file + ": ";
  std::string message = SiTextInDisplayUnits(
      r.message.rfind(prefix, 0) == 0 ? r.message.substr(prefix.size()) : r.message, units);
  // The assumed +-1 mm on L and D is said once for the run (AssumedInputsSummary), not per log.
  if (IsAssumedInputsWarning(message)) message.clear();
  // No fit to show (an error, or rejected before fitting): status and reason only, never NaN.
  if (r.status == TraceStatus::kError || !std::isfinite(r.inertia_total_kg_m2)) {
    return prefix + ToString(r.status) + ": " + message;
  }
  const double scale = InertiaToDisplay(1.0, units);
  const char* unit = InertiaUnitName(units);
  std::snprintf(buffer, sizeof(buffer),
                "%s: %s  I = %s  K_D %.3g  C %.3g  "
                "window [%.2f, %.2f] s  amplitude %.1f -> %.1f deg  rms/noise %.2f  %d it  %.0f ms",
                r.file.c_str(), ToString(r.status),
                StatAndTotal(scale * r.inertia_total_kg_m2, scale * r.inertia_total_std_kg_m2,
                             scale * r.inertia_total_std_total_kg_m2, unit)
                    .c_str(),
                scale * r.drag_coeff_kg_m2,
                scale * r.viscous_coeff_kg_m2_per_s, r.window_s[0], r.window_s[1], r.amplitude_deg[0],
                r.amplitude_deg[1], r.residual_rms_rad_per_s / r.noise_rms_rad_per_s, r.iterations,
                1e3 * r.fit_seconds);
  std::string line = buffer;
  if (r.pitch_measured_deg) {
    std::snprintf(buffer, sizeof(buffer), "  pitch %.2f deg", *r.pitch_measured_deg);
    line += buffer;
  }
  if (!message.empty()) line += "  (" + message + ")";
  // The measured period and the hand calculation beside the nonlinear fit.
  if (std::isfinite(r.period_s)) {
    std::snprintf(buffer, sizeof(buffer),
                  "\n    period %.4f s (%.4f Hz), small-angle I = m g D^2 T^2 / (16 pi^2 L) = %.5g %s",
                  r.period_s, r.frequency_hz, scale * r.small_angle_inertia_total_kg_m2, unit);
    line += buffer;
  }
  // I against amplitude (the ideal model is flat), and every warning on its own line.
  if (!r.sweep.bands.empty()) {
    AmplitudeSweep shown = r.sweep;  // the bands' I in the display units
    for (AmplitudeSweepBand& b : shown.bands) {
      b.inertia_kg_m2 *= scale;
      b.inertia_std_kg_m2 *= scale;
    }
    line += "\n    I(A): " + SweepSummary(shown);
    if (r.sweep.evaluated) {
      std::snprintf(buffer, sizeof(buffer), "  trend %+.3g %% per 10 deg (as A^%g, z = %.1f)%s",
                    r.sweep.trend_percent_per_10deg, r.sweep.trend_exponent, r.sweep.trend_z,
                    r.sweep.trend_detected ? ": the rig departs from the model" : "");
      line += buffer;
    }
  } else if (!r.sweep.note.empty()) {
    line += "\n    I(A): no sweep (" + r.sweep.note + ")";
  }
  if (std::isfinite(r.amplitude_correction_kg_m2)) {
    const double before = r.inertia_total_kg_m2 + r.amplitude_correction_kg_m2;
    std::snprintf(buffer, sizeof(buffer),
                  "\n    amplitude correction (--repeats): %#.5g -> %#.5g kg m^2 (%+.2f %% +- %.2f "
                  "%%) from %.1f deg to zero amplitude",
                  before, r.inertia_total_kg_m2, -100.0 * r.amplitude_correction_kg_m2 / before,
                  100.0 * r.amplitude_correction_std_kg_m2 / before,
                  r.amplitude_correction_from_deg);
    line += buffer;
  }
  for (const std::string& flag : r.flags) {
    if (flag.rfind("block_means_of_", 0) == 0) {
      line += "\n    note: a dense log; the fit used means of " +
              flag.substr(std::string("block_means_of_").size(), flag.find("_samples") - 15) +
              " consecutive samples (docs/method.md, section 6)";
    }
  }
  for (const std::string& w : r.warnings) {
    const std::string shown = SiTextInDisplayUnits(w, units);
    if (message.find(shown) == std::string::npos && !IsAssumedInputsWarning(w))
      line += "\n    warning: " + shown;
  }
  // --plot: which files are this log's figures (a name may carry a hash: FigureStems).
  if (!r.figures.empty()) {
    line += "\n    figures:";
    for (const std::string& f : r.figures) line += " " + f;
  }
  return line;
}

nlohmann::json RepeatGroupsToJson(const std::vector<RepeatGroup>& groups) {
  auto number = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  nlohmann::json out = nlohmann::json::array();
  for (const RepeatGroup& g : groups) {
    out.push_back({{"name", g.name},
                   {"members", g.members},
                   {"n_used", g.n_used},
                   {"mean_kg_m2", number(g.mean_kg_m2)},
                   {"mean_std_kg_m2", number(g.mean_std_kg_m2)},
                   {"plain_mean_kg_m2", number(g.plain_mean_kg_m2)},
                   {"q", number(g.q)},
                   {"tau_kg_m2", number(g.tau_kg_m2)},
                   {"max_abs_z", number(g.max_abs_z)},
                   {"amplitude_trend_percent_per_10deg", number(g.amplitude_trend_percent_per_10deg)},
                   {"amplitude_trend_z", number(g.amplitude_trend_z)},
                   {"spread_before_percent", number(g.spread_before_percent)},
                   {"spread_after_percent", number(g.spread_after_percent)},
                   {"q_before", number(g.q_before)},
                   {"max_abs_z_before", number(g.max_abs_z_before)},
                   {"correction_std_kg_m2", number(g.correction_std_kg_m2)},
                   {"common_mode_std_kg_m2", number(g.common_mode_std_kg_m2)},
                   {"total_std_kg_m2", number(g.total_std_kg_m2)},
                   {"note", g.note}});
  }
  return out;
}

nlohmann::json AmplitudeCorrectionToJson(const RepeatsAmplitudeCorrection& c) {
  auto number = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  return {{"applied", c.applied},
          {"model", "I_0 (1 + c A^2)"},
          {"to_amplitude_deg", 0.0},
          {"coeff_per_deg2", number(c.coeff_per_deg2)},
          {"coeff_std_per_deg2", number(c.coeff_std_per_deg2)},
          {"z", number(c.z)},
          {"birge", number(c.birge)},
          {"scatter_percent", number(c.scatter_percent)},
          {"dof", c.dof},
          {"n_logs", c.n_logs},
          {"n_groups", c.n_groups},
          {"n_corrected", c.n_corrected},
          {"n_low_band_kept", c.n_low_band_kept},
          {"amplitude_range_deg", {number(c.amplitude_min_deg), number(c.amplitude_max_deg)}},
          {"note", c.note}};
}

}  // namespace

void RegisterFitCommand(CLI::App& app, int* exit_code) {
  struct Args {
    std::string config;
    std::vector<std::string> logs;
    bool json = false;
    bool repeats = false;
    std::string model, integrator, window, plot_dir;
    double max_amplitude_deg = NAN;
  };
  auto args = std::make_shared<Args>();
  auto* sub = app.add_subcommand(
      "fit", "Fit single IMU logs: moment of inertia of everything suspended, with uncertainty");
  sub->add_option("config", args->config,
                  "config (YAML): rig geometry, masses, IMU format (configs/README.md)")
      ->required();
  sub->add_option("logs", args->logs, "IMU logs: CSV (optionally .gz) or PX4 ULog (.ulg)")->required();
  sub->add_flag("--json", args->json, "print a JSON array of trace records instead of lines");
  sub->add_option("--model", args->model, "full (default), jardin or linear")
      ->check(CLI::IsMember(PendulumModelNames()));
  sub->add_option("--integrator", args->integrator,
                  "ODE solver of the fit: rk853 (default) or cvodes; overrides fit.integrator")
      ->check(CLI::IsMember(IntegratorMethodNames()));
  sub->add_option("--window", args->window, "fit only T0:T1 (s, the log's own time)");
  sub->add_option("--max-amplitude", args->max_amplitude_deg,
                  "upper end of the amplitude band (deg)")
      ->check(FiniteNumber())
      ->check(CLI::Range(kMinMaxAmplitudeDeg, kMaxMaxAmplitudeDeg));  // as fit.max_amplitude_deg
  sub->add_option("--plot", args->plot_dir,
                  "write fit figures DIR/<log>.svg and .png, and the amplitude sweep (I against "
                  "amplitude) DIR/<log>_sweep.svg and .png when the trace has one");
  sub->add_flag("--repeats", args->repeats,
                "combine repeats: logs whose paths differ only in the last number of the file "
                "name are swings of one set-up; their scatter beyond their stds is added to each");
  sub->callback([args, exit_code] {
    ConfigLoadOptions load;
    load.require_runs = false;
    CampaignConfig config = LoadCampaignConfig(args->config, load);
    if (!args->model.empty()) ParsePendulumModel(args->model, &config.fit.model);
    if (!args->integrator.empty()) ParseIntegratorMethod(args->integrator, &config.fit.integrator);
    if (std::isfinite(args->max_amplitude_deg)) {
      config.fit.max_amplitude_deg = args->max_amplitude_deg;
      if (config.fit.min_amplitude_deg && *config.fit.min_amplitude_deg >= args->max_amplitude_deg) {
        throw UserError("--max-amplitude must exceed fit.min_amplitude_deg of the config");
      }
    }
    // fit.windows as `process` reads it: an entry naming no log is an error before any fit, and
    // each log finds its entry however its path is written (ConfigWindowFor).
    CheckWindowEntriesExist(config);
    TraceProcessOptions options;
    if (!args->window.empty()) {
      double t0 = 0, t1 = 0;
      std::string why;
      if (!ParseWindowSpec(args->window, &t0, &t1, &why)) throw UserError(why);
      options.window_s = std::array<double, 2>{t0, t1};
    }
    if (!args->plot_dir.empty()) {
      std::error_code ec;
      std::filesystem::create_directories(args->plot_dir, ec);
      if (!std::filesystem::is_directory(args->plot_dir)) {
        throw UserError("--plot " + args->plot_dir + ": cannot create folder");
      }
    }
    // rig.calibration: the reference swings fix the geometry first
    // (pipeline/campaign/calibration.h).
    std::optional<RigCalibrationResult> calibration;
    if (config.calibration.enabled) {
      calibration = CalibrateRigFromLogs(config);
      config.geometry_calibration = calibration->Applied();
      if (!args->json) {
        std::cout << calibration->BriefReport() << std::endl;
        for (const std::string& w : calibration->warnings) std::cout << "warning: " << w << std::endl;
      }
    }
    // --repeats: identical data is one repeat; the copies are named and dropped before fitting.
    DistinctLogs distinct;
    if (args->repeats) {
      distinct = DropIdenticalLogs(args->logs);
    } else {
      distinct.kept = args->logs;
    }
    const std::vector<std::string>& logs = distinct.kept;
    if (!args->json) {
      for (const std::string& w : distinct.warnings) std::cout << "warning: " << w << std::endl;
    }
    std::vector<TraceRecord> records;
    int failed = 0;
    InstallInterruptHandler();
    const std::vector<std::string> stems = FigureStems(logs);
    bool mid_fit = false;  // the last fit was stopped by Ctrl-C: its log is not fitted
    for (size_t k = 0; k <= logs.size(); ++k) {
      // Ctrl-C, between logs or inside a fit (which then stops between solver iterations, and
      // its log counts as not fitted): what was fitted, then exit 130.
      if (ProcessInterruptFlag().load()) {
        if (mid_fit) records.pop_back();
        if (args->json || args->repeats) {
          for (const TraceRecord& r : records) std::cout << HumanLine(r, config.units) << std::endl;
        }
        std::cerr << "bifilar: interrupted: " << records.size() << " of " << logs.size()
                  << " logs fitted (above)\n";
        *exit_code = kInterruptedExitCode;
        return;
      }
      if (k == logs.size()) break;
      const std::string& log = logs[k];
      TraceProcessOptions trace = options;
      trace.display_name = log;
      trace.interrupt = &ProcessInterruptFlag();
      if (!args->plot_dir.empty()) {
        const std::string base = (std::filesystem::path(args->plot_dir) / stems[k]).string();
        trace.figure_paths = {base + ".svg", base + ".png"};
        trace.sweep_figure_paths = {base + "_sweep.svg", base + "_sweep.png"};
      }
      records.push_back(ProcessTrace(config, log, trace));
      if (ProcessInterruptFlag().load()) {  // not printed: handled at the loop's top
        mid_fit = true;
        continue;
      }
      if (!records.back().ok()) ++failed;
      // Without --repeats each line is printed as soon as its log is fitted.
      if (!args->json && !args->repeats) std::cout << HumanLine(records.back(), config.units) << std::endl;
    }
    std::vector<RepeatGroup> groups;
    RepeatsAmplitudeCorrection correction;
    if (args->repeats) {
      groups = GroupRepeats(logs);
      correction = CombineRepeats(&groups, &records);
    }
    if (args->json) {
      nlohmann::json traces = nlohmann::json::array();
      for (const TraceRecord& r : records) traces.push_back(TraceRecordToJson(r, false));
      nlohmann::json out = traces;
      if (args->repeats || calibration) out = {{"traces", traces}};
      if (args->repeats) {
        out["repeats"] = RepeatGroupsToJson(groups);
        out["amplitude_correction"] = AmplitudeCorrectionToJson(correction);
        nlohmann::json dropped = nlohmann::json::array();
        for (size_t i = 0; i < distinct.dropped.size(); ++i) {
          dropped.push_back({{"file", distinct.dropped[i].first},
                             {"same_as", distinct.dropped[i].second},
                             {"warning", distinct.warnings[i]}});
        }
        out["identical_logs_dropped"] = dropped;
      }
      if (calibration) out["calibration"] = CalibrationToJson(*calibration);
      // Invalid UTF-8 (a log's bytes in a message) is replaced, never a json exception.
      std::cout << out.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << std::endl;
    } else if (args->repeats) {
      // The between-repeat (Q) warning is the same on every member: said once, under its group.
      std::vector<std::string> scatter_warnings;
      for (const TraceRecord& r : records) {
        TraceRecord shown = r;
        shown.warnings.clear();
        for (const std::string& w : r.warnings) {
          if (IsRepeatScatterWarning(w)) {
            if (std::find(scatter_warnings.begin(), scatter_warnings.end(), w) ==
                scatter_warnings.end()) {
              scatter_warnings.push_back(w);
            }
          } else {
            shown.warnings.push_back(w);
          }
        }
        std::cout << HumanLine(shown, config.units) << std::endl;
      }
      std::cout << AmplitudeCorrectionLine(correction) << std::endl;
      for (const RepeatGroup& g : groups) {
        std::cout << RepeatGroupLine(g) << std::endl;
        const std::string of = " repeats of " + g.name + " scatter beyond";
        for (const std::string& w : scatter_warnings) {
          if (w.find(of) == std::string::npos) continue;
          std::string text = w;
          const std::string per_log = "this log's std";
          const size_t at = text.find(per_log);
          if (at != std::string::npos) text.replace(at, per_log.size(), "each log's std");
          std::cout << "    warning: " << text << std::endl;
        }
      }
    }
    // Once for the run: what the assumed +-1 mm on L and D adds (--json records carry it).
    const std::string assumed = AssumedInputsSummary(records);
    if (!assumed.empty() && !args->json) std::cout << assumed << std::endl;
    *exit_code = failed > 0 ? 1 : 0;
  });
}

}  // namespace bifilar
