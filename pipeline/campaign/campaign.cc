#include "pipeline/campaign/campaign.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <map>
#include <new>
#include <ostream>
#include <set>
#include <sstream>
#include <tuple>
#include <utility>

#include "base/bounded_read.h"
#include "base/hash.h"
#include "base/interrupt.h"
#include "base/option_check.h"
#include "base/parallel_runner.h"
#include "base/statistics.h"
#include "base/text_format.h"
#include "base/units.h"
#include "base/user_error.h"
#include "base/version.h"
#include "fit/physical.h"
#include "fit/tensor.h"
#include "pipeline/campaign/calibration.h"
#include "pipeline/campaign/campaign_inputs.h"
#include "pipeline/campaign/campaign_tensor.h"
#include "pipeline/campaign/rig_inertia.h"
#include "pipeline/figures/ellipse_plot.h"
#include "pipeline/records/ellipse_json.h"
#include "pipeline/records/results_json.h"
#include "pipeline/records/total_uncertainty.h"
#include "pipeline/report/report.h"
#include "pipeline/store/cache.h"
#include "pipeline/store/output_set.h"
#include "pipeline/trace/repeat_setups.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// ---- Before any work: options, config, the output folder --------------------------------------

void CheckCampaignInputs(const CampaignConfig& config, const CampaignOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw UserError(why);
  if (!config.Check(&why)) throw UserError(config.file + ": " + why);
}

// OUT created (an existing non-folder is an error); returns its path.
fs::path CreateOutputFolder(const std::string& out_dir) {
  std::error_code ec;
  const fs::path out(out_dir);
  if (fs::exists(out, ec) && !fs::is_directory(out, ec)) {
    throw UserError(out_dir + ": output path exists and is not a folder");
  }
  fs::create_directories(out, ec);
  if (ec) throw UserError(out_dir + ": cannot create output folder: " + ec.message());
  return out;
}

// OUT for the whole run (pipeline/store/output_set.h): locked (one run per folder), its manifest
// read and its owned places checked (nothing removed that bifilar did not write), cache/ and
// figures/ created. A mixed set left by a killed run is a warning: it is rewritten now.
struct OutputFolder {
  explicit OutputFolder(const CampaignOptions& options)
      : dir(CreateOutputFolder(options.out_dir)), lock(dir.string()), manifest(dir.string()) {
    manifest.CheckOwnedPlaces();
    RefuseNonRegularOutputs(dir.string());
    if (options.progress) {
      for (const std::string& problem : CheckOutputSet(dir.string(), true)) {
        *options.progress << "warning: previous outputs are a mixed set (" << problem
                          << "); all are rewritten now\n";
      }
    }
    std::error_code ec;
    fs::create_directories(dir / "cache", ec);
    if (!ec) fs::create_directories(dir / "figures", ec);
    if (ec) throw UserError(options.out_dir + ": cannot create output folder: " + ec.message());
  }
  fs::path figures() const { return dir / "figures"; }

  const fs::path dir;
  const OutputFolderLock lock;
  OutputManifest manifest;
};

// ---- Step 1: discover -------------------------------------------------------------------------

// The logs of the campaign with what their fits need. Vectors are per run, in discovery order.
struct CampaignInputs {
  std::vector<RunFile> runs;
  std::vector<std::optional<std::array<double, 2>>> windows;  // fit.windows override
  std::vector<std::string> hashes;       // content hash (FNV-1a 64), "" when not read
  std::vector<std::string> read_errors;  // why the file could not be read, "" when it could
  int size() const { return static_cast<int>(runs.size()); }
};

// Discovery, before OUT is created or locked: the logs, none of them inside OUT (outputs are
// not inputs, and a log inside OUT is an error: pipeline/campaign/campaign_inputs.h).
std::vector<RunFile> DiscoverLogs(const CampaignConfig& config, const std::string& out_dir) {
  std::vector<RunFile> runs = DiscoverRuns(config);
  DropOutputFolder(out_dir, &runs);
  if (runs.empty()) {
    throw UserError("runs: every file found is inside the output folder " + out_dir);
  }
  return runs;
}

// The discovered logs' windows, then their content hashes in parallel: reading is most of a
// rerun's time.
CampaignInputs DiscoverInputs(const CampaignConfig& config, std::vector<RunFile> runs, int jobs) {
  CampaignInputs in;
  in.runs = std::move(runs);
  in.windows = WindowsForRuns(config, in.runs);
  in.hashes.resize(in.runs.size());
  in.read_errors.resize(in.runs.size());
  ParallelFor(in.size(), jobs, [&](int i) {
    const RunFile& run = in.runs[i];
    if (!run.error.empty()) return;
    std::string bytes;
    std::string& error = in.read_errors[i];
    if (ReadRegularFile(run.path, LogCap(config.limits.LogOptions().max_file_bytes), &bytes,
                        &error)) {
      in.hashes[i] = HashToHex(Fnv1a64(bytes));
    } else {
      error = run.display + ": " +
              (error.rfind(run.path, 0) == 0 ? error.substr(run.path.size() + 2) : error);
    }
  });
  return in;
}

// ---- Step 2: fit traces -----------------------------------------------------------------------

// What the fits have to do: the runs not answered by an error row or the cache.
struct FitPlan {
  std::vector<int> to_fit;  // indices into CampaignInputs, in discovery order
};

// A fitted or cached record takes the fields discovery knows (file, role, nominal pitch, content
// hash, cache key) from the planned record, and says where it came from.
void KeepDiscoveryFields(const TraceRecord& planned, bool from_cache, TraceRecord* r) {
  r->file = planned.file;
  r->role = planned.role;
  r->pitch_nominal_deg = planned.pitch_nominal_deg;
  r->roll_nominal_deg = planned.roll_nominal_deg;
  r->content_hash = planned.content_hash;
  r->cache_key = planned.cache_key;
  r->from_cache = from_cache;
}

// One record per `wanted` run: an error row (discovery error, unreadable, duplicate content), a
// cache hit, or a record to fit (listed in the plan). Counts reuse and refused cache entries.
// Runs not wanted keep their records (the reference swings, fitted by the calibration), but
// their content still counts for the duplicate test, so every pass finds the same duplicates.
FitPlan PlanFits(const CampaignConfig& config, const CampaignOptions& options,
                 const CampaignInputs& in, const TraceCache& cache, const OutputFolder& out,
                 const std::vector<bool>& wanted, CampaignResult* result) {
  FitPlan plan;
  result->traces.resize(in.size());
  std::map<std::string, std::string> first_with_hash;
  for (int i = 0; i < in.size(); ++i) {
    const RunFile& run = in.runs[i];
    if (!wanted[i]) {
      if (run.error.empty() && in.read_errors[i].empty()) {
        first_with_hash.emplace(in.hashes[i], run.display);
      }
      continue;
    }
    TraceRecord& record = result->traces[i];
    record = TraceRecord();
    record.file = run.display;
    record.role = run.role;
    record.model = ToString(config.fit.model);
    record.pitch_nominal_deg = run.pitch_nominal_deg;
    record.roll_nominal_deg = run.roll_nominal_deg;
    record.content_hash = in.hashes[i];
    if (!run.error.empty() || !in.read_errors[i].empty()) {
      record.status = TraceStatus::kError;
      record.message = !run.error.empty() ? run.error : in.read_errors[i];
      continue;
    }
    auto [it, inserted] = first_with_hash.emplace(in.hashes[i], run.display);
    if (!inserted) {
      record.status = TraceStatus::kError;
      record.message = run.display + ": same content as " + it->second + " (duplicate log)";
      continue;
    }
    record.cache_key = CacheKey(in.hashes[i], FitFingerprint(config, run.role, in.windows[i]));
    TraceRecord cached;
    std::string cache_problem;
    const bool loaded =
        !options.force && cache.Load(record.cache_key, in.hashes[i], &cached, &cache_problem);
    if (!cache_problem.empty()) {
      ++result->summary.n_cache_refused;
      if (options.progress) *options.progress << "warning: " << cache_problem << "; refitting\n";
    }
    std::error_code ec;
    // Reused only with its figures: a record with a sweep and no sweep figure (an older run's)
    // is refitted, so the report shows I against amplitude for every trace that has a sweep.
    // Likewise a measured pitch without its roll (written before the roll was recorded).
    if (loaded && (!cached.pitch_measured_deg || cached.roll_measured_deg) &&
        (!options.figures ||
         ((cached.figure.empty() || fs::exists(out.figures() / cached.figure, ec)) &&
          (cached.sweep_figure.empty() ? !cached.sweep.evaluated
                                       : fs::exists(out.figures() / cached.sweep_figure, ec))))) {
      KeepDiscoveryFields(record, /*from_cache=*/true, &cached);
      record = cached;
      ++result->summary.n_reused;
    } else {
      plan.to_fit.push_back(i);
    }
  }
  return plan;
}

// One fit: `fit` on the run's log with its window and figure, an exception turned into an error
// row, the discovery fields kept from `planned`, the record cached.
TraceRecord FitOneTrace(const TraceFitFunction& fit, const CampaignConfig& fit_config,
                        const CampaignOptions& options, const RunFile& run,
                        const std::optional<std::array<double, 2>>& window,
                        const TraceRecord& planned, const TraceCache& cache,
                        const OutputFolder& out) {
  TraceProcessOptions trace_options;
  trace_options.role = run.role;
  trace_options.display_name = run.display;
  trace_options.window_s = window;
  const std::string figure_name = planned.cache_key + ".svg";
  const std::string figure_path = (out.figures() / figure_name).string();
  const std::string sweep_name = planned.cache_key + "_sweep.svg";
  const std::string sweep_path = (out.figures() / sweep_name).string();
  if (options.figures) trace_options.figure_paths = {figure_path};
  if (options.figures) trace_options.sweep_figure_paths = {sweep_path};
  trace_options.compact_figure = true;
  trace_options.figure_width_px = 640;
  trace_options.figure_height_px = 400;
  TraceRecord fitted;
  try {
    fitted = fit(fit_config, run.path, trace_options);
  } catch (const std::bad_alloc&) {
    fitted.status = TraceStatus::kError;
    fitted.message = run.display +
                     ": out of memory while reading or fitting this log (is it "
                     "far larger than a pendulum log?)";
  } catch (const std::exception& e) {
    fitted.status = TraceStatus::kError;
    fitted.message = run.display + ": " + e.what();
  }
  std::error_code ec;
  fitted.figure = options.figures && fs::exists(figure_path, ec) ? figure_name : "";
  fitted.sweep_figure = options.figures && fs::exists(sweep_path, ec) ? sweep_name : "";
  KeepDiscoveryFields(planned, /*from_cache=*/false, &fitted);
  try {
    cache.Store(planned.cache_key, planned.content_hash, fitted);
  } catch (const UserError& e) {
    if (fitted.message.empty()) fitted.message = std::string("not cached: ") + e.what();
  }
  return fitted;
}

// "pitch_10/trial_1.csv: ok I_total = 4.0999 kg m^2": the progress line of a fitted trace.
std::string ProgressLine(const TraceRecord& record, DisplayUnits units) {
  std::string line = record.file + ": " + ToString(record.status);
  if (record.ok()) {
    char buffer[160];
    std::snprintf(buffer, sizeof(buffer),
                  " I_total = %#.5g %s +- %.2g %% (stat) +- %.2g %% (total)",
                  InertiaToDisplay(record.inertia_total_kg_m2, units), InertiaUnitName(units),
                  100.0 * record.inertia_total_std_kg_m2 / record.inertia_total_kg_m2,
                  100.0 * record.inertia_total_std_total_kg_m2 / record.inertia_total_kg_m2);
    line += buffer;
  } else {
    line += " (" + record.message + ")";
  }
  return line;
}

// Fits the planned runs in parallel; their cache and figure names are recorded in the manifest
// before the files exist.
void FitTraces(const CampaignConfig& config, const CampaignOptions& options,
               const CampaignInputs& in, const FitPlan& plan, const TraceCache& cache, int jobs,
               OutputFolder* out, std::vector<TraceRecord>* traces) {
  std::vector<std::string> planned;
  for (int i : plan.to_fit) {
    planned.push_back("cache/" + (*traces)[i].cache_key + ".json");
    planned.push_back("figures/" + (*traces)[i].cache_key + ".svg");
    planned.push_back("figures/" + (*traces)[i].cache_key + "_sweep.svg");
  }
  out->manifest.Record(planned);
  const TraceFitFunction fit = options.fit_function ? options.fit_function : ProcessTrace;
  // Windows are resolved in discovery (WindowsForRuns): the fit gets each in its options, and a
  // config without the list, so no fit searches fit.windows again (cost entries x traces).
  CampaignConfig fit_config = config;
  fit_config.fit.windows_s.clear();
  const int n_fit = static_cast<int>(plan.to_fit.size());
  ProgressReporter progress(options.progress, options.progress_bar, n_fit, options.on_progress);
  auto cancelled = [&] { return options.cancel != nullptr && options.cancel->load(); };
  ParallelFor(n_fit, jobs, [&](int k) {
    if (cancelled()) return;  // Ctrl-C: hand out no further fit
    const int i = plan.to_fit[k];
    TraceRecord& record = (*traces)[i];
    record = FitOneTrace(fit, fit_config, options, in.runs[i], in.windows[i], record, cache, *out);
    progress.TaskDone(ProgressLine(record, config.units));
  });
  if (cancelled()) {
    throw CampaignInterrupted(progress.Stop(), n_fit,
                              (std::filesystem::path(options.out_dir) / "cache").string());
  }
}

// ---- Step 2a: calibrate (rig.calibration, pipeline/campaign/calibration.h)
// --------------------------

// The reference swings (and the tare logs, when they give the rig inertia) fitted round by round
// through the cache, each round at its own geometry; the result goes into `result->calibration`
// and the reference swings' records into the trace list, each with the reference's share
// (total - rig) as its `inertia_kg_m2`. Throws UserError (pipeline/campaign/calibration.h) before
// any aircraft trace is fitted when the calibration cannot be made.
GeometryCalibration CalibrateCampaign(const CampaignConfig& config, const CampaignOptions& options,
                                      const CampaignInputs& in, const TraceCache& cache, int jobs,
                                      OutputFolder* out, CampaignResult* result) {
  const bool from_tare = config.rig_inertia.kind == RigInertiaSpec::Kind::kTare;
  std::vector<bool> wanted(in.size());
  for (int i = 0; i < in.size(); ++i) {
    wanted[i] = in.runs[i].role == TraceRole::kCalibration ||
                (from_tare && in.runs[i].role == TraceRole::kTare);
  }
  if (options.progress) *options.progress << "rig.calibration: fitting the reference swings\n";
  const CalibrationFitFunction fit = [&](const CampaignConfig& round) {
    const FitPlan plan = PlanFits(round, options, in, cache, *out, wanted, result);
    FitTraces(round, options, in, plan, cache, jobs, out, &result->traces);
    result->summary.n_fitted += static_cast<int>(plan.to_fit.size());
    std::vector<TraceRecord> records;
    for (int i = 0; i < in.size(); ++i) {
      if (wanted[i]) records.push_back(result->traces[i]);
    }
    return records;
  };
  result->calibration = CalibrateRig(config, fit);
  const RigCalibrationResult& c = *result->calibration;
  for (TraceRecord& r : result->traces) {
    if (r.role != TraceRole::kCalibration || !r.ok()) continue;
    r.rig_inertia_kg_m2 = c.rig_inertia_kg_m2;
    r.inertia_kg_m2 = r.inertia_total_kg_m2 - c.rig_inertia_kg_m2;
    r.inertia_std_kg_m2 = std::hypot(r.inertia_total_std_kg_m2, c.rig_inertia_std_kg_m2);
  }
  if (options.progress) {
    *options.progress << c.BriefReport() << "\n";
    for (const std::string& w : c.warnings) *options.progress << "warning: " << w << "\n";
  }
  return c.Applied();
}

// ---- Step 3: tare -----------------------------------------------------------------------------

// The tare logs' rig inertia: their mean, and the larger of the between-log standard error and
// the fits' own (rms std / sqrt(n)): three logs that happen to agree closely must not claim more
// than their fits can. NaN when no tare log is usable.
struct TareEstimate {
  double mean_kg_m2 = NAN;
  double std_kg_m2 = NAN;
  int n = 0;  // ok tare logs
};

// Also gives each ok tare record its own inertia (a tare log has no rig to subtract).
TareEstimate EstimateTare(std::vector<TraceRecord>* traces) {
  std::vector<double> values, stds;
  for (TraceRecord& r : *traces) {
    if (r.role != TraceRole::kTare || !r.ok()) continue;
    values.push_back(r.inertia_total_kg_m2);
    stds.push_back(r.inertia_total_std_kg_m2);
    r.inertia_kg_m2 = r.inertia_total_kg_m2;
    r.inertia_std_kg_m2 = r.inertia_total_std_kg_m2;
    r.inertia_std_total_kg_m2 = r.inertia_total_std_total_kg_m2;
    const TotalUncertainty total = ComposeTotalUncertainty(r);
    r.aircraft_scale_std_kg_m2 =
        std::hypot(total.Term(kTermConfiguredInputs), total.Term(kTermCalibration));
  }
  TareEstimate tare;
  tare.n = static_cast<int>(values.size());
  MeanAndStandardError(values, stds, &tare.mean_kg_m2, &tare.std_kg_m2);
  return tare;
}

// The rig reported in the results: the tare mean, or the configured value (a table has none).
void SetRigInertia(const CampaignConfig& config, const TareEstimate& tare, CampaignResult* result) {
  result->rig_tare_n = tare.n;
  if (config.rig_inertia.kind == RigInertiaSpec::Kind::kTare) {
    result->rig_inertia_kg_m2 = tare.mean_kg_m2;
    result->rig_inertia_std_kg_m2 = tare.std_kg_m2;
    if (tare.n == 0) {  // the cause, from the tare logs' own rows, said once
      int failed = 0;
      std::string first;
      for (const TraceRecord& r : result->traces) {
        if (r.role != TraceRole::kTare) continue;
        if (failed++ == 0)
          first = r.message.empty() ? r.file + ": " + ToString(r.status) : r.message;
      }
      result->rig_problem = "no usable tare log, so the rig inertia is unknown: " +
                            (failed == 0 ? std::string("no tare log found") : first) +
                            (failed > 1 ? " (and " + std::to_string(failed - 1) + " more)" : "");
    }
  } else if (config.rig_inertia.kind == RigInertiaSpec::Kind::kValue) {
    result->rig_inertia_kg_m2 = config.rig_inertia.inertia_kg_m2;
    result->rig_inertia_std_kg_m2 = config.rig_inertia.inertia_std_kg_m2;
  }
}

// The measured down vector against the nominal one (docs/physics.md §3.5): farther apart than
// runs.attitude_tolerance_deg is a warning naming the log (a wrong folder, a rig set wrongly, or
// an IMU mounting that imu.imu_to_body does not describe).
void WarnIfAttitudesDisagree(const CampaignConfig& config, TraceRecord* r) {
  if (!r->pitch_measured_deg || !r->pitch_nominal_deg) return;
  const std::array<double, 3> nominal =
      DownInBodyFromAttitude(r->roll_nominal_deg.value_or(0.0), *r->pitch_nominal_deg);
  const std::array<double, 3> measured =
      DownInBodyFromAttitude(r->roll_measured_deg.value_or(0.0), *r->pitch_measured_deg);
  double dot = 0.0;
  for (int k = 0; k < 3; ++k) dot += nominal[k] * measured[k];
  const double angle_deg = std::acos(std::clamp(dot, -1.0, 1.0)) * kDegPerRad;
  if (angle_deg <= config.runs.attitude_tolerance_deg) return;
  char buffer[320];
  std::snprintf(buffer, sizeof(buffer),
                ": the measured down vector (roll %.1f, pitch %.1f deg) is %.1f deg from the "
                "nominal one (roll %.1f, pitch %.1f deg), more than runs.attitude_tolerance_deg "
                "%.3g: check the log's attitude, the rig and imu.imu_to_body",
                r->roll_measured_deg.value_or(0.0), *r->pitch_measured_deg, angle_deg,
                r->roll_nominal_deg.value_or(0.0), *r->pitch_nominal_deg,
                config.runs.attitude_tolerance_deg);
  r->warnings.push_back(r->file + buffer);
}

// Every ok aircraft trace: the pitch used (nominal or measured), then I_aircraft = I_total - I_rig
// with the stds in quadrature. A trace whose pitch or rig inertia is unknown, or whose total is
// not above the rig, becomes an error row.
void SubtractRig(const CampaignConfig& config, const TareEstimate& tare,
                 std::vector<TraceRecord>* traces) {
  for (TraceRecord& r : *traces) {
    if (r.role != TraceRole::kAircraft || !r.ok()) continue;
    if (config.runs.pitch_source == PitchSource::kMeasured) {
      if (!r.pitch_measured_deg) {
        // The accelerometer's own warning says why (not gravity: fit/swing_axis.h).
        std::string why = "the log gave no measured pitch";
        for (const std::string& w : r.warnings) {
          if (w.find(kAccelIgnoredSentence) != std::string::npos) why = w;
        }
        r.status = TraceStatus::kError;
        r.message =
            r.file + ": runs.pitch_source: measured needs the accelerometer's pitch, but " + why;
        continue;
      }
      r.pitch_used_deg = *r.pitch_measured_deg;
      r.roll_used_deg = r.roll_measured_deg.value_or(0.0);
    } else {
      r.pitch_used_deg = r.pitch_nominal_deg ? *r.pitch_nominal_deg : NAN;
      r.roll_used_deg = r.roll_nominal_deg.value_or(0.0);
    }
    WarnIfAttitudesDisagree(config, &r);
    double rig = 0.0, rig_std = 0.0;
    std::string reason;
    if (!RigInertiaAt(config, tare.mean_kg_m2, tare.std_kg_m2, r.pitch_used_deg, &rig, &rig_std,
                      &reason)) {
      r.status = TraceStatus::kError;
      r.message = r.file + ": " + reason;
      continue;
    }
    r.rig_inertia_kg_m2 = rig;
    if (!(r.inertia_total_kg_m2 > rig)) {
      char buffer[200];
      std::snprintf(buffer, sizeof(buffer),
                    ": rig inertia %.6g kg m^2 is not below the measured total %.6g kg m^2 "
                    "(check rig.inertia and the tare logs)",
                    rig, r.inertia_total_kg_m2);
      r.status = TraceStatus::kError;
      r.message = r.file + buffer;
      continue;
    }
    r.inertia_kg_m2 = r.inertia_total_kg_m2 - rig;
    r.inertia_std_kg_m2 = std::hypot(r.inertia_total_std_kg_m2, rig_std);
    const TotalUncertainty total = ComposeAircraftUncertainty(
        r, rig_std, config.rig_inertia.kind == RigInertiaSpec::Kind::kTare);
    r.inertia_std_total_kg_m2 = total.total_std_kg_m2;
    r.aircraft_scale_std_kg_m2 =
        std::hypot(total.Term(kTermConfiguredInputs), total.Term(kTermCalibration));
  }
}

// ---- Step 4: group ----------------------------------------------------------------------------

// The logs of one attitude are repeats of one set-up. When they form two, found by the test
// (pipeline/trace/repeat_setups.h) or named by the user (two values of runs.table's `group`
// column at one attitude), the attitude's result is withheld: each set-up is reported on its own
// (its logs, weighted mean and std) and its logs are marked rejected, so neither the ellipse nor
// the tensor averages them, until the user keeps one set-up (comments out the other's rows in
// runs.table with '#'). docs/guide.md, "Two set-ups at one attitude".
struct SetupGroup {
  std::string name;          // the group column's value, or "set-up 1" / "set-up 2"
  std::vector<int> members;  // trace indices
};

// "group 'A' (a.csv, b.csv): I_total = 0.3201 +- 0.0002 kg m^2" for each set-up, the weighted mean
// of its logs' total moments (rig + aircraft, as the test's text) with the std of a weighted mean
// (Birge-scaled when they scatter).
std::string SetupGroupsText(const std::vector<SetupGroup>& setups,
                            const std::vector<TraceRecord>& traces) {
  std::string text;
  for (const SetupGroup& s : setups) {
    double sw = 0, swy = 0, chi2 = 0;
    for (int i : s.members) {
      const double w =
          1.0 / (traces[i].inertia_total_std_kg_m2 * traces[i].inertia_total_std_kg_m2);
      sw += w;
      swy += w * traces[i].inertia_total_kg_m2;
    }
    const double mean = swy / sw;
    for (int i : s.members) {
      const double d = (traces[i].inertia_total_kg_m2 - mean) / traces[i].inertia_total_std_kg_m2;
      chi2 += d * d;
    }
    const double birge =
        s.members.size() > 1 ? std::max(1.0, std::sqrt(chi2 / (s.members.size() - 1))) : 1.0;
    std::string files;
    for (size_t k = 0; k < s.members.size(); ++k) {
      files += (k ? ", " : "") + traces[s.members[k]].file;
    }
    text += (text.empty() ? "" : "; ") + s.name + " (" + files +
            "): I_total = " + Fmt("%.5g", mean) + " +- " + Fmt("%.2g", birge / std::sqrt(sw)) +
            " kg m^2";
  }
  return text;
}

void WithholdTwoSetups(const std::vector<RunFile>& runs, CampaignResult* result) {
  std::vector<TraceRecord>& traces = result->traces;
  std::map<std::pair<double, double>, std::vector<int>> attitudes;
  for (size_t i = 0; i < traces.size(); ++i) {
    const TraceRecord& r = traces[i];
    if (r.role != TraceRole::kAircraft || !r.ok() || !std::isfinite(r.inertia_total_kg_m2) ||
        !std::isfinite(r.inertia_total_std_kg_m2) || !(r.inertia_total_std_kg_m2 > 0.0)) {
      continue;
    }
    const double pitch =
        r.pitch_nominal_deg ? *r.pitch_nominal_deg : std::round(r.pitch_used_deg * 2.0) / 2.0;
    const double roll = r.pitch_nominal_deg ? r.roll_nominal_deg.value_or(0.0)
                                            : std::round(r.roll_used_deg * 2.0) / 2.0;
    attitudes[{roll, pitch}].push_back(static_cast<int>(i));
  }
  for (const auto& [attitude, members] : attitudes) {
    // Named set-ups: the group column's values at this attitude.
    std::map<std::string, std::vector<int>> named;
    for (int i : members)
      named[static_cast<size_t>(i) < runs.size() ? runs[i].group : ""].push_back(i);
    std::vector<SetupGroup> setups;
    std::string found;
    if (named.size() > 1) {
      for (const auto& [name, logs] : named) {
        setups.push_back({name.empty() ? "no group" : "group '" + name + "'", logs});
      }
      found =
          "are named as " + std::to_string(named.size()) + " set-ups in runs.table's group column";
    } else {
      std::vector<const TraceRecord*> records;
      std::vector<std::string> names;
      for (int i : members) {
        records.push_back(&traces[i]);
        names.push_back(traces[i].file);
      }
      const SetupSplit split = TestTwoSetups(records);
      if (!split.two_setups) continue;
      for (int c = 0; c < 2; ++c) {
        SetupGroup g{"set-up " + std::to_string(c + 1), {}};
        for (int k : split.clusters[c]) g.members.push_back(members[k]);
        setups.push_back(g);
      }
      found = "look like " + TwoSetupsText(split, names);
    }
    char where[96];
    std::snprintf(where, sizeof(where), "roll %g, pitch %g deg", attitude.first, attitude.second);
    const std::string text =
        std::string("result withheld at ") + where + ": its " + std::to_string(members.size()) +
        " logs " + found + ": " + SetupGroupsText(setups, traces) +
        ". They are not averaged. Keep the set-up you trust: comment out the other's rows in "
        "runs.table with '#' (with runs.pattern, list the logs in a runs.table first) and rerun";
    result->setup_warnings.push_back(text);
    for (int i : members) {
      traces[i].status = TraceStatus::kRejected;
      traces[i].message = traces[i].file + ": withheld: " + std::to_string(setups.size()) +
                          " set-ups at " + where + ", not averaged (see the warning on set-ups)";
      traces[i].warnings.push_back(text);
    }
  }
}

void CountStatuses(const std::vector<TraceRecord>& traces, CampaignSummary* summary) {
  for (const TraceRecord& r : traces) {
    ++summary->n_traces;
    if (r.status == TraceStatus::kOk) ++summary->n_ok;
    if (r.status == TraceStatus::kRejected) ++summary->n_rejected;
    if (r.status == TraceStatus::kError) ++summary->n_error;
  }
}

// Per-angle statistics of the ok aircraft traces, sorted by roll then pitch (roll 0 when the
// campaign has no rolls). Groups: the nominal attitude when known, else the measured one to
// 0.5 deg.
std::vector<AngleStats> GroupByAngle(const std::vector<TraceRecord>& traces) {
  std::map<std::pair<double, double>, std::vector<const TraceRecord*>> groups;
  for (const TraceRecord& r : traces) {
    if (r.role != TraceRole::kAircraft || !r.ok()) continue;
    const double pitch =
        r.pitch_nominal_deg ? *r.pitch_nominal_deg : std::round(r.pitch_used_deg * 2.0) / 2.0;
    const double roll = r.pitch_nominal_deg ? r.roll_nominal_deg.value_or(0.0)
                                            : std::round(r.roll_used_deg * 2.0) / 2.0;
    groups[{roll, pitch}].push_back(&r);
  }
  std::vector<AngleStats> angles;
  for (const auto& [key, members] : groups) {
    AngleStats a;
    std::vector<double> values, pitches, rolls, fit_stds, common_mode;
    for (const TraceRecord* r : members) {
      values.push_back(r->inertia_kg_m2);
      pitches.push_back(r->pitch_used_deg);
      rolls.push_back(r->roll_used_deg);
      fit_stds.push_back(r->inertia_std_kg_m2);
      // The trace's common-mode terms (rig inertia, configured inputs, calibration).
      const double total = r->inertia_std_total_kg_m2, stat = r->inertia_total_std_kg_m2;
      common_mode.push_back(std::sqrt(std::max(0.0, total * total - stat * stat)));
    }
    a.pitch_deg = Mean(pitches);
    a.roll_deg = Mean(rolls);
    a.n = static_cast<int>(values.size());
    a.inertia_mean_kg_m2 = Mean(values);
    a.inertia_std_kg_m2 = SampleStd(values);
    a.fit_std_mean_kg_m2 = Mean(fit_stds);
    a.inertia_sem_kg_m2 = a.n >= 2 ? a.inertia_std_kg_m2 / std::sqrt(a.n) : fit_stds[0];
    a.cv_percent = 100.0 * a.inertia_std_kg_m2 / a.inertia_mean_kg_m2;
    // The mean's total: its standard error and the common-mode terms (one trial: its own total).
    a.common_mode_std_kg_m2 = Mean(common_mode);
    a.inertia_std_total_kg_m2 = a.n >= 2 ? std::hypot(a.inertia_sem_kg_m2, a.common_mode_std_kg_m2)
                                         : members[0]->inertia_std_total_kg_m2;
    angles.push_back(a);
  }
  return angles;
}

// Mean over ok aircraft traces of uncertainty budget / total inertia (CampaignResult).
double SystematicRelativeStd(const std::vector<TraceRecord>& traces) {
  std::vector<double> relative_budget;
  for (const TraceRecord& r : traces) {
    if (r.role == TraceRole::kAircraft && r.ok() && std::isfinite(r.budget_total_std_kg_m2)) {
      relative_budget.push_back(r.budget_total_std_kg_m2 / r.inertia_total_kg_m2);
    }
  }
  return Mean(relative_budget);
}

// Mean over ok aircraft traces of the scale terms (configured inputs, calibration) over the
// aircraft's inertia: the common-mode fraction Table 2's total adds (CampaignResult).
double CommonModeRelativeStd(const std::vector<TraceRecord>& traces, bool* assumed) {
  std::vector<double> relative;
  *assumed = false;
  for (const TraceRecord& r : traces) {
    if (r.role == TraceRole::kAircraft && r.ok() && std::isfinite(r.aircraft_scale_std_kg_m2) &&
        r.inertia_kg_m2 > 0.0) {
      relative.push_back(r.aircraft_scale_std_kg_m2 / r.inertia_kg_m2);
      *assumed = *assumed || r.budget_assumed;
    }
  }
  return Mean(relative);
}

// ---- Step 5: ellipse --------------------------------------------------------------------------

// Fig. 3 and Fig. 4 under names keyed by the ellipse inputs, so an unchanged rerun reuses them.
void DrawCampaignFigures(const CampaignConfig& config, const EllipseResult& fit, OutputFolder* out,
                         CampaignResult* result) {
  std::ostringstream key;
  key.precision(17);
  key << ProgramVersion() << ';' << ToString(config.units) << ';' << fit.a_kg_m2 << ';'
      << fit.b_kg_m2 << ';' << fit.c_kg_m2 << ';' << fit.bootstrap_replicates << ';';
  for (const EllipsePoint& p : fit.points) {
    key << p.pitch_deg << ',' << p.inertia_kg_m2 << ',' << p.std_kg_m2 << ';';
  }
  const std::string hash = HashToHex(Fnv1a64(key.str()));
  EllipsePlotOptions plot;
  plot.unit_label = InertiaUnitPlotLabel(config.units);
  if (config.units == DisplayUnits::kImperial) plot.unit_scale = kSlugFt2PerKgM2;
  const fs::path figures = out->figures();
  std::error_code ec;
  std::string why;
  const std::string moments = "moments_" + hash + ".png", polar = "polar_" + hash + ".png";
  out->manifest.Record({"figures/" + moments, "figures/" + polar});
  if (fs::exists(figures / moments, ec) ||
      WriteEllipseMomentFigure(fit, (figures / moments).string(), plot, &why)) {
    result->moments_figure = moments;
  }
  plot.figure.width_px = 1000;
  plot.figure.height_px = 520;
  if (fs::exists(figures / polar, ec) ||
      WriteEllipsePolarFigure(fit, (figures / polar).string(), plot, &why)) {
    result->polar_figure = polar;
  }
}

// One point per ok aircraft trial: pitch used, aircraft inertia after the tare, and the fit's
// own std (the rig's is one offset shared by every point, not independent noise per point; it
// is propagated as EllipseOptions::common_offset_std_kg_m2).
std::vector<EllipsePoint> EllipsePoints(const std::vector<TraceRecord>& traces) {
  std::vector<EllipsePoint> points;
  for (const TraceRecord& r : traces) {
    if (r.role != TraceRole::kAircraft || !r.ok()) continue;
    EllipsePoint p;
    p.pitch_deg = r.pitch_used_deg;
    p.inertia_kg_m2 = r.inertia_kg_m2;
    p.std_kg_m2 = r.inertia_total_std_kg_m2;
    points.push_back(p);
  }
  return points;
}

EllipseOptions MakeEllipseOptions(const CampaignConfig& config, double rig_std_kg_m2) {
  EllipseOptions o;
  o.bootstrap_replicates = config.ellipse.bootstrap;
  o.seed = config.ellipse.seed;
  o.confidence = config.ellipse.confidence;
  o.covariance = config.ellipse.covariance;
  const double rig_std = config.rig_inertia.kind == RigInertiaSpec::Kind::kTare
                             ? rig_std_kg_m2
                             : config.rig_inertia.inertia_std_kg_m2;
  o.common_offset_std_kg_m2 = std::isfinite(rig_std) ? rig_std : 0.0;
  return o;
}

// The ellipse of inertia from every ok aircraft trace, plus Table 1 (from the angle groups,
// replaced by the ellipse fit's own when it runs) and the Fig. 3/4 figures.
void FitCampaignEllipse(const CampaignConfig& config, const CampaignOptions& options,
                        OutputFolder* out, CampaignResult* result) {
  std::vector<double> stds, cvs;
  for (const AngleStats& a : result->angles) {
    if (a.n >= 2) {
      stds.push_back(a.inertia_std_kg_m2);
      cvs.push_back(a.cv_percent);
    }
  }
  result->raw_sigma_kg_m2 = Mean(stds);
  result->cv_percent = Mean(cvs);
  CampaignSummary& summary = result->summary;
  if (!IsPlanarCampaign(result->traces)) {
    summary.ellipse_fitted = false;
    summary.ellipse_message =
        "ellipse not fitted: the campaign swings about axes outside the x-z plane (roll_deg); "
        "see the inertia tensor";
    return;
  }
  if (static_cast<int>(result->angles.size()) < config.ellipse.min_angles) {
    summary.ellipse_fitted = false;
    summary.ellipse_message = "ellipse not fitted: " + std::to_string(result->angles.size()) +
                              " usable pitch angle(s), at least " +
                              std::to_string(config.ellipse.min_angles) + " needed";
    return;
  }
  EllipseResult fit;
  std::string why;
  if (!FitEllipse(EllipsePoints(result->traces),
                  MakeEllipseOptions(config, result->rig_inertia_std_kg_m2), &fit, &why) ||
      !fit.IsUsable()) {
    summary.ellipse_fitted = false;
    summary.ellipse_message = "ellipse not fitted: " + (why.empty() ? "fit not usable" : why);
    return;
  }
  summary.ellipse_fitted = true;
  result->regression_rmse_kg_m2 = fit.rmse_kg_m2;
  if (fit.table1.n_angles_with_trials > 0) {
    result->raw_sigma_kg_m2 = fit.table1.mean_angle_std_kg_m2;
    result->cv_percent = fit.table1.mean_cov_percent;
  }
  result->ellipse = EllipseResultToJson(fit);
  if (options.figures) DrawCampaignFigures(config, fit, out, result);
  result->ellipse_fit = std::move(fit);
}

// The planar ellipse's physical check (fit/physical.h); when it is not physical or borderline,
// the pitch whose removal restores it most is named (a refit without each pitch in turn).
PhysicalCheck CheckPlanarPhysical(const CampaignConfig& config, const CampaignResult& result) {
  PhysicalCheck check = CheckPhysicalEllipse(*result.ellipse_fit, {});
  if (check.status != PhysicalStatus::kNotPhysical && check.status != PhysicalStatus::kBorderline) {
    return check;
  }
  std::vector<double> pitches;
  for (const AngleStats& a : result.angles) pitches.push_back(a.pitch_deg);
  EllipseOptions options = MakeEllipseOptions(config, result.rig_inertia_std_kg_m2);
  options.bootstrap_replicates = 0;
  double best_z = -std::numeric_limits<double>::infinity(), best_pitch = NAN;
  for (const double pitch : pitches) {
    std::vector<TraceRecord> rest;
    for (const TraceRecord& r : result.traces) {
      const double p = r.pitch_nominal_deg ? *r.pitch_nominal_deg : r.pitch_used_deg;
      if (std::fabs(p - pitch) > 0.25) rest.push_back(r);
    }
    EllipseResult refit;
    std::string why;
    if (!FitEllipse(EllipsePoints(rest), options, &refit, &why) || !refit.IsUsable()) continue;
    const PhysicalCheck without = CheckPhysicalEllipse(refit, {});
    if (without.Worst() != nullptr && without.Worst()->z > best_z) {
      best_z = without.Worst()->z;
      best_pitch = pitch;
    }
  }
  if (std::isfinite(best_pitch)) {
    check.attitude = "pitch " + Fmt("%g", best_pitch) + " deg";
    check.z_without_attitude = best_z;
    check.message = PhysicalCheckMessage(check);
  }
  return check;
}

// ---- Step 6: write ----------------------------------------------------------------------------

// The result files, each atomically, results.json last with its siblings' hashes
// (pipeline/store/output_set.h); then the cache entries and figures bifilar wrote that no record
// refers to now are removed, so the folder does not grow.
void WriteCampaignOutputs(const CampaignConfig& config, const CampaignOptions& options,
                          OutputFolder* out, const CampaignResult& result) {
  const nlohmann::json json = ResultsToJson(config, result);
  std::set<std::string> keep = {"results.json", "traces.csv", "angles.csv", "report.html"};
  out->manifest.Record({keep.begin(), keep.end()});
  WriteOutputSet(out->dir.string(), json, TracesCsv(result), AnglesCsv(result),
                 options.write_report ? &BuildReportHtml : nullptr);
  for (const TraceRecord& r : result.traces) {
    if (!r.cache_key.empty()) keep.insert("cache/" + r.cache_key + ".json");
    if (!r.figure.empty()) keep.insert("figures/" + r.figure);
    if (!r.sweep_figure.empty()) keep.insert("figures/" + r.sweep_figure);
  }
  if (result.calibration) {  // every round's fits, so that a rerun finds them all in the cache
    for (const std::string& key : result.calibration->cache_keys) {
      keep.insert("cache/" + key + ".json");
      for (const char* suffix : {".svg", "_sweep.svg"}) keep.insert("figures/" + key + suffix);
    }
  }
  if (!result.moments_figure.empty()) keep.insert("figures/" + result.moments_figure);
  if (!result.polar_figure.empty()) keep.insert("figures/" + result.polar_figure);
  if (!result.tensor_figure.empty()) keep.insert("figures/" + result.tensor_figure);
  for (const std::string& refused : out->manifest.Prune(keep)) {
    if (options.progress) *options.progress << "warning: " << refused << "\n";
  }
}

}  // namespace

bool CampaignOptions::Check(std::string* why) const {
  CheckFailure f;
  const bool ok =
      (!out_dir.empty() || CheckFailText("out_dir", out_dir, "set (the output folder)", &f)) &&
      CheckIn("--jobs (0 = all cores)", jobs, 0, kMaxJobs, Ends::kClosed, &f);
  return ok || FailWith(f, why);
}

// discover -> calibrate (rig.calibration) -> fit traces -> tare -> group -> ellipse -> write.
CampaignResult RunCampaign(const CampaignConfig& config, const CampaignOptions& options) {
  const Clock::time_point start = Clock::now();
  CheckCampaignInputs(config, options);
  std::vector<RunFile> logs = DiscoverLogs(config, options.out_dir);
  OutputFolder out(options);
  const int jobs = ResolveJobs(options.jobs);
  const TraceCache cache((out.dir / "cache").string());
  CampaignResult result;

  // 1. Discover: the logs (found above), their windows and content hashes.
  const CampaignInputs inputs = DiscoverInputs(config, std::move(logs), jobs);
  // 2a. Calibrate: the reference swings fix the geometry every other fit uses.
  CampaignConfig fit_config = config;
  if (config.calibration.enabled) {
    fit_config.geometry_calibration =
        CalibrateCampaign(config, options, inputs, cache, jobs, &out, &result);
  }
  // 2. Fit traces: error rows and cache hits first, then the rest in parallel.
  std::vector<bool> wanted(inputs.size());
  for (int i = 0; i < inputs.size(); ++i) {
    wanted[i] = inputs.runs[i].role != TraceRole::kCalibration;
  }
  const FitPlan plan = PlanFits(fit_config, options, inputs, cache, out, wanted, &result);
  FitTraces(fit_config, options, inputs, plan, cache, jobs, &out, &result.traces);
  result.summary.n_fitted += static_cast<int>(plan.to_fit.size());
  // 3. Tare: the rig inertia, subtracted from every aircraft trace.
  const TareEstimate tare = EstimateTare(&result.traces);
  SetRigInertia(config, tare, &result);
  SubtractRig(config, tare, &result.traces);
  WithholdTwoSetups(inputs.runs, &result);
  // 4. Group: counts, per-angle statistics, the systematic uncertainty.
  CountStatuses(result.traces, &result.summary);
  result.angles = GroupByAngle(result.traces);
  result.systematic_relative_std = SystematicRelativeStd(result.traces);
  result.common_mode_relative_std =
      CommonModeRelativeStd(result.traces, &result.common_mode_assumed);
  result.assumed_inputs_note = AssumedInputsSummary(result.traces);
  // 5. Ellipse of inertia, Table 1, Fig. 3/4; the inertia tensor
  // (pipeline/campaign/campaign_tensor.h).
  FitCampaignEllipse(config, options, &out, &result);
  FitCampaignTensor(
      config, options.figures ? out.figures().string() : "",
      [&out](const std::string& name) { out.manifest.Record({"figures/" + name}); }, &result);
  if (result.ellipse_fit && IsPlanarCampaign(result.traces)) {
    result.physical = CheckPlanarPhysical(config, result);
  }
  if (result.summary.n_rejected + result.summary.n_error > 0 ||
      (!result.summary.ellipse_fitted && !result.summary.tensor_fitted) ||
      (result.ellipse_fit && !result.ellipse_fit->physical) ||
      (result.physical && result.physical->Flagged())) {
    result.summary.exit_code = 1;
  }
  result.summary.wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  // 6. Write the result files; prune what no record refers to.
  WriteCampaignOutputs(config, options, &out, result);
  return result;
}

}  // namespace bifilar
