// The typed functions behind `bifilar ellipse` and `bifilar plan` (the CLI only parses options).
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "base/units.h"
#include "fit/ellipse.h"
#include "pipeline/commands/ellipse_table.h"

namespace bifilar {

struct EllipseCommandOptions {
  std::string table_path;                       // CSV: pitch_deg, inertia[, std]
  DisplayUnits units = DisplayUnits::kSi;       // units of the table and of the console output
  bool json = false;                            // print JSON (SI) instead of tables
  std::string plot_dir;                         // write figures here when non-empty
  EllipseOptions fit;                           // seed, bootstrap, covariance, ...
};

// Reads the table, fits, prints to `out`, writes figures. Returns the exit code (0). Throws
// UserError on bad input (file, column, value, options) with a message naming it.
int RunEllipse(const EllipseCommandOptions& options, std::ostream& out);

// Human-readable report of a fit in the given units (the three fits side by side, Table 1 and
// Table 2, NACA comparison, outliers, warnings).
void PrintEllipseReport(const EllipseResult& result, DisplayUnits units, std::ostream& out);

// Writes ellipse_moments.{png,svg} and ellipse_polar.{png,svg} into dir (created if missing);
// returns the paths written. Throws UserError if a figure cannot be written.
std::vector<std::string> WriteEllipsePlots(const EllipseResult& result, DisplayUnits units,
                                           const std::string& dir);

struct PlanCommandOptions {
  std::vector<double> pitch_deg;                // proposed angles (deg)
  int trials_per_angle = 3;
  double sigma = 0.0;                           // per-trial std, in `units`
  // Guesses of the aircraft, in `units`. Defaults: the paper's PRANDTL-D (Table 2, slug ft^2
  // 2.3596, 2.8477, 0.0178), converted when units are SI.
  double ix = 0.0, iz = 0.0, ixz = 0.0;
  bool guesses_given = false;                   // false: use the defaults above
  DisplayUnits units = DisplayUnits::kSi;
  bool json = false;
};

// Predicts the standard errors of a design; prints them. Returns 0; throws UserError.
int RunPlan(const PlanCommandOptions& options, std::ostream& out);

}  // namespace bifilar
