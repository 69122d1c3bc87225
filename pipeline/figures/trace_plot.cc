#include "pipeline/figures/trace_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <plplot.h>

#include "base/text_format.h"
#include "base/units.h"
#include "pipeline/figures/figure.h"

namespace bifilar {
namespace {

// Above this many samples a dot per sample is drawn no more (more than ~8 per pixel column show
// nothing more, and a 3 M-sample log took 110 s and gave a 750 MB SVG): each series becomes its
// min/max envelope over 2 buckets per pixel, as a zigzag line in time order.
constexpr size_t kMaxDotsDrawn = 8000;

void Envelope(const std::vector<double>& t, const std::vector<double>& v, size_t buckets,
              std::vector<double>* x, std::vector<double>* y) {
  const size_t n = t.size();
  x->clear();
  y->clear();
  if (n <= 2 * buckets) {
    *x = t;
    *y = v;
    return;
  }
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

double Rms(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x * x;
  return v.empty() ? 0.0 : std::sqrt(s / v.size());
}

double AutocorrLag1(const std::vector<double>& v) {
  if (v.size() < 3) return 0.0;
  double mean = 0.0;
  for (double x : v) mean += x;
  mean /= v.size();
  double num = 0.0, den = 0.0;
  for (size_t k = 0; k < v.size(); ++k) {
    den += (v[k] - mean) * (v[k] - mean);
    if (k > 0) num += (v[k] - mean) * (v[k - 1] - mean);
  }
  return den > 0.0 ? num / den : 0.0;
}

// The series of the fit that gave I: the band's (t_s[first ...]) or the window's.
void ResultSeries(const TraceFitResult& r, TraceFigureData* d) {
  const bool band = !r.band_fitted_rate_rad_per_s.empty() &&
                    r.band_first_index + r.band_fitted_rate_rad_per_s.size() <= r.t_s.size();
  d->from_band = band;
  const size_t first = band ? r.band_first_index : 0;
  const size_t n = band ? r.band_fitted_rate_rad_per_s.size() : r.t_s.size();
  d->window_start_s = r.t_s[first];
  for (size_t k = 0; k < n; ++k) {
    const size_t i = first + k;
    const double fitted = band ? r.band_fitted_rate_rad_per_s[k] : r.fitted_rate_rad_per_s[i];
    d->t_s.push_back(r.t_s[i] - d->window_start_s);
    d->measured_deg_per_s.push_back(r.measured_rate_rad_per_s[i] * kDegPerRad);
    d->fitted_deg_per_s.push_back(fitted * kDegPerRad);
    d->residual_deg_per_s.push_back((r.measured_rate_rad_per_s[i] - fitted) * kDegPerRad);
  }
  d->bias_deg_per_s = r.bias_rad_per_s * kDegPerRad;
  if (band) d->bias_deg_per_s = r.sweep.bands[r.sweep.low_band].bias_rad_per_s * kDegPerRad;
  d->residual_rms_deg_per_s = Rms(d->residual_deg_per_s);
  const double noise_deg = r.noise_rad_per_s * kDegPerRad;
  d->rms_over_noise = noise_deg > 0.0 ? d->residual_rms_deg_per_s / noise_deg : 0.0;
  d->autocorr_lag1 = AutocorrLag1(d->residual_deg_per_s);
  if (!band) return;
  const double t0 = r.t_s.front();
  for (size_t i = 0; i < r.t_s.size(); ++i) {
    d->whole_t_s.push_back(r.t_s[i] - t0);
    d->whole_measured_deg_per_s.push_back(r.measured_rate_rad_per_s[i] * kDegPerRad);
    d->whole_fitted_deg_per_s.push_back(r.fitted_rate_rad_per_s[i] * kDegPerRad);
  }
}

// Title (file, I +- std with the std's name), subtitle (which fit), detail (its other
// parameters, each named), and the panels' labels.
void Texts(const TraceFitResult& r, const TracePlotOptions& o, TraceFigureData* d) {
  const std::string name = o.title.empty() ? std::string("trace") : o.title;
  const double k = o.unit_scale;
  const std::string& unit = o.unit_label;
  const double std_kg_m2 =
      std::isfinite(o.inertia_std_kg_m2) ? o.inertia_std_kg_m2 : r.inertia_std_kg_m2;
  d->title = name + ":  I = " + ValueWithStd(k * r.params.inertia_kg_m2, k * std_kg_m2) + " " +
             unit + "  (± 1σ " + o.std_label + ")";
  if (r.status != TraceFitStatus::kOk) d->title += "  (" + std::string(ToString(r.status)) + ")";
  const std::string model = std::string(ToString(r.model)) + " model";
  if (d->from_band) {
    const AmplitudeSweepBand& b = r.sweep.bands[r.sweep.low_band];
    d->subtitle = "result: fit of the lowest-amplitude band, " +
                  Fmt("%.1f", b.amplitude_start_deg) + " → " + Fmt("%.1f", b.amplitude_end_deg) +
                  " deg over " + Fmt("%.1f", b.t1_s - b.t0_s) + " s (I depends on the amplitude)";
  } else {
    d->subtitle = "result: fit of the whole window, amplitude " +
                  Fmt("%.1f", r.amplitude_start_deg) + " → " + Fmt("%.1f", r.amplitude_end_deg) +
                  " deg";
  }
  d->detail = model + "; drag K#dD#u = " + Fmt("%.3g", k * r.params.drag_coeff_kg_m2) + " " + unit +
              ", viscous C = " + Fmt("%.3g", k * r.params.viscous_coeff_kg_m2_per_s) + " " + unit +
              "/s" + (d->from_band ? " (whole-window fit's)" : "") + "; gyro bias " +
              Fmt("%.3f", d->bias_deg_per_s) + " deg/s";
  d->rate_label =
      std::string(d->from_band ? "band" : "window") +
      ": measured samples (grey) and the fit (blue), from t = " + Fmt("%.2f", d->window_start_s) +
      " s of the log";
  d->residual_label = "measured − fit: rms " + Fmt("%.3g", d->residual_rms_deg_per_s) + " deg/s" +
                      (d->rms_over_noise > 0.0
                           ? " = " + Fmt("%.2f", d->rms_over_noise) + " × gyro noise (lines ±1, ±2)"
                           : std::string()) +
                      "; lag-1 autocorrelation " + Fmt("%.2f", d->autocorr_lag1);
  if (d->from_band) {
    d->whole_label = "whole window, band shaded; red: whole-window fit, I = " +
                     Fmt("%.4g", k * r.inertia_window_kg_m2) + " " + unit + " (not the result)";
  }
}

}  // namespace

std::string ValueWithStd(double value, double std_value) {
  if (!(std::isfinite(value) && std::isfinite(std_value) && std_value > 0.0)) {
    return Fmt("%.6g", value);
  }
  const int std_exp = static_cast<int>(std::floor(std::log10(std_value)));
  const int value_exp =
      value != 0.0 ? static_cast<int>(std::floor(std::log10(std::fabs(value)))) : std_exp;
  const int shift = value_exp < -3 || value_exp > 4 ? value_exp : 0;
  const double scale = std::pow(10.0, -shift);
  const int decimals = std::max(0, 1 - (std_exp - shift));
  char buf[128];
  std::snprintf(buf, sizeof buf, "%.*f ± %.*f", decimals, value * scale, decimals,
                std_value * scale);
  if (shift == 0) return buf;
  return "(" + std::string(buf) + ") × 10#u" + std::to_string(shift) + "#d";
}

bool MakeTraceFigureData(const TraceFitResult& r, const TracePlotOptions& options,
                         TraceFigureData* d, std::string* why) {
  const size_t n = r.t_s.size();
  if (n < 2 || r.fitted_rate_rad_per_s.size() != n || r.measured_rate_rad_per_s.size() != n ||
      r.residual_rad_per_s.size() != n) {
    *why = "no fitted series to plot (fit failed or keep_series was off)";
    return false;
  }
  *d = TraceFigureData();
  ResultSeries(r, d);
  Texts(r, options, d);
  return true;
}

namespace {

// Everything drawn, with the ranges and the envelopes of dense series.
struct TracePage {
  TraceFigureData d;
  double noise_deg = 0.0;
  double band_t0 = 0.0, band_t1 = 0.0;  // the band in the whole-window panel's time
  bool dense = false;
  std::vector<double> env_t, env_meas, env_res_t, env_res, whole_t, whole_meas, whole_fit_t,
      whole_fit;
};

double AbsMax(const std::vector<double>& a, const std::vector<double>& b) {
  double m = 0.0;
  for (double v : a) m = std::max(m, std::fabs(v));
  for (double v : b) m = std::max(m, std::fabs(v));
  return m > 0.0 ? m : 1.0;
}

// Measured samples: grey dots (an envelope line when dense), under the fit's line.
void Samples(const TracePage& p, const std::vector<double>& t, const std::vector<double>& v,
             const std::vector<double>& et, const std::vector<double>& ev, double dot) {
  plcol0(kFigureGrey);
  if (p.dense) {
    plwidth(1.0);
    plline(static_cast<PLINT>(et.size()), et.data(), ev.data());
  } else {
    plwidth(dot);
    plpoin(static_cast<PLINT>(t.size()), t.data(), v.data(), -1);  // a point: a round dot
  }
  plwidth(1.0);
}

void Axes(const char* x_opt, const char* y_label) {
  plcol0(kFigureLight);
  LabelledBox("g", "g");
  plcol0(kFigureBlack);
  LabelledBox(x_opt, "bcnstv");
  plmtex("l", 5.0, 0.5, 0.5, y_label);
}

// The whole window (band results only): measured envelope, the whole-window fit, the band shaded.
void WholePanel(const TracePage& p, double y0, double y1) {
  const TraceFigureData& d = p.d;
  plvpor(0.10, 0.97, y0, y1);
  const double y = 1.1 * AbsMax(d.whole_measured_deg_per_s, d.whole_fitted_deg_per_s);
  plwind(0.0, d.whole_t_s.back(), -y, y);
  const PLFLT fx[4] = {p.band_t0, p.band_t1, p.band_t1, p.band_t0}, fy[4] = {-y, -y, y, y};
  plcol0(kFigureTranslucentBand);
  plfill(4, fx, fy);
  Axes("bcnst", "deg/s");
  plcol0(kFigureGrey);
  plline(static_cast<PLINT>(p.whole_t.size()), p.whole_t.data(), p.whole_meas.data());
  plcol0(kFigureRed);
  plline(static_cast<PLINT>(p.whole_fit_t.size()), p.whole_fit_t.data(), p.whole_fit.data());
  plcol0(kFigureBlack);
  plmtex("t", 0.6, 0.0, 0.0, d.whole_label.c_str());
}

// The result's fit over its samples.
void RatePanel(const TracePage& p, double y0, double y1) {
  const TraceFigureData& d = p.d;
  plvpor(0.10, 0.97, y0, y1);
  const double y = 1.1 * AbsMax(d.measured_deg_per_s, d.fitted_deg_per_s);
  plwind(0.0, d.t_s.back(), -y, y);
  Axes("bcst", "swing rate (deg/s)");
  Samples(p, d.t_s, d.measured_deg_per_s, p.env_t, p.env_meas, 3.0);
  plcol0(kFigureBlue);  // the fit on top: the samples show around it, the line stays visible
  plwidth(1.6);
  plline(static_cast<PLINT>(d.t_s.size()), d.t_s.data(), d.fitted_deg_per_s.data());
  plwidth(1.0);
  plcol0(kFigureBlack);
  plmtex("t", 0.6, 0.0, 0.0, d.rate_label.c_str());
}

// That fit's residuals with the noise lines.
void ResidualPanel(const TracePage& p, double y0, double y1) {
  const TraceFigureData& d = p.d;
  plvpor(0.10, 0.97, y0, y1);
  const double r = std::max(AbsMax(d.residual_deg_per_s, {}), 2.5 * p.noise_deg) * 1.1;
  plwind(0.0, d.t_s.back(), -r, r);
  Axes("bcnst", "deg/s");
  plmtex("b", 2.8, 0.5, 0.5, "time (s)");
  Samples(p, d.t_s, d.residual_deg_per_s, p.env_res_t, p.env_res, 2.0);
  if (p.noise_deg > 0.0) {
    plcol0(kFigureBand);
    for (double s : {-2.0, -1.0, 1.0, 2.0}) {
      const PLFLT xs[2] = {0.0, d.t_s.back()}, ys[2] = {s * p.noise_deg, s * p.noise_deg};
      plwidth(std::fabs(s) > 1.5 ? 1.0 : 1.6);
      plline(2, xs, ys);
    }
    plwidth(1.0);
  }
  plcol0(kFigureBlack);
  plmtex("t", 0.6, 0.0, 0.0, d.residual_label.c_str());
}

void Titles(const TracePage& p) {
  plvpor(0.0, 1.0, 0.0, 1.0);
  plwind(0.0, 1.0, 0.0, 1.0);
  plcol0(kFigureBlack);
  // Long file names: shrink the title to fit (about 80 characters fit at full size).
  plschr(0, 1.05 * std::min(1.0, 80.0 / static_cast<double>(p.d.title.size())));
  plptex(0.5, 0.955, 1, 0, 0.5, p.d.title.c_str());
  plschr(0, 0.8);
  plptex(0.5, 0.918, 1, 0, 0.5, p.d.subtitle.c_str());
  plptex(0.5, 0.886, 1, 0, 0.5, p.d.detail.c_str());
}

}  // namespace

// MakeTraceFigureData, the envelopes of dense series, then drawn: titles, the whole window
// (band results), the result's fit, its residuals.
bool WriteTraceFitFigure(const TraceFitResult& r, const std::string& path,
                         const TracePlotOptions& options, std::string* why) {
  TracePage p;
  if (!MakeTraceFigureData(r, options, &p.d, why)) {
    *why = path + ": " + *why;
    return false;
  }
  const TraceFigureData& d = p.d;
  p.noise_deg = r.noise_rad_per_s * kDegPerRad;
  const size_t buckets = 2 * static_cast<size_t>(std::max(1, options.width_px));
  p.dense = d.t_s.size() > kMaxDotsDrawn;
  Envelope(d.t_s, d.measured_deg_per_s, buckets, &p.env_t, &p.env_meas);
  Envelope(d.t_s, d.residual_deg_per_s, buckets, &p.env_res_t, &p.env_res);
  if (d.from_band) {
    Envelope(d.whole_t_s, d.whole_measured_deg_per_s, buckets, &p.whole_t, &p.whole_meas);
    Envelope(d.whole_t_s, d.whole_fitted_deg_per_s, buckets, &p.whole_fit_t, &p.whole_fit);
    p.band_t0 = d.window_start_s - r.t_s.front();
    p.band_t1 = p.band_t0 + d.t_s.back();
  }
  auto draw = [&] {
    SetTranslucentBand(0.2);
    pladv(0);
    plschr(0, 0.8);
    Titles(p);
    plschr(0, 0.8);
    if (d.from_band) {
      WholePanel(p, 0.69, 0.82);
      RatePanel(p, 0.35, 0.60);
      ResidualPanel(p, 0.08, 0.26);
    } else {
      RatePanel(p, 0.40, 0.82);
      ResidualPanel(p, 0.08, 0.31);
    }
  };
  FigureOptions figure;
  figure.width_px = options.width_px;
  figure.height_px = options.height_px;
  return WriteFigure(path, figure, draw, why);
}

}  // namespace bifilar
