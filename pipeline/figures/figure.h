// Writing a PLplot figure to a file. PLplot keeps global state, so every figure is drawn under
// one process-wide lock; callers may plot from worker threads.
#pragma once

#include <functional>
#include <string>

#include "base/units.h"

namespace bifilar {

struct FigureOptions {
  int width_px = 900;   // page width (px); > 0
  int height_px = 600;  // page height (px); > 0
};

// Colour map 0 indices every figure may use: WriteFigure installs this palette after plinit
// (background white, foreground black).
enum FigureColour {
  kFigureBlack = 1,
  kFigureBlue = 2,             // fits, curves
  kFigureRed = 3,              // principal axes, warnings
  kFigureGrey = 4,             // measured data
  kFigureGreen = 5,            // body-axis markers
  kFigureLight = 6,            // grid lines
  kFigureBand = 7,             // noise bands
  kFigureTranslucentBand = 8,  // kFigureBand's colour at an opacity the figure sets (below)
};

// Sets kFigureTranslucentBand to kFigureBand's colour at `opacity` (0-1): a band behind the
// data. Call inside `draw`.
void SetTranslucentBand(double opacity);

// Draws `draw` (PLplot C API calls: plenv, plline, ... between plinit and plend) into `path`.
// The device follows the extension: ".png" -> pngcairo, ".svg" -> PLplot's svg driver (text
// stays text), compacted by CompactSvg (pipeline/figures/svg_compact.h). The file is written
// to a temporary name and renamed. Returns false with *why set on failure.
bool WriteFigure(const std::string& path, const FigureOptions& options,
                 const std::function<void()>& draw, std::string* why);

// The name of the inertia unit (InertiaUnitName) in PLplot text: "kg m#u2#d" or "slug ft#u2#d".
const char* InertiaUnitPlotLabel(DisplayUnits units);

// Axis units in PLplot text. "(U)^-1/2" of a display unit "A B#u2#d" as "(A#u-1/2#d B#u-1#d)"
// (a superscript inside a superscript is garbled); other labels as "1/#(2267)(U)".
std::string InverseSqrtUnit(const std::string& unit);

// The power of ten to draw values up to `r_max` in: 0 within [0.1, 1000), else its exponent
// (PLplot's own "(x10^n)" mark sits where it covers titles and units).
int PowerOfTenFor(double r_max);

// "(slug ft^2)" for values drawn in units of 10^power: "(10^power slug ft^2)".
std::string ScaledUnit(const std::string& unit, int power);

// Axis ticks that stay true at any scale (issue 32: every y tick of a sweep read "0.1"). The
// step of ticks over [lo, hi]: 1, 2 or 5 x 10^n, the smallest giving at most `max_ticks` ticks.
double TickStep(double lo, double hi, int max_ticks = 7);

// The decimals that tell ticks `step` apart ("%.<d>f"): 0.25 -> 2, 0.5 -> 1, 20 -> 0.
int TickDecimals(double step);

// A tick value as its label: fixed notation to `decimals`, never "-0".
std::string TickLabel(double value, int decimals);

// plbox over the current window (plwind) with ticks at TickStep of each axis (or `x_step`,
// `y_step` when > 0) and labels of TickLabel at TickDecimals (PLplot's custom labels,
// plslabelfunc): no two ticks of an axis share a label. `x_opt`, `y_opt` as plbox's.
void LabelledBox(const char* x_opt, const char* y_opt, double x_step = 0.0, double y_step = 0.0);

}  // namespace bifilar
