// The figure of `bifilar plan --rig` (pipeline/commands/rig_plan.h): the expected total std of I
// (%) over the wire separation D and the wire length L, as filled contours, with the constraints
// (period range, D/L, --max-length, --max-separation) shaded, the target's contour drawn in red
// when the grid reaches it (the caption names only what is drawn), a colour bar in %, and the
// recommended rig marked (issue 32 item 7: nothing clipped at any scale).
#pragma once

#include <string>
#include <vector>

namespace bifilar {

struct RigPlanFigure {
  std::vector<double> separation_m, length_m;  // grid axes
  std::vector<double> total_percent;           // [i_d * length_m.size() + i_l]
  std::vector<int> feasible;                   // same layout; 0 outside a constraint (shaded)
  double target_percent = 0.0;                 // its contour
  double chosen_separation_m = 0.0, chosen_length_m = 0.0;  // marked
  double chosen_total_percent = 0.0;
  std::string title;
  // Set by WriteRigPlanFigure: the lowest total on the grid, and whether the target's contour is
  // on it (else the caption says where the target lies, and no red line is named).
  double lowest_percent = 0.0;
  bool target_drawn = false;
};

// PNG or SVG by extension; false with *why on failure.
bool WriteRigPlanFigure(const RigPlanFigure& figure, const std::string& path, std::string* why);

}  // namespace bifilar
