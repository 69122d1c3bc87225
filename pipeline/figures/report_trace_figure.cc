#include "pipeline/figures/report_trace_figure.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <plplot.h>

#include "pendulum/model.h"
#include "pipeline/figures/figure.h"

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
                            const std::string& path, int width_px, int height_px,
                            std::string* why) {
  // Top: measured and fitted rate at ~250 points (the noise is invisible at this scale; it shows
  // in the residual panel). Bottom: the residual's min/max envelope over 150 buckets.
  std::vector<PLFLT> tm, ym, tf, yf, tr, yr;
  const size_t stride = std::max<size_t>(1, fit.t_s.size() / 250);
  for (size_t i = 0; i < fit.t_s.size(); i += stride) {
    tm.push_back(fit.t_s[i] - fit.t_s[0]);
    ym.push_back(kDegPerRad * fit.measured_rate_rad_per_s[i]);
    yf.push_back(kDegPerRad * fit.fitted_rate_rad_per_s[i]);
  }
  tf = tm;
  Envelope(fit.t_s, fit.residual_rad_per_s, 150, -kDegPerRad, &tr, &yr);  // measured - fitted
  if (tm.size() < 2) {
    *why = "nothing to plot";
    return false;
  }
  const double t_end = tm.back();
  double y_max = 0.0, r_max = 0.0;
  for (double v : ym) y_max = std::max(y_max, std::abs(v));
  for (double v : yr) r_max = std::max(r_max, std::abs(v));
  const double noise = kDegPerRad * fit.noise_rad_per_s;
  r_max = std::max(r_max, 2.5 * noise) * 1.1;
  y_max = std::max(y_max, 1e-6) * 1.1;
  char label[256];
  // Short labels: the SVG embeds an outline of every distinct glyph (the file name is in the
  // report's caption).
  (void)title;
  // In the config's units, as every table of the report (I total: rig included).
  std::snprintf(label, sizeof(label), "I#dtotal#u = %.5f #(2233) %.1e %s (%s)",
                InertiaToDisplay(fit.params.inertia_kg_m2, units),
                InertiaToDisplay(fit.inertia_stat_std_kg_m2, units),
                units == DisplayUnits::kImperial ? "slug ft#u2#d" : "kg m#u2#d",
                ToString(fit.model));
  const std::string top_title = label;
  std::snprintf(label, sizeof(label), "residual: rms = %.2f noise", fit.rms_over_noise);
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
        plbox("bct", 0, 0, "bcntv", 0, 0);
        pllab("", "deg/s", top_title.c_str());
        // The fit first (wide, light blue), the measured rate on top of it (thin, dark): where the
        // two agree the measured line shows inside the fit's band (issue 18).
        plscol0(9, 150, 185, 235);
        plcol0(9);
        plwidth(4.0);
        plline(static_cast<PLINT>(tf.size()), tf.data(), yf.data());
        plscol0(15, 0, 0, 0);
        plcol0(15);
        plwidth(1.0);
        plline(static_cast<PLINT>(tm.size()), tm.data(), ym.data());
        plscol0(15, 170, 170, 170);
        plvpor(0.1, 0.97, 0.1, 0.32);
        plwind(0, t_end, -r_max, r_max);
        plcol0(1);
        plbox("bcnt", 0, 0, "bcntv", 0, 0);
        pllab("s", "deg/s", bottom_title.c_str());
        plcol0(15);
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
