// The typed function behind `bifilar plan --tensor` (the CLI only parses options): which attitudes
// to swing for the full inertia tensor, with the expected std of each component. The planning
// itself is fit/tensor_plan.h; conventions docs/physics.md §3 (n = (-sin theta, sin phi cos
// theta, cos phi cos theta), products positive, I_xy = integral x y dm).
#pragma once

#include <array>
#include <nlohmann/json.hpp>
#include <ostream>

#include "base/units.h"
#include "fit/tensor_plan.h"

namespace bifilar {

struct TensorPlanCommandOptions {
  // Rig range, grid, orientations, trials, sigma_relative and attitude_std_deg as in
  // TensorPlanOptions; its SI fields (sigma_kg_m2, guess_kg_m2, target_std_kg_m2) are set by
  // RunTensorPlan from the values below, which are in `units`.
  TensorPlanOptions plan;
  double sigma = 0.0;  // per-swing std, absolute, in `units` (>= 0)
  std::array<double, kTensorComponents> guess = {0, 0, 0, 0, 0, 0};  // in `units`
  bool guess_given = false;  // Ixx, Iyy, Izz given (products default 0)
  double target = 0.0;       // target std of each component, in `units`; 0 = none
  // Target as a fraction of the largest guessed principal moment (needs the guess); 0 = none.
  double target_relative = 0.0;
  DisplayUnits units = DisplayUnits::kSi;  // of the values above and of the console output
  bool json = false;                       // print JSON (SI) instead of the table
};

struct TensorPlanCommandResult {
  TensorPlanOptions options;  // as planned: the SI fields set from the command's values
  TensorPlan plan;
};

// Plans. Throws UserError naming the option on bad input.
TensorPlanCommandResult RunTensorPlan(const TensorPlanCommandOptions& options);

// What `bifilar plan --tensor` prints: the JSON document (SI, `json`) or the attitudes and the
// expected stds in `units`.
void PrintTensorPlan(const TensorPlanCommandResult& result, DisplayUnits units, bool json,
                     std::ostream& out);

// JSON form (SI): rig, orientations, components {Ixx: {observable, std_kg_m2,
// floor_std_kg_m2, trials_needed}, ...}, unobservable, rank, condition_number, warnings, ...
nlohmann::json TensorPlanToJson(const TensorPlan& plan, const TensorPlanOptions& options);

}  // namespace bifilar
