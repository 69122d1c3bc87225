// Machine-readable outputs of a campaign: results.json (config used, every trace record,
// per-angle statistics, ellipse, program version), traces.csv, angles.csv. SI units throughout
// (kg m^2, s, rad/s, deg for angles); numbers that do not apply are null (JSON) or empty (CSV).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "pipeline/config/config.h"
#include "pipeline/records/campaign_result.h"
#include "pipeline/records/results_reader.h"
#include "pipeline/records/trace_record.h"

namespace bifilar {

// The per-trace record (issue 3 item 9 fields first, then the campaign's). With
// `campaign_fields` false only the fit fields (what `bifilar fit --json` and the cache store).
nlohmann::json TraceRecordToJson(const TraceRecord& record, bool campaign_fields = true);
// The one reader of a trace record (the cache's entries, results.json's traces[] for the report):
// the inverse of TraceRecordToJson with the same `campaign_fields`. Every key the writer always
// writes is required; the ones it writes only sometimes (uncertainty.repeat_scatter_kg_m2,
// amplitude_correction, the sweep's trend_* when evaluated, the campaign fields) are read when
// the writer would have written them. Throws UserError naming the key ("'period_s' is missing",
// "'window_s' is not a pair of numbers (string)"); the caller adds the file and what to do. The
// keys written but derived from the fields, not read back, are DerivedTraceKeys(). `keys_read`,
// when given, receives every key path read ("uncertainty.statistical_kg_m2",
// "amplitude_sweep.bands[].window_s"): tests/pipeline_trace_record_json_test.cc checks that they
// are the keys the writer writes.
TraceRecord TraceRecordFromJson(const nlohmann::json& json, bool campaign_fields,
                                KeyLog* keys_read = nullptr);

// Keys TraceRecordToJson writes for other readers (people, scripts) that TraceRecordFromJson
// does not read: composed from the record's fields (pipeline/records/total_uncertainty.h) or
// constant.
const KeyLog& DerivedTraceKeys();

// The `calibration` section of results.json and of `bifilar fit --json` (rig.calibration):
// effective against nominal geometry, the factor with its std and the std's three parts.
nlohmann::json CalibrationToJson(const RigCalibrationResult& calibration);

// The inverse of CalibrationToJson, as TraceRecordFromJson reads a record: every key required,
// a missing or mistyped one a UserError naming it; `keys_read` receives the key paths read. Not
// written, so not read: cache_keys.
RigCalibrationResult CalibrationFromJson(const nlohmann::json& json, KeyLog* keys_read = nullptr);

// The `summary` section of results.json (every field but n_cache_refused) and its inverse, read
// as CalibrationFromJson reads.
nlohmann::json CampaignSummaryToJson(const CampaignSummary& summary);
CampaignSummary CampaignSummaryFromJson(const nlohmann::json& json, KeyLog* keys_read = nullptr);

// The whole results.json document.
nlohmann::json ResultsToJson(const CampaignConfig& config, const CampaignResult& result);

// The "schema_version" of results.json or of a cache entry (kResultsSchemaVersion of
// base/version.h when this bifilar wrote it): 0 when absent, as in files written before the
// number existed. Throws UserError when it is present but not a whole number >= 0.
int SchemaVersionOf(const nlohmann::json& document);

// The schema check of a results.json reader (`report`, `export`): throws UserError naming `name`,
// the file's schema and the version that wrote it, and this bifilar's, when the file is of a
// newer schema than this bifilar reads. An older file is read as before (a key it lacks is named).
void CheckResultsSchema(const nlohmann::json& results, const std::string& name);

std::string TracesCsv(const CampaignResult& result);  // one row per trace
std::string AnglesCsv(const CampaignResult& result);  // one row per pitch angle

// The amplitude sweep in one cell: "A_deg:I+-std" per band, amplitude decreasing.
std::string SweepSummary(const AmplitudeSweep& sweep);

}  // namespace bifilar
