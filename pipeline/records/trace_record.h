// The trace record: what one IMU log yields (fit, diagnostics, campaign bookkeeping), its status
// and role. Written by pipeline/trace/trace_process.h, stored by the cache, combined by the
// campaign, written to results.json (pipeline/records/results_json.h).
#pragma once

#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "fit/trace_fit.h"
#include "pendulum/model.h"
#include "pipeline/config/config.h"

namespace bifilar {

enum class TraceStatus { kOk, kRejected, kError };
const char* ToString(TraceStatus status);  // "ok", "rejected", "error"
bool ParseTraceStatus(const std::string& name, TraceStatus* status);
std::string TraceStatusAllowedValues();  // "ok, rejected or error"

// An aircraft run, a tare log of the rig alone, or a reference swing of rig.calibration (rig +
// reference object).
enum class TraceRole { kAircraft, kTare, kCalibration };
const char* ToString(TraceRole role);  // "aircraft", "tare", "calibration"
bool ParseTraceRole(const std::string& name, TraceRole* role);
std::string TraceRoleAllowedValues();  // "aircraft, tare or calibration"

// One term of the systematic uncertainty budget of I (issue 3 item 7).
struct BudgetTerm {
  std::string name;        // "filar_length", "filar_separation", "mass", "gravity", ...
  double std_kg_m2 = 0.0;  // first-order contribution to the std of I (kg m^2)
};

// Every field of the per-trace JSON record (issue 3 item 9) plus the campaign's additions.
// Numbers that do not apply are NaN in memory and null in JSON.
struct TraceRecord {
  // --- fit of the log (cached per content hash + fit settings) ---
  std::string file;  // path as shown to the user (relative to the config)
  TraceStatus status = TraceStatus::kError;
  std::string message;               // why rejected/error; warnings for ok
  double inertia_total_kg_m2 = NAN;  // fitted I of everything suspended (kg m^2)
  // Its per-trace ("stat") std (kg m^2): statistical (HAC) and model-inadequacy terms in
  // quadrature (and the between-repeat std with --repeats); the ellipse's weights. The budget
  // (L, D, m, g, gyro scale) is common-mode: in inertia_total_std_total_kg_m2, not here.
  double inertia_total_std_kg_m2 = NAN;
  double drag_coeff_kg_m2 = NAN;                     // K_D
  double viscous_coeff_kg_m2_per_s = NAN;            // C
  std::array<double, 2> window_s = {NAN, NAN};       // fitted window [t0, t1] (s)
  std::array<double, 2> amplitude_deg = {NAN, NAN};  // amplitude at start/end of the fitted part
  std::array<double, 2> amplitude_band_deg = {NAN, NAN};  // [min, max] band the fit was held to
  // The measured period: the window search's mean period over the whole free oscillation (the
  // same number `bifilar inspect` prints), its inverse, and the classic small-angle inertia
  // I = m g D^2 T^2 / (16 pi^2 L) of everything suspended, with this trace's geometry (rig +
  // aircraft, rig alone or rig + reference): a hand check beside the nonlinear fit's
  // inertia_total_kg_m2 (docs/method.md). NaN when no window was found.
  double period_s = NAN;
  double frequency_hz = NAN;
  double small_angle_inertia_total_kg_m2 = NAN;
  double bias_rad_per_s = NAN;  // gyro bias b
  double residual_rms_rad_per_s = NAN;
  double noise_rms_rad_per_s = NAN;          // gyro noise estimated from the rest segment
  std::optional<double> pitch_measured_deg;  // from the accelerometer; none without one
  std::optional<double> roll_measured_deg;   // ... and its roll (docs/physics.md §3.5)
  std::string model;                         // "full", "jardin", "linear"
  int iterations = 0;
  double fit_seconds = 0.0;             // wall time of this file's processing (s)
  std::vector<BudgetTerm> budget;       // systematic contributions (L, D, m, g)
  double budget_total_std_kg_m2 = NAN;  // root-sum-square of the budget terms
  std::vector<std::string> flags;       // quality flags raised (rejecting ones and warnings)
  std::vector<std::string> warnings;    // every warning (reader, window, fit), for every status
  std::string figure;                   // fit figure file name inside OUT/figures/, "" if none
  std::vector<std::string> figures;     // every figure written for this trace (paths)
  std::string sweep_figure;             // amplitude-sweep figure name in OUT/figures/, "" if none

  // --- diagnostics (issue 8: what a user needs to judge a real log) ---
  std::array<double, 3> swing_axis_in_imu = {NAN, NAN, NAN};  // unit swing axis used
  double secondary_motion_ratio = NAN;      // rate energy off the swing axis / on it
  double rms_over_noise = NAN;              // residual RMS / noise estimate
  double residual_autocorr_lag1 = NAN;      // rho_1 of the residuals
  double residual_ar1_phi = NAN;            // AR(1) coefficient of the residuals
  double prewhitened_autocorr_max = NAN;    // whiteness statistic (after AR(1) prewhitening)
  double inertia_window_kg_m2 = NAN;        // I of the fit over the whole window
  std::string inertia_source;               // "window" or "low_amplitude_band"
  double inertia_stat_std_kg_m2 = NAN;      // statistical (HAC) std of I
  double inertia_iid_std_kg_m2 = NAN;       // textbook std assuming white residuals (comparison)
  double model_inadequacy_std_kg_m2 = NAN;  // from the amplitude sweep's trend (0: none)
  // Between-repeat std added by `bifilar fit --repeats` (pipeline/trace/repeats.h); NaN: not
  // combined.
  double repeat_scatter_std_kg_m2 = NAN;
  // Amplitude correction applied by `bifilar fit --repeats` (pipeline/trace/repeats.h): the pooled
  // coefficient c moves I from the amplitude of its result to zero amplitude, I_0 = I / (1 + c
  // A^2). The correction I - I_0 (subtracted from inertia_total_kg_m2), its std (added in
  // quadrature to inertia_total_std_kg_m2) and A (deg); NaN: not corrected.
  double amplitude_correction_kg_m2 = NAN;
  double amplitude_correction_std_kg_m2 = NAN;
  double amplitude_correction_from_deg = NAN;
  // Total uncertainty of inertia_total_kg_m2 (pipeline/records/total_uncertainty.h): the per-log
  // terms above and the common-mode ones (budget, calibration) in quadrature; NaN without a fit.
  double inertia_total_std_total_kg_m2 = NAN;
  // The budget's L and D lines hold the assumed +-1 mm (the config has no rig.uncertainties).
  bool budget_assumed = false;
  // rig.calibration (a reference object fixed the rig's effective geometry): its relative std is
  // a common-mode term and the budget's L, D and g lines drop out. false: not calibrated.
  bool calibrated = false;
  double calibration_relative_std = 0.0;  // (fraction) >= 0
  int hac_bandwidth = 0;
  AmplitudeSweep sweep;  // I against amplitude

  // --- campaign bookkeeping (not cached) ---
  TraceRole role = TraceRole::kAircraft;
  std::string content_hash;  // 16 hex digits, FNV-1a 64 of the file bytes
  std::string cache_key;     // 16 hex digits, content hash + fit settings
  bool from_cache = false;
  std::optional<double> pitch_nominal_deg;  // from the path or table
  double pitch_used_deg = NAN;              // nominal or measured, per runs.pitch_source
  std::optional<double> roll_nominal_deg;   // from the path or table ({roll_deg}, roll_deg)
  double roll_used_deg = NAN;               // nominal (0 when none) or measured, like the pitch
  double rig_inertia_kg_m2 = NAN;           // subtracted tare at this pitch
  double inertia_kg_m2 = NAN;               // aircraft alone = total - rig (kg m^2)
  double inertia_std_kg_m2 = NAN;           // sqrt(fit std^2 + rig std^2)
  // Total uncertainty of inertia_kg_m2 (ComposeAircraftUncertainty): per-log terms, rig inertia,
  // and the scale terms (configured inputs, calibration); the last alone in aircraft_scale_std.
  double inertia_std_total_kg_m2 = NAN;
  double aircraft_scale_std_kg_m2 = NAN;

  bool ok() const { return status == TraceStatus::kOk; }
};

// The longest warning line: with the console's "    warning: " before it, within the console's
// 160 characters.
constexpr size_t kWarningLineChars = 146;

// A warning's one-line summary. Warnings (TraceRecord::warnings, TraceFitResult::warnings) state
// the finding and what to do in their first sentence and give the detail after it: the summary
// is that first sentence (up to ". " or "? " before a capital letter), cut at a word to at most
// max_chars with " ..." when longer. The console and the report show it through LineOfWarning;
// the full text is in results.json, `bifilar fit --json` and the report's expanded warning.
std::string WarningSummary(const std::string& warning, size_t max_chars = kWarningLineChars);

// The clause of a warning that says what to do: the last clause (the text split at ". " and
// "; ") whose first word is a verb of action ("raise ...", "swing ...", "set ..."); "" when none.
std::string WarningAction(const std::string& warning);

// A warning on one line, as the console and the report both show it: its summary and, when the
// summary does not hold the clause that says what to do (a first sentence cut short), that
// clause after it; the summary is then cut shorter so that the line stays near max_chars.
struct WarningLine {
  std::string summary;       // WarningSummary of the warning
  std::string action;        // WarningAction, "" when the summary holds it or there is none
  bool folded = false;       // the line leaves out part of the warning (the rest is on click)
  std::string Text() const;  // "summary -> action" (the console's form)
};
WarningLine LineOfWarning(const std::string& warning, size_t max_chars = kWarningLineChars);

// The geometry (L, D, suspended mass, g) a trace of `role` is fitted with.
RigGeometry GeometryForRole(const CampaignConfig& config, TraceRole role);

}  // namespace bifilar
