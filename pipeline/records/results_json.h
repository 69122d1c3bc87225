// Machine-readable outputs of a campaign: results.json (config used, every trace record,
// per-angle statistics, ellipse, program version), traces.csv, angles.csv. SI units throughout
// (kg m^2, s, rad/s, deg for angles); numbers that do not apply are null (JSON) or empty (CSV).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "pipeline/config/config.h"
#include "pipeline/records/campaign_result.h"
#include "pipeline/records/trace_record.h"

namespace bifilar {

// The per-trace record (issue 3 item 9 fields first, then the campaign's). With
// `campaign_fields` false only the fit fields (what `bifilar fit --json` and the cache store).
nlohmann::json TraceRecordToJson(const TraceRecord& record, bool campaign_fields = true);
// Inverse of TraceRecordToJson; throws UserError when a required field is missing or mistyped.
TraceRecord TraceRecordFromJson(const nlohmann::json& json);

// The `calibration` section of results.json and of `bifilar fit --json` (rig.calibration):
// effective against nominal geometry, the factor with its std and the std's three parts.
nlohmann::json CalibrationToJson(const RigCalibrationResult& calibration);

// The whole results.json document.
nlohmann::json ResultsToJson(const CampaignConfig& config, const CampaignResult& result);

std::string TracesCsv(const CampaignResult& result);  // one row per trace
std::string AnglesCsv(const CampaignResult& result);  // one row per pitch angle

// The amplitude sweep in one cell: "A_deg:I+-std" per band, amplitude decreasing.
std::string SweepSummary(const AmplitudeSweep& sweep);

}  // namespace bifilar
