// What a campaign yields (pipeline/campaign/campaign.h RunCampaign): every trace record, the rig
// inertia, the per-angle statistics, the ellipse and tensor, the counts. A header of its own, so
// results.json and the tensor campaign need not include the campaign.
#pragma once

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fit/ellipse.h"
#include "fit/tensor.h"
#include "pipeline/records/calibration_result.h"
#include "pipeline/records/trace_record.h"

namespace bifilar {

// Per-angle statistics of the usable (ok) traces of one pitch group.
struct AngleStats {
  double pitch_deg = NAN;           // group pitch: the nominal pitch, or mean measured pitch
  double roll_deg = NAN;            // group roll, likewise (0 in a campaign without rolls)
  int n = 0;                        // ok traces
  double inertia_mean_kg_m2 = NAN;  // mean aircraft inertia
  double inertia_std_kg_m2 = NAN;   // sample standard deviation between trials (n >= 2), else NaN
  double inertia_sem_kg_m2 = NAN;   // standard error of the mean: the between-trial std / sqrt(n)
                                    // when n >= 2, else the fit's own std
  double cv_percent = NAN;          // 100 std / mean
  double fit_std_mean_kg_m2 = NAN;  // mean of the traces' own fit std
  // Total uncertainty of the mean (pipeline/records/total_uncertainty.h): the standard error and
  // the common-mode terms (rig inertia, configured inputs, calibration; their mean over the trials)
  // in quadrature; with one trial, its own total.
  double common_mode_std_kg_m2 = NAN;
  double inertia_std_total_kg_m2 = NAN;
};

struct CampaignSummary {
  int n_traces = 0, n_ok = 0, n_rejected = 0, n_error = 0;  // aircraft + tare
  int n_fitted = 0, n_reused = 0;                           // fits run now / taken from the cache
  int n_cache_refused = 0;  // cache entries refused as damaged or not theirs (refitted)
  double wall_s = 0.0;      // whole run
  bool ellipse_fitted = false;
  std::string ellipse_message;  // why not fitted, if so
  bool tensor_fitted = false;   // the inertia tensor (or the components it can observe)
  std::string tensor_message;   // why not fitted, if so
  int exit_code = 0;            // 0 all well, 1 some traces failed or rejected (or no ellipse)
};

struct CampaignResult {
  std::vector<TraceRecord> traces;  // aircraft runs, tare logs, reference swings: discovery order
  double rig_inertia_kg_m2 = NAN;   // value / tare mean (table: NaN, see per-trace field)
  double rig_inertia_std_kg_m2 = NAN;
  int rig_tare_n = 0;  // ok tare logs used
  // rig.calibration: the effective geometry every trace was fitted with
  // (pipeline/campaign/calibration.h); absent without the section.
  std::optional<RigCalibrationResult> calibration;
  // Why the rig inertia is unknown (tare: no usable tare log, with the first tare log's own
  // message), "" when known; the console says it once, before the traces it affects.
  std::string rig_problem;
  std::vector<AngleStats> angles;            // sorted by pitch
  std::optional<EllipseResult> ellipse_fit;  // fit/ellipse.h, when >= min_angles angles remain
  // pipeline/records/ellipse_json.h document, null when not fitted
  nlohmann::json ellipse;
  std::string moments_figure;  // Fig. 3 file name in OUT/figures/, "" when none
  std::string polar_figure;    // Fig. 4 file name in OUT/figures/, "" when none
  // The inertia tensor (pipeline/campaign/campaign_tensor.h): the `tensor` section of results.json
  // (null when nothing was fitted), its fit when it ran as a tensor fit, and the principal-axes
  // figure ("" when none).
  nlohmann::json tensor;
  std::optional<TensorResult> tensor_fit;
  std::string tensor_figure;
  // Systematic relative uncertainty from the configured uncertainties (L, D, masses, g, gyro
  // scale; with rig.calibration: masses, gyro scale and the calibration): the mean over ok
  // aircraft traces of budget total / inertia total. It scales every moment alike, so it is not
  // in the ellipse's std; reported beside it. NaN when no budget.
  double systematic_relative_std = NAN;
  // The scale terms of the total (configured inputs, calibration;
  // pipeline/records/total_uncertainty.h) as a fraction of the aircraft's inertia, mean over ok
  // aircraft traces: Table 2's total std of a moment is hypot(its std, this x |moment|); tau has
  // none. NaN when no trace.
  double common_mode_relative_std = NAN;
  bool common_mode_assumed = false;  // it holds the assumed +-1 mm on L and D
  std::string assumed_inputs_note;   // AssumedInputsSummary of the traces ("" when none)
  // Attitudes whose logs look like two set-ups (pipeline/trace/repeat_setups.h), one sentence
  // each; also a warning on each of their traces.
  std::vector<std::string> setup_warnings;
  // Can a body have the result's moments (fit/physical.h): the tensor's check, or the planar
  // ellipse's; the attitude named by roll and pitch. Empty when neither was fitted.
  std::optional<PhysicalCheck> physical;
  // Table 1 of the paper (kg m^2): mean of per-angle std, mean CV (%), regression RMSE.
  double raw_sigma_kg_m2 = NAN, cv_percent = NAN, regression_rmse_kg_m2 = NAN;
  CampaignSummary summary;
};

}  // namespace bifilar
