// `bifilar process CONFIG [--out DIR] [--jobs N] [--force]` and `bifilar report DIR`.
#include <unistd.h>

#include <iostream>

#include "base/interrupt.h"
#include "pendulum/integrator.h"
#include "pipeline/campaign/campaign.h"
#include "pipeline/campaign/campaign_summary.h"
#include "pipeline/cli/cli_commands.h"
#include "pipeline/commands/process_command.h"
#include "pipeline/config/config.h"
#include "pipeline/records/total_uncertainty.h"
#include "pipeline/records/trace_record.h"
#include "pipeline/report/report.h"

namespace bifilar {
namespace {

// The traces' warnings after the summary (issue 25 item 5), in the traces' order: each trace that
// raised one, then one line per warning (LineOfWarning, the report's line too), the most
// important first.
// The assumed +-1 mm on L and D is said once in the summary. At most kShownTraces traces; the rest
// and the full texts are named where to find them.
void PrintTraceWarnings(const CampaignResult& campaign, DisplayUnits units, std::ostream& out) {
  constexpr int kShownTraces = 20;
  int warned = 0, shown = 0;
  std::string block;
  for (const TraceRecord& r : campaign.traces) {
    std::string lines;
    for (const std::string& w : r.warnings) {
      if (!IsAssumedInputsWarning(w))
        lines += "    warning: " + LineOfWarning(SiTextInDisplayUnits(w, units)).Text() + "\n";
    }
    if (lines.empty()) continue;
    if (++warned > kShownTraces) continue;
    ++shown;
    block += "  " + r.file + " (" + ToString(r.status) + "):\n" + lines;
  }
  if (warned == 0) return;
  out << "Warnings of " << warned << " trace" << (warned == 1 ? "" : "s")
      << " (first sentence of each; full texts in results.json and report.html, section "
         "Warnings):\n"
      << block;
  if (warned > shown) {
    out << "  ... and " << warned - shown << " more traces with warnings (report.html, section "
        << "Warnings)\n";
  }
}

}  // namespace

void RegisterProcessCommands(CLI::App& app, int* exit_code) {
  struct Args {
    std::string config;
    std::string out;
    int jobs = 0;
    bool force = false;
    std::string integrator;
    std::string runs_root;
    std::string report_dir;
  };
  auto args = std::make_shared<Args>();

  auto* process = app.add_subcommand(
      "process",
      "Process a campaign: fit every log, subtract the rig, fit the ellipse, write "
      "results.json, traces.csv, angles.csv and report.html");
  process->add_option("config", args->config, "campaign config (YAML, see configs/README.md)")
      ->required();
  process->add_option("--out", args->out, "output folder (default: out/ beside the config)");
  process->add_option("--jobs", args->jobs, "worker threads (default: all cores)")
      ->check(CLI::Range(0, kMaxJobs));
  process->add_flag("--force", args->force, "ignore the cache and refit every log");
  process
      ->add_option("--integrator", args->integrator,
                   "ODE solver of the fits: " + IntegratorMethodAllowedValues() +
                       "; overrides fit.integrator")
      ->check(CLI::IsMember(IntegratorMethodNames()));
  process->add_option("--runs-root", args->runs_root,
                      "folder of the aircraft logs, instead of the config's runs.root");
  process->callback([args, exit_code] {
    ProcessCommandOptions options;
    options.config_path = args->config;
    options.runs_root = args->runs_root;
    options.integrator = args->integrator;
    if (!args->out.empty()) options.out_dir = args->out;
    options.campaign.jobs = args->jobs;
    options.campaign.force = args->force;
    options.campaign.progress = &std::cerr;
    options.campaign.progress_bar = isatty(2) != 0;
    options.handle_interrupt = true;
    ProcessCommandResult result;
    try {
      result = RunProcess(options);
    } catch (const CampaignInterrupted& e) {
      std::cerr << "bifilar: " << e.what() << "\n";
      *exit_code = kInterruptedExitCode;
      return;
    }
    PrintCampaignSummary(result.config, result.campaign, std::cout);
    PrintTraceWarnings(result.campaign, result.config.units, std::cout);
    std::cout << "Wrote " << result.out_dir
              << "/{results.json, traces.csv, angles.csv, report.html}\n";
    *exit_code = result.campaign.summary.exit_code;
  });

  auto* report = app.add_subcommand("report", "Rebuild DIR/report.html from DIR/results.json");
  report->add_option("dir", args->report_dir, "output folder of `bifilar process`")->required();
  report->callback([args, exit_code] {
    RunReport(args->report_dir);
    std::cout << "Wrote " << args->report_dir << "/report.html\n";
    *exit_code = 0;
  });
}

}  // namespace bifilar
