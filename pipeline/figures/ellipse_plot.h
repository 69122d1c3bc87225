// Figures of an ellipse-of-inertia fit (PLplot through pipeline/figures/figure.h): the paper's Fig.
// 3 (moment against pitch with the fitted curve and the principal axes) and Fig. 4 (the moments in
// polar coordinates, beside the true ellipse of inertia, radius 1/sqrt(I)). Conventions:
// docs/physics.md section 3; the polar panels draw the body x-z plane with x forward to the
// right and z down, so tau > 0 shows the principal x axis below body x.
#pragma once

#include <string>

#include "fit/ellipse.h"
#include "pipeline/figures/figure.h"

namespace bifilar {

struct EllipsePlotOptions {
  double unit_scale = 1.0;  // display value = kg m^2 value * unit_scale; > 0
  std::string unit_label = InertiaUnitPlotLabel(DisplayUnits::kSi);  // PLplot text
  FigureOptions figure;                                              // page size (px)
};

// Moment against pitch: trials, per-angle mean +- std error bars (given std when weighted), the
// fitted curve, I_zp at theta = tau and I_xp at tau +- 90 (red dotted), I_x and I_z marked.
bool WriteEllipseMomentFigure(const EllipseResult& result, const std::string& path,
                              const EllipsePlotOptions& options, std::string* why);

// Two polar panels in the body x-z plane: the moments I(theta) along each axis (paper Fig. 4)
// and the ellipse of inertia 1/sqrt(I(theta)); body axes black, principal axes red dotted.
bool WriteEllipsePolarFigure(const EllipseResult& result, const std::string& path,
                             const EllipsePlotOptions& options, std::string* why);

}  // namespace bifilar
