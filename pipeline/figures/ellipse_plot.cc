#include "pipeline/figures/ellipse_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <plplot.h>

#include "base/text_format.h"
#include "base/units.h"

namespace bifilar {
namespace {

// The fitted curve: blue, thick, dashed.
void DrawFittedCurve(const std::vector<double>& x, const std::vector<double>& y) {
  plcol0(kFigureBlue);
  plwidth(2.0);
  pllsty(2);
  plline(static_cast<PLINT>(x.size()), x.data(), y.data());
  pllsty(1);
  plwidth(1.0);
}

double Curve(const EllipseResult& r, double pitch_deg) {
  return EllipseMoment(r.a_kg_m2, r.b_kg_m2, r.c_kg_m2, pitch_deg);
}

// Everything the moment figure draws, in display units.
struct MomentPage {
  double k = 1.0;  // kg m^2 -> display unit
  double x_lo = -90, x_hi = 90, y_lo = 0.0, y_hi = 0.0;
  std::vector<double> cx, cy;        // the fitted curve
  std::vector<double> px, py;        // the trials
  std::vector<double> ex, elo, ehi;  // the error bars
  bool legend_below = false;
};

// Curve, trials, error bars (the given stds of a weighted fit, else each angle's mean +- std).
void MomentSeries(const EllipseResult& r, MomentPage* p) {
  const double k = p->k;
  for (const auto& q : r.points) {
    p->x_lo = std::min(p->x_lo, std::floor(q.pitch_deg / 10) * 10);
    p->x_hi = std::max(p->x_hi, std::ceil(q.pitch_deg / 10) * 10);
  }
  for (int i = 0; i <= 720; ++i) {
    const double t = p->x_lo + (p->x_hi - p->x_lo) * i / 720.0;
    p->cx.push_back(t);
    p->cy.push_back(Curve(r, t) * k);
  }
  for (const auto& q : r.points) {
    p->px.push_back(q.pitch_deg);
    p->py.push_back(q.inertia_kg_m2 * k);
  }
  if (r.weighted) {
    for (const auto& q : r.points) {
      p->ex.push_back(q.pitch_deg);
      p->elo.push_back((q.inertia_kg_m2 - q.std_kg_m2) * k);
      p->ehi.push_back((q.inertia_kg_m2 + q.std_kg_m2) * k);
    }
  } else {
    for (const auto& a : r.angles) {
      if (a.n < 2) continue;
      p->ex.push_back(a.pitch_deg);
      p->elo.push_back((a.mean_kg_m2 - a.std_kg_m2) * k);
      p->ehi.push_back((a.mean_kg_m2 + a.std_kg_m2) * k);
    }
  }
}

// The axes' ranges: everything drawn, with room for the legend where the curve is not (below
// when the middle, 0 deg, is high, else above).
void MomentAxes(const EllipseResult& r, MomentPage* p) {
  double y_lo = *std::min_element(p->cy.begin(), p->cy.end());
  double y_hi = *std::max_element(p->cy.begin(), p->cy.end());
  for (double v : p->py) y_lo = std::min(y_lo, v), y_hi = std::max(y_hi, v);
  for (double v : p->elo) y_lo = std::min(y_lo, v);
  for (double v : p->ehi) y_hi = std::max(y_hi, v);
  p->legend_below = Curve(r, 0.0) >= Curve(r, 90.0);
  // The legend's 4 rows take ~0.3 of the plot's height: 9.5 pads of 0.06 leave 0.35 of it free
  // (5.5 let the legend cover the trials near +-90 deg, issue 25).
  const double pad = 0.06 * (y_hi - y_lo) + 1e-12 * std::fabs(y_hi);
  y_lo -= p->legend_below ? 9.5 * pad : pad;
  y_hi += p->legend_below ? pad : 9.5 * pad;
  p->y_lo = y_lo;
  p->y_hi = y_hi;
  p->x_lo -= 5;
  p->x_hi += 5;
}

// Principal axes: theta = tau (I_zp) and tau +- 90 (I_xp), as labelled vertical lines.
void DrawPrincipalLines(const EllipseResult& r, const MomentPage& p) {
  std::vector<std::pair<double, std::string>> principal;
  if (r.tau_defined) {
    for (double t : {r.tau_deg.value - 90, r.tau_deg.value, r.tau_deg.value + 90}) {
      if (t < p.x_lo || t > p.x_hi) continue;
      principal.push_back({t, std::fabs(t - r.tau_deg.value) < 1 ? "z#dp#u" : "x#dp#u"});
    }
  }
  plcol0(kFigureRed);
  pllsty(3);
  plwidth(1.5);
  for (const auto& [t, label] : principal) {
    const double xs[2] = {t, t}, ys[2] = {p.y_lo, p.y_hi};
    plline(2, xs, ys);
    const bool right_edge = t > p.x_hi - 12;
    const double y_text =
        p.legend_below ? p.y_hi - 0.05 * (p.y_hi - p.y_lo) : p.y_lo + 0.06 * (p.y_hi - p.y_lo);
    plptex(t + (right_edge ? -1.5 : 1.5), y_text, 1, 0, right_edge ? 1 : 0, label.c_str());
  }
  pllsty(1);
}

// Error bars and trials, then the body-axis moments: I_z at 0 deg, I_x at +-90 deg.
void DrawTrials(const EllipseResult& r, const MomentPage& p) {
  plcol0(kFigureGrey);
  if (!p.ex.empty())
    plerry(static_cast<PLINT>(p.ex.size()), p.ex.data(), p.elo.data(), p.ehi.data());
  plcol0(kFigureBlack);
  plssym(0, 0.9);
  plpoin(static_cast<PLINT>(p.px.size()), p.px.data(), p.py.data(), 4);  // open circles
  plcol0(kFigureGreen);
  plssym(0, 1.6);
  std::vector<double> bx, by;
  for (double t : {-90.0, 0.0, 90.0}) {
    if (t < p.x_lo || t > p.x_hi) continue;
    bx.push_back(t);
    by.push_back(Curve(r, t) * p.k);
  }
  plpoin(static_cast<PLINT>(bx.size()), bx.data(), by.data(), 5);  // crosses
  plssym(0, 1.0);
}

// Legend: trials, error bars, the fit with tau, the body-axis moments.
void DrawMomentLegend(const EllipseResult& r, const MomentPage& p) {
  const double k = p.k;
  const std::string curve_text = r.tau_defined
                                     ? "fit (Eq. 7), #gt = " + Fmt("%.2f", r.tau_deg.value) +
                                           " ± " + Fmt("%.2f", r.tau_deg.std) + " deg"
                                     : std::string("fit (Eq. 7), #gt undefined");
  const std::string body_text = "body axes: I#dx#u = " + Fmt("%.4g", r.ix.value * k) +
                                ", I#dz#u = " + Fmt("%.4g", r.iz.value * k) +
                                ", I#dxz#u = " + Fmt("%.3g", r.ixz.value * k);
  const char* texts[4] = {"trials", r.weighted ? "± 1 std (given)" : "angle mean ± 1 std",
                          curve_text.c_str(), body_text.c_str()};
  PLINT opts[4] = {PL_LEGEND_SYMBOL, PL_LEGEND_LINE, PL_LEGEND_LINE, PL_LEGEND_SYMBOL};
  PLINT text_colors[4] = {kFigureBlack, kFigureBlack, kFigureBlack, kFigureBlack};
  PLINT line_colors[4] = {kFigureBlack, kFigureGrey, kFigureBlue, kFigureGreen};
  PLINT line_styles[4] = {1, 1, 2, 1};
  PLFLT line_widths[4] = {1, 1, 2, 1};
  PLINT symbol_colors[4] = {kFigureBlack, kFigureBlack, kFigureBlack, kFigureGreen};
  PLFLT symbol_scales[4] = {1.2, 1, 1, 1.6};
  PLINT symbol_numbers[4] = {1, 1, 1, 1};
  const char* symbols[4] = {"○", "", "", "×"};
  PLFLT lw, lh;
  pllegend(&lw, &lh, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX,
           (p.legend_below ? PL_POSITION_BOTTOM : PL_POSITION_TOP) | PL_POSITION_INSIDE, 0.0, 0.02,
           0.06, 0, kFigureBlack, 1, 4, 1, 4, opts, 0.8, 0.8, 2.0, 0.0, text_colors, texts, nullptr,
           nullptr, nullptr, nullptr, line_colors, line_styles, line_widths, symbol_colors,
           symbol_scales, symbol_numbers, symbols);
}

}  // namespace

// MomentSeries -> MomentAxes, then drawn: frame -> DrawPrincipalLines -> DrawFittedCurve ->
// DrawTrials -> DrawMomentLegend.
bool WriteEllipseMomentFigure(const EllipseResult& r, const std::string& path,
                              const EllipsePlotOptions& options, std::string* why) {
  MomentPage p;
  p.k = options.unit_scale;
  MomentSeries(r, &p);
  MomentAxes(r, &p);
  auto draw = [&] {
    plschr(0, 1.1);
    plcol0(kFigureBlack);
    pladv(0);
    plvsta();
    plwind(p.x_lo, p.x_hi, p.y_lo, p.y_hi);
    plcol0(kFigureLight);
    LabelledBox("g", "g", 30);
    plcol0(kFigureBlack);
    LabelledBox("bcnst", "bcnstv", 30);
    pllab("pitch #gh (deg, nose up)", ("moment of inertia (" + options.unit_label + ")").c_str(),
          "Moments against pitch and the fitted ellipse of inertia");
    DrawPrincipalLines(r, p);
    DrawFittedCurve(p.cx, p.cy);
    DrawTrials(r, p);
    DrawMomentLegend(r, p);
  };
  return WriteFigure(path, options.figure, draw, why);
}

bool WriteEllipsePolarFigure(const EllipseResult& r, const std::string& path,
                             const EllipsePlotOptions& options, std::string* why) {
  const double k = options.unit_scale;
  // Direction of the swing axis at pitch theta in the plot (x forward right, z down):
  // n = (-sin theta, cos theta) in (x, z) -> plot (x, -z) = (-sin theta, -cos theta).
  auto dir = [](double pitch_deg, double* px, double* py) {
    const double t = pitch_deg * kRadPerDeg;
    *px = -std::sin(t);
    *py = -std::cos(t);
  };
  FigureOptions figure = options.figure;
  figure.width_px = std::max(figure.width_px, 1100);
  figure.height_px = std::max(figure.height_px, 680);

  auto panel = [&](bool inverse_sqrt, double vx0, double vx1) {
    auto radius = [&](double inertia_kg_m2) {
      return inverse_sqrt ? 1.0 / std::sqrt(inertia_kg_m2 * k) : inertia_kg_m2 * k;
    };
    std::vector<double> cx, cy;
    double r_max = 0;
    for (int i = 0; i <= 720; ++i) {
      const double t = -180.0 + 360.0 * i / 720.0;
      double dx, dy;
      dir(t, &dx, &dy);
      const double rr = radius(Curve(r, t));
      cx.push_back(rr * dx);
      cy.push_back(rr * dy);
      r_max = std::max(r_max, rr);
    }
    // Each measured axis is drawn at both ends (theta and theta + 180 deg are the same axis).
    std::vector<double> px, py;
    for (const auto& p : r.points) {
      double dx, dy;
      dir(p.pitch_deg, &dx, &dy);
      const double rr = radius(p.inertia_kg_m2);
      px.push_back(rr * dx);
      py.push_back(rr * dy);
      px.push_back(-rr * dx);
      py.push_back(-rr * dy);
      r_max = std::max(r_max, rr);
    }
    // Radii far from 1 are drawn in units of a power of ten named in the axis labels: PLplot's
    // own "(x10^n)" mark sits where it covers the title or the unit.
    const int power = PowerOfTenFor(r_max);
    const double scale = std::pow(10.0, -power);
    for (std::vector<double>* v : {&cx, &cy, &px, &py}) {
      for (double& x : *v) x *= scale;
    }
    r_max *= scale;
    // Room between the data and the frame for the axis labels (x_p, x_body were cut or covered).
    const double lim = 1.6 * r_max;
    plcol0(kFigureBlack);
    plvpas(vx0, vx1, 0.2, 0.86, 1.0);
    plwind(-lim, lim, -lim, lim);
    LabelledBox("bcnst", "bcnstv");
    // (slug ft^2)^-1/2 written slug^-1/2 ft^-1: a superscript inside a superscript is garbled.
    const std::string unit = ScaledUnit(
        inverse_sqrt ? InverseSqrtUnit(options.unit_label) : "(" + options.unit_label + ")", power);
    pllab(("forward, x#dbody#u  " + unit).c_str(), ("up, -z#dbody#u  " + unit).c_str(),
          inverse_sqrt ? "Ellipse of inertia, radius 1/#(2267)I(#gh)"
                       : "Moments in polar coordinates, radius I(#gh)");
    // Body axes.
    plcol0(kFigureGrey);
    pllsty(1);
    const double hx[2] = {-lim, lim}, hy[2] = {0, 0};
    plline(2, hx, hy);
    plline(2, hy, hx);
    plcol0(kFigureBlack);
    plptex(0.98 * lim, 0.05 * lim, 1, 0, 1, "x#dbody#u");
    plptex(0.04 * lim, -0.9 * lim, 1, 0, 0, "z#dbody#u");
    // Principal axes: principal z at pitch tau, principal x perpendicular.
    if (r.tau_defined) {
      plcol0(kFigureRed);
      pllsty(3);
      plwidth(1.5);
      double zx, zy;
      dir(r.tau_deg.value, &zx, &zy);
      const double ax[2] = {-lim * zx, lim * zx}, ay[2] = {-lim * zy, lim * zy};
      plline(2, ax, ay);
      const double bx[2] = {lim * zy, -lim * zy}, by[2] = {-lim * zx, lim * zx};
      plline(2, bx, by);  // perpendicular: (x, z) = (cos tau, sin tau)
      pllsty(1);
      plwidth(1.0);
      // Labels at the negative ends (up, aft), away from the body-axis labels.
      plptex(-0.9 * lim * zx + 0.04 * lim, -0.9 * lim * zy, 1, 0, 0, "z#dp#u");
      plptex(0.9 * lim * zy, -0.9 * lim * zx + 0.04 * lim, 1, 0, 0, "x#dp#u");
    }
    // Curve and data.
    DrawFittedCurve(cx, cy);
    plcol0(kFigureBlack);
    plssym(0, 0.8);
    plpoin(static_cast<PLINT>(px.size()), px.data(), py.data(), 4);
    plssym(0, 1.0);
  };

  auto draw = [&] {
    plschr(0, 0.95);
    pladv(0);
    // Room right of each panel for PLplot's "(x10^n)" of the x axis (it was cut at the page's
    // edge, issue 25).
    panel(false, 0.1, 0.44);
    panel(true, 0.6, 0.91);
    plcol0(kFigureBlack);
    plvpor(0.0, 1.0, 0.0, 1.0);
    plwind(0, 1, 0, 1);
    const std::string caption =
        r.tau_defined ? "principal axes (red dashed) at #gt = " + Fmt("%.2f", r.tau_deg.value) +
                            " deg: the principal x axis lies #gt below body x when #gt > 0"
                      : std::string("#gt undefined: the curve cannot be told from a circle");
    plptex(0.5, 0.03, 1, 0, 0.5, caption.c_str());
  };
  return WriteFigure(path, figure, draw, why);
}

}  // namespace bifilar
