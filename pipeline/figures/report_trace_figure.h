// The report's fit-and-residual thumbnail of one trace fit: the fit (wide blue) and the measured
// rate (dark, on top), the residual envelope with the +-noise band beneath. Lines only
// (pipeline/figures/trace_plot.h draws a symbol per sample, ~0.1 s per trace; this is a few ms),
// so a campaign of 60 traces stays fast.
#pragma once

#include <string>

#include "base/units.h"
#include "fit/trace_fit.h"

namespace bifilar {

// Needs the series (TraceFitOptions::keep_series). `title` is not drawn (the file name is in the
// report's caption). Returns false with *why when there is nothing to draw or the file cannot be
// written.
bool WriteReportTraceFigure(const TraceFitResult& fit, const std::string& title, DisplayUnits units,
                            const std::string& path, int width_px, int height_px, std::string* why);

}  // namespace bifilar
