// The use case behind `bifilar process CONFIG`: loads the campaign config, applies the command
// line's overrides and runs the campaign (RunCampaign, pipeline/campaign/campaign.h). The CLI
// (pipeline/cli/cli_process.cc) and Python's bifilar.process (python/src/campaign.cc) call it.
#pragma once

#include <optional>
#include <string>

#include "pipeline/campaign/campaign.h"
#include "pipeline/config/config.h"

namespace bifilar {

struct ProcessCommandOptions {
  std::string config_path;             // campaign config (YAML, configs/README.md)
  std::string runs_root;               // "" : the config's runs.root (--runs-root)
  std::string integrator;              // "" : the config's fit.integrator; else rk853 or cvodes
  std::optional<std::string> out_dir;  // none: out/ beside the config
  // Jobs, cache, figures, progress, cancel flag and callback; its out_dir is set by RunProcess.
  CampaignOptions campaign;
  // Install the Ctrl-C handler (base/interrupt.h) after the config is loaded and cancel on it.
  bool handle_interrupt = false;
};

struct ProcessCommandResult {
  CampaignConfig config;    // as loaded, with the overrides
  std::string out_dir;      // where the results were written
  CampaignResult campaign;  // what RunCampaign returned (summary.exit_code: the CLI's exit code)
};

// Throws UserError (config, options) and CampaignInterrupted (Ctrl-C or the cancel flag) as
// RunCampaign does; nothing is written then.
ProcessCommandResult RunProcess(const ProcessCommandOptions& options);

}  // namespace bifilar
