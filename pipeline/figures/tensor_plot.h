// The inertia tensor's figure (PLplot through pipeline/figures/figure.h): the ellipsoid of inertia
// (radius 1/sqrt(I(n))) cut by the three body planes, top (x-y), side (x-z) and front (y-z) views,
// with the body axes (grey), the principal axes projected onto each plane (red, labelled 1-3 in
// ascending moment) and the measured moments whose axes lie near that plane; and the residual of
// each orientation in units of its expected scatter. Conventions: docs/physics.md §3.5 (x
// forward, y right wing, z down; the side and front views draw z down as "down").
#pragma once

#include <string>

#include "fit/tensor.h"
#include "pipeline/figures/figure.h"

namespace bifilar {

struct TensorPlotOptions {
  double unit_scale = 1.0;  // display value = kg m^2 value * unit_scale; > 0
  std::string unit_label = InertiaUnitPlotLabel(DisplayUnits::kSi);  // PLplot text
  FigureOptions figure = {1100, 900};                                // page size (px)
  double near_plane_deg = 10.0;  // measured axes within this of a plane are drawn in it
};

// Needs a full 3-D result (result.full); false with *why otherwise or when drawing fails.
bool WriteTensorFigure(const TensorResult& result, const std::string& path,
                       const TensorPlotOptions& options, std::string* why);

}  // namespace bifilar
