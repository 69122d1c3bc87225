// Planning a tensor campaign: which attitudes (roll, pitch) to hang the aircraft in, so that the
// six components of its inertia tensor come out with a target standard error.
//
// Conventions: docs/physics.md §3 (body x forward, y right wing, z down; pitch theta nose-up,
// roll phi right-wing-down). The swing axis is the down vertical, in body axes
//     n = (-sin theta, sin phi cos theta, cos phi cos theta),
// products of inertia are the paper's positive ones (I_xy = integral x y dm, ...), so the moment
// about n is linear in the six components (Ixx, Iyy, Izz, Ixy, Ixz, Iyz):
//     I(n) = Ixx nx^2 + Iyy ny^2 + Izz nz^2 - 2 Ixy nx ny - 2 Ixz nx nz - 2 Iyz ny nz.
//
// The plan (PlanTensor) lays a grid over the rig's reachable roll and pitch range, keeps one
// candidate per distinct axis (n and -n swing alike), and chooses N orientations that maximise
// log det of the information matrix of the components the grid can observe (D-optimal: greedy
// forward selection, then Fedorov exchange until no swap improves it). The expected covariance is
// the inverse of that information matrix: each orientation's mean moment has variance
//     v = (sigma_abs^2 + (sigma_rel I(n))^2) / trials + (sigma_att g(n))^2,
// the swing noise averaged over the trials plus the error of setting the attitude, which the
// trials of one orientation share (g = 2 |(1 - n n^T) J n| is how fast I(n) changes as the axis
// tilts, per radian). Components outside the row space of the reachable axes are named as
// unobservable, never given a number. Details: docs/method.md, "Planning the attitudes".
//
// The swing axis of an attitude is fit/tensor.h's DownInBodyFromAttitude, the one the fit uses.
// This header is plain C++ and Eigen-free.
#pragma once

#include <array>
#include <limits>
#include <string>
#include <vector>

#include "fit/tensor_components.h"

namespace bifilar {

struct CheckFailure;  // base/option_check.h

// The row of the design matrix for the axis n (normalised first):
// (nx^2, ny^2, nz^2, -2 nx ny, -2 nx nz, -2 ny nz), so I(n) = row . components.
std::array<double, kTensorComponents> TensorDesignRow(const std::array<double, 3>& n);

struct TensorPlanOptions {
  // The rig's reachable attitudes (deg): roll in [-180, 180], pitch in [-90, 90], min <= max.
  // A range of zero width (min == max) holds the angle fixed. Defaults: roll 0, pitch -90..90.
  double roll_min_deg = 0.0;
  double roll_max_deg = 0.0;
  double pitch_min_deg = -90.0;
  double pitch_max_deg = 90.0;
  // Spacing of the candidate grid (deg), in [0.5, 90]; both ends of each range are candidates.
  // Default 5.
  double grid_step_deg = 5.0;
  // Orientations to choose, in [1, 100]; fewer when the grid has fewer distinct axes (with a
  // warning). At least the rank of the reachable design. Default 12.
  int n_orientations = 12;
  // Swings (trials) per orientation, in [1, 1e6]. Default 3.
  int trials_per_orientation = 3;
  // Per-swing standard deviation of a measured moment: absolute (kg m^2) and relative (fraction
  // of the moment I(n)), added in quadrature; absolute in [0, 1e100], relative in [0, 1), not both
  // 0. Any std of a moment down to 1e-300 kg m^2 works (the plan is computed in units of the
  // largest std). Defaults 0.
  double sigma_kg_m2 = 0.0;
  double sigma_relative = 0.0;
  // Standard deviation (deg, per tilt axis) of the attitude actually set against the nominal one,
  // shared by the trials of an orientation, in [0, 10]. Default 0 (attitudes exact).
  double attitude_std_deg = 0.0;
  // The guessed tensor (kg m^2; Ixx, Iyy, Izz, Ixy, Ixz, Iyz, products positive convention).
  // Each within +-1e100. Needed (and positive definite) when sigma_relative > 0 or
  // attitude_std_deg > 0;
  // otherwise unused, and `guess_given` may be false.
  std::array<double, kTensorComponents> guess_kg_m2 = {0, 0, 0, 0, 0, 0};
  bool guess_given = false;
  // Target standard error of every observable component (kg m^2), in (0, 1e100], or 0 for none.
  // Default 0.
  double target_std_kg_m2 = 0.0;
  // A singular value of the reachable axes' design below this fraction of the largest is a
  // direction the rig cannot observe; (0, 1). Default 1e-6 (as the tensor fit).
  double rank_tolerance = 1e-6;

  bool Check(std::string* why) const;
  // The same, the first failing bound as field, value and bound (base/option_check.h), so that
  // `plan --tensor` names the flag of the field.
  bool Check(CheckFailure* failure) const;
};

struct TensorPlanOrientation {
  double roll_deg = 0.0;
  double pitch_deg = 0.0;
  std::array<double, 3> axis_in_body = {0, 0, 1};  // unit, the down vertical
  // The guessed moment about the axis (kg m^2), NaN without a guess.
  double inertia_kg_m2 = std::numeric_limits<double>::quiet_NaN();
  double swing_std_kg_m2 = 0.0;  // per-swing std there (absolute and relative parts)
  double mean_std_kg_m2 = 0.0;   // std of the orientation's mean: sqrt(v) above
};

struct TensorPlan {
  std::vector<TensorPlanOrientation> orientations;  // the chosen design, by roll then pitch
  int n_candidates = 0;                             // distinct reachable axes on the grid
  int n_points = 0;                                 // orientations x trials
  int rank = 0;  // of the reachable axes' design (6: every component observable)
  std::array<bool, kTensorComponents> observable = {};
  std::vector<std::string> unobservable;  // component names, in order
  // Number of determined directions that are combinations of unobservable components (rank
  // minus the observable components), e.g. 1 for a rig that holds pitch at 0 and 90 only.
  int n_combinations = 0;
  // Expected standard errors (kg m^2) and covariance (kg^2 m^4) of the components; entries of
  // unobservable components are NaN (never printed as numbers).
  std::array<double, kTensorComponents> std_kg_m2 = {};
  std::array<std::array<double, kTensorComponents>, kTensorComponents> covariance = {};
  // The part of each std that more trials cannot shrink (attitude error only; 0 without it).
  std::array<double, kTensorComponents> floor_std_kg_m2 = {};
  double log_det_information = 0.0;  // of the chosen design, on the observable subspace
  double condition_number = 0.0;     // of the chosen unit-axis design rows (non-zero values)
  int exchange_sweeps = 0;           // Fedorov sweeps until no swap improved
  // With a target: trials per orientation needed for each component (0 when unobservable), and
  // for all of them; -1 when more trials cannot reach it (the attitude error's floor is above it).
  std::array<int, kTensorComponents> trials_needed = {};
  int trials_needed_all = 0;
  std::vector<std::string> warnings;
};

// Chooses the orientations and predicts the stds. False with *why on bad options, a guess that is
// not positive definite when needed, or fewer orientations than the reachable design's rank (the
// number of components, or combinations, it determines). A rig range that cannot observe every
// component is not an error: `unobservable` names them and a warning says so.
bool PlanTensor(const TensorPlanOptions& options, TensorPlan* plan, std::string* why);

}  // namespace bifilar
