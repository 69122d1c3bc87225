#include "pipeline/figures/tensor_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <plplot.h>

#include "base/text_format.h"
#include "base/units.h"

namespace bifilar {
namespace {

// A body plane seen in a panel: the body axes along the panel's horizontal and vertical
// directions (unit vectors in body axes) and their labels.
struct View {
  const char* title;
  double h[3], v[3];
  const char* h_label;
  const char* v_label;
};

const View kViews[3] = {
    {"Top view (x-y plane)", {0, 1, 0}, {1, 0, 0}, "y#dbody#u, right wing", "x#dbody#u, forward"},
    {"Side view (x-z plane)", {1, 0, 0}, {0, 0, -1}, "x#dbody#u, forward", "-z#dbody#u, up"},
    {"Front view (y-z plane)", {0, 1, 0}, {0, 0, -1}, "y#dbody#u, right wing", "-z#dbody#u, up"},
};

double Dot(const double a[3], const std::array<double, 3>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

// The ellipsoid's radius along an axis of moment `inertia_kg_m2`: 1/sqrt(I) in display units.
double Radius(double inertia_kg_m2, double scale) { return 1.0 / std::sqrt(inertia_kg_m2 * scale); }

// The section of the ellipsoid in the view's plane: radius 1/sqrt(I(n)) for n in the plane.
void DrawSection(const std::array<double, kTensorComponents>& c, double scale, const View& view) {
  std::vector<double> ex, ey;
  for (int i = 0; i <= 720; ++i) {
    const double t = 2 * kPi * i / 720.0;
    const std::array<double, 3> n = {std::cos(t) * view.h[0] + std::sin(t) * view.v[0],
                                     std::cos(t) * view.h[1] + std::sin(t) * view.v[1],
                                     std::cos(t) * view.h[2] + std::sin(t) * view.v[2]};
    const double rr = Radius(TensorMoment(c, n), scale);
    ex.push_back(rr * std::cos(t));
    ey.push_back(rr * std::sin(t));
  }
  plcol0(kFigureBlue);
  plwidth(2.0);
  plline(static_cast<PLINT>(ex.size()), ex.data(), ey.data());
  plwidth(1.0);
}

// Principal axes projected onto the plane, at the length of their own radius.
void DrawPrincipalAxes(const TensorResult& r, double scale, double lim, const View& view) {
  plcol0(kFigureRed);
  pllsty(3);
  plwidth(1.5);
  for (int k = 0; k < 3; ++k) {
    const double rr = Radius(r.principal_moments[k].value, scale);
    const double px = Dot(view.h, r.principal_axes[k]) * rr;
    const double py = Dot(view.v, r.principal_axes[k]) * rr;
    if (std::hypot(px, py) < 0.05 * lim) continue;  // nearly normal to this plane
    const double ax[2] = {-px, px}, ay[2] = {-py, py};
    plline(2, ax, ay);
    plptex(1.08 * px, 1.08 * py, 1, 0, 0.5, std::to_string(k + 1).c_str());
  }
  pllsty(1);
  plwidth(1.0);
}

// Measured moments whose axes lie near this plane, at both ends of the axis.
void DrawMeasuredMoments(const TensorResult& r, const TensorPlotOptions& options,
                         const View& view) {
  const double sin_near = std::sin(options.near_plane_deg * kRadPerDeg);
  const double normal[3] = {view.h[1] * view.v[2] - view.h[2] * view.v[1],
                            view.h[2] * view.v[0] - view.h[0] * view.v[2],
                            view.h[0] * view.v[1] - view.h[1] * view.v[0]};
  std::vector<double> mx, my;
  for (const TensorPointResidual& p : r.residuals) {
    const std::array<double, 3>& n = r.orientations[p.orientation].nominal_in_body;
    if (std::fabs(Dot(normal, n)) > sin_near) continue;
    const double rr = Radius(p.inertia_kg_m2, options.unit_scale);
    const double h = Dot(view.h, n), v = Dot(view.v, n), norm = std::hypot(h, v);
    mx.push_back(rr * h / norm);
    my.push_back(rr * v / norm);
    mx.push_back(-rr * h / norm);
    my.push_back(-rr * v / norm);
  }
  plcol0(kFigureBlack);
  plssym(0, 0.8);
  if (!mx.empty()) plpoin(static_cast<PLINT>(mx.size()), mx.data(), my.data(), 4);
  plssym(0, 1.0);
}

// One body plane in the viewport (x0, x1, y0, y1): axes, the ellipsoid's section, the principal
// axes and the measured moments near the plane; `lim` is every panel's half-width.
void ViewPanel(const TensorResult& r, const std::array<double, kTensorComponents>& c,
               const TensorPlotOptions& options, double lim, const View& view, double x0, double x1,
               double y0, double y1) {
  plcol0(kFigureBlack);
  plvpas(x0, x1, y0, y1, 1.0);
  plwind(-lim, lim, -lim, lim);
  LabelledBox("bcnst", "bcnstv");
  const std::string unit = InverseSqrtUnit(options.unit_label);
  pllab((std::string(view.h_label) + "  " + unit).c_str(),
        (std::string(view.v_label) + "  " + unit).c_str(), view.title);
  plcol0(kFigureGrey);
  const double hx[2] = {-lim, lim}, hy[2] = {0, 0};
  plline(2, hx, hy);
  plline(2, hy, hx);
  DrawSection(c, options.unit_scale, view);
  DrawPrincipalAxes(r, options.unit_scale, lim, view);
  DrawMeasuredMoments(r, options, view);
}

// The per-orientation residuals over their expected scatter, as bars (red beyond 3).
void ResidualPanel(const TensorResult& r, double x0, double x1, double y0, double y1) {
  const int m = static_cast<int>(r.orientations.size());
  double z_max = 3.0;
  for (const TensorOrientation& o : r.orientations) z_max = std::max(z_max, 1.2 * std::fabs(o.z));
  plcol0(kFigureBlack);
  plvpor(x0, x1, y0, y1);
  plwind(0.0, m + 1.0, -z_max, z_max);
  LabelledBox("bcnst", "bcnstv", 1);
  pllab("orientation (as listed in the report)", "residual / expected scatter",
        "Per-orientation residuals");
  plcol0(kFigureLight);
  for (double level : {-2.0, -1.0, 1.0, 2.0}) {
    const double lx[2] = {0, m + 1.0}, ly[2] = {level, level};
    plline(2, lx, ly);
  }
  plcol0(kFigureGrey);
  const double zx[2] = {0, m + 1.0}, zy[2] = {0, 0};
  plline(2, zx, zy);
  for (int g = 0; g < m; ++g) {
    const double z = r.orientations[g].z;
    plcol0(std::fabs(z) > 3 ? kFigureRed : kFigureBlue);
    plwidth(6.0);
    const double bx[2] = {g + 1.0, g + 1.0}, by[2] = {0, z};
    plline(2, bx, by);
    plwidth(1.0);
  }
}

}  // namespace

// Three ViewPanels (top, side, front), the ResidualPanel and the caption.
bool WriteTensorFigure(const TensorResult& r, const std::string& path,
                       const TensorPlotOptions& options, std::string* why) {
  if (!r.full) {
    *why = "the tensor figure needs a full 3-D fit";
    return false;
  }
  std::array<double, kTensorComponents> c;
  for (int k = 0; k < kTensorComponents; ++k) c[k] = r.components[k].value;
  const double scale = options.unit_scale;
  // The common limit: the largest radius, along the axis of the smallest principal moment.
  const double lim = 1.25 * Radius(r.principal_moments[0].value, scale);
  auto draw = [&] {
    plschr(0, 0.85);
    pladv(0);
    // Rows apart enough for the upper row's x label and the lower row's title (they overlapped,
    // issue 25).
    ViewPanel(r, c, options, lim, kViews[0], 0.07, 0.47, 0.57, 0.86);
    ViewPanel(r, c, options, lim, kViews[1], 0.57, 0.97, 0.57, 0.86);
    ViewPanel(r, c, options, lim, kViews[2], 0.07, 0.47, 0.09, 0.38);
    ResidualPanel(r, 0.57, 0.97, 0.11, 0.36);
    plcol0(kFigureBlack);
    plvpor(0.0, 1.0, 0.0, 1.0);
    plwind(0, 1, 0, 1);
    const std::string caption = "ellipsoid of inertia (blue), principal axes 1-3 (red: " +
                                Fmt("%#.4g", r.principal_moments[0].value * scale) + ", " +
                                Fmt("%#.4g", r.principal_moments[1].value * scale) + ", " +
                                Fmt("%#.4g", r.principal_moments[2].value * scale) + " " +
                                options.unit_label + ")";
    plptex(0.5, 0.97, 1, 0, 0.5, caption.c_str());  // its superscript inside the page
    plptex(0.5, 0.943, 1, 0, 0.5, "o: measured moments whose axes lie near that plane");
  };
  return WriteFigure(path, options.figure, draw, why);
}

}  // namespace bifilar
