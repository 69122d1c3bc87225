// `bifilar plan --rig` (issue 27): choose the wire length L, the separation D, the release
// amplitude, the swing length and the number of repeats for a target total std of I, before the
// rig is built (Jardin and Mueller, AIAA 2007-6822, optimise the same error variance).
//
// The expected std is the total the fit reports (pipeline/records/total_uncertainty.h): per-log
// terms (statistical, between-repeat) over sqrt(repeats), common-mode terms (the configured
// inputs L, D, m, g; or a calibration with a reference object, which replaces L, D and g). Over the
// (D, L) grid the terms come from the first-order budget of docs/physics.md §5,
// dI/I = dm/m + dg/g + 2 dD/D - dL/L, and a Cramer-Rao bound for the period of a decaying swing;
// the recommended rig and its alternatives are then evaluated with the project's own pieces: a
// swing simulated with the full model (fit/trace_synth.h) and fitted by FitTrace with the
// uncertainties configured, whose statistical std and implicit-function budget lines are the
// numbers reported. Conventions: docs/physics.md §2 (I, m of everything that swings).
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "base/units.h"

namespace bifilar {

struct RigPlanOptions {
  // What the user knows before building. Masses and inertia of everything that swings.
  double mass_kg = NAN;            // --mass: the aircraft (kg); > 0, required
  double cradle_mass_kg = 0.0;     // --cradle-mass: cradle + IMU (kg); >= 0, default 0 (thread)
  double inertia_kg_m2 = NAN;      // --inertia: aircraft (+ cradle) about the swing axis; > 0
  double inertia_max_kg_m2 = NAN;  // --inertia-max: upper end of a range (NaN: one value)
  // --radius-of-gyration: instead of --inertia, I = (mass + cradle) r^2 (m); NaN: not given.
  double radius_of_gyration_m = NAN;
  // Constraints.
  double max_length_m = NAN;       // --max-length: the longest L the ceiling allows (m), required
  double max_separation_m = NAN;   // --max-separation: the widest D the airframe allows, required
  double min_length_m = 0.1;       // --min-length (m), default 0.1
  double min_separation_m = 0.01;  // --min-separation (m), default 0.01
  double min_period_s = 0.5;       // --min-period (s), default 0.5
  double max_period_s = 6.0;       // --max-period (s), default 6
  // How well things will be measured (1 sigma).
  double length_std_m = 0.001;                 // --length-std (m), default 1 mm (a tape)
  double separation_std_m = 0.001;             // --separation-std (m), default 1 mm
  double mass_std_kg = NAN;                    // --mass-std (kg); NaN: 0.1 % of the suspended mass
  double gravity_mps2 = kStandardGravityMps2;  // --gravity (m/s^2)
  double gravity_std_mps2 = 0.0;               // --gravity-std (m/s^2), default 0 (local g known)
  // The IMU.
  double imu_rate_hz = 100.0;          // --imu-rate (Hz), default 100
  double gyro_noise_deg_per_s = 0.25;  // --gyro-noise (deg/s per sample), default 0.25
  // Real rigs (defaults from the public quadrotor logs and the simulator's non-ideal preset).
  double repeat_scatter_percent = 0.25;  // --repeat-scatter: between-repeat std (%), default 0.25
  double rig_departure_percent = 3.0;    // --rig-departure: I excess at 30 deg (%), default 3
  double decay_periods = 40.0;           // amplitude falls to 1/e in this many periods
  // The target.
  double target_percent = NAN;  // --target-percent: total std of I (%); > 0, required
  // Monte-Carlo check (hidden --monte-carlo N): N swings simulated on the recommended rig with
  // L, D, m drawn from their stds, fitted with FitTrace; 0: none.
  int monte_carlo_swings = 0;
  unsigned seed = 1;

  // The first bad value: *why names the flag and the bound (negative masses, D >= L, NaN).
  bool Check(std::string* why) const;
};

// Relative 1-sigma terms of the total std of I (fractions), named as the fit names them.
struct RigPlanTerms {
  double statistical = 0.0;       // one swing's statistical std (FitTrace, HAC)
  double between_repeat = 0.0;    // the hang-up scatter between repeats (assumed)
  double filar_length = 0.0;      // L  (budget line)
  double filar_separation = 0.0;  // D (budget line: D counts twice, I ~ D^2)
  double mass = 0.0;              // m
  double gravity = 0.0;           // g
  double calibration = 0.0;       // reference object (replaces L, D, g when used)
  int repeats = 1;                // per-log terms divided by sqrt(repeats)
  double PerLog() const { return std::hypot(statistical, between_repeat); }
  double Common() const;       // the common-mode terms in quadrature
  double Total() const;        // sqrt(common^2 + per_log^2 / repeats)
  double SingleSwing() const;  // one swing, no between-repeat scatter: what the MC measures
};

struct RigCandidate {
  std::string label;  // "recommended", "shorter L", ...
  double length_m = 0.0, separation_m = 0.0;
  double period_s = 0.0;  // from the full model at the release amplitude
  RigPlanTerms terms;     // evaluated with FitTrace on a simulated swing
};

// The reference object: a flat bar swung flat, centred, I = M (a^2 + b^2) / 12.
struct ReferenceBar {
  bool needed = false;
  // Within the bounds a workshop can make (length 20 mm to 2 m, at least 3 mm thick and no
  // thicker than wide); false: none fits, `why_not` says what it would take.
  bool buildable = true;
  std::string why_not;
  std::string material;  // "steel" or "aluminium"
  double density_kg_m3 = 0.0;
  double length_m = 0.0, width_m = 0.0, thickness_m = 0.0, mass_kg = 0.0;
  double inertia_kg_m2 = 0.0;
  double tolerance_m = 5e-5;     // machining tolerance assumed on a and b (m)
  double inertia_rel_std = 0.0;  // from the drawing and the weighing
  int swings = 3;                // reference swings (kRecommendedReferenceSwings)
};

struct RigMonteCarlo {
  int swings = 0, usable = 0;
  double predicted_rel_std = 0.0;  // SingleSwing() of the recommended rig
  double scatter_rel_std = 0.0;    // std of I_fit / I_true - 1 over the usable swings
  double ratio = 0.0;              // scatter / predicted
};

// The (D, L) grid of the figure: total std (%) by the first-order model, feasibility.
struct RigPlanGrid {
  std::vector<double> separation_m, length_m;  // axes
  std::vector<double> total_percent;           // [i_d * length_m.size() + i_l]
  std::vector<int> feasible;                   // 1 inside every constraint
};

// The floor no rig and no reference object lowers: the mass and the per-swing terms at the most
// repeats planned (kMaxRepeats). A target below it is unreachable; `term` sets it, `lift` says
// what would lower it (a measurement: a better weighing, a steadier rig, a quieter gyro).
struct RigPlanFloor {
  double rel_std = 0.0;  // fraction
  std::string term;      // "mass", "between-repeat" or "statistical"
  std::string flag;      // the flag that states it (--mass-std, --repeat-scatter, --gyro-noise)
  std::string lift;      // what would lower it
  std::string parts;     // "mass 0.1 %, between-repeat 0.25 %/sqrt(10) = 0.079 %, ..."
};

struct RigPlan {
  RigPlanOptions options;  // with the defaults resolved (mass_std_kg)
  bool target_met = false;
  // No rig within the constraints swings inside [--min-period, --max-period]: the rig shown is
  // only the widest D on the longest L; `periods_possible_s` the span the constraints allow.
  bool period_window_missed = false;
  double periods_possible_s[2] = {NAN, NAN};
  // The target is below the floor: no rig, reference object or relaxed constraint reaches it.
  bool below_floor = false;
  RigPlanFloor floor;
  std::string binding;            // flag of the constraint that binds ("" when met)
  std::string advice;             // one sentence: what would meet the target
  double best_std_percent = 0.0;  // the best total possible within the constraints
  // The rate the swings were simulated at: --imu-rate, or fewer samples (at most
  // kMaxPlanSamples per swing) with the noise of the fit's block means (the same information).
  double simulated_rate_hz = 0.0;
  RigCandidate recommended;
  std::vector<RigCandidate> alternatives;
  double release_amplitude_deg = 0.0;          // largest release keeping the rig departure small
  double departure_fraction_of_target = 0.25;  // the stated fraction
  double small_angle_excess_percent = 0.0;     // (T(A)/T0)^2 - 1 of the full model at A
  double swing_s = 0.0;
  double separation_for_target_m = NAN;  // smallest D meeting the target (constraints relaxed)
  double length_for_target_m = NAN;      // at this L
  ReferenceBar reference;
  RigPlanTerms calibrated;  // the recommended rig with the reference object
  RigPlanGrid grid;
  RigMonteCarlo monte_carlo;
  double plan_seconds = 0.0;
};

// Plans the rig. Throws UserError naming the flag on a non-physical value; constraints that no
// rig can meet are an answer (target_met false, binding, best_std_percent), not an error.
RigPlan RunRigPlan(const RigPlanOptions& options);

// The exit code of `bifilar plan --rig`: 0 when the plan meets the target (with the reference
// object it designs, when one is needed and buildable), 1 when nothing it offers does (a target
// below the floor, no rig in the period window, constraints too tight).
int RigPlanExitCode(const RigPlan& plan);

// The most samples of one simulated swing (the cost of the plan is bounded whatever --imu-rate).
constexpr double kMaxPlanSamples = 30000.0;

// The console text, the JSON (SI) and the starting config (the format `bifilar init` writes,
// pipeline/config/config_template.h, with the rig, rig.uncertainties, aircraft and, when the
// reference object is needed, rig.calibration), checked with the config loader before it is
// returned (UserError naming `path` otherwise).
std::string RigPlanText(const RigPlan& plan);
std::string RigPlanJson(const RigPlan& plan);
std::string RigPlanConfigText(const RigPlan& plan, const std::string& path);

// The figure: expected total std over (D, L), constraints shaded, the choice marked.
bool WriteRigPlanPlot(const RigPlan& plan, const std::string& path, std::string* why);

}  // namespace bifilar
