// Checks of a campaign's inputs that need the discovered logs, run by RunCampaign before any fit
// (issue 9 item 11: one set of checks, nothing found out halfway).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/campaign/run_discovery.h"
#include "pipeline/config/config.h"

namespace bifilar {

// Removes the files found inside the output folder `out_dir` that are bifilar's own outputs
// (its result files, cache/ and figures/ are outputs, never inputs: an output folder inside
// runs.root must not feed the rerun). Returns how many were removed. Throws UserError naming
// them when any other log of the campaign lies inside `out_dir` (`--out LOGS/pitch_0`, or an
// --out that holds runs.root or a tare folder): those would be left out in silence. Called
// before the output folder is created or locked, so a refused --out is left as it was.
int DropOutputFolder(const std::string& out_dir, std::vector<RunFile>* runs);

// The fit.windows override of each run (same order), looked up once per run in a map of the
// resolved entries, so the cost is linear in entries + runs. Throws UserError naming the entry
// when a fit.windows entry matches none of the logs found ("a window for a file that does not
// exist" used to be ignored silently).
std::vector<std::optional<std::array<double, 2>>> WindowsForRuns(const CampaignConfig& config,
                                                                 const std::vector<RunFile>& runs);

// `bifilar fit`'s check of fit.windows, as WindowsForRuns's for `process`: throws UserError
// naming the entry when it names no file that exists (relative to runs.root or the config
// folder). The logs fit is given need not be all of them; each finds its entry through
// ConfigWindowFor (pipeline/trace/trace_process.h), matched as `process` matches it.
void CheckWindowEntriesExist(const CampaignConfig& config);

}  // namespace bifilar
