// The console summary of a campaign (`bifilar process`).
#pragma once

#include <ostream>

#include "pipeline/config/config.h"
#include "pipeline/records/campaign_result.h"

namespace bifilar {

// The console summary: Table 2 with uncertainties in the config's units, counts, reuse, time.
// The physical check (fit/physical.h) when not physical ("Error: NOT PHYSICAL ...") or
// borderline ("Warning: ..."), word-wrapped at 150 characters; nothing otherwise.
void PrintPhysicalCheck(const CampaignResult& result, std::ostream& out);

void PrintCampaignSummary(const CampaignConfig& config, const CampaignResult& result,
                          std::ostream& out);

}  // namespace bifilar
