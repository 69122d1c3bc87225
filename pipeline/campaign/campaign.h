// A test campaign: a folder of IMU logs (a few trials per pitch angle) plus the rig's tare logs
// -> every trace fitted (in parallel, cached), the rig subtracted, per-angle statistics, the
// ellipse of inertia, and results.json / traces.csv / angles.csv / report.html in OUT.
// RunCampaign's steps: discover (pipeline/campaign/run_discovery.h) -> calibrate the rig geometry
// when rig.calibration is set (pipeline/campaign/calibration.h) -> fit traces (in parallel,
// base/parallel_runner.h, cached) -> tare -> group by angle -> ellipse -> write
// (pipeline/store/output_set.h, atomically: base/atomic_file.h).
// Conventions: docs/physics.md §2 (tare: I_aircraft = I_total - I_rig), §3 (pitch, ellipse).
#pragma once

#include <atomic>
#include <functional>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fit/ellipse.h"
#include "fit/tensor.h"
#include "pipeline/campaign/calibration.h"
#include "pipeline/config/config.h"
#include "pipeline/campaign/run_discovery.h"  // RunFile, DiscoverRuns
#include "pipeline/trace/trace_process.h"

namespace bifilar {

// Per-angle statistics of the usable (ok) traces of one pitch group.
struct AngleStats {
  double pitch_deg = NAN;          // group pitch: the nominal pitch, or mean measured pitch
  double roll_deg = NAN;           // group roll, likewise (0 in a campaign without rolls)
  int n = 0;                       // ok traces
  double inertia_mean_kg_m2 = NAN; // mean aircraft inertia
  double inertia_std_kg_m2 = NAN;  // sample standard deviation between trials (n >= 2), else NaN
  double inertia_sem_kg_m2 = NAN;  // standard error of the mean: the between-trial std / sqrt(n)
                                   // when n >= 2, else the fit's own std
  double cv_percent = NAN;         // 100 std / mean
  double fit_std_mean_kg_m2 = NAN; // mean of the traces' own fit std
  // Total uncertainty of the mean (pipeline/records/total_uncertainty.h): the standard error and
  // the common-mode terms (rig inertia, configured inputs, calibration; their mean over the trials)
  // in quadrature; with one trial, its own total.
  double common_mode_std_kg_m2 = NAN;
  double inertia_std_total_kg_m2 = NAN;
};

struct CampaignSummary {
  int n_traces = 0, n_ok = 0, n_rejected = 0, n_error = 0;  // aircraft + tare
  int n_fitted = 0, n_reused = 0;  // fits run now / taken from the cache
  int n_cache_refused = 0;         // cache entries refused as damaged or not theirs (refitted)
  double wall_s = 0.0;             // whole run
  bool ellipse_fitted = false;
  std::string ellipse_message;     // why not fitted, if so
  bool tensor_fitted = false;      // the inertia tensor (or the components it can observe)
  std::string tensor_message;      // why not fitted, if so
  int exit_code = 0;               // 0 all well, 1 some traces failed or rejected (or no ellipse)
};

struct CampaignResult {
  std::vector<TraceRecord> traces;  // aircraft runs, tare logs, reference swings: discovery order
  double rig_inertia_kg_m2 = NAN;   // value / tare mean (table: NaN, see per-trace field)
  double rig_inertia_std_kg_m2 = NAN;
  int rig_tare_n = 0;               // ok tare logs used
  // rig.calibration: the effective geometry every trace was fitted with
  // (pipeline/campaign/calibration.h); absent without the section.
  std::optional<RigCalibrationResult> calibration;
  // Why the rig inertia is unknown (tare: no usable tare log, with the first tare log's own
  // message), "" when known; the console says it once, before the traces it affects.
  std::string rig_problem;
  std::vector<AngleStats> angles;   // sorted by pitch
  std::optional<EllipseResult> ellipse_fit;  // fit/ellipse.h, when >= min_angles angles remain
  // pipeline/records/ellipse_json.h document, null when not fitted
  nlohmann::json ellipse;
  std::string moments_figure;       // Fig. 3 file name in OUT/figures/, "" when none
  std::string polar_figure;         // Fig. 4 file name in OUT/figures/, "" when none
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
  // Table 1 of the paper (kg m^2): mean of per-angle std, mean CV (%), regression RMSE.
  double raw_sigma_kg_m2 = NAN, cv_percent = NAN, regression_rmse_kg_m2 = NAN;
  CampaignSummary summary;
};

// Fits one trace; ProcessTrace in production, a fake in tests.
using TraceFitFunction = std::function<TraceRecord(const CampaignConfig&, const std::string& path,
                                                   const TraceProcessOptions&)>;

constexpr int kMaxJobs = 256;  // limit of CampaignOptions::jobs (--jobs)

struct CampaignOptions {
  std::string out_dir;        // output folder (created); an existing non-folder is an error
  int jobs = 0;               // worker threads; 0 = hardware concurrency; <= kMaxJobs
  bool force = false;         // ignore the cache (refit everything)
  bool write_report = true;   // report.html (needs the figures)
  bool figures = true;        // draw per-trace fit figures and Fig. 3/4
  std::ostream* progress = nullptr;  // progress lines / bar; nullptr = quiet
  bool progress_bar = false;  // redraw one line ('\r') instead of one line per trace
  TraceFitFunction fit_function;  // empty = ProcessTrace
  // Ctrl-C (base/interrupt.h): when set, no further fit starts; fits running finish and are
  // cached, and RunCampaign throws CampaignInterrupted before writing any result. nullptr: none.
  const std::atomic<bool>* cancel = nullptr;
  // Called after each fit (from worker threads, serialised): fits done, fits planned, the
  // trace's progress line. Empty: none. Beside `progress`, for the Python module's callback.
  std::function<void(int done, int total, const std::string& line)> on_progress;

  bool Check(std::string* why) const;
};

// Runs the campaign and writes OUT/{results.json, traces.csv, angles.csv, report.html} (each
// atomically), OUT/cache/ and OUT/figures/. Throws UserError for config/usage problems (the CLI
// turns it into exit code 2), and when rig.calibration cannot be made (a reference swing that
// does not fit, named; no aircraft trace is fitted then); problems with single logs are error
// rows.
CampaignResult RunCampaign(const CampaignConfig& config, const CampaignOptions& options);

// The start of a trace's message when a tare campaign has no usable tare log.
inline constexpr char kNoUsableTareLog[] = "no usable tare log";

// Rig inertia subtracted at `pitch_deg` from the spec and the fitted tare mean/std. False with
// *why when it cannot be found (table: pitch outside it; tare: kNoUsableTareLog ...).
bool RigInertiaAt(const CampaignConfig& config, double tare_mean_kg_m2, double tare_std_kg_m2,
                  double pitch_deg, double* inertia_kg_m2, double* std_kg_m2, std::string* why);

// The console summary: Table 2 with uncertainties in the config's units, counts, reuse, time.
void PrintCampaignSummary(const CampaignConfig& config, const CampaignResult& result,
                          std::ostream& out);

}  // namespace bifilar
