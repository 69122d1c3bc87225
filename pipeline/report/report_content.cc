// The report page's content (report_steps.h): results.json read section by section through the
// typed readers (a key missing or of another type names the section and the version that wrote
// the file), the traces in table order, the campaign's kind and the display units. The HTML
// written from it is report.cc.
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "base/text_format.h"
#include "base/units.h"
#include "base/user_error.h"
#include "base/version.h"
#include "pipeline/logs/simulated_log.h"
#include "pipeline/records/results_json.h"
#include "pipeline/records/total_uncertainty.h"
#include "pipeline/report/report_steps.h"

namespace bifilar {
namespace report_page {
namespace {

// A section of results.json read by its one typed reader (pipeline/records/results_json.h, the
// one the cache uses for a trace record): a key missing or of another type (a file of another
// version, or edited) throws UserError naming the section, the key and the version that wrote
// the file; RunReport adds the file and what to do. The keys read go to `log` under `path`.
template <typename Read>
auto ReadSection(const R& results, const std::string& what, const std::string& path, KeyLog* log,
                 const Read& read) {
  KeyLog keys;
  try {
    auto value = read(&keys);
    if (log != nullptr) {
      for (const std::string& key : keys) log->insert(path + "." + key);
    }
    return value;
  } catch (const UserError& e) {
    const std::string version = results.Str("version");
    throw UserError(what + ": " + e.what() + "; the file was written by bifilar " +
                    (version.empty() ? std::string("of an unknown version") : version) +
                    ", this is bifilar " + ProgramVersion());
  }
}

// results.json's traces, each read by TraceRecordFromJson as the cache reads its entries.
std::vector<TraceRecord> ReadTraces(const R& results, KeyLog* log) {
  std::vector<TraceRecord> out;
  const std::vector<R> items = results.Items("traces");
  for (size_t i = 0; i < items.size(); ++i) {
    const json& element = items[i].node();
    const auto file = element.is_object() ? element.find("file") : element.end();
    const std::string name =
        file != element.end() && file->is_string() ? " (" + file->get<std::string>() + ")" : "";
    out.push_back(
        ReadSection(results, "traces[" + std::to_string(i) + "]" + name, "traces[]", log,
                    [&](KeyLog* keys) { return TraceRecordFromJson(element, true, keys); }));
  }
  return out;
}

// The calibration section (null without rig.calibration).
std::optional<RigCalibrationResult> ReadCalibration(const R& results, KeyLog* log) {
  const R section = results.Get("calibration");
  if (!section.IsObject()) return std::nullopt;
  return ReadSection(results, "calibration", "calibration", log,
                     [&](KeyLog* keys) { return CalibrationFromJson(section.node(), keys); });
}

}  // namespace

// Trace `t`'s warnings as the report lists them: not the assumed +-1 mm on L and D (Table 2
// states it once) nor the simulated-log mark (the page says it once, at the top).
std::vector<std::string> TraceWarnings(const TraceRecord& t) {
  std::vector<std::string> out;
  for (const std::string& w : t.warnings) {
    if (!IsAssumedInputsWarning(w) && !IsSimulatedLogWarning(w)) out.push_back(w);
  }
  return out;
}

// The status a reader sees: "ok (warned)" for an ok trace with warnings, else the record's.
std::string DisplayStatus(const TraceRecord& t) {
  const std::string status = ToString(t.status);
  return status == "ok" && !TraceWarnings(t).empty() ? "ok (warned)" : status;
}

// A message or warning as the page shows it: in the page's units (the fit writes them in SI).
std::string InDisplayUnits(const Units& u, const std::string& text) {
  return SiTextInDisplayUnits(text, u.imperial ? DisplayUnits::kImperial : DisplayUnits::kSi);
}

Estimate GetEstimate(const R& section, const std::string& key) {
  Estimate e;
  if (!section.IsObject()) return e;
  e.value = section.Num(key.c_str());
  e.defined = std::isfinite(e.value);
  e.std = section.Num((key + "_std").c_str());
  const std::vector<double> ci = section.Nums((key + "_ci95").c_str());
  if (ci.size() == 2) {
    e.lo = ci[0];
    e.hi = ci[1];
  }
  return e;
}

ReportPage::ReportPage(const json& results_in, const std::string& out_dir_in, KeyLog* log)
    : results(results_in, log), log_(log), out_dir(out_dir_in) {
  if (results.Str("units") == "imperial") {
    u.imperial = true;
    u.scale = kSlugFt2PerKgM2;
    u.name = "slug ft<sup>2</sup>";
  }
  const std::string mode = tensor.Str("mode");
  const R observable = tensor.Get("observable");
  const bool products = observable.Bool("Ixy") || observable.Bool("Ixz") || observable.Bool("Iyz");
  kind = mode == "full_3d" ? CampaignKind::kFullTensor
         : mode == "partial"
             ? (products ? CampaignKind::kPartialTensor : CampaignKind::kSeparateAxes)
             : CampaignKind::kPlanar;
  for (TraceRecord& t : ReadTraces(results, log_)) {
    TraceRow row{std::move(t)};
    const double roll = row.t.roll_used_deg;
    row.roll = std::isfinite(roll) ? roll : 0.0;
    row.pitch = row.t.pitch_used_deg;
    if (row.roll != 0.0) rolls = true;
    traces.push_back(row);
  }
  std::stable_sort(traces.begin(), traces.end(), [](const TraceRow& a, const TraceRow& b) {
    const double pa = std::isfinite(a.pitch) ? a.pitch : 1e9,
                 pb = std::isfinite(b.pitch) ? b.pitch : 1e9;
    if (a.roll != b.roll) return a.roll < b.roll;
    if (pa != pb) return pa < pb;
    return NaturalLess(a.t.file, b.t.file);  // case ignored, numbers as numbers
  });
  // A campaign whose tensor fit failed is still not planar when its logs roll.
  if (kind == CampaignKind::kPlanar && rolls) kind = CampaignKind::kPartialTensor;
  summary = ReadSection(results, "summary", "summary", log_, [this](KeyLog* keys) {
    return CampaignSummaryFromJson(results.Get("summary").node(), keys);
  });
  calibration = ReadCalibration(results, log_);
}

const char* KindName(CampaignKind kind) {
  switch (kind) {
    case CampaignKind::kPlanar:
      return "planar pitch (the ellipse of inertia in the x-z plane)";
    case CampaignKind::kFullTensor:
      return "full inertia tensor (swings about axes in every plane)";
    case CampaignKind::kPartialTensor:
      return "partial inertia tensor";
    case CampaignKind::kSeparateAxes:
      return "separate axes (one moment per body axis)";
  }
  return "";
}

}  // namespace report_page
}  // namespace bifilar
