#include "pipeline/figures/sweep_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <plplot.h>

#include "base/units.h"

namespace bifilar {
namespace {

enum Colour {
  kBlack = kFigureBlack, kBlue = kFigureBlue, kRed = kFigureRed, kGrey = kFigureGrey,
  kLight = kFigureLight,
  kBandFill = 8,  // kFigureBand at 25 % opacity: the reported I's +-1 sigma band
};

std::string Fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

// A red ring of radii (rx, ry) in world units around (mx, my), 2 px wide.
void DrawRing(double mx, double my, double rx, double ry) {
  PLFLT cx[41], cy[41];
  for (int j = 0; j <= 40; ++j) {
    cx[j] = mx + rx * std::cos(2.0 * kPi * j / 40.0);
    cy[j] = my + ry * std::sin(2.0 * kPi * j / 40.0);
  }
  plcol0(kRed);
  plwidth(2.0);
  plline(41, cx, cy);
  plwidth(1.0);
}

}  // namespace

bool WriteAmplitudeSweepFigure(const AmplitudeSweep& sweep, double inertia_kg_m2,
                               double inertia_std_kg_m2, const std::string& path,
                               const SweepPlotOptions& options, std::string* why) {
  if (!sweep.evaluated) {
    *why = path + ": no amplitude sweep to plot (" +
           (sweep.note.empty() ? std::string("not evaluated") : sweep.note) + ")";
    return false;
  }
  if (!(std::isfinite(inertia_kg_m2) && inertia_kg_m2 > 0.0 && std::isfinite(inertia_std_kg_m2) &&
        options.unit_scale > 0.0)) {
    *why = path + ": no finite inertia to plot the sweep against";
    return false;
  }
  // Display values: the unit, then a power of ten so tick labels stay short (a 34 g quadrotor is
  // 1.6e-5 kg m^2): "I (10^-5 kg m^2)".
  const double reported = inertia_kg_m2 * options.unit_scale;
  const int exponent = static_cast<int>(std::floor(std::log10(reported)));
  const bool scaled = exponent <= -2 || exponent >= 3;
  const double k = options.unit_scale * (scaled ? std::pow(10.0, -exponent) : 1.0);
  const std::string y_label =
      "I (" + (scaled ? "10#u" + std::to_string(exponent) + "#d " : std::string()) +
      options.unit_label + ")";

  std::vector<double> ax, ai, a_lo, a_hi, i_lo, i_hi;
  for (const AmplitudeSweepBand& b : sweep.bands) {
    if (!b.ok) continue;
    ax.push_back(b.amplitude_mean_deg);
    ai.push_back(b.inertia_kg_m2 * k);
    a_lo.push_back(std::min(b.amplitude_start_deg, b.amplitude_end_deg));
    a_hi.push_back(std::max(b.amplitude_start_deg, b.amplitude_end_deg));
    i_lo.push_back((b.inertia_kg_m2 - b.inertia_std_kg_m2) * k);
    i_hi.push_back((b.inertia_kg_m2 + b.inertia_std_kg_m2) * k);
  }
  if (ax.size() < 2) {
    *why = path + ": fewer than 2 fitted bands to plot";
    return false;
  }
  const bool trend = sweep.trend_detected;
  const bool marked = trend && sweep.low_band >= 0 &&
                      sweep.low_band < static_cast<int>(sweep.bands.size()) &&
                      sweep.bands[sweep.low_band].ok;

  // Amplitude axis: the bands' ranges with a margin; from 0 when that is close anyway.
  double x_lo = *std::min_element(a_lo.begin(), a_lo.end());
  double x_hi = *std::max_element(a_hi.begin(), a_hi.end());
  const double x_pad = 0.08 * std::max(x_hi - x_lo, 1.0);
  x_lo = std::max(0.0, x_lo - x_pad);
  x_hi += x_pad;
  if (x_lo < 0.25 * x_hi) x_lo = 0.0;

  // The trend I_0 (1 + c A^p) over the axis.
  std::vector<double> tx, ty;
  if (trend) {
    for (int j = 0; j <= 60; ++j) {
      const double a = x_lo + (x_hi - x_lo) * j / 60.0;
      tx.push_back(a);
      ty.push_back(sweep.TrendAt(a) * k);
    }
  }
  const double y_ref = inertia_kg_m2 * k, y_ref_std = inertia_std_kg_m2 * k;
  double y_lo = std::min(*std::min_element(i_lo.begin(), i_lo.end()), y_ref - y_ref_std);
  double y_hi = std::max(*std::max_element(i_hi.begin(), i_hi.end()), y_ref + y_ref_std);
  for (double v : ty) y_lo = std::min(y_lo, v), y_hi = std::max(y_hi, v);
  const double y_pad = 0.08 * (y_hi - y_lo) + 1e-9 * std::fabs(y_ref);
  y_lo -= y_pad;
  y_hi += y_pad;

  // Text in one size (an SVG embeds every glyph once per size) and short: the report inlines one
  // of these per trace.
  const std::string name = options.title.empty() ? std::string("trace") : options.title;
  const std::string trend_text = "trend z = " + Fmt("%.1f", sweep.trend_z) + ", " +
                                 Fmt("%+.2g", sweep.trend_percent_per_10deg) + " % per 10 deg";
  // Compact: the page's caption names the trace (a file name is many distinct glyphs) and the
  // subtitle's facts go in the title.
  const std::string scatter_text =
      sweep.std_scale > 1.0 ? "bands scatter " + Fmt("%.1f", sweep.std_scale) + "× σ" : "";
  const std::string title =
      options.compact ? "I(A): " + trend_text + (scatter_text.empty() ? "" : ", " + scatter_text)
                      : name + ": I(A), " + trend_text;
  std::string subtitle = trend ? "the ideal model is flat: this rig departs from it"
                               : "the ideal model is flat: no trend beyond its error";
  if (!scatter_text.empty()) subtitle += "; " + scatter_text;
  const std::string reported_text =
      std::string(marked ? "result (lowest band)" : "result (window fit)") + " ± 1σ";

  const double kChar = 1.2;  // character scale: readable at the report's 540 px thumbnails
  // Page layout (normalised page coordinates), top down: title, subtitle and two legend rows
  // (not when compact), the axis labels (horizontal: rotated text is a second set of glyphs), the
  // plot.
  // The left margin holds the longest y tick label: a tare of 0.18442 slug ft^2 needs 7
  // characters where 2.992 needs 5 (issue 18: the labels were clipped). Decimals as PLplot's
  // tick step (3 to 8 ticks) needs them; about 11 px a character at this size.
  const double y_range = std::max(y_hi - y_lo, 1e-300);
  const int decimals = std::max(0, -static_cast<int>(std::floor(std::log10(y_range / 8.0))));
  const double y_abs = std::max(std::fabs(y_lo), std::fabs(y_hi));
  const int int_digits = std::max(1, static_cast<int>(std::floor(std::log10(std::max(y_abs, 1.0)))) + 1);
  const int label_chars = int_digits + (decimals > 0 ? 1 + decimals : 0) + (y_lo < 0.0 ? 1 : 0);
  const double kLeft = std::min(0.3, (22.0 + 11.0 * label_chars) /
                                         std::max(1, options.figure.width_px));
  constexpr double kRight = 0.91, kBottom = 0.13;
  const double kTop = options.compact ? 0.83 : 0.655;
  const double px_w = options.figure.width_px * (kRight - kLeft);
  const double px_h = options.figure.height_px * (kTop - kBottom);
  const double ring_px = 0.022 * options.figure.width_px;  // radius of the result band's ring
  auto draw = [&] {
    plscol0a(kBandFill, 120, 160, 220, 0.25);
    pladv(0);
    plschr(0, kChar);
    plvpor(kLeft, kRight, kBottom, kTop);
    plwind(x_lo, x_hi, y_lo, y_hi);
    plsyax(7, 0);  // up to 7 digits before PLplot switches to its own "x10^n"
    plcol0(kLight);
    plbox("g", 0, 0, "g", 0, 0);
    // The reported I and its band.
    {
      const PLFLT fx[4] = {x_lo, x_hi, x_hi, x_lo};
      const double lo = y_ref - y_ref_std, hi = y_ref + y_ref_std;
      const PLFLT fy[4] = {lo, lo, hi, hi};
      plcol0(kBandFill);
      plfill(4, fx, fy);
      const PLFLT lx[2] = {x_lo, x_hi}, ly[2] = {y_ref, y_ref};
      plcol0(kBlue);
      plwidth(2.0);
      plline(2, lx, ly);
    }
    if (trend) {  // solid: PLplot draws a dashed line as one SVG path per dash
      plcol0(kRed);
      plwidth(2.0);
      plline(static_cast<PLINT>(tx.size()), tx.data(), ty.data());
    }
    plwidth(1.5);
    // The bands: amplitude range and +-1 sigma, then the point.
    const PLINT n = static_cast<PLINT>(ax.size());
    plcol0(kGrey);
    plerrx(n, a_lo.data(), a_hi.data(), ai.data());
    plcol0(kBlack);
    plerry(n, ax.data(), i_lo.data(), i_hi.data());
    plstring(n, ax.data(), ai.data(), "●");
    if (marked) {  // the band the result was taken from: a red ring around its point
      const AmplitudeSweepBand& low = sweep.bands[sweep.low_band];
      const double mx = low.amplitude_mean_deg, my = low.inertia_kg_m2 * k;
      DrawRing(mx, my, ring_px * (x_hi - x_lo) / px_w, ring_px * (y_hi - y_lo) / px_h);
    }
    plwidth(1.0);
    // Axes: I on the left, its deviation from the result in % on the right.
    plcol0(kBlack);
    plbox("bnt", 0, 0, "bntv", 0, 0);  // no minor ticks: the grid is the reference
    plmtex("b", 2.9, 0.5, 0.5, "amplitude (deg)");
    plwind(x_lo, x_hi, 100.0 * (y_lo / y_ref - 1.0), 100.0 * (y_hi / y_ref - 1.0));
    plbox("c", 0, 0, "cmtv", 0, 0);

    // Titles and legend on the whole page.
    plvpor(0.0, 1.0, 0.0, 1.0);
    plwind(0.0, 1.0, 0.0, 1.0);
    plcol0(kBlack);
    plptex(0.02, kTop + 0.035, 1, 0, 0.0, y_label.c_str());
    plptex(0.98, kTop + 0.035, 1, 0, 1.0, "I / result - 1 (%)");
    // A long file name shrinks the title (about 62 characters fit at full size).
    const double title_scale = std::min(1.0, 62.0 / static_cast<double>(title.size()));
    plschr(0, kChar * title_scale);
    plptex(0.5, 0.94, 1, 0, 0.5, title.c_str());
    plschr(0, kChar);
    if (options.compact) return;
    plptex(0.5, 0.875, 1, 0, 0.5, subtitle.c_str());
    // Legend: a 0.05-wide sample, then the text; two columns, two rows.
    const double col[2] = {0.05, 0.55}, row[2] = {0.815, 0.755}, w = 0.05;
    auto sample_line = [&](double x, double y, int colour, double width) {
      const PLFLT lx[2] = {x, x + w}, ly[2] = {y, y};
      plcol0(colour);
      plwidth(width);
      plline(2, lx, ly);
      plwidth(1.0);
    };
    auto text = [&](double x, double y, const char* t) {
      plcol0(kBlack);
      plptex(x + w + 0.015, y - 0.015, 1, 0, 0, t);
    };
    {  // a band: its amplitude range (grey) and its point
      sample_line(col[0], row[0], kGrey, 1.5);
      const PLFLT mx = col[0] + 0.5 * w, my = row[0];
      plcol0(kBlack);
      plstring(1, &mx, &my, "●");
      text(col[0], row[0], "band: I ± 1σ, amplitude range");
    }
    {  // the result and its band
      const PLFLT fx[4] = {col[0], col[0] + w, col[0] + w, col[0]};
      const PLFLT fy[4] = {row[1] - 0.02, row[1] - 0.02, row[1] + 0.02, row[1] + 0.02};
      plcol0(kBandFill);
      plfill(4, fx, fy);
      sample_line(col[0], row[1], kBlue, 2.0);
      text(col[0], row[1], reported_text.c_str());
    }
    if (trend) {
      sample_line(col[1], row[0], kRed, 2.0);
      const std::string legend = "trend I#d0#u (1 + c A" +
                                 (sweep.trend_exponent == 1.0
                                      ? std::string()
                                      : "#u" + Fmt("%g", sweep.trend_exponent) + "#d") +
                                 ")";
      text(col[1], row[0], legend.c_str());
    }
    if (marked) {
      const double mx = col[1] + 0.5 * w, my = row[1];
      DrawRing(mx, my, 0.75 * ring_px / options.figure.width_px,
               0.75 * ring_px / options.figure.height_px);
      text(col[1], row[1], "band used for the result");
    }
  };
  return WriteFigure(path, options.figure, draw, why);
}

}  // namespace bifilar
