// report.html as HTML (report.h): the sections written from the page's content (ReportPage,
// report_content.cc), the figures embedded (inline SVG compacted, PNG as base64), the style, and
// `bifilar report`.
#include "pipeline/report/report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <optional>
#include <set>
#include <sstream>
#include <vector>

#include "base/atomic_file.h"
#include "base/bounded_read.h"
#include "base/hash.h"
#include "base/json_error.h"
#include "base/text_format.h"
#include "base/units.h"
#include "base/user_error.h"
#include "base/version.h"
#include "fit/tensor_components.h"
#include "pipeline/figures/svg_compact.h"
#include "pipeline/logs/simulated_log.h"
#include "pipeline/records/results_json.h"
#include "pipeline/records/results_reader.h"
#include "pipeline/records/tensor_json.h"
#include "pipeline/records/total_uncertainty.h"
#include "pipeline/report/report_steps.h"
#include "pipeline/store/output_set.h"

namespace bifilar {
namespace report_page {

std::string Fmt(double value, const char* format) {
  if (!std::isfinite(value)) return "&ndash;";
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

// The decimals that show `std` to two significant digits (0 to 12), in fixed notation.
int DecimalsFor(double std) {
  if (!(std::isfinite(std) && std > 0)) return 4;
  const int decimals = 1 - static_cast<int>(std::floor(std::log10(std)));
  return std::clamp(decimals, 0, 12);
}

// `value` with `decimals` decimals, fixed notation (never e-notation), no "-0".
std::string Fixed(double value, int decimals) {
  if (!std::isfinite(value)) return "&ndash;";
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*f", decimals, value);
  std::string out = buffer;
  if (out.find_first_not_of("-0.") == std::string::npos && out[0] == '-') out.erase(0, 1);
  return out;
}

namespace {

namespace fs = std::filesystem;

std::string Escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// The first line of a figure that the report has compacted (CompactSvg) and stored in its place.
constexpr const char* kCompactMark = "<!-- bifilar: compact svg for report.html -->\n";

// A figure file as page content: an SVG inline (its ids prefixed, so the glyph and clip ids that
// every cairo SVG names alike do not collide; a third smaller than base64), a PNG as a base64
// data URI.
// Names outside OUT/figures never reach here (CheckFigureNames refuses the page first); the
// check is repeated so that no name is read unchecked. A figure that is a symbolic link (inside
// the folder) is embedded but never replaced by its compact form.
std::string Figure(const std::string& out_dir, const std::string& name, const std::string& alt,
                   const std::string& css_class, int* counter) {
  if (name.empty()) return "<p class=\"note\">(no figure)</p>";
  std::string bytes, why, path;
  if (!ResolveInsideFolder(out_dir, "figures", name, &path, &why)) {
    return "<p class=\"note\">(figure " + Escape(PrintableAscii(name, 200)) +
           " refused: " + Escape(why) + ")</p>";
  }
  if (!ReadRegularFile(path, FigureCap(), &bytes, &why)) {
    return "<p class=\"note\">(figure " + Escape(name) + " missing)</p>";
  }
  const std::string ext = fs::path(name).extension().string();
  if (ext == ".svg") {
    const std::string prefix = "f" + std::to_string((*counter)++) + "-";
    std::string svg;
    if (bytes.compare(0, std::strlen(kCompactMark), kCompactMark) == 0) {
      svg = bytes.substr(std::strlen(kCompactMark));  // compacted by an earlier report
    } else {
      const size_t start = bytes.find("<svg");
      if (start == std::string::npos)
        return "<p class=\"note\">(figure " + Escape(name) + " unreadable)</p>";
      svg = CompactSvg(bytes.substr(start));
      // The figure's name is keyed by its content, so its compact form serves every later report:
      // stored in its place (atomically; best effort, a read-only folder only costs the time).
      std::error_code ec;
      try {
        if (!fs::is_symlink(path, ec)) WriteFileAtomically(path, kCompactMark + svg);
      } catch (const std::exception&) {
      }
    }
    svg = PrefixSvgIds(svg, prefix);
    svg.replace(0, 4,
                "<svg class=\"" + css_class + "\" role=\"img\" aria-label=\"" + Escape(alt) + "\"");
    return svg;
  }
  return "<img class=\"" + css_class + "\" alt=\"" + Escape(alt) +
         "\" src=\"data:image/png;base64," + Base64(bytes) + "\">";
}

// The amplitude-sweep figure beside trace `t`'s fit figure (I against amplitude,
// pipeline/figures/sweep_plot.h), or a note saying why there is none.
std::string SweepFigure(const TraceRecord& t, const std::string& out_dir, int* counter) {
  const std::string& name = t.sweep_figure;
  const std::string file = Escape(t.file);
  const AmplitudeSweep& sweep = t.sweep;
  if (name.empty()) {
    const std::string& note = sweep.note;
    return "<figure><p class=\"note\">" + file + ": no amplitude sweep" +
           (note.empty() ? std::string() : " (" + Escape(note) + ")") + ".</p></figure>\n";
  }
  // The compact figure has no legend: the caption is its legend.
  const bool trend = sweep.trend_detected;
  const double exponent = sweep.trend_exponent;
  const std::string alt = "I against amplitude, " + t.file;
  return "<figure>" + Figure(out_dir, name, alt, "sweep", counter) + "<figcaption>" + file +
         " &middot; I against amplitude, flat for the ideal model: each band &plusmn; 1&sigma; "
         "over its amplitude range; blue, the result &plusmn; 1&sigma;" +
         (trend ? "; red, the trend I<sub>0</sub>(1 + c A<sup>" +
                      Fmt(std::isfinite(exponent) ? exponent : 2.0, "%g") +
                      "</sup>) and a ring on the band the result is taken from"
                : "") +
         "</figcaption></figure>\n";
}

// Every figure name results.json gives (figures.*, traces[i].figure, traces[i].sweep_figure)
// must name a file inside OUT/figures (ResolveInsideFolder): anything else (`../x`, an absolute
// path, a link leading out of OUT) throws UserError naming the key and the value, before any
// figure is read, embedded or rewritten (issue 33 item 2).
void CheckFigureNames(const json& results, const std::string& out_dir) {
  const auto check = [&](const std::string& key, const json& value) {
    if (!value.is_string() || value.get<std::string>().empty()) return;
    std::string path, why;
    if (!ResolveInsideFolder(out_dir, "figures", value.get<std::string>(), &path, &why)) {
      throw UserError((fs::path(out_dir) / "results.json").string() + ": " + key + " = \"" +
                      PrintableAscii(value.get<std::string>(), 200) + "\" is " + why +
                      ", not a figure in " + (fs::path(out_dir) / "figures").string() +
                      "; refused, no file was read or written (a results.json from elsewhere? "
                      "rerun `bifilar process` to rewrite it)");
    }
  };
  if (results.contains("figures") && results["figures"].is_object()) {
    for (const auto& [kind, name] : results["figures"].items()) check("figures." + kind, name);
  }
  if (results.contains("traces") && results["traces"].is_array()) {
    const json& traces = results["traces"];
    for (size_t i = 0; i < traces.size(); ++i) {
      if (!traces[i].is_object()) continue;
      for (const char* field : {"figure", "sweep_figure"}) {
        if (traces[i].contains(field)) {
          check("traces[" + std::to_string(i) + "]." + field, traces[i][field]);
        }
      }
    }
  }
}

const char* kStyle = R"(
body { font-family: sans-serif; margin: 2em auto; max-width: 1100px; color: #222; }
h1 { font-size: 1.6em; } h2 { border-bottom: 1px solid #ccc; padding-bottom: .2em; margin-top: 2em; }
.scroll { overflow-x: auto; max-width: 100%; }
table { border-collapse: collapse; margin: .5em 0 1em; font-size: .9em; }
th, td { border: 1px solid #ccc; padding: .25em .6em; text-align: right; }
td { white-space: nowrap; }
th { background: #f2f2f2; } td.l, th.l { text-align: left; } td.w { white-space: normal; }
tr.rejected td { background: #fff4e0; } tr.warned td { background: #fffbe0; } tr.error td { background: #fde8e8; }
.note { color: #666; font-style: italic; }
.result { font-size: 1.1em; background: #f4f8ff; border: 1px solid #c8d8f0; padding: .6em .9em; }
img.fig, svg.fig { max-width: 100%; height: auto; border: 1px solid #ddd; }
.traces { display: flex; flex-wrap: wrap; gap: 10px; }
.traces figure { margin: 0; width: 540px; }
.traces img, .traces svg { width: 540px; height: auto; border: 1px solid #ddd; }
figcaption { font-size: .8em; color: #444; }
details summary { cursor: pointer; } details p { margin: .3em 0 .3em 1.2em; color: #444; }
pre { background: #f7f7f7; padding: .8em; overflow-x: auto; font-size: .85em; }
.ok { color: #1a7f37; } .bad { color: #b42318; } .warn { color: #8a5a00; }
)";

// Tables wider than the text column scroll inside their own box.
const char* kScrollOpen = "<div class=\"scroll\">";
const char* kScrollClose = "</div>\n";

// The main result in one box at the top: the moments with their total std.
void WriteHeadline(const ReportPage& p, std::ostream& h) {
  const Units& u = p.u;
  std::string items;
  // Each moment with its stat and its total std, labelled (the total adds the common-mode terms,
  // pipeline/records/total_uncertainty.h).
  const auto add = [&](const std::string& label, const Estimate& e, double total) {
    if (!e.defined) return;
    items += (items.empty() ? "" : ", ") + label + " = " + u.Value(e.value, e.std) + " &plusmn; " +
             u.Std(e.std) + " (stat)" +
             (std::isfinite(total) ? " &plusmn; " + u.Std(total) + " (total)" : std::string());
  };
  const double common = p.results.Get("total_uncertainty").Num("common_mode_relative_std");
  if (p.Planar()) {
    if (!p.ellipse.IsObject()) {
      h << "<p class=\"bad\">" << Escape(p.summary.ellipse_message) << "</p>\n";
      return;
    }
    const R total = p.results.Get("total_uncertainty");
    for (const auto& [key, label] :
         {std::make_pair("Ix_kg_m2", "I<sub>x</sub>"), std::make_pair("Iz_kg_m2", "I<sub>z</sub>"),
          std::make_pair("Ixz_kg_m2", "I<sub>xz</sub>")}) {
      add(label, GetEstimate(p.ellipse, key), total.Num(key));
    }
    h << "<p class=\"result\">Result: " << items << " " << u.name
      << " (&plusmn; 1 std: stat, then total; Table 2).</p>\n";
    return;
  }
  if (!p.tensor.IsObject()) {
    h << "<p class=\"bad\">" << Escape(p.summary.tensor_message) << "</p>\n";
    return;
  }
  for (int k = 0; k < kTensorComponents; ++k) {
    const char* name = TensorComponentName(k);
    const Estimate e = GetEstimate(p.tensor, std::string(name) + "_kg_m2");
    add(std::string("I<sub>") + (name + 1) + "</sub>", e,
        WithCommonModeScale(e.value, e.std, common));
  }
  h << "<p class=\"result\">Result: " << items << " " << u.name
    << " (&plusmn; 1 std: stat, then total; inertia tensor below).</p>\n";
}

// results.json's `physical` (fit/physical.h) beside the result box: not physical in red with the
// worst inequality's numbers, borderline as a warning; nothing when physical or not checked.
void WritePhysicalBox(const ReportPage& p, std::ostream& h) {
  const R physical = p.results.Get("physical");
  if (!physical.IsObject()) return;
  const std::string status = physical.Str("status");
  if (status != "not_physical" && status != "borderline") return;
  const R worst = physical.Get("worst");
  const bool bad = status == "not_physical";
  h << "<p class=\"result " << (bad ? "bad" : "warn") << "\""
    << (bad ? " style=\"border-color:#b42318;background:#fde8e8\"" : "") << "><b>"
    << (bad ? "Not physical" : "Borderline") << "</b>";
  if (worst.IsObject()) {
    h << ": " << Escape(worst.Str("inequality")) << " = " << Fmt(worst.Num("margin_kg_m2"), "%.4g")
      << " &plusmn; " << Fmt(worst.Num("std_kg_m2"), "%.2g")
      << " kg m&sup2; (z = " << Fmt(worst.Num("z"), "%.2f") << ", not physical at z &le; "
      << Fmt(physical.Num("threshold_z"), "%.2f") << ")";
  }
  if (!physical.Str("attitude").empty()) h << "; attitude " << Escape(physical.Str("attitude"));
  h << ". " << Escape(physical.Str("message")) << "</p>\n";
}

// Title, version, config, the campaign kind and the trace counts, then the main result.
void WriteHeader(const ReportPage& p, std::ostream& h) {
  const CampaignSummary& summary = p.summary;
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
    << "<title>bifilar report</title><style>" << kStyle << "</style></head><body>\n";
  h << "<h1>Mass properties from bifilar pendulum swings</h1>\n";
  h << "<p>bifilar " << Escape(p.results.Str("version")) << " &middot; config <code>"
    << Escape(p.results.Str("config_file")) << "</code> &middot; campaign: " << KindName(p.kind)
    << " &middot; attitude source " << Escape(p.results.Str("pitch_source"));
  // The fit's model and ODE solver (fit.integrator or --integrator), and glitch removal when off.
  const R settings = p.results.Get("fit_settings");
  if (settings.Has("integrator")) {
    h << " &middot; fit model " << Escape(settings.Str("model")) << ", integrator <code>"
      << Escape(settings.Str("integrator")) << "</code>";
    if (!settings.Get("glitch").Bool("enabled", true)) h << ", glitch removal off";
  }
  h << ". Traces: " << summary.n_traces << " (<span class=\"ok\">" << summary.n_ok << " ok</span>, "
    << summary.n_rejected << " rejected, " << summary.n_error
    << " error); fits reused from cache: " << summary.n_reused << ".</p>\n";
  // Simulated logs say so in their warnings (pipeline/logs/simulated_log.h): the page says it
  // first.
  int simulated = 0;
  std::string mark;  // the first log's own words, once for the page
  for (const TraceRow& row : p.traces) {
    bool marked = false;
    for (const std::string& w : row.t.warnings) {
      if (!IsSimulatedLogWarning(w)) continue;
      marked = true;
      if (mark.empty()) mark = w;
    }
    simulated += marked ? 1 : 0;
  }
  if (simulated > 0) {
    h << "<p class=\"warn\">Simulated data: " << simulated << " of the " << p.traces.size()
      << " logs were written by <code>bifilar simulate</code>, not measured (" << Escape(mark)
      << ").</p>\n";
  }
  WriteHeadline(p, h);
  WritePhysicalBox(p, h);
}

// A warning's line (LineOfWarning, pipeline/records/trace_record.h: the console's line) as page
// content: the clause that says what to do, when the summary does not hold it, in bold after it.
std::string WarningLineHtml(const WarningLine& line) {
  return Escape(line.summary) +
         (line.action.empty() ? std::string() : " &rarr; <b>" + Escape(line.action) + "</b>");
}

// One warning as its line, the full text on click.
std::string WarningItem(const Units& u, const std::string& warning) {
  const std::string text = InDisplayUnits(u, warning);
  const WarningLine line = LineOfWarning(text);
  const std::string summary = WarningLineHtml(line);
  if (!line.folded) return "<p>" + summary + "</p>";  // nothing more to expand
  return "<details><summary>" + summary + "</summary><p>" + Escape(text) + "</p></details>";
}

// A section's own warnings: one line each, the full text on click.
void WriteNotes(const std::vector<std::string>& warnings, const Units& u, std::ostream& h) {
  for (const std::string& w : warnings)
    h << "<div class=\"note\">" << WarningItem(u, w) << "</div>\n";
}

// The points flagged as outliers (|studentized residual| > 3), named by their log.
void WriteOutliers(const ReportPage& p, std::ostream& h) {
  std::string names;
  int n = 0;
  // A planar campaign's outliers are the ellipse's (the points its warning counts), named
  // through the tensor section's per-point files; a tensor campaign's are its own.
  std::set<int> planar_outliers;
  for (const R& o : p.ellipse.Items("outliers")) planar_outliers.insert(o.Int("index", -1));
  for (const R& r : p.tensor.Items("residuals")) {
    if (p.Planar() ? planar_outliers.count(r.Int("index", -1)) == 0 : !r.Bool("outlier")) continue;
    ++n;
    names += (names.empty() ? "" : ", ") + Escape(r.Str("file")) + " (roll " +
             Fmt(r.Num("roll_deg"), "%.1f") + ", pitch " + Fmt(r.Num("pitch_deg"), "%.1f") +
             ", studentized residual " + Fmt(r.Num("studentized"), "%+.2f") + ")";
  }
  if (n > 0) {
    h << "<p class=\"warn\">Outlier" << (n == 1 ? "" : "s")
      << " (|studentized residual| &gt; 3; check the log, its attitude and its fit): " << names
      << ".</p>\n";
  }
}

// Table 2: I_x, I_z, I_xz, tau and the principal moments with std and interval, the systematic
// share, the ellipse's warnings and outliers. Planar campaigns only.
void WriteTable2(const ReportPage& p, std::ostream& h) {
  const Units& u = p.u;
  const R& ellipse = p.ellipse;
  h << "<h2>Table 2: inertia properties</h2>\n";
  if (!ellipse.IsObject()) {
    h << "<p class=\"bad\">" << Escape(p.summary.ellipse_message) << "</p>\n";
    return;
  }
  // The total column (results.json total_uncertainty, pipeline/records/total_uncertainty.h): the
  // std and the common-mode scale terms in quadrature.
  const R total = p.results.Get("total_uncertainty");
  h << kScrollOpen
    << "<table><tr><th class=\"l\">quantity</th><th>value</th><th>std (stat)</th>"
       "<th>std (total)</th><th>interval (stat)</th><th class=\"l\">unit</th></tr>\n";
  struct Row {
    const char* key;
    const char* label;
    bool angle;
  };
  for (const Row& row :
       {Row{"Ix_kg_m2", "I<sub>x</sub>", false}, Row{"Iz_kg_m2", "I<sub>z</sub>", false},
        Row{"Ixz_kg_m2", "I<sub>xz</sub>", false},
        Row{"tau_deg", "&tau; (principal inclination)", true},
        Row{"Ixp_kg_m2", "I<sub>xp</sub> (principal)", false},
        Row{"Izp_kg_m2", "I<sub>zp</sub> (principal)", false}}) {
    const Estimate e = GetEstimate(ellipse, row.key);
    h << "<tr><td class=\"l\">" << row.label << "</td>";
    const double e_total = total.Num(row.key);
    if (!e.defined) {
      h << "<td colspan=\"4\">ill-defined (I<sub>x</sub> &asymp; I<sub>z</sub>)</td>";
    } else {
      const double scale = row.angle ? 1.0 : u.scale;
      const int d = DecimalsFor(e.std * scale);
      h << "<td>" << Fixed(e.value * scale, d) << "</td><td>" << Fixed(e.std * scale, d)
        << "</td><td>" << Fixed(e_total * scale, DecimalsFor(e_total * scale)) << "</td><td>["
        << Fixed(e.lo * scale, d) << ", " << Fixed(e.hi * scale, d) << "]</td>";
    }
    h << "<td class=\"l\">" << (row.angle ? "deg" : u.name) << "</td></tr>\n";
  }
  h << "</table>" << kScrollClose;
  const bool calibrated = p.calibration.has_value();
  const double common = total.Num("common_mode_relative_std");
  const bool assumed = total.Bool("configured_inputs_assumed");
  h << "<p><b>std (stat)</b>: the scatter between trials and angles, the fits' own errors and the "
       "rig inertia's offset; the interval is its 95 % bootstrap interval. <b>std (total)</b> adds "
       "in quadrature the common-mode terms, one error shared by every moment: the "
    << (calibrated
            ? "rig calibration (it replaces the uncertainties of L, D and g)"
            : std::string("uncertainties of L, D") +
                  (assumed ? " (<b>assumed</b> &plusmn;1 mm: no <code>rig.uncertainties</code>)"
                           : "") +
                  ", g")
    << ", the masses and the gyro scale, &plusmn;" << Fmt(100.0 * common, "%.2f")
    << " % of each moment. It scales every moment alike and leaves &tau; unchanged. Read the total "
       "when you use a number; compare trials or set-ups with the stat std. Values are given to "
       "the digits their std supports.</p>\n";
  const std::string note = total.Str("note");
  if (!note.empty()) h << "<p class=\"warn\">" << Escape(note) << "</p>\n";
  WriteOutliers(p, h);
  WriteNotes(ellipse.Strs("warnings"), u, h);
}

// rig.calibration: effective against configured geometry, the factor with its std and parts.
void WriteCalibration(const ReportPage& p, std::ostream& h) {
  if (!p.calibration) return;
  const RigCalibrationResult& c = *p.calibration;
  h << "<h2>Rig calibration (reference object)</h2>\n<table><tr><th class=\"l\">geometry</th>"
       "<th>L (m)</th><th>D (m)</th><th>D<sup>2</sup>/L (m)</th></tr>\n";
  const auto row = [&](const char* label, double separation_m, double d2_over_l_m) {
    h << "<tr><td class=\"l\">" << label << "</td><td>" << Fmt(c.filar_length_m, "%.4f")
      << "</td><td>" << Fmt(separation_m, "%.5f") << "</td><td>" << Fmt(d2_over_l_m, "%.6f")
      << "</td></tr>\n";
  };
  row("configured", c.nominal_separation_m, c.nominal_d2_over_l_m);
  row("effective", c.effective_separation_m, c.effective_d2_over_l_m);
  h << "</table>\n<p>Factor k = " << Fmt(c.factor, "%.5f") << " &plusmn; "
    << Fmt(c.factor_std, "%.5f") << " (&plusmn;" << Fmt(100.0 * c.factor_rel_std, "%.3f")
    << " %, common to every moment: reference inertia " << Fmt(100.0 * c.rel_std_reference, "%.3f")
    << " %, reference swings " << Fmt(100.0 * c.rel_std_swings, "%.3f") << " %, rig inertia "
    << Fmt(100.0 * c.rel_std_rig, "%.3f") << " %), from " << c.n_swings
    << " swing(s) of a reference of " << p.u.Inertia(c.reference_inertia_kg_m2, "%.5g") << " "
    << p.u.name << " and " << Fmt(c.reference_mass_kg, "%.4g")
    << " kg. Every trace, tare logs included, was fitted with the effective geometry; the "
       "tape-measure uncertainties of L and D and that of g do not apply.</p>\n";
  WriteNotes(c.warnings, p.u, h);
}

// Table 1 (data quality) and the rig line. The regression RMSE is the ellipse's (planar) or the
// tensor's.
void WriteTable1AndRig(const ReportPage& p, std::ostream& h) {
  const Units& u = p.u;
  const R t1 = p.results.Get("table1");
  const double rmse = p.Planar() ? t1.Num("regression_rmse_kg_m2") : p.tensor.Num("rmse_kg_m2");
  h << "<h2>Table 1: data quality</h2>\n<table><tr><th class=\"l\">statistic</th><th>value</th>"
       "<th class=\"l\">unit</th></tr>\n";
  h << "<tr><td class=\"l\">raw data &sigma; (mean of per-" << (p.Planar() ? "angle" : "attitude")
    << " standard deviations)</td><td>" << u.Inertia(t1.Num("raw_sigma_kg_m2"), "%.3g")
    << "</td><td class=\"l\">" << u.name << "</td></tr>\n";
  h << "<tr><td class=\"l\">coefficient of variation (mean per "
    << (p.Planar() ? "angle" : "attitude") << ")</td><td>" << Fmt(t1.Num("cv_percent"), "%.3g")
    << "</td><td class=\"l\">%</td></tr>\n";
  h << "<tr><td class=\"l\">regression RMSE" << (p.Planar() ? "" : " (tensor fit)") << "</td><td>"
    << u.Inertia(rmse, "%.3g") << "</td><td class=\"l\">" << u.name << "</td></tr>\n</table>\n";
  const R rig = p.results.Get("rig");
  // A mass or rig inertia the config does not give reads "not configured", never 0.0000.
  const double aircraft_mass = rig.Num("aircraft_mass_kg");
  const std::string source = rig.Str("inertia_source");
  const double rig_inertia = rig.Num("inertia_kg_m2");
  h << "<p>Rig: L = " << Fmt(rig.Num("filar_length_m"), "%.4f")
    << " m, D = " << Fmt(rig.Num("filar_separation_m"), "%.4f") << " m, rig mass "
    << Fmt(rig.Num("mass_kg"), "%.4g") << " kg, aircraft mass "
    << (aircraft_mass > 0 ? Fmt(aircraft_mass, "%.4g") + " kg" : std::string("not configured"))
    << ", g = " << Fmt(rig.Num("gravity_mps2"), "%.5f") << " m/s<sup>2</sup>. Rig inertia";
  if (source.empty() || source == "none" || !std::isfinite(rig_inertia)) {
    h << ": not configured (the moments are of everything that hangs)";
  } else {
    h << " (" << Escape(source) << "): " << u.Value(rig_inertia, rig.Num("inertia_std_kg_m2"))
      << " &plusmn; " << u.Std(rig.Num("inertia_std_kg_m2")) << " " << u.name;
    if (source == "tare") h << " from " << rig.Int("tare_n") << " tare log(s)";
  }
  h << ".</p>\n";
  WriteCalibration(p, h);
}

// Figures 3 and 4 (those drawn), and the NACA Report 467 comparison of I_xz when it applies.
void WriteEllipseSection(ReportPage& p, std::ostream& h) {
  const Units& u = p.u;
  const R& ellipse = p.ellipse;
  const std::string moments = p.figures.Str("moments"), polar = p.figures.Str("polar");
  if (!moments.empty()) {
    h << "<h2>Figure 3: moment of inertia against pitch</h2>\n"
      << Figure(p.out_dir, moments, "moments of inertia against pitch angle", "fig",
                &p.figures_drawn)
      << "\n";
  }
  if (!polar.empty()) {
    h << "<h2>Figure 4: ellipse of inertia</h2>\n"
      << Figure(p.out_dir, polar, "polar plot of the ellipse of inertia", "fig", &p.figures_drawn)
      << "\n";
  }
  const std::vector<R> naca = ellipse.Items("naca");
  if (naca.empty()) return;
  const Estimate ixz = GetEstimate(ellipse, "Ixz_kg_m2");
  h << "<h2>NACA Report 467 comparison</h2>\n<p>I<sub>xz</sub> from one oblique angle (paper Eq. "
       "1) "
       "against the multi-angle fit "
    << u.Value(ixz.value, ixz.std) << " &plusmn; " << u.Std(ixz.std) << " " << u.name << ".</p>\n"
    << kScrollOpen
    << "<table><tr><th>pitch (deg)</th><th>I<sub>xz</sub> NACA 467</th><th>std</th>"
       "<th>difference from fit</th></tr>\n";
  for (const R& e : naca) {
    const double v = e.Num("Ixz_kg_m2"), s = e.Num("Ixz_std_kg_m2");
    h << "<tr><td>" << Fmt(e.Num("pitch_deg"), "%.1f") << "</td><td>" << u.Value(v, s)
      << "</td><td>" << u.Std(s) << "</td><td>" << u.Value(v - ixz.value, s) << "</td></tr>\n";
  }
  h << "</table>" << kScrollClose;
}

// The principal moments, axes and Euler angles of a full tensor.
void WritePrincipal(const ReportPage& p, std::ostream& h) {
  const Units& u = p.u;
  const R& tensor = p.tensor;
  const std::vector<double> moments = tensor.Nums("principal_moments_kg_m2");
  if (moments.size() != 3) return;
  const std::vector<double> stds = tensor.Nums("principal_moments_kg_m2_std");
  const std::vector<double> axes_std = tensor.Nums("principal_axes_std_deg");
  const std::vector<std::vector<double>> axes = tensor.Rows("principal_axes");
  const auto at = [](const std::vector<double>& a, size_t i) { return i < a.size() ? a[i] : NAN; };
  const double common = p.results.Get("total_uncertainty").Num("common_mode_relative_std");
  h << kScrollOpen
    << "<table><tr><th>principal</th><th>moment</th><th>std (stat)</th><th>std (total)</th>"
       "<th>axis x</th><th>axis y</th><th>axis z</th><th>axis std (deg)</th></tr>\n";
  for (size_t k = 0; k < 3; ++k) {
    h << "<tr><td>" << k + 1 << "</td><td>" << u.Value(moments[k], at(stds, k)) << "</td><td>"
      << u.Std(at(stds, k)) << "</td><td>"
      << u.Std(WithCommonModeScale(moments[k], at(stds, k), common));
    const std::vector<double> a = k < axes.size() ? axes[k] : std::vector<double>();
    for (size_t c = 0; c < 3; ++c) h << "</td><td>" << Fmt(at(a, c), "%+.4f");
    h << "</td><td>" << Fmt(at(axes_std, k), "%.2f") << "</td></tr>\n";
  }
  h << "</table>" << kScrollClose;
  const R euler = tensor.Get("principal_euler_deg");
  h << "<p>Principal axes from body axes (Z-Y-X Euler angles, each principal axis matched to the "
       "nearest body axis): roll "
    << Fmt(euler.Num("roll"), "%.3f") << " &plusmn; " << Fmt(euler.Num("roll_std"), "%.3f")
    << ", pitch " << Fmt(euler.Num("pitch"), "%.3f") << " &plusmn; "
    << Fmt(euler.Num("pitch_std"), "%.3f") << ", yaw " << Fmt(euler.Num("yaw"), "%.3f")
    << " &plusmn; " << Fmt(euler.Num("yaw_std"), "%.3f") << " deg.</p>\n";
}

// The per-orientation residuals of the tensor fit, roll and pitch of each.
void WriteOrientations(const ReportPage& p, std::ostream& h) {
  const Units& u = p.u;
  const double common = p.results.Get("total_uncertainty").Num("common_mode_relative_std");
  h << "<h2>Per-orientation residuals</h2>\n"
    << kScrollOpen
    << "<table><tr><th>#</th><th>roll (deg)</th><th>pitch (deg)</th><th>axis in body</th>"
       "<th>logs</th><th>mean ("
    << u.name
    << ")</th><th>std (stat)</th><th>std (total)</th>"
       "<th>fitted</th><th>residual</th><th>residual / expected</th></tr>\n";
  int index = 0;
  for (const R& o : p.tensor.Items("orientations")) {
    const std::vector<double> axis = o.Nums("axis_in_body");
    std::string axis_text = "&ndash;";
    if (axis.size() == 3) {
      axis_text =
          "(" + Fixed(axis[0], 3) + ", " + Fixed(axis[1], 3) + ", " + Fixed(axis[2], 3) + ")";
    }
    const double z = o.Num("z"), scatter = o.Num("scatter_kg_m2");
    const double d_std = scatter > 0 ? scatter : std::fabs(o.Num("residual_kg_m2"));
    // The mean's std: its expected scatter (the weights and variance factor of the fit).
    const double mean_std = o.Num("residual_std_kg_m2");
    h << "<tr><td>" << ++index << "</td><td>" << Fmt(o.Num("roll_deg"), "%.1f") << "</td><td>"
      << Fmt(o.Num("pitch_deg"), "%.1f") << "</td><td>" << axis_text << "</td><td>" << o.Int("n")
      << "</td><td>" << u.Value(o.Num("mean_kg_m2"), d_std) << "</td><td>" << u.Std(mean_std)
      << "</td><td>" << u.Std(WithCommonModeScale(o.Num("mean_kg_m2"), mean_std, common))
      << "</td><td>" << u.Value(o.Num("fitted_kg_m2"), d_std) << "</td><td>"
      << u.Value(o.Num("residual_kg_m2"), d_std) << "</td><td"
      << (std::fabs(z) > 3 ? " class=\"bad\"" : "") << ">" << Fmt(z, "%+.2f") << "</td></tr>\n";
  }
  h << "</table>" << kScrollClose;
}

// The inertia tensor of a campaign that rolls: the six components with std and interval
// (unobservable ones named), the scatter and the logs behind it, the outliers, the principal
// moments and axes with the ellipsoid figure (a full tensor), the per-orientation residuals.
void WriteTensorSection(ReportPage& p, std::ostream& h) {
  const Units& u = p.u;
  const R& tensor = p.tensor;
  h << "<h2>Inertia tensor</h2>\n";
  if (!tensor.IsObject()) {
    h << "<p class=\"bad\">" << Escape(p.summary.tensor_message) << "</p>\n";
    return;
  }
  h << "<p>" << tensor.Int("n_points") << " moments about " << tensor.Int("n_orientations")
    << " axes; design rank " << tensor.Int("rank") << " of 6, condition number "
    << Fmt(tensor.Num("condition_number"), "%.3g") << "; covariance "
    << Escape(tensor.Str("covariance"));
  const double scatter = tensor.Num("attitude_scatter_deg");
  if (scatter > 0) h << "; attitude scatter " << Fmt(scatter, "%.2f") << " deg";
  h << ". Products are positive (I<sub>xy</sub> = &int; x y dm); the tensor holds their negatives "
       "(docs/physics.md &sect;3.5). Values are given to the digits their std supports.</p>\n";
  const double common = p.results.Get("total_uncertainty").Num("common_mode_relative_std");
  h << kScrollOpen
    << "<table><tr><th class=\"l\">component</th><th>value</th><th>std (stat)</th>"
       "<th>std (total)</th><th>interval (stat)</th><th class=\"l\">unit</th></tr>\n";
  for (int k = 0; k < kTensorComponents; ++k) {
    const char* name = TensorComponentName(k);
    const Estimate e = GetEstimate(tensor, std::string(name) + "_kg_m2");
    h << "<tr><td class=\"l\">I<sub>" << (name + 1) << "</sub></td>";
    if (!e.defined) {
      h << "<td colspan=\"4\" class=\"note\">not observable from these swing axes</td>";
    } else {
      h << "<td>" << u.Value(e.value, e.std) << "</td><td>" << u.Std(e.std) << "</td><td>"
        << u.Std(WithCommonModeScale(e.value, e.std, common)) << "</td><td>["
        << u.Value(e.lo, e.std) << ", " << u.Value(e.hi, e.std) << "]</td>";
    }
    h << "<td class=\"l\">" << u.name << "</td></tr>\n";
  }
  h << "</table>" << kScrollClose;
  h << "<p><b>std (stat)</b>: the logs' own errors and their scatter; <b>std (total)</b> adds in "
       "quadrature the common-mode terms (the configured uncertainties of L, D, g, the masses "
       "and the gyro scale, or the rig calibration), &plusmn;"
    << Fmt(100.0 * common, "%.2f")
    << " % of each component, one error that scales every component alike. Read the total when "
       "you use a number.</p>\n";
  const double relative = tensor.Num("relative_scatter");
  std::vector<std::pair<std::string, double>> logs;
  for (const R& l : tensor.Items("scatter_logs"))
    logs.emplace_back(l.Str("file"), l.Num("residual_over_std"));
  if (relative > 0 || scatter > 0) {
    h << "<p class=\"warn\">The moments scatter "
      << (relative > 0 ? "by " + Fmt(100.0 * relative, "%.2f") + " %"
                       : "as if each axis were off by " + Fmt(scatter, "%.2f") + " deg")
      << " beyond their logs' stds; the fit is weighed by that (docs/method.md)"
      << (logs.empty() ? "" : "; " + Escape(ScatterLogsText(logs))) << ".</p>\n";
  }
  WriteOutliers(p, h);
  WriteNotes(tensor.Strs("warnings"), u, h);
  WritePrincipal(p, h);
  const std::string figure = p.figures.Str("tensor");
  if (!figure.empty()) {
    h << "<h2>Ellipsoid of inertia and per-orientation residuals</h2>\n"
      << Figure(p.out_dir, figure, "ellipsoid of inertia in three plane views and residuals", "fig",
                &p.figures_drawn)
      << "\n";
  }
  WriteOrientations(p, h);
}

// Per-attitude statistics (roll, pitch), sorted numerically.
void WriteAngleTable(const ReportPage& p, std::ostream& h) {
  const Units& u = p.u;
  std::vector<R> angles = p.results.Items("angles");
  const auto roll = [](const R& a) {
    const double r = a.Num("roll_deg");
    return std::isfinite(r) ? r : 0.0;
  };
  std::stable_sort(angles.begin(), angles.end(), [&](const R& a, const R& b) {
    if (roll(a) != roll(b)) return roll(a) < roll(b);
    return a.Num("pitch_deg") < b.Num("pitch_deg");
  });
  h << "<h2>Per-" << (p.Planar() ? "angle" : "attitude") << " statistics</h2>\n"
    << kScrollOpen << "<table><tr><th>roll (deg)</th><th>pitch (deg)</th><th>n</th><th>mean ("
    << u.name << ")</th><th>std</th><th>sem</th><th>total of the mean</th><th>CV (%)</th></tr>\n";
  for (const R& a : angles) {
    const double sem = a.Num("inertia_sem_kg_m2");
    h << "<tr><td>" << Fmt(roll(a), "%.2f") << "</td><td>" << Fmt(a.Num("pitch_deg"), "%.2f")
      << "</td><td>" << a.Int("n") << "</td><td>" << u.Value(a.Num("inertia_mean_kg_m2"), sem)
      << "</td><td>" << u.Std(a.Num("inertia_std_kg_m2")) << "</td><td>" << u.Std(sem)
      << "</td><td>" << u.Std(a.Num("inertia_std_total_kg_m2")) << "</td><td>"
      << Fmt(a.Num("cv_percent"), "%.3f") << "</td></tr>\n";
  }
  h << "</table>" << kScrollClose;
}

// The traces that are not ok, with the reason.
void WriteRejectedTraces(const ReportPage& p, std::ostream& h) {
  int bad = 0;
  std::ostringstream rows;
  for (const TraceRow& row : p.traces) {
    const std::string status = ToString(row.t.status);
    if (row.t.ok()) continue;
    ++bad;
    rows << "<tr class=\"" << Escape(status) << "\"><td class=\"l\">" << Escape(row.t.file)
         << "</td><td class=\"l\">" << Escape(status) << "</td><td class=\"l w\">"
         << Escape(InDisplayUnits(p.u, row.t.message)) << "</td></tr>\n";
  }
  if (bad == 0) return;  // nothing to show: the header's counts say every trace was fitted
  h << "<h2>Rejected and failed traces</h2>\n"
    << kScrollOpen
    << "<table><tr><th class=\"l\">file</th><th class=\"l\">status</th><th "
       "class=\"l\">reason</th></tr>\n"
    << rows.str() << "</table>" << kScrollClose;
}

// Every fitted trace that raised a warning: one line per warning, its full text on click.
void WriteWarnings(const ReportPage& p, std::ostream& h) {
  std::ostringstream rows;
  int warned = 0;
  for (const TraceRow& row : p.traces) {
    if (!row.t.ok()) continue;  // rejected and failed: the section above
    const std::vector<std::string> warnings = TraceWarnings(row.t);
    if (warnings.empty()) continue;
    ++warned;
    rows << "<tr class=\"warned\"><td class=\"l\">" << Escape(row.t.file)
         << "</td><td class=\"l w\">";
    for (const std::string& w : warnings) rows << WarningItem(p.u, w);
    rows << "</td></tr>\n";
  }
  h << "<h2 id=\"warnings\">Warnings</h2>\n";
  if (warned == 0) {
    h << "<p class=\"ok\">None: no fitted trace raised a warning.</p>\n";
    return;
  }
  h << "<p class=\"warn\">" << warned << " fitted trace" << (warned == 1 ? "" : "s")
    << " raised warnings. Their numbers are in every table above; read why before you trust "
       "them (click a line for the full text).</p>\n"
    << kScrollOpen
    << "<table class=\"warnings\"><tr><th class=\"l\">file</th><th class=\"l\">warnings</th></tr>\n"
    << rows.str() << "</table>" << kScrollClose;
}

// The traces table's status cell: "ok (warned)" links to the Warnings section and carries the
// warnings' first lines as its tooltip.
std::string StatusCell(const Units& u, const TraceRecord& t) {
  const std::string shown = DisplayStatus(t);
  if (shown != "ok (warned)") return Escape(shown);
  std::string tip;
  for (const std::string& w : TraceWarnings(t)) {
    tip += (tip.empty() ? "" : "\n") + LineOfWarning(InDisplayUnits(u, w)).Text();
  }
  return "<a href=\"#warnings\" title=\"" + Escape(tip) + "\">" + Escape(shown) + "</a>";
}

// One row per trace, sorted by roll and pitch: role, status, attitude, total and aircraft
// inertia, window, amplitude.
void WriteTraceTable(const ReportPage& p, std::ostream& h) {
  const Units& u = p.u;
  h << "<h2>Traces</h2>\n"
    << kScrollOpen
    << "<table><tr><th class=\"l\">file</th><th class=\"l\">role</th>"
       "<th class=\"l\">status</th><th>roll (deg)</th><th>pitch (deg)</th><th>I total ("
    << u.name
    << ")</th><th>std (stat)</th><th>std (total)</th><th>period (s)</th><th>I aircraft</th><th>std "
       "(stat)</th>"
       "<th>std (total)</th><th>window (s)</th><th>amplitude (deg)</th><th>rms/noise</th></tr>\n";
  for (const TraceRow& row : p.traces) {
    const TraceRecord& t = row.t;
    const std::string status = ToString(t.status);
    std::string window = "&ndash;", amplitude = "&ndash;";
    const std::array<double, 2>& w = t.window_s;
    const std::array<double, 2>& a = t.amplitude_deg;
    // A pair is written only when both ends are finite (null otherwise).
    if (std::isfinite(w[0]) && std::isfinite(w[1]))
      window = Fmt(w[0], "%.2f") + "&ndash;" + Fmt(w[1], "%.2f");
    if (std::isfinite(a[0]) && std::isfinite(a[1]))
      amplitude = Fmt(a[0], "%.1f") + "&rarr;" + Fmt(a[1], "%.1f");
    const double total_std = t.inertia_total_std_kg_m2, std = t.inertia_std_kg_m2;
    const std::string row_class = DisplayStatus(t) == "ok (warned)" ? "warned"
                                  : status == "ok"                  ? ""
                                                                    : status;
    h << "<tr class=\"" << Escape(row_class) << "\"><td class=\"l\">" << Escape(t.file)
      << "</td><td class=\"l\">" << Escape(ToString(t.role)) << "</td><td class=\"l\">"
      << StatusCell(u, t) << "</td><td>" << Fmt(row.roll, "%.2f") << "</td><td>"
      << Fmt(row.pitch, "%.2f") << "</td><td>" << u.Value(t.inertia_total_kg_m2, total_std)
      << "</td><td>" << u.Std(total_std) << "</td><td>" << u.Std(t.inertia_total_std_total_kg_m2)
      << "</td><td>" << Fmt(t.period_s, "%.4f") << "</td><td>" << u.Value(t.inertia_kg_m2, std)
      << "</td><td>" << u.Std(std) << "</td><td>" << u.Std(t.inertia_std_total_kg_m2) << "</td><td>"
      << window << "</td><td>" << amplitude << "</td><td>"
      << Fmt(t.residual_rms_rad_per_s / t.noise_rms_rad_per_s, "%.2f") << "</td></tr>\n";
  }
  h << "</table>" << kScrollClose;
}

// A trace figure's caption after the status: the record's I with its stds, labelled (the number
// the tables give), period and small-angle I, and each warning's line.
std::string TraceCaptionFacts(const ReportPage& p, const TraceRecord& t) {
  std::string out;
  const double value = t.inertia_total_kg_m2, stat = t.inertia_total_std_kg_m2;
  const double total = t.inertia_total_std_total_kg_m2;
  if (std::isfinite(value)) {
    out += "<br>I<sub>total</sub> = " + p.u.Value(value, stat) + " &plusmn; " + p.u.Std(stat) +
           " (stat) &plusmn; " + p.u.Std(total) + " (total) " + p.u.name;
  }
  const double period = t.period_s;
  if (std::isfinite(period)) {
    out += " &middot; T = " + Fmt(period, "%.4f") +
           " s, small-angle I = " + p.u.Inertia(t.small_angle_inertia_total_kg_m2, "%.5f") + " " +
           p.u.name;
  }
  for (const std::string& w : TraceWarnings(t)) {
    out += "<br><span class=\"warn\">warning: " +
           WarningLineHtml(LineOfWarning(InDisplayUnits(p.u, w))) + "</span>";
  }
  return out;
}

// The per-trace section: every trace's figures (fit and residual) with its caption.
void WriteTraceFigures(ReportPage& p, std::ostream& h) {
  std::ostringstream figures;
  for (const TraceRow& row : p.traces) {
    const std::string& fig = row.t.figure;
    if (fig.empty()) continue;
    figures << "<figure>"
            << Figure(p.out_dir, fig, "fit of " + row.t.file, "trace", &p.figures_drawn)
            << "<figcaption>" << Escape(row.t.file) << " &middot; " << Escape(DisplayStatus(row.t))
            << TraceCaptionFacts(p, row.t) << "</figcaption></figure>\n"
            << SweepFigure(row.t, p.out_dir, &p.figures_drawn);
  }
  if (figures.tellp() == 0) return;  // no figures drawn (process --no-figures): no section
  h << "<h2>Fit and residual of every trace</h2>\n<p>Left, each trace: the measured samples of the "
       "swing rate (black dots) on the fit that gave I (light blue line), and beneath them that "
       "fit's residual (grey) with the &plusmn;1&sigma; gyro noise (red) and its rms, labelled "
       "with "
       "the part of the log it belongs to (the lowest-amplitude band or the whole window; a "
       "warning's &ldquo;residual N&times; noise&rdquo; is the whole window's). Its caption gives "
       "the record's I<sub>total</sub> with "
       "its stat and total std (the numbers of the tables), the measured period T "
       "and the small-angle inertia m g D<sup>2</sup> T<sup>2</sup> / (16 &pi;<sup>2</sup> L) of "
       "everything suspended, the hand check of the fitted I<sub>total</sub>. Right: I against "
       "amplitude.</p>\n<div class=\"traces\">\n"
    << figures.str() << "</div>\n";
}

// The config text used, and the end of the page.
void WriteFooter(const ReportPage& p, std::ostream& h) {
  h << "<h2>Config used</h2>\n<pre>" << Escape(p.results.Str("config")) << "</pre>\n";
  h << "</body></html>\n";
}

}  // namespace
}  // namespace report_page

std::string Base64(const std::string& bytes) {
  static const char* kTable = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  const auto* b = reinterpret_cast<const unsigned char*>(bytes.data());
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (b[i] << 16) | (b[i + 1] << 8) | b[i + 2];
    out += kTable[(v >> 18) & 63];
    out += kTable[(v >> 12) & 63];
    out += kTable[(v >> 6) & 63];
    out += kTable[v & 63];
  }
  if (i + 1 == bytes.size()) {
    const unsigned v = b[i] << 16;
    out += kTable[(v >> 18) & 63];
    out += kTable[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == bytes.size()) {
    const unsigned v = (b[i] << 16) | (b[i + 1] << 8);
    out += kTable[(v >> 18) & 63];
    out += kTable[(v >> 12) & 63];
    out += kTable[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

// header (main result) -> Table 1 and rig -> planar: Table 2, Figures 3 and 4, NACA 467; a
// campaign that rolls: the inertia tensor -> per-attitude table -> rejected traces -> warnings ->
// trace table -> per-trace figures -> footer. The paper's order (Table 1 before Table 2); the main
// result is first in the header's box.
namespace report_page {
namespace {

std::string BuildPage(const json& results, const std::string& out_dir, KeyLog* keys_read) {
  CheckFigureNames(results, out_dir);
  ReportPage page(results, out_dir, keys_read);
  std::ostringstream h;
  WriteHeader(page, h);
  WriteTable1AndRig(page, h);
  if (page.Planar()) {
    WriteTable2(page, h);
    WriteEllipseSection(page, h);
  } else {
    WriteTensorSection(page, h);
  }
  WriteAngleTable(page, h);
  WriteRejectedTraces(page, h);
  WriteWarnings(page, h);
  WriteTraceTable(page, h);
  WriteTraceFigures(page, h);
  WriteFooter(page, h);
  return ShareSvgGlyphs(ShareStyles(h.str()));
}

}  // namespace
}  // namespace report_page

std::string BuildReportHtml(const nlohmann::json& results, const std::string& out_dir) {
  return report_page::BuildPage(results, out_dir, nullptr);
}

KeyLog ReportKeysRead(const nlohmann::json& results, const std::string& out_dir) {
  KeyLog keys;
  report_page::BuildPage(results, out_dir, &keys);
  return keys;
}

void RunReport(const std::string& out_dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(out_dir, ec)) throw UserError(out_dir + ": no such folder");
  const OutputFolderLock lock(out_dir);
  const std::string path = (fs::path(out_dir) / "results.json").string();
  std::string bytes, why;
  if (!ReadRegularFile(path, OutputFileCap(), &bytes, &why)) throw UserError(why);
  nlohmann::json results;
  try {
    results = nlohmann::json::parse(bytes);
  } catch (const std::exception& e) {
    throw UserError(path + ": not valid JSON (" + DescribeJsonError(e) +
                    "); rerun `bifilar process` to rewrite it");
  }
  if (!results.is_object() || !results.contains("traces")) {
    throw UserError(path + ": not a bifilar results file (no 'traces')");
  }
  CheckResultsSchema(results, path);  // a newer schema: named before any key is read
  report_page::CheckFigureNames(results,
                                out_dir);  // before anything reads a file results.json names
  // A mixed set (a run killed between two renames) is reported, not turned into a page.
  const std::vector<std::string> problems = CheckOutputSet(out_dir, false);
  if (!problems.empty()) {
    throw UserError(
        out_dir + ": the outputs are a mixed set from different runs (" + problems.front() +
        (problems.size() > 1 ? ", and " + std::to_string(problems.size() - 1) + " more" : "") +
        "); rerun `bifilar process` to rewrite them");
  }
  std::string html;
  try {
    html = BuildReportHtml(results, out_dir);
  } catch (
      const nlohmann::json::exception& e) {  // a field of the wrong type: name the file, not json
    throw UserError(path + ": not a results file bifilar can read (" + DescribeJsonError(e) +
                    "); rerun `bifilar process` to rewrite it");
  } catch (const UserError& e) {  // ResultsReader: a key of the wrong type, named
    throw UserError(path + ": not a results file bifilar can read (" + e.what() +
                    "); rerun `bifilar process` to rewrite it");
  }
  WriteFileAtomically((fs::path(out_dir) / "report.html").string(),
                      StampReport(html, HashToHex(Fnv1a64(bytes))));
}

}  // namespace bifilar
