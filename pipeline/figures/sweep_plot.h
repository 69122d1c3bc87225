// Figure of a trace's amplitude sweep (issue 8 item 3): I against amplitude, where the ideal model
// is flat. One point per fitted band at the band's mean amplitude, with its +-1 sigma statistical
// (HAC) error bar and a horizontal bar over the band's amplitude range; the reported I as a flat
// line with its +-1 sigma band; when the sweep found a trend, the fitted I_0 (1 + c A^p) and a
// marker on the band the result was taken from. A right-hand axis gives the deviation from the
// reported I in %. PNG or SVG by extension, via pipeline/figures/figure.h. Method: docs/method.md,
// "Amplitude sweep".
#pragma once

#include <string>

#include "fit/trace_fit.h"
#include "pipeline/figures/figure.h"

namespace bifilar {

struct SweepPlotOptions {
  std::string title;        // usually the log's name; empty: "trace"
  double unit_scale = 1.0;  // display value = kg m^2 value * unit_scale; > 0
  std::string unit_label = InertiaUnitPlotLabel(DisplayUnits::kSi);  // PLplot text
  FigureOptions figure = {800, 500};                                 // page size (px)
  // true: title and axes only, no subtitle or legend, for a page that explains the figure in its
  // caption (the report, which shows one per trace at thumbnail size).
  bool compact = false;
};

// Draws `sweep` with the reported inertia (kg m^2) and its per-trace 1-sigma std (kg m^2).
// Returns false with *why when the sweep was not evaluated (fewer than two fitted bands: no
// figure), when a value is not finite, or when the file cannot be written.
bool WriteAmplitudeSweepFigure(const AmplitudeSweep& sweep, double inertia_kg_m2,
                               double inertia_std_kg_m2, const std::string& path,
                               const SweepPlotOptions& options, std::string* why);

}  // namespace bifilar
