// The report's fit-and-residual thumbnail of one trace fit: the fit that gave the reported I (the
// lowest-amplitude band's when the result comes from there, pipeline/figures/trace_plot.h) over
// its samples, the measured rate (grey) under the fit (blue), the residual envelope with the
// +-noise lines beneath. Lines only
// (pipeline/figures/trace_plot.h draws a symbol per sample, ~0.1 s per trace; this is a few ms),
// so a campaign of 60 traces stays fast.
#pragma once

#include <cmath>
#include <string>

#include "base/units.h"
#include "fit/trace_fit.h"

namespace bifilar {

// Needs the series (TraceFitOptions::keep_series). `title` is not drawn (the file name is in the
// report's caption). The title's +- is inertia_std_kg_m2 (the record's 1-sigma std, kg m^2; NaN:
// the fit's own), named std_label ("total", "stat"). Returns false with *why when there is
// nothing to draw or the file cannot be written.
bool WriteReportTraceFigure(const TraceFitResult& fit, const std::string& title, DisplayUnits units,
                            const std::string& path, int width_px, int height_px, std::string* why,
                            double inertia_std_kg_m2 = NAN, const std::string& std_label = "total");

}  // namespace bifilar
