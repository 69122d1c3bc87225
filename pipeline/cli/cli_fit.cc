// `bifilar fit CONFIG LOG... [--json] [--model M] [--window T0:T1] [--max-amplitude DEG]
// [--plot DIR]`: fits single logs with the campaign's trace processing
// (pipeline/trace/trace_process.h). The config needs only the rig geometry, the masses and the IMU
// format (configs/README.md).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pendulum/integrator.h"
#include "pendulum/model.h"
#include "pipeline/cli/cli_commands.h"
#include "pipeline/commands/fit_command.h"
#include "pipeline/config/config.h"
#include "pipeline/records/results_json.h"
#include "pipeline/records/total_uncertainty.h"
#include "pipeline/trace/repeats.h"
#include "pipeline/trace/trace_process.h"

namespace bifilar {
namespace {

// Console output of one record (issue 25 item 5): one result line of at most ~160 characters,
// indented detail lines (the fit's settings and solver, the period and the hand calculation,
// I(A)), then one line per warning, the most important first (the record's order), each shown by
// its one line (LineOfWarning); *folded is set when a line shortens a warning.

// "FILE: ok  I = ... kg m^2  amplitude A0 -> A1 deg  rms/noise R": status, the result, and how
// well the model follows the data. No fit (an error, or rejected before fitting): status only.
std::string ResultLine(const TraceRecord& r, DisplayUnits units) {
  if (r.status == TraceStatus::kError || !std::isfinite(r.inertia_total_kg_m2)) {
    const std::string prefix = r.file + ": ";
    const std::string message = SiTextInDisplayUnits(
        r.message.rfind(prefix, 0) == 0 ? r.message.substr(prefix.size()) : r.message, units);
    return prefix + ToString(r.status) + (message.empty() ? "" : ": " + message);
  }
  const double scale = InertiaToDisplay(1.0, units);
  char buffer[512];
  std::snprintf(
      buffer, sizeof(buffer), "%s: %s  I = %s  amplitude %.1f -> %.1f deg  rms/noise %.2f",
      r.file.c_str(), ToString(r.status),
      StatAndTotal(scale * r.inertia_total_kg_m2, scale * r.inertia_total_std_kg_m2,
                   scale * r.inertia_total_std_total_kg_m2, InertiaUnitName(units))
          .c_str(),
      r.amplitude_deg[0], r.amplitude_deg[1], r.residual_rms_rad_per_s / r.noise_rms_rad_per_s);
  return buffer;
}

// The indented lines under the result: the fit (window, damping, solver), the measured period with
// the small-angle hand calculation, I against amplitude, the amplitude correction of --repeats,
// block means.
std::string DetailLines(const TraceRecord& r, DisplayUnits units) {
  const double scale = InertiaToDisplay(1.0, units);
  const char* unit = InertiaUnitName(units);
  char buffer[512];
  std::string lines;
  if (std::isfinite(r.inertia_total_kg_m2)) {
    std::snprintf(buffer, sizeof(buffer),
                  "\n    fit: window [%.2f, %.2f] s  K_D %.3g  C %.3g  %d it  %.0f ms",
                  r.window_s[0], r.window_s[1], scale * r.drag_coeff_kg_m2,
                  scale * r.viscous_coeff_kg_m2_per_s, r.iterations, 1e3 * r.fit_seconds);
    lines += buffer;
    if (r.pitch_measured_deg) {
      std::snprintf(buffer, sizeof(buffer), "  pitch %.2f deg", *r.pitch_measured_deg);
      lines += buffer;
    }
  }
  // The measured period and the hand calculation beside the nonlinear fit: over the whole free
  // oscillation, with no amplitude or damping correction.
  if (std::isfinite(r.period_s)) {
    std::snprintf(
        buffer, sizeof(buffer),
        "\n    period %.4f s (%.4f Hz), small-angle I = m g D^2 T^2 / (16 pi^2 L) = %.5g %s "
        "(whole free swing)",
        r.period_s, r.frequency_hz, scale * r.small_angle_inertia_total_kg_m2, unit);
    lines += buffer;
  }
  // I against amplitude (the ideal model is flat).
  if (!r.sweep.bands.empty()) {
    AmplitudeSweep shown = r.sweep;  // the bands' I in the display units
    for (AmplitudeSweepBand& b : shown.bands) {
      b.inertia_kg_m2 *= scale;
      b.inertia_std_kg_m2 *= scale;
    }
    lines += "\n    I(A): " + SweepSummary(shown);
    if (r.sweep.evaluated) {
      std::snprintf(buffer, sizeof(buffer), "  trend %+.3g %% per 10 deg (as A^%g, z = %.1f)%s",
                    r.sweep.trend_percent_per_10deg, r.sweep.trend_exponent, r.sweep.trend_z,
                    r.sweep.trend_detected ? ": the rig departs from the model" : "");
      lines += buffer;
    }
  } else if (!r.sweep.note.empty()) {
    lines += "\n    I(A): no sweep (" + r.sweep.note + ")";
  }
  if (std::isfinite(r.amplitude_correction_kg_m2)) {
    const double before = r.inertia_total_kg_m2 + r.amplitude_correction_kg_m2;
    std::snprintf(buffer, sizeof(buffer),
                  "\n    amplitude correction (--repeats): %#.5g -> %#.5g kg m^2 (%+.2f %% +- %.2f "
                  "%%) from %.1f deg to zero amplitude",
                  before, r.inertia_total_kg_m2, -100.0 * r.amplitude_correction_kg_m2 / before,
                  100.0 * r.amplitude_correction_std_kg_m2 / before,
                  r.amplitude_correction_from_deg);
    lines += buffer;
  }
  for (const std::string& flag : r.flags) {
    if (flag.rfind("block_means_of_", 0) == 0) {
      lines += "\n    note: a dense log; the fit used means of " +
               flag.substr(std::string("block_means_of_").size(), flag.find("_samples") - 15) +
               " consecutive samples (docs/method.md, section 6)";
    }
  }
  return lines;
}

// "    warning: SUMMARY", one line per warning (the assumed +-1 mm on L and D is said once for the
// run, AssumedInputsSummary); a rejection or error first, as "    rejected: REASON".
std::string WarningLines(const TraceRecord& r, DisplayUnits units, bool* folded) {
  std::string lines;
  // Messages name the file already; the line under it does not repeat it.
  const std::string prefix = r.file + ": ";
  if (!r.ok() && !r.message.empty() && std::isfinite(r.inertia_total_kg_m2) &&
      r.status != TraceStatus::kError) {  // with no fit, the message is on the result line
    const std::string message = SiTextInDisplayUnits(
        r.message.rfind(prefix, 0) == 0 ? r.message.substr(prefix.size()) : r.message, units);
    lines += "\n    " + std::string(ToString(r.status)) + ": " + message;
  }
  // The most important first: a two-set-up finding before the record's other warnings.
  std::vector<std::string> warnings = r.warnings;
  std::stable_partition(warnings.begin(), warnings.end(), [](const std::string& w) {
    return w.find("two set-ups") != std::string::npos;
  });
  for (const std::string& w : warnings) {
    if (IsAssumedInputsWarning(w)) continue;
    const std::string shown = SiTextInDisplayUnits(w, units);
    const WarningLine line = LineOfWarning(shown);  // the report's line too
    if (line.folded) *folded = true;
    lines += "\n    warning: " + line.Text();
  }
  // --plot: which files are this log's figures (a name may carry a hash: FigureStems).
  if (!r.figures.empty()) {
    lines += "\n    figures:";
    for (const std::string& f : r.figures) lines += " " + f;
  }
  return lines;
}

std::string HumanLine(const TraceRecord& r, DisplayUnits units, bool* folded) {
  return ResultLine(r, units) + DetailLines(r, units) + WarningLines(r, units, folded);
}

// Said once after the records when a warning was shown shortened.
const char kFoldedNote[] =
    "(warnings shown by their first sentence, which says what to do; `bifilar fit --json` prints "
    "them in full)";

// --repeats without --json: the records, then the amplitude correction and each group. The
// between-repeat (Q) warning is the same on every member: said once, under its group.
void PrintRepeats(const FitCommandResult& result, bool* folded) {  // *folded: as HumanLine
  std::vector<std::string> scatter_warnings;
  for (const TraceRecord& r : result.records) {
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
    std::cout << HumanLine(shown, result.config.units, folded) << std::endl;
  }
  std::cout << AmplitudeCorrectionLine(result.correction) << std::endl;
  for (const RepeatGroup& g : result.groups) {
    // The group's result line, then its two-set-up finding (the most important: the mean is of
    // two set-ups), then its other lines and the scatter warning.
    const std::string group_text = RepeatGroupLine(g);
    const size_t first_end = group_text.find('\n');
    std::cout << group_text.substr(0, first_end) << std::endl;
    const std::string of = " repeats of " + g.name + " scatter beyond";
    const std::string setups = "; they look like two set-ups";
    std::vector<std::string> later;
    for (const std::string& w : scatter_warnings) {
      if (w.find(of) == std::string::npos) continue;
      std::string text = w;
      const std::string per_log = "this log's std";
      const size_t at = text.find(per_log);
      if (at != std::string::npos) text.replace(at, per_log.size(), "each log's std");
      const size_t split = text.find(setups);
      if (split != std::string::npos) {  // once per group, in full
        std::cout << "    warning: they look like two set-ups" << text.substr(split + setups.size())
                  << std::endl;
        text.erase(split);
      }
      later.push_back(text);
    }
    if (first_end != std::string::npos) std::cout << group_text.substr(first_end + 1) << std::endl;
    for (const std::string& text : later) std::cout << "    warning: " << text << std::endl;
  }
}

struct FitCli {
  FitCommandOptions options;
  bool json = false;
};

void AddFitOptions(CLI::App* sub, FitCli* args) {
  FitCommandOptions& o = args->options;
  sub->add_option("config", o.config_path,
                  "config (YAML): rig geometry, masses, IMU format (configs/README.md)")
      ->required();
  sub->add_option("logs", o.logs, "IMU logs: CSV (optionally .gz) or PX4 ULog (.ulg)")->required();
  sub->add_flag("--json", args->json, "print a JSON array of trace records instead of lines");
  sub->add_option("--model", o.model,
                  "pendulum model: " + PendulumModelAllowedValues() + "; overrides fit.model " +
                      "(default " + ToString(FitConfig().model) + ")")
      ->check(CLI::IsMember(PendulumModelNames()));
  sub->add_option("--integrator", o.integrator,
                  "ODE solver of the fit: " + IntegratorMethodAllowedValues() +
                      "; overrides fit.integrator (default " + ToString(FitConfig().integrator) +
                      ")")
      ->check(CLI::IsMember(IntegratorMethodNames()));
  sub->add_option("--window", o.window, "fit only T0:T1 (s, the log's own time)");
  sub->add_option("--max-amplitude", o.max_amplitude_deg, "upper end of the amplitude band (deg)")
      ->check(FiniteNumber())
      ->check(CLI::Range(kMinMaxAmplitudeDeg, kMaxMaxAmplitudeDeg));  // as fit.max_amplitude_deg
  sub->add_option("--plot", o.plot_dir,
                  "write fit figures DIR/<log>.svg and .png, and the amplitude sweep (I against "
                  "amplitude) DIR/<log>_sweep.svg and .png when the trace has one")
      ->check(NonEmptyName());
  sub->add_flag("--force", o.force,
                "with --plot: replace files of the figures' names that bifilar did not write in "
                "DIR (never a symbolic link)");
  sub->add_flag("--repeats", o.repeats,
                "combine repeats: logs whose paths differ only in the last number of the file "
                "name (case ignored) are swings of one set-up; their scatter beyond their stds "
                "is added to each; a group that looks like two set-ups is named");
  sub->add_option("--group-by", o.group_by,
                  "with --repeats: a regular expression for the part of each file name that names "
                  "the set-up (its first group, else the whole match; case ignored)");
  sub->add_option("--runs-table", o.runs_table,
                  "with --repeats: a CSV naming each log's group (columns path and group; or "
                  "pitch_deg/roll_deg: one group per attitude, as `process` does)");
}

}  // namespace

void RegisterFitCommand(CLI::App& app, int* exit_code) {
  auto args = std::make_shared<FitCli>();
  auto* sub = app.add_subcommand(
      "fit", "Fit single IMU logs: moment of inertia of everything suspended, with uncertainty");
  AddFitOptions(sub, args.get());
  sub->callback([args, exit_code] {
    FitCommandOptions options = args->options;
    const bool json = args->json, repeats = options.repeats;
    options.handle_interrupt = true;
    auto folded = std::make_shared<bool>(false);  // a warning was shown by its summary
    if (!json) {
      options.on_calibration = [](const RigCalibrationResult& calibration) {
        std::cout << calibration.BriefReport() << std::endl;
        for (const std::string& w : calibration.warnings) {
          std::cout << "warning: " << w << std::endl;
        }
      };
      options.on_identical_log = [](const std::string& w) {
        std::cout << "warning: " << w << std::endl;
      };
      options.on_groups = [](const std::string& groups) { std::cout << groups << std::endl; };
      // Without --repeats each line is printed as soon as its log is fitted.
      if (!repeats) {
        options.on_record = [folded](const TraceRecord& r, const CampaignConfig& config) {
          std::cout << HumanLine(r, config.units, folded.get()) << std::endl;
        };
      }
    }
    const FitCommandResult result = RunFit(options);
    if (result.interrupted) {
      if (json || repeats) {
        for (const TraceRecord& r : result.records) {
          std::cout << HumanLine(r, result.config.units, folded.get()) << std::endl;
        }
      }
      std::cerr << "bifilar: interrupted: " << result.records.size() << " of "
                << result.distinct.kept.size() << " logs fitted (above)\n";
      *exit_code = result.ExitCode();
      return;
    }
    if (json) {
      // Invalid UTF-8 (a log's bytes in a message) is replaced, never a json exception.
      std::cout << result.json.dump(2, ' ', false, nlohmann::json::error_handler_t::replace)
                << std::endl;
    } else if (repeats) {
      PrintRepeats(result, folded.get());
    }
    if (*folded && !json) std::cout << kFoldedNote << std::endl;
    // Once for the run: what the assumed +-1 mm on L and D adds (--json records carry it).
    const std::string assumed = AssumedInputsSummary(result.records);
    if (!assumed.empty() && !json) std::cout << assumed << std::endl;
    *exit_code = result.ExitCode();
  });
}

}  // namespace bifilar
