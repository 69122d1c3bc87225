// Writing a PLplot figure to a file. PLplot keeps global state, so every figure is drawn under
// one process-wide lock; callers may plot from worker threads.
#pragma once

#include <functional>
#include <string>

namespace bifilar {

struct FigureOptions {
  int width_px = 900;   // page width (px); > 0
  int height_px = 600;  // page height (px); > 0
};

// Draws `draw` (PLplot C API calls: plenv, plline, ... between plinit and plend) into `path`.
// The device follows the extension: ".png" -> pngcairo, ".svg" -> svgcairo. The file is written
// to a temporary name and renamed. Returns false with *why set on failure.
bool WriteFigure(const std::string& path, const FigureOptions& options,
                 const std::function<void()>& draw, std::string* why);

}  // namespace bifilar
