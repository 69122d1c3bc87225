#include "pipeline/figures/sweep_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <plplot.h>

#include "base/text_format.h"
#include "base/units.h"

namespace bifilar {
namespace {

// A red ring of radii (rx, ry) in world units around (mx, my), 2 px wide.
void DrawRing(double mx, double my, double rx, double ry) {
  PLFLT cx[41], cy[41];
  for (int j = 0; j <= 40; ++j) {
    cx[j] = mx + rx * std::cos(2.0 * kPi * j / 40.0);
    cy[j] = my + ry * std::sin(2.0 * kPi * j / 40.0);
  }
  plcol0(kFigureRed);
  plwidth(2.0);
  plline(41, cx, cy);
  plwidth(1.0);
}

constexpr double kChar = 1.2;  // character scale: readable at the report's 540 px thumbnails

// Everything the sweep figure draws, in display units.
struct SweepPage {
  double k = 1.0;  // kg m^2 -> displayed I
  std::string y_label;
  std::vector<double> ax, ai, a_lo, a_hi, i_lo, i_hi;  // the ok bands
  bool trend = false, marked = false;  // a trend; its low band marked as the result's
  double x_lo = 0.0, x_hi = 0.0, y_lo = 0.0, y_hi = 0.0;
  std::vector<double> tx, ty;           // the trend curve
  double y_ref = 0.0, y_ref_std = 0.0;  // the reported I and its std
  std::string title, subtitle, reported_text;
  double left = 0.0, top = 0.0, px_w = 0.0, px_h = 0.0, ring_px = 0.0;
};
constexpr double kRight = 0.91, kBottom = 0.13;

// Display values: the unit, then a power of ten so tick labels stay short (a 34 g quadrotor is
// 1.6e-5 kg m^2): "I (10^-5 kg m^2)".
void SweepDisplayScale(double inertia_kg_m2, const SweepPlotOptions& options, SweepPage* p) {
  const double reported = inertia_kg_m2 * options.unit_scale;
  const int exponent = static_cast<int>(std::floor(std::log10(reported)));
  const bool scaled = exponent <= -2 || exponent >= 3;
  p->k = options.unit_scale * (scaled ? std::pow(10.0, -exponent) : 1.0);
  p->y_label = "I (" + (scaled ? "10#u" + std::to_string(exponent) + "#d " : std::string()) +
               options.unit_label + ")";
}

// The ok bands: amplitude mean and range, I and its +-1 sigma.
void SweepPoints(const AmplitudeSweep& sweep, SweepPage* p) {
  for (const AmplitudeSweepBand& b : sweep.bands) {
    if (!b.ok) continue;
    p->ax.push_back(b.amplitude_mean_deg);
    p->ai.push_back(b.inertia_kg_m2 * p->k);
    p->a_lo.push_back(std::min(b.amplitude_start_deg, b.amplitude_end_deg));
    p->a_hi.push_back(std::max(b.amplitude_start_deg, b.amplitude_end_deg));
    p->i_lo.push_back((b.inertia_kg_m2 - b.inertia_std_kg_m2) * p->k);
    p->i_hi.push_back((b.inertia_kg_m2 + b.inertia_std_kg_m2) * p->k);
  }
}

// Amplitude axis: the bands' ranges with a margin; from 0 when that is close anyway.
void AmplitudeAxis(SweepPage* p) {
  p->x_lo = *std::min_element(p->a_lo.begin(), p->a_lo.end());
  p->x_hi = *std::max_element(p->a_hi.begin(), p->a_hi.end());
  const double x_pad = 0.08 * std::max(p->x_hi - p->x_lo, 1.0);
  p->x_lo = std::max(0.0, p->x_lo - x_pad);
  p->x_hi += x_pad;
  if (p->x_lo < 0.25 * p->x_hi) p->x_lo = 0.0;
}

// The trend I_0 (1 + c A^p) over the axis, and the I axis holding the bands, the result's band
// and the trend, with a margin.
void TrendCurveAndValueAxis(const AmplitudeSweep& sweep, double inertia_kg_m2,
                            double inertia_std_kg_m2, SweepPage* p) {
  if (p->trend) {
    for (int j = 0; j <= 60; ++j) {
      const double a = p->x_lo + (p->x_hi - p->x_lo) * j / 60.0;
      p->tx.push_back(a);
      p->ty.push_back(sweep.TrendAt(a) * p->k);
    }
  }
  p->y_ref = inertia_kg_m2 * p->k;
  p->y_ref_std = inertia_std_kg_m2 * p->k;
  p->y_lo = std::min(*std::min_element(p->i_lo.begin(), p->i_lo.end()), p->y_ref - p->y_ref_std);
  p->y_hi = std::max(*std::max_element(p->i_hi.begin(), p->i_hi.end()), p->y_ref + p->y_ref_std);
  for (double v : p->ty) p->y_lo = std::min(p->y_lo, v), p->y_hi = std::max(p->y_hi, v);
  const double y_pad = 0.08 * (p->y_hi - p->y_lo) + 1e-9 * std::fabs(p->y_ref);
  p->y_lo -= y_pad;
  p->y_hi += y_pad;
}

// Text short: the report inlines one of these per trace.
void SweepTexts(const AmplitudeSweep& sweep, const SweepPlotOptions& options, SweepPage* p) {
  const std::string name = options.title.empty() ? std::string("trace") : options.title;
  const std::string trend_text = "trend z = " + Fmt("%.1f", sweep.trend_z) + ", " +
                                 Fmt("%+.2g", sweep.trend_percent_per_10deg) + " % per 10 deg";
  // Compact: the page's caption names the trace and the subtitle's facts go in the title.
  const std::string scatter_text =
      sweep.std_scale > 1.0 ? "bands scatter " + Fmt("%.1f", sweep.std_scale) + "× σ" : "";
  p->title = options.compact
                 ? "I(A): " + trend_text + (scatter_text.empty() ? "" : ", " + scatter_text)
                 : name + ": I(A), " + trend_text;
  p->subtitle = p->trend ? "the ideal model is flat: this rig departs from it"
                         : "the ideal model is flat: no trend beyond its error";
  if (!scatter_text.empty()) p->subtitle += "; " + scatter_text;
  p->reported_text =
      std::string(p->marked ? "result (lowest band)" : "result (window fit)") + " ± 1σ";
}

// Page layout (normalised page coordinates), top down: title, subtitle and two legend rows
// (not when compact), the axis labels (horizontal: rotated text is a second set of glyphs), the
// plot.
void SweepPageLayout(const SweepPlotOptions& options, SweepPage* p) {
  // The left margin holds the longest y tick label: a tare of 0.18442 slug ft^2 needs 7
  // characters where 2.992 needs 5 (issue 18: the labels were clipped). Decimals as PLplot's
  // tick step (3 to 8 ticks) needs them; about 11 px a character at this size.
  const double y_range = std::max(p->y_hi - p->y_lo, 1e-300);
  const int decimals = std::max(0, -static_cast<int>(std::floor(std::log10(y_range / 8.0))));
  const double y_abs = std::max(std::fabs(p->y_lo), std::fabs(p->y_hi));
  const int int_digits =
      std::max(1, static_cast<int>(std::floor(std::log10(std::max(y_abs, 1.0)))) + 1);
  const int label_chars = int_digits + (decimals > 0 ? 1 + decimals : 0) + (p->y_lo < 0.0 ? 1 : 0);
  // PLplot's characters scale with the page height: font size ~0.04 of it at this kChar, a digit
  // up to 0.64 of that wide (DejaVu Sans); the tick labels sit ~0.8 font sizes off the axis.
  // (A fixed 11 px a character clipped ".127" on the 1100 x 700 page of `fit --plot`.)
  const double font_px = 0.04 * options.figure.height_px;
  p->left =
      std::min(0.3, (font_px * (0.64 * label_chars + 1.0)) / std::max(1, options.figure.width_px));
  // Not compact: room between the legend's lower row and the axis label above the plot.
  p->top = options.compact ? 0.83 : 0.63;
  p->px_w = options.figure.width_px * (kRight - p->left);
  p->px_h = options.figure.height_px * (p->top - kBottom);
  p->ring_px = 0.022 * options.figure.width_px;  // radius of the result band's ring
}

// The reported I and its band.
void DrawReportedBand(const SweepPage& p) {
  const PLFLT fx[4] = {p.x_lo, p.x_hi, p.x_hi, p.x_lo};
  const double lo = p.y_ref - p.y_ref_std, hi = p.y_ref + p.y_ref_std;
  const PLFLT fy[4] = {lo, lo, hi, hi};
  plcol0(kFigureTranslucentBand);
  plfill(4, fx, fy);
  const PLFLT lx[2] = {p.x_lo, p.x_hi}, ly[2] = {p.y_ref, p.y_ref};
  plcol0(kFigureBlue);
  plwidth(2.0);
  plline(2, lx, ly);
}

// The trend, then the bands: amplitude range and +-1 sigma, then the point; the band the result
// was taken from ringed.
void DrawBands(const AmplitudeSweep& sweep, const SweepPage& p) {
  if (p.trend) {  // solid: PLplot draws a dashed line as one SVG path per dash
    plcol0(kFigureRed);
    plwidth(2.0);
    plline(static_cast<PLINT>(p.tx.size()), p.tx.data(), p.ty.data());
  }
  plwidth(1.5);
  const PLINT n = static_cast<PLINT>(p.ax.size());
  plcol0(kFigureGrey);
  plerrx(n, p.a_lo.data(), p.a_hi.data(), p.ai.data());
  plcol0(kFigureBlack);
  plerry(n, p.ax.data(), p.i_lo.data(), p.i_hi.data());
  plstring(n, p.ax.data(), p.ai.data(), "●");
  if (p.marked) {  // the band the result was taken from: a red ring around its point
    const AmplitudeSweepBand& low = sweep.bands[sweep.low_band];
    const double mx = low.amplitude_mean_deg, my = low.inertia_kg_m2 * p.k;
    DrawRing(mx, my, p.ring_px * (p.x_hi - p.x_lo) / p.px_w,
             p.ring_px * (p.y_hi - p.y_lo) / p.px_h);
  }
  plwidth(1.0);
}

// Axes: I on the left, its deviation from the result in % on the right.
void DrawAxes(const SweepPage& p) {
  plcol0(kFigureBlack);
  LabelledBox("bnt", "bntv");  // no minor ticks: the grid is the reference
  plmtex("b", 2.9, 0.5, 0.5, "amplitude (deg)");
  plwind(p.x_lo, p.x_hi, 100.0 * (p.y_lo / p.y_ref - 1.0), 100.0 * (p.y_hi / p.y_ref - 1.0));
  LabelledBox("c", "cmtv");
}

// Titles on the whole page (the viewport left there for the legend).
void DrawTitles(const SweepPage& p) {
  plvpor(0.0, 1.0, 0.0, 1.0);
  plwind(0.0, 1.0, 0.0, 1.0);
  plcol0(kFigureBlack);
  plptex(0.02, p.top + 0.035, 1, 0, 0.0, p.y_label.c_str());
  plptex(0.98, p.top + 0.035, 1, 0, 1.0, "I / result - 1 (%)");
  // A long file name shrinks the title (about 62 characters fit at full size).
  const double title_scale = std::min(1.0, 62.0 / static_cast<double>(p.title.size()));
  plschr(0, kChar * title_scale);
  plptex(0.5, 0.94, 1, 0, 0.5, p.title.c_str());
  plschr(0, kChar);
}

// Subtitle and legend: a 0.05-wide sample, then the text; two columns, two rows.
void DrawSubtitleAndLegend(const AmplitudeSweep& sweep, const SweepPlotOptions& options,
                           const SweepPage& p) {
  plptex(0.5, 0.875, 1, 0, 0.5, p.subtitle.c_str());
  const double col[2] = {0.05, 0.55}, row[2] = {0.815, 0.755}, w = 0.05;
  auto sample_line = [&](double x, double y, int colour, double width) {
    const PLFLT lx[2] = {x, x + w}, ly[2] = {y, y};
    plcol0(colour);
    plwidth(width);
    plline(2, lx, ly);
    plwidth(1.0);
  };
  auto text = [&](double x, double y, const char* t) {
    plcol0(kFigureBlack);
    plptex(x + w + 0.015, y - 0.015, 1, 0, 0, t);
  };
  {  // a band: its amplitude range (grey) and its point
    sample_line(col[0], row[0], kFigureGrey, 1.5);
    const PLFLT mx = col[0] + 0.5 * w, my = row[0];
    plcol0(kFigureBlack);
    plstring(1, &mx, &my, "●");
    text(col[0], row[0], "band: I ± 1σ, amplitude range");
  }
  {  // the result and its band
    const PLFLT fx[4] = {col[0], col[0] + w, col[0] + w, col[0]};
    const PLFLT fy[4] = {row[1] - 0.02, row[1] - 0.02, row[1] + 0.02, row[1] + 0.02};
    plcol0(kFigureTranslucentBand);
    plfill(4, fx, fy);
    sample_line(col[0], row[1], kFigureBlue, 2.0);
    text(col[0], row[1], p.reported_text.c_str());
  }
  if (p.trend) {
    sample_line(col[1], row[0], kFigureRed, 2.0);
    const std::string legend =
        "trend I#d0#u (1 + c A" +
        (sweep.trend_exponent == 1.0 ? std::string()
                                     : "#u" + Fmt("%g", sweep.trend_exponent) + "#d") +
        ")";
    text(col[1], row[0], legend.c_str());
  }
  if (p.marked) {
    const double mx = col[1] + 0.5 * w, my = row[1];
    DrawRing(mx, my, 0.75 * p.ring_px / options.figure.width_px,
             0.75 * p.ring_px / options.figure.height_px);
    text(col[1], row[1], "band used for the result");
  }
}

}  // namespace

// SweepDisplayScale -> SweepPoints -> AmplitudeAxis -> TrendCurveAndValueAxis -> SweepTexts ->
// SweepPageLayout, then drawn: grid -> DrawReportedBand -> DrawBands -> DrawAxes -> DrawTitles
// -> DrawSubtitleAndLegend (not when compact).
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
  SweepPage p;
  SweepDisplayScale(inertia_kg_m2, options, &p);
  SweepPoints(sweep, &p);
  if (p.ax.size() < 2) {
    *why = path + ": fewer than 2 fitted bands to plot";
    return false;
  }
  p.trend = sweep.trend_detected;
  p.marked = p.trend && sweep.low_band >= 0 &&
             sweep.low_band < static_cast<int>(sweep.bands.size()) &&
             sweep.bands[sweep.low_band].ok;
  AmplitudeAxis(&p);
  TrendCurveAndValueAxis(sweep, inertia_kg_m2, inertia_std_kg_m2, &p);
  SweepTexts(sweep, options, &p);
  SweepPageLayout(options, &p);
  auto draw = [&] {
    SetTranslucentBand(0.25);
    pladv(0);
    plschr(0, kChar);
    plvpor(p.left, kRight, kBottom, p.top);
    plwind(p.x_lo, p.x_hi, p.y_lo, p.y_hi);
    plsyax(7, 0);  // up to 7 digits before PLplot switches to its own "x10^n"
    plcol0(kFigureLight);
    LabelledBox("g", "g");
    DrawReportedBand(p);
    DrawBands(sweep, p);
    DrawAxes(p);
    DrawTitles(p);
    if (options.compact) return;
    DrawSubtitleAndLegend(sweep, options, p);
  };
  return WriteFigure(path, options.figure, draw, why);
}

}  // namespace bifilar
