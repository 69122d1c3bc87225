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

// The total std in filled bands, on a log-like scale capped at 4x the target.
void DrawShades(const RigPlanFigure& f, Grid2* z, PLcGrid* cg) {
  const double lo = *std::min_element(f.total_percent.begin(), f.total_percent.end());
  const double hi = std::max(
      std::min(*std::max_element(f.total_percent.begin(), f.total_percent.end()), 30.0 * lo),
      1.01 * lo);
  const int n = 16;
  std::vector<PLFLT> levels(n + 1);
  for (int k = 0; k <= n; ++k) levels[k] = lo * std::pow(hi / lo, static_cast<double>(k) / n);
  levels[n] = 1e9;  // everything above the cap in the last band
  const PLFLT r[2] = {0.35, 1.0}, g[2] = {0.55, 0.95}, b[2] = {0.95, 0.6}, pos[2] = {0.0, 1.0};
  plscmap1l(1, 2, pos, r, g, b, nullptr);
  plshades(z->rows.data(), static_cast<PLINT>(f.separation_m.size()),
           static_cast<PLINT>(f.length_m.size()), nullptr, f.separation_m.front() * 1e3,
           f.separation_m.back() * 1e3, f.length_m.front(), f.length_m.back(), levels.data(), n + 1,
           0.0, 0, 0.0, plfill, true, pltr1, cg);
  // Labelled contours of the total.
  std::vector<PLFLT> lines;
  for (double v : {0.1, 0.2, 0.3, 0.5, 1.0, 2.0, 3.0, 5.0, 10.0, 20.0}) {
    if (v > lo && v < hi) lines.push_back(v);
  }
  plcol0(kFigureGrey);
  pl_setcontlabelparam(0.008, 0.5, 0.3, 1);
  pl_setcontlabelformat(3, 2);
  if (!lines.empty()) {
    plcont(z->rows.data(), static_cast<PLINT>(f.separation_m.size()),
           static_cast<PLINT>(f.length_m.size()), 1, static_cast<PLINT>(f.separation_m.size()), 1,
           static_cast<PLINT>(f.length_m.size()), lines.data(), static_cast<PLINT>(lines.size()),
           pltr1, cg);
  }
  pl_setcontlabelparam(0.006, 0.3, 0.1, 0);
  // The target.
  PLFLT target = f.target_percent;
  plcol0(kFigureRed);
  plwidth(3.0);
  plcont(z->rows.data(), static_cast<PLINT>(f.separation_m.size()),
         static_cast<PLINT>(f.length_m.size()), 1, static_cast<PLINT>(f.separation_m.size()), 1,
         static_cast<PLINT>(f.length_m.size()), &target, 1, pltr1, cg);
  plwidth(1.0);
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

}  // namespace

bool WriteRigPlanFigure(const RigPlanFigure& f, const std::string& path, std::string* why) {
  const size_t nx = f.separation_m.size(), ny = f.length_m.size();
  if (nx < 2 || ny < 2 || f.total_percent.size() != nx * ny || f.feasible.size() != nx * ny) {
    *why = "rig plan figure: the grid is empty or inconsistent";
    return false;
  }
  FigureOptions options;
  options.width_px = 1000;
  options.height_px = 750;
  return WriteFigure(
      path, options,
      [&] {
        pladv(0);
        plvpor(0.1, 0.95, 0.17, 0.9);
        plwind(f.separation_m.front() * 1e3, f.separation_m.back() * 1e3, f.length_m.front(),
               f.length_m.back());
        std::vector<double> xg(nx), yg(ny);
        for (size_t i = 0; i < nx; ++i) xg[i] = f.separation_m[i] * 1e3;
        for (size_t j = 0; j < ny; ++j) yg[j] = f.length_m[j];
        PLcGrid cg{xg.data(), yg.data(), nullptr, static_cast<PLINT>(nx), static_cast<PLINT>(ny),
                   0};
        Grid2 z(f.total_percent, nx, ny);
        DrawShades(f, &z, &cg);
        DrawConstraints(f);
        plcol0(kFigureBlack);
        plbox("bcnst", 0, 0, "bcnstv", 0, 0);
        pllab("wire separation D (mm)", "wire length L (m)", f.title.c_str());
        PLFLT mx = f.chosen_separation_m * 1e3, my = f.chosen_length_m;
        plcol0(kFigureBlack);
        plssym(0, 2.5);
        plpoin(1, &mx, &my, 18);  // a star
        plssym(0, 1.0);
        const double up = my > 0.5 * (f.length_m.front() + f.length_m.back()) ? -1.0 : 1.0;
        const double right = mx > 0.5e3 * (f.separation_m.front() + f.separation_m.back());
        plptex(mx, my + up * 0.05 * (f.length_m.back() - f.length_m.front()), 1, 0,
               right ? 1.0 : 0.0,
               ("recommended: " + Fmt("%.3g", f.chosen_total_percent) + " %").c_str());
        plschr(0, 0.8);
        plmtex("b", 6.2, 0.0, 0.0,
               ("colour and grey lines: expected total std (%); red: the target " +
                Fmt("%.3g", f.target_percent) + " %; shaded: outside a constraint")
                   .c_str());
        plschr(0, 1.0);
      },
      why);
}

}  // namespace bifilar
