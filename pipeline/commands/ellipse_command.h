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
  std::string table_path;                  // CSV: pitch_deg, inertia[, std]
  DisplayUnits units = DisplayUnits::kSi;  // units of the table and of the console output
  bool json = false;                       // print JSON (SI) instead of tables
  std::string plot_dir;                    // write figures here when non-empty
  bool force = false;  // --force: replace files of the figures' names bifilar did not write
  EllipseOptions fit;  // seed, bootstrap, covariance, ...
};

struct EllipseCommandResult {
  EllipseResult fit;                 // SI
  std::vector<std::string> figures;  // written into options.plot_dir
};

// Reads the table, fits and writes the figures. Throws UserError on bad input (file, column,
// value, options) with a message naming it. A non-physical tensor is a result, with its warning.
EllipseCommandResult RunEllipse(const EllipseCommandOptions& options);

// What `bifilar ellipse` prints: the JSON document (options.json) or the tables, then the
// figures written.
void PrintEllipseCommand(const EllipseCommandOptions& options, const EllipseCommandResult& result,
                         std::ostream& out);

// The exit code of `bifilar ellipse`: 0, or 1 for a non-physical tensor.
int EllipseExitCode(const EllipseCommandResult& result);

// Human-readable report of a fit in the given units (the three fits side by side, Table 1 and
// Table 2, NACA comparison, outliers, warnings).
void PrintEllipseReport(const EllipseResult& result, DisplayUnits units, std::ostream& out);

// Writes ellipse_moments.{png,svg} and ellipse_polar.{png,svg} into dir (created if missing);
// returns the paths written. Throws UserError if a figure cannot be written, or, before any is
// written, when a file of those names there was not written by bifilar (without `force`) or is a
// link (base/plot_folder.h).
std::vector<std::string> WriteEllipsePlots(const EllipseResult& result, DisplayUnits units,
                                           const std::string& dir, bool force = false);

struct PlanCommandOptions {
  std::vector<double> pitch_deg;  // proposed angles (deg)
  int trials_per_angle = 3;
  double sigma = 0.0;  // per-trial std, in `units`
  // Guesses of the aircraft, in `units`. Defaults: the paper's PRANDTL-D (Table 2, slug ft^2
  // 2.3596, 2.8477, 0.0178), converted when units are SI.
  double ix = 0.0, iz = 0.0, ixz = 0.0;
  bool guesses_given = false;  // false: use the defaults above
  DisplayUnits units = DisplayUnits::kSi;
  bool json = false;
};

// Predicts the standard errors of a design (SI). Throws UserError naming the option.
EllipsePlan RunPlan(const PlanCommandOptions& options);

// What `bifilar plan` prints: the JSON document (options.json) or the design and its stds in
// options.units.
void PrintPlan(const PlanCommandOptions& options, const EllipsePlan& plan, std::ostream& out);

}  // namespace bifilar
