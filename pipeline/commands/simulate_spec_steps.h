// Private to pipeline/commands/ (the simulate_* files): what `bifilar simulate`'s run
// (simulate_run.cc) takes from its truth writer (simulate_truth.cc).
#pragma once

#include <string>

#include "pendulum/simulate.h"
#include "pipeline/commands/simulate_spec.h"

namespace bifilar {

// Rows of the Crazyflie-like footer after the data (format.footer): a blank line and 3 summary
// rows.
constexpr int kSimulateFooterRows = 4;

// The truth JSON text of one simulated trace (`simulate --trace`): spec.trace's geometry (L, D
// given), the IMU's place, the options and the trace, named `csv_path`.
std::string TraceTruthJson(const SimulateSpec& spec, const CampaignTrace& ct,
                           const std::string& csv_path);

}  // namespace bifilar
