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

// Everything the trace figure draws: the series (time from the start of the window, rates in
// deg/s), the panels' ranges, the texts, and the envelopes of a dense series.
struct TracePage {
  size_t n = 0;
  std::vector<double> t, meas, fit, res;
  double t_hi = 0.0, y_abs = 0.0, y_top = 0.0, y_bottom = 0.0, noise_deg = 0.0, r_abs = 0.0;
  std::string title, subtitle, residual_label;
  bool dense = false;
  std::vector<double> env_t, env_meas, fit_t, fit_v, res_t, res_v;
};

// Time from the start of the window; rates in deg/s (what people read off a gyro); the panels'
// ranges.
void TraceSeries(const TraceFitResult& r, TracePage* p) {
  const size_t n = p->n;
  const double t0 = r.t_s.front();
  p->t.resize(n);
  p->meas.resize(n);
  p->fit.resize(n);
  p->res.resize(n);
  for (size_t k = 0; k < n; ++k) {
    p->t[k] = r.t_s[k] - t0;
    p->meas[k] = r.measured_rate_rad_per_s[k] * kDegPerRad;
    p->fit[k] = r.fitted_rate_rad_per_s[k] * kDegPerRad;
    p->res[k] = -r.residual_rad_per_s[k] * kDegPerRad;  // measured - fitted
  }
  p->t_hi = p->t.back();
  double y_abs = 0.0;
  for (size_t k = 0; k < n; ++k) {
    y_abs = std::max({y_abs, std::fabs(p->meas[k]), std::fabs(p->fit[k])});
  }
  p->y_abs = y_abs;
  p->y_top = 1.35 * y_abs;  // room for the legend on top
  p->y_bottom = -1.12 * y_abs;
  p->noise_deg = r.noise_rad_per_s * kDegPerRad;
  double r_abs = 0.0;
  for (double v : p->res) r_abs = std::max(r_abs, std::fabs(v));
  r_abs = std::max(r_abs, 2.5 * p->noise_deg) * 1.1;
  if (!(r_abs > 0.0)) r_abs = 1.0;
  p->r_abs = r_abs;
}

// Title (file, model, I +- std), subtitle (K_D, C, bias, amplitude) and the residual's label.
void TraceTexts(const TraceFitResult& r, const TracePlotOptions& options, TracePage* p) {
  const std::string name = options.title.empty() ? std::string("trace") : options.title;
  const double k = options.unit_scale;
  const std::string& unit = options.unit_label;
  p->title = name + " [" + ToString(r.model) + "]: I = " +
             Fmt("%.6g", k * r.params.inertia_kg_m2) + " ± " +
             Fmt("%.2g", k * r.inertia_std_kg_m2) + " " + unit;
  if (r.status != TraceFitStatus::kOk) p->title += "  (" + std::string(ToString(r.status)) + ")";
  p->subtitle =
      "K#dD#u = " + Fmt("%.3g", k * r.params.drag_coeff_kg_m2) + " " + unit + ",  C = " +
      Fmt("%.3g", k * r.params.viscous_coeff_kg_m2_per_s) + " " + unit + "/s,  bias = " +
      Fmt("%.3f", r.bias_rad_per_s * kDegPerRad) + " deg/s,  amplitude " +
      Fmt("%.1f", r.amplitude_start_deg) + " → " + Fmt("%.1f", r.amplitude_end_deg) + " deg";
  p->residual_label =
      "residual: rms " + Fmt("%.3f", r.residual_rms_rad_per_s * kDegPerRad) + " deg/s = " +
      Fmt("%.2f", r.rms_over_noise) + " × noise (" + (r.noise_from_input ? "rest" : "window") +
      "),  #gr#d1#u = " + Fmt("%.3f", r.residual_autocorr_lag1);
}

// Dense series: envelopes (above), drawn as lines.
void DenseEnvelope(int width_px, TracePage* p) {
  p->dense = p->n > kMaxDotsDrawn;
  if (!p->dense) return;
  const size_t buckets = 2 * static_cast<size_t>(std::max(1, width_px));
  Envelope(p->t, p->meas, buckets, &p->env_t, &p->env_meas);
  Envelope(p->t, p->fit, buckets, &p->fit_t, &p->fit_v);
  Envelope(p->t, p->res, buckets, &p->res_t, &p->res_v);
}

// A dot per sample (x, y), or the envelope (ex, ey) as a line when the series is dense.
void Dots(const TracePage& p, const std::vector<double>& x, const std::vector<double>& y,
          const std::vector<double>& ex, const std::vector<double>& ey) {
  if (p.dense) {
    plline(static_cast<PLINT>(ex.size()), ex.data(), ey.data());
  } else {
    plpoin(static_cast<PLINT>(x.size()), x.data(), y.data(), 1);
  }
}

// Top panel: rates, the titles and the legend.
void RatePanel(const TracePage& p) {
  plvpor(0.10, 0.97, 0.45, 0.87);
  plwind(0.0, p.t_hi, p.y_bottom, p.y_top);
  plcol0(kLight);
  plbox("g", 0, 0, "g", 0, 0);
  plcol0(kBlack);
  plbox("bcst", 0, 0, "bcnstv", 0, 0);
  plmtex("l", 4.2, 0.5, 0.5, "swing rate (deg/s)");
  // Long file names: shrink the title to fit (about 75 characters fit at full size).
  plschr(0, 1.1 * std::min(1.0, 75.0 / static_cast<double>(p.title.size())));
  plmtex("t", 2.6, 0.5, 0.5, p.title.c_str());
  plschr(0, 0.85);
  plmtex("t", 1.0, 0.5, 0.5, p.subtitle.c_str());
  plschr(0, 0.95);
  // The fitted line first, the measured samples on top of it: where they agree the samples
  // still show (issue 18); the envelope of a dense log is a thin band, so the line under it is
  // drawn wide enough to show on both sides.
  plcol0(kBlue);
  plwidth(p.dense ? 3.0 : 1.2);
  if (p.dense) {
    plline(static_cast<PLINT>(p.fit_t.size()), p.fit_t.data(), p.fit_v.data());
  } else {
    plline(static_cast<PLINT>(p.n), p.t.data(), p.fit.data());
  }
  plwidth(1.0);
  plcol0(kBlack);
  plssym(0, 0.45);
  // measured: filled dots that show on the line (Hershey code 17; dense: their envelope)
  if (p.dense) {
    Dots(p, p.t, p.meas, p.env_t, p.env_meas);
  } else {
    plpoin(static_cast<PLINT>(p.n), p.t.data(), p.meas.data(), 17);
  }
  // Legend (top right, inside).
  const double lx = 0.62 * p.t_hi, ly = 1.22 * p.y_abs, dx = 0.035 * p.t_hi;
  const double xs[2] = {lx, lx + dx}, ys[2] = {ly, ly};
  plcol0(kBlue);
  plline(2, xs, ys);
  plcol0(kBlack);
  plptex(lx + 1.3 * dx, ly, 1, 0, 0, "fitted");
  const double mx = lx + 0.2 * p.t_hi;
  const double px[3] = {mx + 0.1 * dx, mx + 0.5 * dx, mx + 0.9 * dx}, py[3] = {ly, ly, ly};
  plcol0(kBlack);
  plssym(0, 0.45);
  plpoin(3, px, py, 17);
  plcol0(kBlack);
  plptex(mx + 1.3 * dx, ly, 1, 0, 0, "measured");
}

// Bottom panel: residuals with the noise bands.
void ResidualPanel(const TracePage& p) {
  plvpor(0.10, 0.97, 0.10, 0.35);
  plwind(0.0, p.t_hi, -p.r_abs, p.r_abs);
  plcol0(kLight);
  plbox("g", 0, 0, "g", 0, 0);
  plcol0(kBlack);
  plbox("bcnst", 0, 0, "bcnstv", 0, 0);
  plmtex("b", 3.0, 0.5, 0.5, "time from the start of the window (s)");
  plmtex("l", 4.2, 0.5, 0.5, "meas. - fit (deg/s)");
  plmtex("t", 1.4, 0.0, 0.0, p.residual_label.c_str());
  plcol0(kGrey);
  plssym(0, 0.35);
  Dots(p, p.t, p.res, p.res_t, p.res_v);
  if (p.noise_deg > 0.0) {
    plcol0(kBand);
    for (double s : {-2.0, -1.0, 1.0, 2.0}) {
      const double xs[2] = {0.0, p.t_hi}, ys[2] = {s * p.noise_deg, s * p.noise_deg};
      pllsty(std::fabs(s) > 1.5 ? 2 : 1);
      plline(2, xs, ys);
    }
    pllsty(1);
  }
  plcol0(kBlack);
}

}  // namespace

// TraceSeries -> TraceTexts -> DenseEnvelope, then drawn: RatePanel -> ResidualPanel.
bool WriteTraceFitFigure(const TraceFitResult& r, const std::string& path,
                         const TracePlotOptions& options, std::string* why) {
  const size_t n = r.t_s.size();
  if (n < 2 || r.fitted_rate_rad_per_s.size() != n || r.measured_rate_rad_per_s.size() != n ||
      r.residual_rad_per_s.size() != n) {
    *why = path + ": no fitted series to plot (fit failed or keep_series was off)";
    return false;
  }
  TracePage p;
  p.n = n;
  TraceSeries(r, &p);
  TraceTexts(r, options, &p);
  DenseEnvelope(options.width_px, &p);
  auto draw = [&] {
    pladv(0);
    plschr(0, 0.95);
    RatePanel(p);
    ResidualPanel(p);
  };
  FigureOptions figure;
  figure.width_px = options.width_px;
  figure.height_px = options.height_px;
  return WriteFigure(path, figure, draw, why);
}

}  // namespace bifilar
