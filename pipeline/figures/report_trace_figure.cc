#include "pipeline/figures/report_trace_figure.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <plplot.h>

#include "pendulum/model.h"
#include "pipeline/figures/figure.h"
#include "pipeline/figures/trace_plot.h"

namespace bifilar {
namespace {

// Min/max envelope of v over `buckets` equal index ranges, as a zigzag polyline (2 points per
// bucket, in time order): what a line of every sample looks like at thumbnail size, for a fraction
// of the drawing cost.
void Envelope(const std::vector<double>& t, const std::vector<double>& v, size_t buckets,
              double scale, std::vector<PLFLT>* x, std::vector<PLFLT>* y) {
  const size_t n = t.size();
  x->clear();
  y->clear();
  if (n == 0) return;
  if (n <= 2 * buckets) {
    for (size_t i = 0; i < n; ++i) {
      x->push_back(t[i] - t[0]);
      y->push_back(scale * v[i]);
    }
    return;
  }
  for (size_t b = 0; b < buckets; ++b) {
    const size_t lo = b * n / buckets, hi = (b + 1) * n / buckets;
    size_t i_min = lo, i_max = lo;
    for (size_t i = lo; i < hi; ++i) {
      if (v[i] < v[i_min]) i_min = i;
      if (v[i] > v[i_max]) i_max = i;
    }
    const size_t first = std::min(i_min, i_max), second = std::max(i_min, i_max);
    x->push_back(t[first] - t[0]);
    y->push_back(scale * v[first]);
    x->push_back(t[second] - t[0]);
    y->push_back(scale * v[second]);
  }
}

}  // namespace

bool WriteReportTraceFigure(const TraceFitResult& fit, const std::string& title, DisplayUnits units,
                            const std::string& path, int width_px, int height_px, std::string* why,
                            double inertia_std_kg_m2, const std::string& std_label) {
  (void)title;  // the file name is in the report's caption
  // The series of the fit that gave I (trace_plot.h). Top: measured and fitted rate at ~250
  // points (the noise is invisible at this scale; it shows in the residual panel). Bottom: the
  // residual's min/max envelope over 150 buckets.
  TracePlotOptions options;
  options.unit_scale = InertiaToDisplay(1.0, units);
  options.unit_label = InertiaUnitPlotLabel(units);
  options.inertia_std_kg_m2 = inertia_std_kg_m2;
  options.std_label = std_label;
  TraceFigureData d;
  if (!MakeTraceFigureData(fit, options, &d, why)) return false;
  std::vector<PLFLT> tm, ym, yf, tr, yr;
  const size_t stride = std::max<size_t>(1, d.t_s.size() / 250);
  for (size_t i = 0; i < d.t_s.size(); i += stride) {
    tm.push_back(d.t_s[i]);
    ym.push_back(d.measured_deg_per_s[i]);
    yf.push_back(d.fitted_deg_per_s[i]);
  }
  Envelope(d.t_s, d.residual_deg_per_s, 150, 1.0, &tr, &yr);
  if (tm.size() < 2) {
    *why = "nothing to plot";
    return false;
  }
  const double t_end = tm.back();
  double y_max = 0.0, r_max = 0.0;
  for (double v : ym) y_max = std::max(y_max, std::abs(v));
  for (double v : yf) y_max = std::max(y_max, std::abs(v));
  for (double v : yr) r_max = std::max(r_max, std::abs(v));
  const double noise = kDegPerRad * fit.noise_rad_per_s;
  r_max = std::max(r_max, 2.5 * noise) * 1.1;
  y_max = std::max(y_max, 1e-6) * 1.1;
  const double k = options.unit_scale, std_kg_m2 = std::isfinite(inertia_std_kg_m2)
                                                       ? inertia_std_kg_m2
                                                       : fit.inertia_std_kg_m2;
  // In the config's units, as every table of the report (I total: rig included).
  const std::string top_title =
      "I#dtotal#u = " + ValueWithStd(k * fit.params.inertia_kg_m2, k * std_kg_m2) + " " +
      options.unit_label + " (1σ " + std_label + "), " +
      (d.from_band ? "lowest-amplitude band" : "whole window");
  // The rms of the fit drawn (the band's or the window's), named as such: a warning's "residual
  // 10.3x noise" is the whole window's.
  char label[256];
  std::snprintf(label, sizeof(label), "measured − fit (%s): rms = %.2f × gyro noise",
                d.from_band ? "lowest band" : "window", d.rms_over_noise);
  const std::string bottom_title = label;
  FigureOptions figure;
  figure.width_px = width_px;
  figure.height_px = height_px;
  return WriteFigure(
      path, figure,
      [&] {
        pladv(0);
        plschr(0, 0.8);
        plvpor(0.1, 0.97, 0.42, 0.9);
        plwind(0, t_end, -y_max, y_max);
        plcol0(1);
        LabelledBox("bct", "bcntv");
        pllab("", "deg/s", top_title.c_str());
        // The fit first (a light blue line), the measured samples on top of it (black dots), as
        // the report's caption says: both stay visible where they agree.
        plscol0(11, 120, 170, 230);
        plcol0(11);
        plwidth(2.5);
        plline(static_cast<PLINT>(tm.size()), tm.data(), yf.data());
        plcol0(kFigureBlack);
        plwidth(2.2);
        plpoin(static_cast<PLINT>(tm.size()), tm.data(), ym.data(), -1);  // a point: a round dot
        plwidth(1.0);
        plvpor(0.1, 0.97, 0.1, 0.32);
        plwind(0, t_end, -r_max, r_max);
        plcol0(1);
        LabelledBox("bcnt", "bcntv");
        pllab("s", "deg/s", bottom_title.c_str());
        plcol0(kFigureGrey);
        plline(static_cast<PLINT>(tr.size()), tr.data(), yr.data());
        plscol0(10, 200, 60, 40);
        plcol0(10);
        for (double level : {noise, -noise}) {
          PLFLT xs[2] = {0, t_end}, ys[2] = {level, level};
          plline(2, xs, ys);  // solid: PLplot draws a dashed line as one path per dash
        }
      },
      why);
}

}  // namespace bifilar
