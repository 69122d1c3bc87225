// The rig inertia subtracted from every aircraft trace: a configured value, the mean of the tare
// logs, or a table over pitch (rig.inertia). Used by the campaign and by rig.calibration.
#pragma once

#include <string>

#include "pipeline/config/config.h"

namespace bifilar {

// The start of a trace's message when a tare campaign has no usable tare log.
inline constexpr char kNoUsableTareLog[] = "no usable tare log";

// Rig inertia subtracted at `pitch_deg` from the spec and the fitted tare mean/std. False with
// *why when it cannot be found (table: pitch outside it; tare: kNoUsableTareLog ...).
bool RigInertiaAt(const CampaignConfig& config, double tare_mean_kg_m2, double tare_std_kg_m2,
                  double pitch_deg, double* inertia_kg_m2, double* std_kg_m2, std::string* why);

}  // namespace bifilar
