#include "pipeline/report/report.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <vector>

#include "base/atomic_file.h"
#include "base/bounded_read.h"
#include "base/hash.h"
#include "base/json_error.h"
#include "base/units.h"
#include "base/user_error.h"
#include "pipeline/figures/svg_compact.h"
#include "pipeline/logs/simulated_log.h"
#include "pipeline/records/total_uncertainty.h"
#include "pipeline/store/output_set.h"

namespace bifilar {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

std::string Escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

double Num(const json& j, const char* key) {
  if (!j.is_object()) return NAN;
  auto it = j.find(key);
  return it != j.end() && it->is_number() ? it->get<double>() : NAN;
}

std::string Str(const json& j, const char* key) {
  if (!j.is_object()) return "";
  auto it = j.find(key);
  return it != j.end() && it->is_string() ? it->get<std::string>() : "";
}

// Trace `t`'s warnings as the report shows them: every warning of the record except the assumed
// +-1 mm on L and D, which Table 2 states once for the campaign.
std::vector<std::string> TraceWarnings(const json& t) {
  std::vector<std::string> out;
  if (!t.is_object() || !t.contains("warnings") || !t["warnings"].is_array()) return out;
  for (const auto& w : t["warnings"]) {
    if (w.is_string() && !IsAssumedInputsWarning(w.get<std::string>())) out.push_back(w.get<std::string>());
  }
  return out;
}

// The status a reader sees: "ok (warned)" for an ok trace with warnings, else the record's.
std::string DisplayStatus(const json& t) {
  const std::string status = Str(t, "status");
  return status == "ok" && !TraceWarnings(t).empty() ? "ok (warned)" : status;
}

std::string Fmt(double value, const char* format = "%.4f") {
  if (!std::isfinite(value)) return "&ndash;";
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

struct Units {
  bool imperial = false;
  double scale = 1.0;  // display per kg m^2
  std::string name = "kg m<sup>2</sup>";
  std::string Inertia(double kg_m2, const char* format = "%.4f") const {
    return Fmt(kg_m2 * scale, format);
  }
};

// A message or warning as the page shows it: in the page's units (the fit writes them in SI).
std::string InDisplayUnits(const Units& u, const std::string& text) {
  return SiTextInDisplayUnits(text, u.imperial ? DisplayUnits::kImperial : DisplayUnits::kSi);
}

// An estimate of the ellipse JSON (pipeline/records/ellipse_json.h): KEY, KEY_std, KEY_ci95 [lo,
// hi]; null when undefined (tau, I_xp, I_zp when I_x ~ I_z).
struct Estimate {
  bool present = false, defined = false;
  double value = NAN, std = NAN, lo = NAN, hi = NAN;
};
Estimate GetEstimate(const json& ellipse, const std::string& key) {
  Estimate e;
  if (!ellipse.is_object() || !ellipse.contains(key)) return e;
  e.present = true;
  e.defined = ellipse[key].is_number();
  e.value = Num(ellipse, key.c_str());
  e.std = Num(ellipse, (key + "_std").c_str());
  const json ci = ellipse.value(key + "_ci95", json(nullptr));
  if (ci.is_array() && ci.size() == 2 && ci[0].is_number() && ci[1].is_number()) {
    e.lo = ci[0].get<double>();
    e.hi = ci[1].get<double>();
  }
  return e;
}

// A figure file as page content: an SVG inline (its ids prefixed, so the glyph and clip ids that
// every cairo SVG names alike do not collide; a third smaller than base64), a PNG as a base64
// data URI.
std::string Figure(const std::string& out_dir, const std::string& name, const std::string& alt,
                   const std::string& css_class, int* counter) {
  if (name.empty()) return "<p class=\"note\">(no figure)</p>";
  std::string bytes, why;
  const std::string path = (fs::path(out_dir) / "figures" / name).string();
  if (!ReadRegularFile(path, FigureCap(), &bytes, &why)) {
    return "<p class=\"note\">(figure " + Escape(name) + " missing)</p>";
  }
  const std::string ext = fs::path(name).extension().string();
  if (ext == ".svg") {
    const size_t start = bytes.find("<svg");
    if (start == std::string::npos) return "<p class=\"note\">(figure " + Escape(name) + " unreadable)</p>";
    const std::string prefix = "f" + std::to_string((*counter)++) + "-";
    std::string svg = PrefixSvgIds(CompactSvg(bytes.substr(start)), prefix);
    svg.replace(0, 4, "<svg class=\"" + css_class + "\" role=\"img\" aria-label=\"" + Escape(alt) + "\"");
    return svg;
  }
  return "<img class=\"" + css_class + "\" alt=\"" + Escape(alt) + "\" src=\"data:image/png;base64," +
         Base64(bytes) + "\">";
}

// The amplitude-sweep figure beside trace `t`'s fit figure (I against amplitude,
// pipeline/figures/sweep_plot.h), or a note saying why there is none: a trace without a sweep gets
// no figure and no link.
std::string SweepFigure(const json& t, const std::string& out_dir, int* counter) {
  const std::string name = Str(t, "sweep_figure"), file = Escape(Str(t, "file"));
  const json sweep = t.contains("amplitude_sweep") ? t["amplitude_sweep"] : json::object();
  if (name.empty()) {
    const std::string note = Str(sweep, "note");
    return "<figure><p class=\"note\">" + file + ": no amplitude sweep" +
           (note.empty() ? std::string() : " (" + Escape(note) + ")") + ".</p></figure>\n";
  }
  // The compact figure has no legend: the caption is its legend.
  const bool trend = sweep.is_object() && sweep.value("trend_detected", false);
  const std::string alt = "I against amplitude, " + Str(t, "file");
  return "<figure>" + Figure(out_dir, name, alt, "sweep", counter) + "<figcaption>" + file +
         " &middot; I against amplitude, flat for the ideal model: each band &plusmn; 1&sigma; "
         "over its amplitude range; blue, the result &plusmn; 1&sigma;" +
         (trend ? "; red, the trend I<sub>0</sub>(1 + c A<sup>" +
                      Fmt(sweep.value("trend_exponent", 2.0), "%g") +
                      "</sup>) and a ring on the band the "
                  "result is taken from"
                : "") +
         "</figcaption></figure>\n";
}

const char* kStyle = R"(
body { font-family: sans-serif; margin: 2em auto; max-width: 1100px; color: #222; }
h1 { font-size: 1.6em; } h2 { border-bottom: 1px solid #ccc; padding-bottom: .2em; margin-top: 2em; }
table { border-collapse: collapse; margin: .5em 0 1em; font-size: .9em; }
th, td { border: 1px solid #ccc; padding: .25em .6em; text-align: right; }
th { background: #f2f2f2; } td.l, th.l { text-align: left; }
tr.rejected td { background: #fff4e0; } tr.warned td { background: #fffbe0; } tr.error td { background: #fde8e8; }
.note { color: #666; font-style: italic; }
img.fig, svg.fig { max-width: 100%; height: auto; border: 1px solid #ddd; }
.traces { display: flex; flex-wrap: wrap; gap: 10px; }
.traces figure { margin: 0; width: 540px; }
.traces img, .traces svg { width: 540px; height: auto; border: 1px solid #ddd; }
figcaption { font-size: .8em; color: #444; }
pre { background: #f7f7f7; padding: .8em; overflow-x: auto; font-size: .85em; }
.ok { color: #1a7f37; } .bad { color: #b42318; }
)";

// What every section reads: the results document, its parts, the units, and the number of
// figures embedded so far (the inline SVGs' id prefixes).
struct ReportPage {
  ReportPage(const json& results_in, const std::string& out_dir_in)
      : results(results_in), out_dir(out_dir_in) {
    if (Str(results, "units") == "imperial") {
      u.imperial = true;
      u.scale = kSlugFt2PerKgM2;
      u.name = "slug ft<sup>2</sup>";
    }
  }
  json Part(const char* key, const json& fallback) const {
    return results.contains(key) ? results[key] : fallback;
  }
  const json& results;
  const std::string& out_dir;
  Units u;
  const json summary = Part("summary", json::object());
  const json ellipse = Part("ellipse", json(nullptr));
  const json traces = Part("traces", json::array());
  const json angles = Part("angles", json::array());
  const json figures = Part("figures", json::object());
  int figures_drawn = 0;
};

// Title, version, config and the trace counts.
void WriteHeader(const ReportPage& p, std::ostream& h) {
  const json& summary = p.summary;
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
    << "<title>bifilar report</title><style>" << kStyle << "</style></head><body>\n";
  h << "<h1>Mass properties from bifilar pendulum swings</h1>\n";
  h << "<p>bifilar " << Escape(Str(p.results, "version")) << " &middot; config <code>"
    << Escape(Str(p.results, "config_file")) << "</code> &middot; pitch source "
    << Escape(Str(p.results, "pitch_source"));
  // The fit's model and ODE solver (fit.integrator or --integrator), and glitch removal when off.
  const json settings = p.results.is_object() ? p.results.value("fit_settings", json::object())
                                              : json::object();
  if (settings.is_object() && settings.contains("integrator")) {
    h << " &middot; fit model " << Escape(Str(settings, "model")) << ", integrator <code>"
      << Escape(Str(settings, "integrator")) << "</code>";
    const json glitch = settings.value("glitch", json::object());
    if (glitch.is_object() && !glitch.value("enabled", true)) h << ", glitch removal off";
  }
  h << ". Traces: " << summary.value("n_traces", 0)
    << " (<span class=\"ok\">" << summary.value("n_ok", 0) << " ok</span>, "
    << summary.value("n_rejected", 0) << " rejected, " << summary.value("n_error", 0)
    << " error); fits reused from cache: " << summary.value("n_reused", 0) << ".</p>\n";
  // Simulated logs say so in their warnings (pipeline/logs/simulated_log.h): the page says it first.
  int simulated = 0;
  for (const auto& t : p.traces) {
    bool marked = false;
    if (t.is_object() && t.contains("warnings") && t["warnings"].is_array()) {
      for (const auto& w : t["warnings"]) {
        marked = marked || (w.is_string() && IsSimulatedLogWarning(w.get<std::string>()));
      }
    }
    simulated += marked ? 1 : 0;
  }
  if (simulated > 0) {
    h << "<p class=\"bad\">Simulated data: " << simulated << " of the " << p.traces.size()
      << " logs were written by <code>bifilar simulate</code>, not measured (see Warnings).</p>\n";
  }
}

// Table 2: I_x, I_z, I_xz, tau and the principal moments with std and interval, the systematic
// share, the ellipse's warnings; or why there is no ellipse.
void WriteTable2(const ReportPage& p, std::ostream& h) {
  const Units& u = p.u;
  const json& ellipse = p.ellipse;
  h << "<h2>Table 2: inertia properties</h2>\n";
  if (!ellipse.is_object()) {
    h << "<p class=\"bad\">"
      << Escape(p.summary.value("ellipse_message", std::string("ellipse not fitted"))) << "</p>\n";
    return;
  }
  // The total column (results.json total_uncertainty, pipeline/records/total_uncertainty.h): the
  // std and the common-mode scale terms in quadrature.
  const json total = p.Part("total_uncertainty", json::object());
  h << "<table><tr><th class=\"l\">quantity</th><th>value</th><th>std (stat)</th>"
       "<th>std (total)</th><th>interval (stat)</th><th class=\"l\">unit</th></tr>\n";
  struct Row { const char* key; const char* label; bool angle; };
  for (const Row& row : {Row{"Ix_kg_m2", "I<sub>x</sub>", false}, Row{"Iz_kg_m2", "I<sub>z</sub>", false},
                         Row{"Ixz_kg_m2", "I<sub>xz</sub>", false}, Row{"tau_deg", "&tau; (principal inclination)", true},
                         Row{"Ixp_kg_m2", "I<sub>xp</sub> (principal)", false},
                         Row{"Izp_kg_m2", "I<sub>zp</sub> (principal)", false}}) {
    const Estimate e = GetEstimate(ellipse, row.key);
    if (!e.present) continue;
    h << "<tr><td class=\"l\">" << row.label << "</td>";
    const double e_total = Num(total, row.key);
    if (!e.defined) {
      h << "<td colspan=\"4\">ill-defined (I<sub>x</sub> &asymp; I<sub>z</sub>)</td>";
    } else if (row.angle) {
      h << "<td>" << Fmt(e.value) << "</td><td>" << Fmt(e.std) << "</td><td>" << Fmt(e_total)
        << "</td><td>[" << Fmt(e.lo) << ", " << Fmt(e.hi) << "]</td>";
    } else {
      h << "<td>" << u.Inertia(e.value) << "</td><td>" << u.Inertia(e.std) << "</td><td>"
        << u.Inertia(e_total) << "</td><td>[" << u.Inertia(e.lo) << ", " << u.Inertia(e.hi)
        << "]</td>";
    }
    h << "<td class=\"l\">" << (row.angle ? "deg" : u.name) << "</td></tr>\n";
  }
  h << "</table>\n";
  const bool calibrated = p.Part("calibration", json(nullptr)).is_object();
  const double common = Num(total, "common_mode_relative_std");
  const bool assumed = total.is_object() && total.value("configured_inputs_assumed", false);
  h << "<p><b>std (stat)</b>: the scatter between trials and angles, the fits' own errors and the "
       "rig inertia's offset; the interval is its 95 % bootstrap interval. <b>std (total)</b> adds "
       "in quadrature the common-mode terms, one error shared by every moment: the "
    << (calibrated ? "rig calibration (it replaces the uncertainties of L, D and g)"
                   : std::string("uncertainties of L, D") +
                         (assumed ? " (<b>assumed</b> &plusmn;1 mm: no <code>rig.uncertainties</code>)"
                                  : "") +
                         ", g")
    << ", the masses and the gyro scale, &plusmn;" << Fmt(100.0 * common, "%.2f")
    << " % of each moment. It scales every moment alike and leaves &tau; unchanged. Read the total "
       "when you use a number; compare trials or set-ups with the stat std.</p>\n";
  const std::string note = Str(total, "note");
  if (!note.empty()) h << "<p class=\"bad\">" << Escape(note) << "</p>\n";
  if (ellipse.contains("warnings")) {
    for (const auto& w : ellipse["warnings"]) {
      if (w.is_string()) h << "<p class=\"note\">" << Escape(w.get<std::string>()) << "</p>\n";
    }
  }
}

// rig.calibration: effective against configured geometry, the factor with its std and parts.
void WriteCalibration(const ReportPage& p, std::ostream& h) {
  const json c = p.Part("calibration", json(nullptr));
  if (!c.is_object()) return;
  const json nominal = c.value("nominal", json::object()), effective = c.value("effective", json::object());
  const json parts = c.value("relative_std_parts", json::object());
  const json swings = c.value("swings", json::object()), reference = c.value("reference", json::object());
  h << "<h2>Rig calibration (reference object)</h2>\n<table><tr><th class=\"l\">geometry</th>"
       "<th>L (m)</th><th>D (m)</th><th>D<sup>2</sup>/L (m)</th></tr>\n";
  for (const auto& [label, g] : {std::make_pair("configured", nominal), std::make_pair("effective", effective)}) {
    h << "<tr><td class=\"l\">" << label << "</td><td>" << Fmt(Num(g, "filar_length_m"), "%.4f")
      << "</td><td>" << Fmt(Num(g, "filar_separation_m"), "%.5f") << "</td><td>"
      << Fmt(Num(g, "d2_over_l_m"), "%.6f") << "</td></tr>\n";
  }
  h << "</table>\n<p>Factor k = " << Fmt(Num(c, "factor"), "%.5f") << " &plusmn; "
    << Fmt(Num(c, "factor_std"), "%.5f") << " (&plusmn;" << Fmt(100.0 * Num(c, "factor_relative_std"), "%.3f")
    << " %, common to every moment: reference inertia " << Fmt(100.0 * Num(parts, "reference_inertia"), "%.3f")
    << " %, reference swings " << Fmt(100.0 * Num(parts, "reference_swings"), "%.3f") << " %, rig inertia "
    << Fmt(100.0 * Num(parts, "rig_inertia"), "%.3f") << " %), from " << swings.value("n", 0)
    << " swing(s) of a reference of " << p.u.Inertia(Num(reference, "inertia_kg_m2"), "%.5g") << " "
    << p.u.name << " and " << Fmt(Num(reference, "mass_kg"), "%.4g")
    << " kg. Every trace, tare logs included, was fitted with the effective geometry; the "
       "tape-measure uncertainties of L and D and that of g do not apply.</p>\n";
  for (const auto& w : c.value("warnings", json::array())) {
    if (w.is_string()) h << "<p class=\"note\">" << Escape(w.get<std::string>()) << "</p>\n";
  }
}

// The inertia tensor of a campaign that rolls (or has too few pitch angles for the ellipse):
// the six components with std and interval (unobservable ones named), the principal moments,
// axes and Euler angles, the principal-axes figure, the per-orientation residuals. Nothing for a
// planar campaign (its tensor section repeats Table 2).
void WriteTensorSection(ReportPage& p, std::ostream& h) {
  const Units& u = p.u;
  const json tensor = p.Part("tensor", json(nullptr));
  if (!tensor.is_object() || Str(tensor, "mode") == "planar_xz") return;
  h << "<h2>Inertia tensor</h2>\n<p>" << tensor.value("n_points", 0) << " moments about "
    << tensor.value("n_orientations", 0) << " axes; design rank " << tensor.value("rank", 0)
    << " of 6, condition number " << Fmt(Num(tensor, "condition_number"), "%.3g")
    << "; covariance " << Escape(Str(tensor, "covariance"));
  const double scatter = Num(tensor, "attitude_scatter_deg");
  if (scatter > 0) h << "; attitude scatter " << Fmt(scatter, "%.2f") << " deg";
  h << ". Products are positive (I<sub>xy</sub> = &int; x y dm); the tensor holds their negatives "
       "(docs/physics.md &sect;3.5).</p>\n";
  h << "<table><tr><th class=\"l\">component</th><th>value</th><th>std</th><th>interval</th>"
       "<th class=\"l\">unit</th></tr>\n";
  for (const char* name : {"Ixx", "Iyy", "Izz", "Ixy", "Ixz", "Iyz"}) {
    const Estimate e = GetEstimate(tensor, std::string(name) + "_kg_m2");
    h << "<tr><td class=\"l\">I<sub>" << (name + 1) << "</sub></td>";
    if (!e.defined) {
      h << "<td colspan=\"3\">not observable from these swing axes</td>";
    } else {
      h << "<td>" << u.Inertia(e.value, "%.5g") << "</td><td>" << u.Inertia(e.std, "%.2g")
        << "</td><td>[" << u.Inertia(e.lo, "%.5g") << ", " << u.Inertia(e.hi, "%.5g") << "]</td>";
    }
    h << "<td class=\"l\">" << u.name << "</td></tr>\n";
  }
  h << "</table>\n";
  const json moments = tensor.value("principal_moments_kg_m2", json(nullptr));
  if (moments.is_array() && moments.size() == 3) {
    const json stds = tensor.value("principal_moments_kg_m2_std", json::array());
    const json axes = tensor.value("principal_axes", json::array());
    const json axes_std = tensor.value("principal_axes_std_deg", json::array());
    h << "<table><tr><th>principal</th><th>moment</th><th>std</th><th>axis x</th><th>axis y</th>"
         "<th>axis z</th><th>axis std (deg)</th></tr>\n";
    for (int k = 0; k < 3; ++k) {
      auto at = [](const json& a, int i) {
        return a.is_array() && i < static_cast<int>(a.size()) && a[i].is_number() ? a[i].get<double>()
                                                                                : NAN;
      };
      const json axis = k < static_cast<int>(axes.size()) ? axes[k] : json::array();
      h << "<tr><td>" << k + 1 << "</td><td>" << u.Inertia(at(moments, k), "%.5g") << "</td><td>"
        << u.Inertia(at(stds, k), "%.2g") << "</td><td>" << Fmt(at(axis, 0)) << "</td><td>"
        << Fmt(at(axis, 1)) << "</td><td>" << Fmt(at(axis, 2)) << "</td><td>"
        << Fmt(at(axes_std, k), "%.2f") << "</td></tr>\n";
    }
    h << "</table>\n";
    const json euler = tensor.value("principal_euler_deg", json::object());
    h << "<p>Principal axes from body axes (Z-Y-X Euler angles, each principal axis matched to the "
         "nearest body axis): roll "
      << Fmt(Num(euler, "roll"), "%.3f") << " &plusmn; " << Fmt(Num(euler, "roll_std"), "%.3f")
      << ", pitch " << Fmt(Num(euler, "pitch"), "%.3f") << " &plusmn; "
      << Fmt(Num(euler, "pitch_std"), "%.3f") << ", yaw " << Fmt(Num(euler, "yaw"), "%.3f")
      << " &plusmn; " << Fmt(Num(euler, "yaw_std"), "%.3f") << " deg.</p>\n";
  }
  h << "<p>Uncertainties are statistical; the configured uncertainties add a systematic &plusmn;"
    << Fmt(100.0 * Num(tensor, "systematic_relative_std"), "%.2f")
    << " % that scales every component alike.</p>\n";
  for (const auto& w : tensor.value("warnings", json::array())) {
    if (w.is_string()) h << "<p class=\"note\">" << Escape(w.get<std::string>()) << "</p>\n";
  }
  if (!Str(p.figures, "tensor").empty()) {
    h << "<h2>Principal axes and per-orientation residuals</h2>\n"
      << Figure(p.out_dir, Str(p.figures, "tensor"),
                "ellipsoid of inertia in three plane views and residuals", "fig", &p.figures_drawn)
      << "\n";
  }
  h << "<h2>Per-orientation residuals</h2>\n<table><tr><th>#</th><th>roll (deg)</th>"
       "<th>pitch (deg)</th><th>axis in body</th><th>logs</th><th>mean</th><th>fitted</th>"
       "<th>residual</th><th>residual / expected</th></tr>\n";
  int index = 0;
  for (const auto& o : tensor.value("orientations", json::array())) {
    const json axis = o.value("axis_in_body", json::array());
    std::string axis_text = "&ndash;";
    if (axis.is_array() && axis.size() == 3 && axis[0].is_number()) {
      axis_text = "(" + Fmt(axis[0].get<double>(), "%.3f") + ", " + Fmt(axis[1].get<double>(), "%.3f") +
                  ", " + Fmt(axis[2].get<double>(), "%.3f") + ")";
    }
    const double z = Num(o, "z");
    h << "<tr><td>" << ++index << "</td><td>" << Fmt(Num(o, "roll_deg"), "%.1f") << "</td><td>"
      << Fmt(Num(o, "pitch_deg"), "%.1f") << "</td><td>" << axis_text << "</td><td>"
      << o.value("n", 0) << "</td><td>" << u.Inertia(Num(o, "mean_kg_m2"), "%.5g") << "</td><td>"
      << u.Inertia(Num(o, "fitted_kg_m2"), "%.5g") << "</td><td>"
      << u.Inertia(Num(o, "residual_kg_m2"), "%.2g") << "</td><td"
      << (std::fabs(z) > 3 ? " class=\"bad\"" : "") << ">" << Fmt(z, "%+.2f") << "</td></tr>\n";
  }
  h << "</table>\n";
}

// Table 1 (data quality) and the rig line.
void WriteTable1AndRig(const ReportPage& p, std::ostream& h) {
  const Units& u = p.u;
  const json t1 = p.Part("table1", json::object());
  h << "<h2>Table 1: data quality</h2>\n<table><tr><th class=\"l\">statistic</th><th>value</th>"
       "<th class=\"l\">unit</th></tr>\n";
  h << "<tr><td class=\"l\">raw data &sigma; (mean of per-angle standard deviations)</td><td>"
    << u.Inertia(Num(t1, "raw_sigma_kg_m2")) << "</td><td class=\"l\">" << u.name << "</td></tr>\n";
  h << "<tr><td class=\"l\">coefficient of variation (mean per angle)</td><td>"
    << Fmt(Num(t1, "cv_percent"), "%.4f") << "</td><td class=\"l\">%</td></tr>\n";
  h << "<tr><td class=\"l\">regression RMSE</td><td>" << u.Inertia(Num(t1, "regression_rmse_kg_m2"))
    << "</td><td class=\"l\">" << u.name << "</td></tr>\n</table>\n";
  const json rig = p.Part("rig", json::object());
  h << "<p>Rig: L = " << Fmt(Num(rig, "filar_length_m"), "%.4f") << " m, D = "
    << Fmt(Num(rig, "filar_separation_m"), "%.4f") << " m, rig mass "
    << Fmt(Num(rig, "mass_kg"), "%.4f") << " kg, aircraft mass "
    << Fmt(Num(rig, "aircraft_mass_kg"), "%.4f") << " kg, g = "
    << Fmt(Num(rig, "gravity_mps2"), "%.5f") << " m/s<sup>2</sup>. Rig inertia ("
    << Escape(Str(rig, "inertia_source")) << "): " << u.Inertia(Num(rig, "inertia_kg_m2"), "%.5f")
    << " &plusmn; " << u.Inertia(Num(rig, "inertia_std_kg_m2"), "%.2e") << " " << u.name;
  if (Str(rig, "inertia_source") == "tare") h << " from " << rig.value("tare_n", 0) << " tare log(s)";
  h << ".</p>\n";
  WriteCalibration(p, h);
}

// Figures 3 and 4, and the NACA Report 467 comparison of I_xz.
void WriteEllipseSection(ReportPage& p, std::ostream& h) {
  const Units& u = p.u;
  const json& ellipse = p.ellipse;
  h << "<h2>Figure 3: moment of inertia against pitch</h2>\n"
    << Figure(p.out_dir, Str(p.figures, "moments"), "moments of inertia against pitch angle", "fig", &p.figures_drawn)
    << "\n<h2>Figure 4: ellipse of inertia</h2>\n"
    << Figure(p.out_dir, Str(p.figures, "polar"), "polar plot of the ellipse of inertia", "fig", &p.figures_drawn) << "\n";
  h << "<h2>NACA Report 467 comparison</h2>\n";
  if (!(ellipse.is_object() && ellipse.contains("naca") && !ellipse["naca"].empty())) {
    h << "<p class=\"note\">No NACA 467 estimate (needs the ellipse fit and oblique angles).</p>\n";
    return;
  }
  const Estimate ixz = GetEstimate(ellipse, "Ixz_kg_m2");
  h << "<p>I<sub>xz</sub> from one oblique angle (paper Eq. 1) against the multi-angle fit "
    << u.Inertia(ixz.value) << " &plusmn; " << u.Inertia(ixz.std) << " " << u.name << ".</p>\n"
    << "<table><tr><th>pitch (deg)</th><th>I<sub>xz</sub> NACA 467</th><th>std</th>"
       "<th>difference from fit</th></tr>\n";
  for (const auto& e : ellipse["naca"]) {
    const double v = Num(e, "Ixz_kg_m2");
    h << "<tr><td>" << Fmt(Num(e, "pitch_deg"), "%.1f") << "</td><td>" << u.Inertia(v)
      << "</td><td>" << u.Inertia(Num(e, "Ixz_std_kg_m2")) << "</td><td>"
      << u.Inertia(v - ixz.value) << "</td></tr>\n";
  }
  h << "</table>\n";
}

void WriteAngleTable(const ReportPage& p, std::ostream& h) {
  const Units& u = p.u;
  h << "<h2>Per-angle statistics</h2>\n<table><tr><th>pitch (deg)</th><th>n</th><th>mean ("
    << u.name << ")</th><th>std</th><th>sem</th><th>total of the mean</th><th>CV (%)</th></tr>\n";
  for (const auto& a : p.angles) {
    h << "<tr><td>" << Fmt(Num(a, "pitch_deg"), "%.2f") << "</td><td>" << a.value("n", 0)
      << "</td><td>" << u.Inertia(Num(a, "inertia_mean_kg_m2")) << "</td><td>"
      << u.Inertia(Num(a, "inertia_std_kg_m2"), "%.5f") << "</td><td>"
      << u.Inertia(Num(a, "inertia_sem_kg_m2"), "%.5f") << "</td><td>"
      << u.Inertia(Num(a, "inertia_std_total_kg_m2"), "%.5f") << "</td><td>"
      << Fmt(Num(a, "cv_percent"), "%.3f") << "</td></tr>\n";
  }
  h << "</table>\n";
}

// The traces that are not ok, with the reason.
void WriteRejectedTraces(const ReportPage& p, std::ostream& h) {
  h << "<h2>Rejected and failed traces</h2>\n";
  int bad = 0;
  std::ostringstream rows;
  for (const auto& t : p.traces) {
    const std::string status = Str(t, "status");
    if (status == "ok") continue;
    ++bad;
    rows << "<tr class=\"" << Escape(status) << "\"><td class=\"l\">" << Escape(Str(t, "file"))
         << "</td><td class=\"l\">" << Escape(status) << "</td><td class=\"l\">"
         << Escape(InDisplayUnits(p.u, Str(t, "message"))) << "</td></tr>\n";
  }
  if (bad == 0) {
    h << "<p class=\"ok\">None: every trace was fitted (warnings, if any, are listed below).</p>\n";
  } else {
    h << "<table><tr><th class=\"l\">file</th><th class=\"l\">status</th><th class=\"l\">reason</th></tr>\n"
      << rows.str() << "</table>\n";
  }
}

// Every fitted trace that raised a warning, with the warnings' text: its number is used, so the
// reader must see why to doubt it (the traces table says "ok (warned)").
void WriteWarnings(const ReportPage& p, std::ostream& h) {
  h << "<h2 id=\"warnings\">Warnings</h2>\n";
  std::ostringstream rows;
  int warned = 0;
  for (const auto& t : p.traces) {
    if (Str(t, "status") != "ok") continue;  // rejected and failed: the section above
    const std::vector<std::string> warnings = TraceWarnings(t);
    if (warnings.empty()) continue;
    ++warned;
    rows << "<tr class=\"warned\"><td class=\"l\">" << Escape(Str(t, "file")) << "</td><td class=\"l\">";
    for (size_t i = 0; i < warnings.size(); ++i) {
      rows << (i ? "<br>" : "") << Escape(InDisplayUnits(p.u, warnings[i]));
    }
    rows << "</td></tr>\n";
  }
  if (warned == 0) {
    h << "<p class=\"ok\">None: no fitted trace raised a warning.</p>\n";
    return;
  }
  h << "<p class=\"bad\">" << warned << " fitted trace" << (warned == 1 ? "" : "s")
    << " raised warnings. Their numbers are in every table above; read why before you trust "
       "them.</p>\n<table class=\"warnings\"><tr><th class=\"l\">file</th><th class=\"l\">warnings</th></tr>\n"
    << rows.str() << "</table>\n";
}

// The traces table's status cell: "ok (warned)" links to the Warnings section and carries the
// warnings' text as its tooltip.
std::string StatusCell(const Units& u, const json& t) {
  const std::string shown = DisplayStatus(t);
  if (shown != "ok (warned)") return Escape(shown);
  std::string tip;
  for (const std::string& w : TraceWarnings(t)) tip += (tip.empty() ? "" : "\n") + InDisplayUnits(u, w);
  return "<a href=\"#warnings\" title=\"" + Escape(tip) + "\">" + Escape(shown) + "</a>";
}

// One row per trace: role, status, pitch, total and aircraft inertia, window, amplitude.
void WriteTraceTable(const ReportPage& p, std::ostream& h) {
  const Units& u = p.u;
  h << "<h2>Traces</h2>\n<table><tr><th class=\"l\">file</th><th class=\"l\">role</th>"
       "<th class=\"l\">status</th><th>pitch (deg)</th><th>I total (" << u.name
    << ")</th><th>std (stat)</th><th>std (total)</th><th>period (s)</th><th>I aircraft</th><th>std (stat)</th>"
       "<th>std (total)</th><th>window (s)</th>"
       "<th>amplitude (deg)</th><th>rms/noise</th></tr>\n";
  for (const auto& t : p.traces) {
    const std::string status = Str(t, "status");
    std::string window = "&ndash;", amplitude = "&ndash;";
    if (t.contains("window_s") && t["window_s"].is_array()) {
      window = Fmt(t["window_s"][0].get<double>(), "%.2f") + "&ndash;" +
               Fmt(t["window_s"][1].get<double>(), "%.2f");
    }
    if (t.contains("amplitude_deg") && t["amplitude_deg"].is_array()) {
      amplitude = Fmt(t["amplitude_deg"][0].get<double>(), "%.1f") + "&rarr;" +
                  Fmt(t["amplitude_deg"][1].get<double>(), "%.1f");
    }
    const std::string row_class = DisplayStatus(t) == "ok (warned)" ? "warned" : status;
    h << "<tr class=\"" << Escape(row_class) << "\"><td class=\"l\">" << Escape(Str(t, "file"))
      << "</td><td class=\"l\">" << Escape(Str(t, "role")) << "</td><td class=\"l\">"
      << StatusCell(u, t) << "</td><td>" << Fmt(Num(t, "pitch_used_deg"), "%.2f") << "</td><td>"
      << u.Inertia(Num(t, "inertia_total_kg_m2"), "%.5f") << "</td><td>"
      << u.Inertia(Num(t, "inertia_total_std_kg_m2"), "%.2e") << "</td><td>"
      << u.Inertia(Num(t, "inertia_total_std_total_kg_m2"), "%.2e") << "</td><td>"
      << Fmt(Num(t, "period_s"), "%.4f") << "</td><td>"
      << u.Inertia(Num(t, "inertia_kg_m2"), "%.5f") << "</td><td>"
      << u.Inertia(Num(t, "inertia_std_kg_m2"), "%.2e") << "</td><td>"
      << u.Inertia(Num(t, "inertia_std_total_kg_m2"), "%.2e") << "</td><td>" << window << "</td><td>"
      << amplitude << "</td><td>"
      << Fmt(Num(t, "residual_rms_rad_per_s") / Num(t, "noise_rms_rad_per_s"), "%.2f")
      << "</td></tr>\n";
  }
  h << "</table>\n";
}

// A trace figure's caption after the status: period, small-angle I, and each warning in red.
std::string TraceCaptionFacts(const ReportPage& p, const json& t) {
  std::string out;
  const double period = Num(t, "period_s");
  if (std::isfinite(period)) {
    out += " &middot; T = " + Fmt(period, "%.4f") + " s, small-angle I = " +
           p.u.Inertia(Num(t, "small_angle_inertia_total_kg_m2"), "%.5f") + " " + p.u.name;
  }
  for (const std::string& w : TraceWarnings(t)) {
    out += "<br><span class=\"bad\">warning: " + Escape(InDisplayUnits(p.u, w)) + "</span>";
  }
  return out;
}

// The per-trace section: every trace's figures (fit and residual) with its caption.
void WriteTraceFigures(ReportPage& p, std::ostream& h) {
  h << "<h2>Fit and residual of every trace</h2>\n<p>Left, each trace: the measured swing rate "
       "(black) over the fit (light blue), and beneath them the residual (grey) with the "
       "&plusmn;1&sigma; noise estimate (red). Its caption gives the measured period T "
       "and the small-angle inertia m g D<sup>2</sup> T<sup>2</sup> / (16 &pi;<sup>2</sup> L) of "
       "everything suspended, the hand check of the fitted I<sub>total</sub>. Right: I against "
       "amplitude.</p>\n<div class=\"traces\">\n";
  for (const auto& t : p.traces) {
    const std::string fig = Str(t, "figure");
    if (fig.empty()) continue;
    h << "<figure>" << Figure(p.out_dir, fig, "fit of " + Str(t, "file"), "trace", &p.figures_drawn)
      << "<figcaption>" << Escape(Str(t, "file")) << " &middot; " << Escape(DisplayStatus(t))
      << TraceCaptionFacts(p, t) << "</figcaption></figure>\n"
      << SweepFigure(t, p.out_dir, &p.figures_drawn);
  }
  h << "</div>\n";
}

// The config text used, and the end of the page.
void WriteFooter(const ReportPage& p, std::ostream& h) {
  h << "<h2>Config used</h2>\n<pre>" << Escape(Str(p.results, "config")) << "</pre>\n";
  h << "</body></html>\n";
}

}  // namespace

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

// header -> Table 2 -> inertia tensor (campaigns that roll) -> Table 1 and rig -> ellipse figures and NACA 467 -> per-angle table ->
// rejected traces -> warnings -> trace table -> per-trace figures -> footer.
std::string BuildReportHtml(const json& results, const std::string& out_dir) {
  ReportPage page(results, out_dir);
  std::ostringstream h;
  WriteHeader(page, h);
  WriteTable2(page, h);
  WriteTensorSection(page, h);
  WriteTable1AndRig(page, h);
  WriteEllipseSection(page, h);
  WriteAngleTable(page, h);
  WriteRejectedTraces(page, h);
  WriteWarnings(page, h);
  WriteTraceTable(page, h);
  WriteTraceFigures(page, h);
  WriteFooter(page, h);
  return ShareSvgGlyphs(ShareStyles(h.str()));
}

void RunReport(const std::string& out_dir) {
  std::error_code ec;
  if (!fs::is_directory(out_dir, ec)) throw UserError(out_dir + ": no such folder");
  const OutputFolderLock lock(out_dir);
  const std::string path = (fs::path(out_dir) / "results.json").string();
  std::string bytes, why;
  if (!ReadRegularFile(path, OutputFileCap(), &bytes, &why)) throw UserError(why);
  json results;
  try {
    results = json::parse(bytes);
  } catch (const std::exception& e) {
    throw UserError(path + ": not valid JSON (" + DescribeJsonError(e) +
                    "); rerun `bifilar process` to rewrite it");
  }
  if (!results.is_object() || !results.contains("traces")) {
    throw UserError(path + ": not a bifilar results file (no 'traces')");
  }
  // A mixed set (a run killed between two renames) is reported, not turned into a page.
  const std::vector<std::string> problems = CheckOutputSet(out_dir, false);
  if (!problems.empty()) {
    throw UserError(out_dir + ": the outputs are a mixed set from different runs (" +
                    problems.front() +
                    (problems.size() > 1 ? ", and " + std::to_string(problems.size() - 1) + " more" : "") +
                    "); rerun `bifilar process` to rewrite them");
  }
  std::string html;
  try {
    html = BuildReportHtml(results, out_dir);
  } catch (const json::exception& e) {  // a field of the wrong type: name the file, not json
    throw UserError(path + ": not a results file bifilar can read (" + DescribeJsonError(e) +
                    "); rerun `bifilar process` to rewrite it");
  }
  WriteFileAtomically((fs::path(out_dir) / "report.html").string(),
                      StampReport(html, HashToHex(Fnv1a64(bytes))));
}

}  // namespace bifilar
