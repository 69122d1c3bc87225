// Private to pipeline/report/: the page's content (report_content.cc: results.json read through
// its typed readers into a ReportPage, the campaign's kind, the units, the trace order) and its
// HTML (report.cc: the sections written from a ReportPage, the figures embedded, the style).
#pragma once

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/records/calibration_result.h"
#include "pipeline/records/campaign_result.h"
#include "pipeline/records/results_reader.h"
#include "pipeline/records/trace_record.h"

namespace bifilar {
namespace report_page {

using nlohmann::json;
using R = ResultsReader;

// --- Numbers as the page writes them (report.cc).

// `value` with a printf `format` ("%.4f" by default); "&ndash;" when not finite.
std::string Fmt(double value, const char* format = "%.4f");

// The decimals that show `std` to two significant digits (0 to 12), in fixed notation.
int DecimalsFor(double std);

// `value` with `decimals` decimals, fixed notation (never e-notation), no "-0".
std::string Fixed(double value, int decimals);

// --- The page's content (report_content.cc).

// The page's units: SI, or slug ft^2 when results.json says "imperial".
struct Units {
  bool imperial = false;
  double scale = 1.0;  // display per kg m^2
  std::string name = "kg m<sup>2</sup>";
  std::string Inertia(double kg_m2, const char* format = "%.4f") const {
    return Fmt(kg_m2 * scale, format);
  }
  // A moment and its std in display units, each to the digits the std supports.
  std::string Value(double kg_m2, double std_kg_m2) const {
    return Fixed(kg_m2 * scale, DecimalsFor(std_kg_m2 * scale));
  }
  std::string Std(double std_kg_m2) const {
    return Fixed(std_kg_m2 * scale, DecimalsFor(std_kg_m2 * scale));
  }
};

// Trace `t`'s warnings as the report lists them: not the assumed +-1 mm on L and D (Table 2
// states it once) nor the simulated-log mark (the page says it once, at the top).
std::vector<std::string> TraceWarnings(const TraceRecord& t);

// The status a reader sees: "ok (warned)" for an ok trace with warnings, else the record's.
std::string DisplayStatus(const TraceRecord& t);

// A message or warning as the page shows it: in the page's units (the fit writes them in SI).
std::string InDisplayUnits(const Units& u, const std::string& text);

// An estimate of the ellipse or tensor JSON: KEY, KEY_std, KEY_ci95 [lo, hi]; null when
// undefined.
struct Estimate {
  bool defined = false;
  double value = NAN, std = NAN, lo = NAN, hi = NAN;
};
Estimate GetEstimate(const R& section, const std::string& key);

// The kind of campaign, from its tensor section (pipeline/records/tensor_json.h): planar pitch
// (the paper's ellipse), a full tensor, a partial one, or three separate axes (moments only).
enum class CampaignKind { kPlanar, kFullTensor, kPartialTensor, kSeparateAxes };
const char* KindName(CampaignKind kind);

// One trace in the order of the tables: by roll, pitch (numerically), then file.
struct TraceRow {
  TraceRecord t;
  double roll = 0.0, pitch = NAN;
};

// What every section reads: the results document, its parts, the units, the campaign kind, and
// the number of figures embedded so far (the inline SVGs' id prefixes).
struct ReportPage {
  // Reads the results document: its units, kind, traces (sorted), summary and calibration.
  ReportPage(const json& results_in, const std::string& out_dir_in, KeyLog* log);
  bool Planar() const { return kind == CampaignKind::kPlanar; }
  R results;
  KeyLog* log_;  // every key read (ReportKeysRead), or null
  const std::string& out_dir;
  Units u;
  CampaignSummary summary;  // read after the traces (a broken trace is named first)
  std::optional<RigCalibrationResult> calibration;
  const R ellipse = results.Get("ellipse");
  const R tensor = results.Get("tensor");
  const R figures = results.Get("figures");
  std::vector<TraceRow> traces;
  bool rolls = false;
  CampaignKind kind = CampaignKind::kPlanar;
  int figures_drawn = 0;
};

}  // namespace report_page
}  // namespace bifilar
