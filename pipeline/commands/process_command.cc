// The use case of `bifilar process` (pipeline/commands/process_command.h).
#include "pipeline/commands/process_command.h"

#include <filesystem>

#include "base/interrupt.h"

namespace bifilar {

ProcessCommandResult RunProcess(const ProcessCommandOptions& options) {
  ProcessCommandResult result;
  ConfigLoadOptions load;
  load.runs_root = options.runs_root;
  result.config = LoadCampaignConfig(options.config_path, load);
  if (!options.integrator.empty()) {
    ParseIntegratorMethod(options.integrator, &result.config.fit.integrator);
  }
  CampaignOptions campaign = options.campaign;
  campaign.out_dir = options.out_dir
                         ? *options.out_dir
                         : (std::filesystem::path(result.config.folder) / "out").string();
  result.out_dir = campaign.out_dir;
  if (options.handle_interrupt) {
    InstallInterruptHandler();
    campaign.cancel = &ProcessInterruptFlag();
  }
  result.campaign = RunCampaign(result.config, campaign);
  return result;
}

}  // namespace bifilar
