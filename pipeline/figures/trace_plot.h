// Figure of one trace fit (issue 3 item 10, issue 25): the fit that gave the reported I over its
// own samples (the lowest-amplitude band when the amplitude sweep took the result from there,
// else the whole window), measured samples under the fitted line, and that fit's residuals with
// the +-1 and +-2 noise-sigma lines beneath. A band result adds a panel above of the whole
// window, its own fit labelled as not the result. PNG or SVG by extension, via
// pipeline/figures/figure.h.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "fit/trace_fit.h"
#include "pipeline/figures/figure.h"

namespace bifilar {

struct TracePlotOptions {
  std::string title;    // usually the log's file name; empty: "trace"
  int width_px = 1100;  // page width (px); > 0
  int height_px = 700;  // page height (px); > 0
  // Inertias (I, K_D, C) in the title are multiplied by unit_scale and labelled unit_label
  // (PLplot text): the config's display units (slug ft^2 under units: imperial).
  double unit_scale = 1.0;
  std::string unit_label = InertiaUnitPlotLabel(DisplayUnits::kSi);
  // The 1-sigma std of I shown in the title (kg m^2) and its name ("total", "stat"); NaN: the
  // fit's own inertia_std_kg_m2, named "total".
  double inertia_std_kg_m2 = NAN;
  std::string std_label = "total";
};

// What the fit figure draws (times from the start of the plotted window, rates in deg/s).
struct TraceFigureData {
  bool from_band = false;       // the result is the lowest-amplitude band's fit
  double window_start_s = 0.0;  // log time of the plotted window's first sample (s)
  std::vector<double> t_s;      // the plotted window's samples
  std::vector<double> measured_deg_per_s;
  std::vector<double> fitted_deg_per_s;    // the fit that gave the reported I
  std::vector<double> residual_deg_per_s;  // measured - fitted
  double bias_deg_per_s = 0.0;             // that fit's gyro bias
  double residual_rms_deg_per_s = 0.0;
  double rms_over_noise = 0.0;  // of that fit; 0 when the noise is unknown
  double autocorr_lag1 = 0.0;   // of its residuals
  // from_band: the whole window (from its own first sample) and its fit, not the result.
  std::vector<double> whole_t_s, whole_measured_deg_per_s, whole_fitted_deg_per_s;
  std::string title, subtitle, detail, rate_label, residual_label, whole_label;
};

// The figure's data; false (with *why) when the fit kept no series.
bool MakeTraceFigureData(const TraceFitResult& result, const TracePlotOptions& options,
                         TraceFigureData* data, std::string* why);

// "0.05018 ± 0.00066": value and std to the digits the std supports (two significant digits of
// the std); a power of ten factored out for very small or large values: "(1.600 ± 0.020)e-5".
std::string ValueWithStd(double value, double std_value);

// Needs the series (TraceFitOptions::keep_series, the default); works for ok and rejected fits.
// Returns false with *why when there is nothing to draw or the file cannot be written.
bool WriteTraceFitFigure(const TraceFitResult& result, const std::string& path,
                         const TracePlotOptions& options, std::string* why);

}  // namespace bifilar
