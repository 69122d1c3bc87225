// The console summary of a campaign (`bifilar process`).
#pragma once

#include <ostream>

#include "pipeline/config/config.h"
#include "pipeline/records/campaign_result.h"

namespace bifilar {

// The console summary: Table 2 with uncertainties in the config's units, counts, reuse, time.
void PrintCampaignSummary(const CampaignConfig& config, const CampaignResult& result,
                          std::ostream& out);

}  // namespace bifilar
