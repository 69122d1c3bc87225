// Figure of one trace fit (issue 3 item 10): measured and fitted swing rate over the window
// (top), the residuals beneath with the +-1 and +-2 noise-sigma bands (bottom). The title carries
// the file name, the model and I +- std. PNG or SVG by extension, via pipeline/figures/figure.h.
#pragma once

#include <string>

#include "fit/trace_fit.h"

namespace bifilar {

struct TracePlotOptions {
  std::string title;     // usually the log's file name; empty: "trace"
  int width_px = 1100;   // page width (px); > 0
  int height_px = 700;   // page height (px); > 0
  // Inertias (I, K_D, C) in the title are multiplied by unit_scale and labelled unit_label
  // (PLplot text): the config's display units (slug ft^2 under units: imperial).
  double unit_scale = 1.0;
  std::string unit_label = "kg m#u2#d";
};

// Needs the series (TraceFitOptions::keep_series, the default); works for ok and rejected fits.
// Returns false with *why when there is nothing to draw or the file cannot be written.
bool WriteTraceFitFigure(const TraceFitResult& result, const std::string& path,
                         const TracePlotOptions& options, std::string* why);

}  // namespace bifilar
