#include "pipeline/figures/rig_plan_plot.h"

#include <plplot.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "base/text_format.h"
#include "pipeline/figures/figure.h"

namespace bifilar {
namespace {

// Row pointers over a column-major copy: z[i][j] at separation i, length j (PLplot's layout).
struct Grid2 {
  std::vector<double> data;
  std::vector<PLFLT*> rows;
  Grid2(const std::vector<double>& v, size_t nx, size_t ny) : data(v), rows(nx) {
    for (size_t i = 0; i < nx; ++i) rows[i] = data.data() + i * ny;
  }
};

// The shading's levels (%): 1-2-5 steps (finer over a narrow range) covering lo..hi,
// capped at 30x the lowest, at most ~12 bands.
std::vector<double> NiceLevels(double lo, double hi) {
  hi = std::max(std::min(hi, 30.0 * lo), 1.05 * lo);
  const double span = hi / lo;
  const std::vector<double> steps =
      span < 4.0    ? std::vector<double>{1.0, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0}
      : span < 10.0 ? std::vector<double>{1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 7.0}
                    : std::vector<double>{1.0, 2.0, 5.0};
  std::vector<double> levels;
  for (int e = static_cast<int>(std::floor(std::log10(lo))) - 1;
       e <= static_cast<int>(std::ceil(std::log10(hi))) + 1; ++e) {
    for (double s : steps) {
      const double v = s * std::pow(10.0, e);
      // Not crowding the ends' labels on the colour bar (within 6 % of the log span).
      const double room = 0.06 * std::log10(hi / lo);
      if (std::log10(v / lo) > room && std::log10(hi / v) > room) levels.push_back(v);
    }
  }
  // The ends: the lowest value, and the cap (everything above it in the last band).
  levels.insert(levels.begin(), lo);
  levels.push_back(hi);
  while (levels.size() > 13) {  // too many: every other inner level
    std::vector<double> fewer = {levels.front()};
    for (size_t k = 2; k + 1 < levels.size(); k += 2) fewer.push_back(levels[k]);
    fewer.push_back(levels.back());
    levels = fewer;
  }
  return levels;
}

// Tick labels of the colour bar: the shading is of log10(total %), labelled in %.
void PercentOfLog10(PLINT, PLFLT value, char* label, PLINT length, PLPointer) {
  std::snprintf(label, static_cast<size_t>(length), "%s",
                Fmt("%.3g", std::pow(10.0, value)).c_str());
}

// The total std (%) in filled bands of log10, the colour bar to the right, labelled grey
// contours of the levels, and the target's contour in red when the grid reaches it.
void DrawShades(const RigPlanFigure& f, const std::vector<double>& levels, PLcGrid* cg) {
  const size_t nx = f.separation_m.size(), ny = f.length_m.size();
  std::vector<double> log_total(f.total_percent.size());
  for (size_t k = 0; k < log_total.size(); ++k) {
    log_total[k] = std::log10(std::max(f.total_percent[k], 1e-300));
  }
  Grid2 z(log_total, nx, ny);
  std::vector<PLFLT> edges(levels.size());
  for (size_t k = 0; k < levels.size(); ++k) edges[k] = std::log10(levels[k]);
  std::vector<PLFLT> shade_edges = edges;
  shade_edges.back() = 300.0;  // everything above the cap in the last band
  const PLFLT r[2] = {0.35, 1.0}, g[2] = {0.55, 0.95}, b[2] = {0.95, 0.6}, pos[2] = {0.0, 1.0};
  plscmap1l(1, 2, pos, r, g, b, nullptr);
  plshades(z.rows.data(), static_cast<PLINT>(nx), static_cast<PLINT>(ny), nullptr,
           f.separation_m.front() * 1e3, f.separation_m.back() * 1e3, f.length_m.front(),
           f.length_m.back(), shade_edges.data(), static_cast<PLINT>(shade_edges.size()), 0.0, 0,
           0.0, plfill, true, pltr1, cg);
  // Labelled contours at the inner levels, of the total itself (labels in %), readable
  // (PLplot's default label size is tiny).
  Grid2 linear(f.total_percent, nx, ny);
  std::vector<PLFLT> inner(levels.begin() + 1, levels.end() - 1);
  plcol0(kFigureGrey);
  pl_setcontlabelparam(0.008, 0.9, 0.45, 1);
  pl_setcontlabelformat(3, 3);
  if (!inner.empty()) {
    plcont(linear.rows.data(), static_cast<PLINT>(nx), static_cast<PLINT>(ny), 1,
           static_cast<PLINT>(nx), 1, static_cast<PLINT>(ny), inner.data(),
           static_cast<PLINT>(inner.size()), pltr1, cg);
  }
  pl_setcontlabelparam(0.006, 0.3, 0.1, 0);
  if (f.target_drawn) {
    PLFLT target = f.target_percent;
    plcol0(kFigureRed);
    plwidth(3.0);
    plcont(linear.rows.data(), static_cast<PLINT>(nx), static_cast<PLINT>(ny), 1,
           static_cast<PLINT>(nx), 1, static_cast<PLINT>(ny), &target, 1, pltr1, cg);
    plwidth(1.0);
  }
  // The colour bar: one box per band, each edge labelled in % (the last band: above the cap).
  plcol0(kFigureBlack);
  plschr(0, 0.8);
  const char* axis_opts[] = {"bcvtmo"};
  const PLINT label_opts[] = {PL_COLORBAR_LABEL_RIGHT};
  const char* labels[] = {"expected total std of I (%)"};
  const PLFLT ticks[] = {0.0};
  const PLINT sub_ticks[] = {0};
  const PLINT n_values[] = {static_cast<PLINT>(edges.size())};
  const PLFLT* values[] = {edges.data()};
  PLFLT width = 0, height = 0;
  plslabelfunc(PercentOfLog10, nullptr);  // the bar's edges in %
  plcolorbar(&width, &height, PL_COLORBAR_SHADE | PL_COLORBAR_SHADE_LABEL,
             PL_POSITION_RIGHT | PL_POSITION_OUTSIDE | PL_POSITION_VIEWPORT, 0.02, 0.0, 0.035, 1.0,
             0, 1, 1, 0.0, 0.0, 0, 0.0, 1, label_opts, labels, 1, axis_opts, ticks, sub_ticks,
             n_values, values);
  plslabelfunc(nullptr, nullptr);
  plschr(0, 1.0);
}

// Cells outside a constraint: grey, one rectangle per run of cells in a column.
void DrawConstraints(const RigPlanFigure& f) {
  const size_t nx = f.separation_m.size(), ny = f.length_m.size();
  const double dx = (f.separation_m.back() - f.separation_m.front()) * 1e3 / (nx - 1);
  const double dy = (f.length_m.back() - f.length_m.front()) / (ny - 1);
  plscol0a(kFigureLight, 80, 80, 80, 0.5);
  plcol0(kFigureLight);
  for (size_t i = 0; i < nx; ++i) {
    for (size_t j = 0; j < ny;) {
      if (f.feasible[i * ny + j]) {
        ++j;
        continue;
      }
      size_t k = j;
      while (k + 1 < ny && !f.feasible[i * ny + k + 1]) ++k;
      const double x0 = std::max(f.separation_m[i] * 1e3 - dx / 2, f.separation_m.front() * 1e3);
      const double x1 = std::min(f.separation_m[i] * 1e3 + dx / 2, f.separation_m.back() * 1e3);
      const double y0 = std::max(f.length_m[j] - dy / 2, f.length_m.front());
      const double y1 = std::min(f.length_m[k] + dy / 2, f.length_m.back());
      PLFLT px[4] = {x0, x1, x1, x0}, py[4] = {y0, y0, y1, y1};
      plfill(4, px, py);
      j = k + 1;
    }
  }
}

// The recommended rig: a star, its label inside the frame on the side with room.
void DrawChoice(const RigPlanFigure& f, const double window[4]) {
  PLFLT mx = f.chosen_separation_m * 1e3, my = f.chosen_length_m;
  plcol0(kFigureBlack);
  plssym(0, 2.5);
  plpoin(1, &mx, &my, 18);  // a star
  plssym(0, 1.0);
  const double w = window[1] - window[0], h = window[3] - window[2];
  const bool right = mx > window[0] + 0.5 * w, up = my > window[2] + 0.5 * h;
  plschr(0, 0.9);
  plptex(mx + (right ? -0.03 : 0.03) * w, my + (up ? -0.06 : 0.045) * h, 1, 0, right ? 1.0 : 0.0,
         ("recommended: " + Fmt("%.3g", f.chosen_total_percent) + " %").c_str());
  plschr(0, 1.0);
}

// Two caption lines under the axis label, inside the page.
void DrawCaption(const RigPlanFigure& f) {
  std::string target;
  if (f.target_drawn) {
    target = "red line: the target " + Fmt("%.3g", f.target_percent) + " %";
  } else if (f.target_percent < f.lowest_percent) {
    target = "the target " + Fmt("%.3g", f.target_percent) +
             " % is below every rig shown (lowest " + Fmt("%.3g", f.lowest_percent) + " %)";
  } else {
    target = "the target " + Fmt("%.3g", f.target_percent) + " % is met everywhere shown";
  }
  plcol0(kFigureBlack);
  plschr(0, 0.75);
  plmtex("b", 5.6, 0.0, 0.0, "colours, grey contours: expected total std of I (%, 3 repeats)");
  plmtex("b", 7.2, 0.0, 0.0, target.c_str());
  plmtex("b", 8.8, 0.0, 0.0,
         "dark shading: outside a constraint (period window, D <= 0.9 L); star: the recommended "
         "rig");
  plschr(0, 1.0);
}

}  // namespace

bool WriteRigPlanFigure(const RigPlanFigure& figure, const std::string& path, std::string* why) {
  const size_t nx = figure.separation_m.size(), ny = figure.length_m.size();
  if (nx < 2 || ny < 2 || figure.total_percent.size() != nx * ny ||
      figure.feasible.size() != nx * ny) {
    *why = "rig plan figure: the grid is empty or inconsistent";
    return false;
  }
  RigPlanFigure f = figure;
  const auto [lo_it, hi_it] = std::minmax_element(f.total_percent.begin(), f.total_percent.end());
  const double lo = std::max(*lo_it, 1e-12), hi = std::max(*hi_it, lo);
  f.lowest_percent = lo;
  const std::vector<double> levels = NiceLevels(lo, hi);
  f.target_drawn = f.target_percent > lo && f.target_percent < hi;
  FigureOptions options;
  options.width_px = 1000;
  options.height_px = 750;
  return WriteFigure(
      path, options,
      [&] {
        pladv(0);
        plvpor(0.1, 0.8, 0.2, 0.92);
        // A margin around the grid, so the star at a corner of the constraints is whole.
        const double x0 = f.separation_m.front() * 1e3, x1 = f.separation_m.back() * 1e3;
        const double y0 = f.length_m.front(), y1 = f.length_m.back();
        const double window[4] = {x0 - 0.03 * (x1 - x0), x1 + 0.03 * (x1 - x0),
                                  y0 - 0.03 * (y1 - y0), y1 + 0.03 * (y1 - y0)};
        plwind(window[0], window[1], window[2], window[3]);
        std::vector<double> xg(nx), yg(ny);
        for (size_t i = 0; i < nx; ++i) xg[i] = f.separation_m[i] * 1e3;
        for (size_t j = 0; j < ny; ++j) yg[j] = f.length_m[j];
        PLcGrid cg{xg.data(), yg.data(), nullptr, static_cast<PLINT>(nx), static_cast<PLINT>(ny),
                   0};
        DrawShades(f, levels, &cg);
        DrawConstraints(f);
        plcol0(kFigureBlack);
        plbox("bcnst", 0, 0, "bcnstv", 0, 0);
        pllab("wire separation D (mm)", "wire length L (m)", f.title.c_str());
        DrawChoice(f, window);
        DrawCaption(f);
      },
      why);
}

}  // namespace bifilar
