#include "pipeline/figures/trace_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <plplot.h>

#include "base/units.h"
#include "pipeline/figures/figure.h"

namespace bifilar {
namespace {

enum Colour {
  kBlack = kFigureBlack, kBlue = kFigureBlue, kRed = kFigureRed, kGrey = kFigureGrey,
  kLight = kFigureLight, kBand = kFigureBand
};

std::string Fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

// Above this many samples a dot per sample is drawn no more (a 3 M-sample log took 110 s and gave
// a 750 MB SVG): each series becomes its min/max envelope over `buckets` equal index ranges, as a
// zigzag line in time order, which at 2 buckets per pixel fills the band the dots would cover.
constexpr size_t kMaxDotsDrawn = 20000;

void Envelope(const std::vector<double>& t, const std::vector<double>& v, size_t buckets,
              std::vector<double>* x, std::vector<double>* y) {
  const size_t n = t.size();
  x->clear();
  y->clear();
  for (size_t b = 0; b < buckets; ++b) {
    const size_t lo = b * n / buckets, hi = (b + 1) * n / buckets;
    if (lo >= hi) continue;
    size_t i_min = lo, i_max = lo;
    for (size_t i = lo; i < hi; ++i) {
      if (v[i] < v[i_min]) i_min = i;
      if (v[i] > v[i_max]) i_max = i;
    }
    for (size_t i : {std::min(i_min, i_max), std::max(i_min, i_max)}) {
      x->push_back(t[i]);
      y->push_back(v[i]);
    }
  }
}

}  // namespace

bool WriteTraceFitFigure(const TraceFitResult& r, const std::string& path,
                         const TracePlotOptions& options, std::string* why) {
  const size_t n = r.t_s.size();
  if (n < 2 || r.fitted_rate_rad_per_s.size() != n || r.measured_rate_rad_per_s.size() != n ||
      r.residual_rad_per_s.size() != n) {
    *why = path + ": no fitted series to plot (fit failed or keep_series was off)";
    return false;
  }
  // Time from the start of the window; rates in deg/s (what people read off a gyro).
  const double t0 = r.t_s.front();
  std::vector<double> t(n), meas(n), fit(n), res(n);
  for (size_t k = 0; k < n; ++k) {
    t[k] = r.t_s[k] - t0;
    meas[k] = r.measured_rate_rad_per_s[k] * kDegPerRad;
    fit[k] = r.fitted_rate_rad_per_s[k] * kDegPerRad;
    res[k] = -r.residual_rad_per_s[k] * kDegPerRad;  // measured - fitted
  }
  const double t_hi = t.back();
  double y_abs = 0.0;
  for (size_t k = 0; k < n; ++k) y_abs = std::max({y_abs, std::fabs(meas[k]), std::fabs(fit[k])});
  const double y_top = 1.35 * y_abs, y_bottom = -1.12 * y_abs;  // room for the legend on top
  const double noise_deg = r.noise_rad_per_s * kDegPerRad;
  double r_abs = 0.0;
  for (double v : res) r_abs = std::max(r_abs, std::fabs(v));
  r_abs = std::max(r_abs, 2.5 * noise_deg) * 1.1;
  if (!(r_abs > 0.0)) r_abs = 1.0;

  const std::string name = options.title.empty() ? std::string("trace") : options.title;
  const double k = options.unit_scale;
  const std::string& unit = options.unit_label;
  std::string title = name + " [" + ToString(r.model) + "]: I = " +
                      Fmt("%.6g", k * r.params.inertia_kg_m2) + " ± " +
                      Fmt("%.2g", k * r.inertia_std_kg_m2) + " " + unit;
  if (r.status != TraceFitStatus::kOk) title += "  (" + std::string(ToString(r.status)) + ")";
  const std::string subtitle =
      "K#dD#u = " + Fmt("%.3g", k * r.params.drag_coeff_kg_m2) + " " + unit + ",  C = " +
      Fmt("%.3g", k * r.params.viscous_coeff_kg_m2_per_s) + " " + unit + "/s,  bias = " +
      Fmt("%.3f", r.bias_rad_per_s * kDegPerRad) + " deg/s,  amplitude " +
      Fmt("%.1f", r.amplitude_start_deg) + " → " + Fmt("%.1f", r.amplitude_end_deg) + " deg";
  const std::string residual_label =
      "residual: rms " + Fmt("%.3f", r.residual_rms_rad_per_s * kDegPerRad) + " deg/s = " +
      Fmt("%.2f", r.rms_over_noise) + " × noise (" + (r.noise_from_input ? "rest" : "window") +
      "),  #gr#d1#u = " + Fmt("%.3f", r.residual_autocorr_lag1);

  // Dense series: envelopes (above), drawn as lines.
  const bool dense = n > kMaxDotsDrawn;
  std::vector<double> env_t, env_meas, fit_t, fit_v, res_t, res_v;
  if (dense) {
    const size_t buckets = 2 * static_cast<size_t>(std::max(1, options.width_px));
    Envelope(t, meas, buckets, &env_t, &env_meas);
    Envelope(t, fit, buckets, &fit_t, &fit_v);
    Envelope(t, res, buckets, &res_t, &res_v);
  }
  auto dots = [&](const std::vector<double>& x, const std::vector<double>& y,
                  const std::vector<double>& ex, const std::vector<double>& ey) {
    if (dense) {
      plline(static_cast<PLINT>(ex.size()), ex.data(), ey.data());
    } else {
      plpoin(static_cast<PLINT>(x.size()), x.data(), y.data(), 1);
    }
  };
  auto draw = [&] {
    pladv(0);
    plschr(0, 0.95);
    // Top panel: rates.
    plvpor(0.10, 0.97, 0.45, 0.87);
    plwind(0.0, t_hi, y_bottom, y_top);
    plcol0(kLight);
    plbox("g", 0, 0, "g", 0, 0);
    plcol0(kBlack);
    plbox("bcst", 0, 0, "bcnstv", 0, 0);
    plmtex("l", 4.2, 0.5, 0.5, "swing rate (deg/s)");
    // Long file names: shrink the title to fit (about 75 characters fit at full size).
    plschr(0, 1.1 * std::min(1.0, 75.0 / static_cast<double>(title.size())));
    plmtex("t", 2.6, 0.5, 0.5, title.c_str());
    plschr(0, 0.85);
    plmtex("t", 1.0, 0.5, 0.5, subtitle.c_str());
    plschr(0, 0.95);
    // The fitted line first, the measured samples on top of it: where they agree the samples
    // still show (issue 18); the envelope of a dense log is a thin band, so the line under it is
    // drawn wide enough to show on both sides.
    plcol0(kBlue);
    plwidth(dense ? 3.0 : 1.2);
    if (dense) {
      plline(static_cast<PLINT>(fit_t.size()), fit_t.data(), fit_v.data());
    } else {
      plline(static_cast<PLINT>(n), t.data(), fit.data());
    }
    plwidth(1.0);
    plcol0(kBlack);
    plssym(0, 0.45);
    // measured: filled dots that show on the line (Hershey code 17; dense: their envelope)
    if (dense) {
      dots(t, meas, env_t, env_meas);
    } else {
      plpoin(static_cast<PLINT>(n), t.data(), meas.data(), 17);
    }
    // Legend (top right, inside).
    {
      const double lx = 0.62 * t_hi, ly = 1.22 * y_abs, dx = 0.035 * t_hi;
      const double xs[2] = {lx, lx + dx}, ys[2] = {ly, ly};
      plcol0(kBlue);
      plline(2, xs, ys);
      plcol0(kBlack);
      plptex(lx + 1.3 * dx, ly, 1, 0, 0, "fitted");
      const double mx = lx + 0.2 * t_hi;
      const double px[3] = {mx + 0.1 * dx, mx + 0.5 * dx, mx + 0.9 * dx}, py[3] = {ly, ly, ly};
      plcol0(kBlack);
      plssym(0, 0.45);
      plpoin(3, px, py, 17);
      plcol0(kBlack);
      plptex(mx + 1.3 * dx, ly, 1, 0, 0, "measured");
    }
    // Bottom panel: residuals with the noise bands.
    plvpor(0.10, 0.97, 0.10, 0.35);
    plwind(0.0, t_hi, -r_abs, r_abs);
    plcol0(kLight);
    plbox("g", 0, 0, "g", 0, 0);
    plcol0(kBlack);
    plbox("bcnst", 0, 0, "bcnstv", 0, 0);
    plmtex("b", 3.0, 0.5, 0.5, "time from the start of the window (s)");
    plmtex("l", 4.2, 0.5, 0.5, "meas. - fit (deg/s)");
    plmtex("t", 1.4, 0.0, 0.0, residual_label.c_str());
    plcol0(kGrey);
    plssym(0, 0.35);
    dots(t, res, res_t, res_v);
    if (noise_deg > 0.0) {
      plcol0(kBand);
      for (double s : {-2.0, -1.0, 1.0, 2.0}) {
        const double xs[2] = {0.0, t_hi}, ys[2] = {s * noise_deg, s * noise_deg};
        pllsty(std::fabs(s) > 1.5 ? 2 : 1);
        plline(2, xs, ys);
      }
      pllsty(1);
    }
    plcol0(kBlack);
  };
  FigureOptions figure;
  figure.width_px = options.width_px;
  figure.height_px = options.height_px;
  return WriteFigure(path, figure, draw, why);
}

}  // namespace bifilar
