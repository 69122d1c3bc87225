// JSON form of the inertia tensor: the `tensor` section of results.json and the document of the
// Python module's fit_tensor. SI (kg m^2), angles in deg; a component the swing axes do not
// determine is null with its name in "unobservable", never a number; never NaN.
// Conventions: docs/physics.md §3.5 (products positive, I_xy = integral x y dm; the tensor's
// off-diagonal terms are their negatives).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fit/ellipse.h"
#include "fit/tensor.h"

namespace bifilar {

// What a campaign knows about each point and orientation (all optional: empty vectors).
struct TensorJsonContext {
  std::string mode;                      // "full_3d", "partial", "planar_xz"
  double confidence = 0.95;              // of the intervals
  double common_offset_std_kg_m2 = 0.0;  // the rig's, propagated into Ixx, Iyy, Izz
  double systematic_relative_std = NAN;  // L, D, masses, g, gyro scale: scales everything alike
  struct Point {
    std::string file;
    double roll_deg = NAN, pitch_deg = NAN;  // the attitude used for its axis
    double std_kg_m2 = NAN;                  // the log's own std (names the logs of a scatter)
  };
  std::vector<Point> points;  // one per fitted point, same order
  struct Orientation {
    double roll_deg = NAN, pitch_deg = NAN;  // nominal attitude of the group
  };
  std::vector<Orientation> orientations;  // one per TensorResult::orientations entry
};

// Keys (fit/tensor.h): mode, Ixx_kg_m2 ... Iyz_kg_m2 each with _std and _ci95, observable,
// unobservable, observable_combinations, components_order, covariance_kg2_m4 (6 x 6, null rows
// for unobservable components), tensor_kg_m2 (3 x 3, null unless full), principal_moments_kg_m2
// (ascending) with _std and _ci95, principal_axes (unit vectors in body axes, in the moments'
// order), principal_axes_std_deg, principal_euler_deg {roll, pitch, yaw, *_std},
// principal_moments_matched_kg_m2 {x, y, z}, rank, condition_number, design_singular_values,
// n_points, n_orientations, covariance, variance_factor, dof, reduced_chi2, rmse_kg_m2,
// bootstrap_replicates, confidence, residuals (per point), orientations (per orientation, the
// per-orientation residuals), solver, closed_form_max_relative_difference, warnings;
// scatter_logs: when the moments scatter beyond their logs' stds (relative_scatter or
// attitude_scatter_deg > 0), the logs behind it, {file, residual_over_std}, largest first.
nlohmann::json TensorScatterLogs(const TensorResult& result, const TensorJsonContext& context);

// The scatter_logs in one line, as the console and the report show them: "the logs behind the
// scatter, residual over their own std: a.csv +5.2, b.csv -3.1, and 2 more"; "" for none.
std::string ScatterLogsText(const std::vector<std::pair<std::string, double>>& logs);
nlohmann::json TensorResultToJson(const TensorResult& result, const TensorJsonContext& context);

// The `physical` object of results.json (fit/physical.h): status ("physical", "borderline",
// "not_physical", "not_checked"), checked, worst {inequality, margin_kg_m2, std_kg_m2, z},
// threshold_z, attitude ("" when none named), z_without_attitude (null: no refit), message, and
// every inequality as {inequality, margin_kg_m2, std_kg_m2, z}. Infinite z is null.
nlohmann::json PhysicalCheckToJson(const PhysicalCheck& check);

// The tensor section of a planar x-z campaign: the ellipse's I_x, I_z, I_xz (the same numbers)
// as Ixx, Izz, Ixz; Iyy, Ixy, Iyz unobservable (a pitch-only rig never swings about y).
nlohmann::json PlanarTensorJson(const EllipseResult& ellipse, const TensorJsonContext& context);

}  // namespace bifilar
