#include "pipeline/trace/trace_process.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <new>

#include "base/units.h"
#include "base/user_error.h"
#include "fit/block_mean.h"
#include "fit/glitch.h"
#include "fit/swing_axis.h"
#include "fit/trace_fit.h"
#include "fit/window.h"
#include "pendulum/model.h"
#include "pipeline/config/plausibility.h"
#include "pipeline/figures/figure.h"
#include "pipeline/figures/report_trace_figure.h"
#include "pipeline/figures/sweep_plot.h"
#include "pipeline/figures/trace_plot.h"
#include "pipeline/logs/imu_log.h"
#include "pipeline/records/total_uncertainty.h"

namespace bifilar {

std::string CanonicalLogPath(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path absolute = std::filesystem::absolute(path, ec);
  if (ec) return std::filesystem::path(path).lexically_normal().string();
  const std::filesystem::path canonical = std::filesystem::weakly_canonical(absolute, ec);
  return ec ? absolute.lexically_normal().string() : canonical.string();
}

std::optional<std::array<double, 2>> ConfigWindowFor(const CampaignConfig& config,
                                                     const std::string& path) {
  if (config.fit.windows_s.empty()) return std::nullopt;
  const std::string target = CanonicalLogPath(path);
  for (const auto& [key, window] : config.fit.windows_s) {
    if ((!config.runs.root.empty() &&
         CanonicalLogPath(ResolvePath(config.runs.root, key)) == target) ||
        CanonicalLogPath(ResolvePath(config.folder, key)) == target) {
      return window;
    }
  }
  return std::nullopt;
}

namespace {

// The log's own path at the start of a reader message becomes the display name.
std::string Renamed(const std::string& message, const std::string& path, const std::string& name) {
  if (message.rfind(path, 0) == 0) return name + message.substr(path.size());
  if (message.find(name) != std::string::npos) return message;
  return name + ": " + message;
}

TraceRecord ProcessData(const CampaignConfig& config, const std::string& path, const ImuData& data,
                        const TraceProcessOptions& options, TraceRecord record,
                        TraceFitResult* fit_out);

// A user window checked against the log, said in the log's own terms (its span in seconds, and
// the window read as ms or us when that would fit), before the swing axis or the window code look
// inside it. A window that overlaps the log has its open or too-large end(s) clamped to the log,
// with *note saying so; one that misses the log is an error naming the wrong end (returned).
// Inside means up to half a mean sample step beyond the ends, as ApplyWindowOverride allows.
std::string WindowOutsideLog(const ImuData& data, std::array<double, 2>* window_s, bool from_cli,
                             TimeUnit time_unit, std::string* note) {
  const std::vector<double>& t = data.t_s;
  if (t.size() < 2) return "";
  const double half_dt = 0.5 * (t.back() - t.front()) / static_cast<double>(t.size() - 1);
  auto inside = [&](double t0, double t1) {
    return t0 >= t.front() - half_dt && t1 <= t.back() + half_dt;
  };
  const double t0 = (*window_s)[0], t1 = (*window_s)[1];
  if (inside(t0, t1)) return "";
  const char* key = from_cli ? "--window" : "fit.windows";
  char buf[512];
  // The window read as ms or us, when that lies inside the log: a unit mistake, never clamped.
  std::string unit_hint;
  for (const auto& [factor, unit] : {std::make_pair(1e-3, "ms"), std::make_pair(1e-6, "us")}) {
    const double s0 = t0 * factor, s1 = t1 * factor;
    if (inside(s0, s1)) {
      std::snprintf(buf, sizeof(buf), "; if these are %s, give %g:%g", unit, s0, s1);
      unit_hint = buf;
      break;
    }
  }
  if (unit_hint.empty() && t0 < t.back() && t1 > t.front()) {  // overlaps: clamp what is beyond
    std::string clamped;
    if (t0 < t.front() - half_dt) {
      std::snprintf(buf, sizeof(buf), "start %g s is before the log's start %g s", t0, t.front());
      clamped = buf;
      (*window_s)[0] = t.front();
    }
    if (t1 > t.back() + half_dt) {
      std::snprintf(buf, sizeof(buf), "%send %g s is after the log's end %g s",
                    clamped.empty() ? "" : " and its ", t1, t.back());
      clamped += buf;
      (*window_s)[1] = t.back();
    }
    std::snprintf(buf, sizeof(buf), "%s %g-%g s: its %s; clamped to %g-%g s", key, t0, t1,
                  clamped.c_str(), (*window_s)[0], (*window_s)[1]);
    *note = buf;
    return "";
  }
  std::snprintf(buf, sizeof(buf), "window %g-%g s is outside the log (%g-%g s); %s takes seconds",
                t0, t1, t.front(), t.back(), key);
  std::string message = buf;
  if (time_unit != TimeUnit::kSeconds) {
    message += std::string(" (the file's time column is in ") + ToString(time_unit) +
               ", converted to seconds)";
  }
  // Which end is wrong: the start after the log's end, the end before its start, or both ends
  // beyond the log (read in another unit).
  if (t0 >= t.back()) {
    std::snprintf(buf, sizeof(buf), "; its start %g s is after the log's end", t0);
  } else if (t1 <= t.front()) {
    std::snprintf(buf, sizeof(buf), "; its end %g s is before the log's start", t1);
  } else {
    std::snprintf(buf, sizeof(buf), "; %s",
                  t0 < t.front() - half_dt && t1 > t.back() + half_dt
                      ? "both ends are beyond the log"
                  : t0 < t.front() - half_dt ? "its start is before the log's start"
                                             : "its end is after the log's end");
  }
  return message + buf + unit_hint;
}

TraceRecord Process(const CampaignConfig& config, const std::string& path,
                    const TraceProcessOptions& options, TraceRecord record) {
  const std::string& name = record.file;
  auto fail = [&](TraceStatus status, const std::string& message) {
    record.status = status;
    record.message = Renamed(message, path, name);
    return record;
  };

  // 1. Read.
  ImuData data;
  std::string why;
  if (!TryReadImuLog(path, config.imu.format, config.LogOptions(), &data, &why)) {
    return fail(TraceStatus::kError, why);
  }
  return ProcessData(config, path, data, options, std::move(record), nullptr);
}

// Marks `record` failed with `message` (the log's path in it becomes the record's name); false.
bool Fail(TraceRecord* record, TraceStatus status, const std::string& message,
          const std::string& path) {
  record->status = status;
  record->message = Renamed(message, path, record->file);
  return false;
}

// 1b. Isolated glitch samples (fit/glitch.h, `fit.glitch`) are dropped before anything looks at
// the data: the raw log when there are none, else *cleaned (filled here).
const ImuData& DropRawGlitches(const CampaignConfig& config, const ImuData& raw, ImuData* cleaned,
                               TraceRecord* record) {
  const std::vector<size_t> glitches = FindGyroGlitches(raw, config.fit.glitch);
  if (glitches.empty()) return raw;
  record->warnings.push_back(DescribeGlitches(raw, glitches));
  *cleaned = WithoutSamples(raw, glitches);
  return *cleaned;
}

// 2. Swing axis (and the pitch, from the accelerometer at rest), inside the window override
// (*override_s: the CLI's, else the config's for this log, clamped to the log) when there is one.
bool FindSwingAxis(const CampaignConfig& config, const std::string& path, const ImuData& data,
                   const TraceProcessOptions& options,
                   std::optional<std::array<double, 2>>* override_s, SwingAxis* axis,
                   TraceRecord* record) {
  const std::string& name = record->file;
  *override_s = options.window_s ? options.window_s : ConfigWindowFor(config, path);
  if (*override_s) {
    std::string clamped;
    const std::string outside = WindowOutsideLog(data, &**override_s, options.window_s.has_value(),
                                                 config.imu.format.time_unit, &clamped);
    if (!outside.empty()) return Fail(record, TraceStatus::kError, name + ": " + outside, path);
    if (!clamped.empty()) record->warnings.push_back(clamped);
  }
  std::optional<std::pair<double, double>> axis_window;
  if (*override_s) axis_window = std::make_pair((**override_s)[0], (**override_s)[1]);
  std::string why;
  if (!EstimateSwingAxis(data, SwingAxisOptionsFor(config.imu), axis_window, axis, &why)) {
    return Fail(record, TraceStatus::kError, why, path);
  }
  for (const std::string& w : axis->warnings) record->warnings.push_back(w);
  return true;
}

// 3. Free-oscillation window (the override when given), the pitch measured over it when no rest
// was seen, the measured period and the small-angle inertia (the hand calculation `inspect`
// prints).
bool FindWindowAndPitch(const CampaignConfig& config, const std::string& path, const ImuData& data,
                        const TraceProcessOptions& options,
                        const std::optional<std::array<double, 2>>& override_s, SwingAxis* axis,
                        FreeOscillationWindow* window, TraceRecord* record) {
  const std::string& name = record->file;
  WindowOptions window_options;
  window_options.min_periods = config.fit.quality.min_periods;
  *window = override_s
                ? ApplyWindowOverride(data.t_s, axis->rate_rad_per_s, (*override_s)[0],
                                      (*override_s)[1], window_options, name)
                : FindFreeOscillationWindow(data.t_s, axis->rate_rad_per_s, window_options, name);
  if (!window->IsUsable()) {
    // Time in s declared ms (or the reverse) puts every period 1000 times outside the range.
    const std::string hint = !override_s && config.imu.format.container != LogContainer::kUlog &&
                                     window->no_oscillation_found
                                 ? TimeUnitHint(data.t_s, axis->rate_rad_per_s, window_options,
                                                config.imu.format.time_unit)
                                 : "";
    return Fail(
        record,
        window->status == WindowStatus::kError ? TraceStatus::kError : TraceStatus::kRejected,
        window->message + hint, path);
  }
  // No rest seen: the accelerometer averaged over the window still gives the pitch.
  if (!axis->pitch_measured_deg && data.has_accel() && !axis->accel_ignored && !override_s) {
    SwingAxis again;
    std::string why;
    if (EstimateSwingAxis(data, SwingAxisOptionsFor(config.imu),
                          std::make_pair(window->t0_s, window->t1_s), &again, &why)) {
      axis->pitch_measured_deg = again.pitch_measured_deg;
      axis->roll_measured_deg = again.roll_measured_deg;
    }
  }
  record->pitch_measured_deg = axis->pitch_measured_deg;
  if (axis->pitch_measured_deg) record->roll_measured_deg = axis->roll_measured_deg;
  for (int k = 0; k < 3; ++k) record->swing_axis_in_imu[k] = axis->axis_in_imu[k];
  if (window->period_s > 0.0) {
    record->period_s = window->period_s;
    record->frequency_hz = 1.0 / window->period_s;
    record->small_angle_inertia_total_kg_m2 =
        InertiaFromSmallAnglePeriod(GeometryForRole(config, options.role), window->period_s);
  }
  return true;
}

// The amplitude band of the config (fit.min/max_amplitude_deg, fit.quality.min_periods).
AmplitudeBandOptions AmplitudeBandOptionsFor(const CampaignConfig& config) {
  AmplitudeBandOptions band_options;
  band_options.max_amplitude_deg = config.fit.max_amplitude_deg.value_or(kDefaultMaxAmplitudeDeg);
  band_options.min_amplitude_deg = config.fit.min_amplitude_deg.value_or(0.0);
  band_options.min_periods = config.fit.quality.min_periods;
  return band_options;
}

// 4. Amplitude band: the window trimmed to the config's band of swing amplitude.
bool ChooseAmplitudeBand(const CampaignConfig& config, const std::string& path, const ImuData& data,
                         const SwingAxis& axis, const FreeOscillationWindow& window,
                         AmplitudeBand* band, TraceRecord* record) {
  const AmplitudeBandOptions band_options = AmplitudeBandOptionsFor(config);
  record->amplitude_band_deg = {band_options.min_amplitude_deg, band_options.max_amplitude_deg};
  *band = TrimToAmplitudeBand(data.t_s, axis.rate_rad_per_s, window, band_options, record->file);
  record->window_s = {window.t0_s, window.t1_s};
  // A swing beyond 180 deg (deg/s read as rad/s): a hint on a rejection, a warning on a fit.
  double largest_deg = 0.0, smallest_deg = INFINITY;
  for (const AngleExtreme& e : band->extremes) {
    largest_deg = std::max(largest_deg, e.amplitude_deg);
    smallest_deg = std::min(smallest_deg, e.amplitude_deg);
  }
  const std::string impossible =
      ImpossibleAmplitude(largest_deg, smallest_deg, config.imu.format.gyro_unit);
  if (!band->IsUsable()) {
    return Fail(record,
                band->status == WindowStatus::kError ? TraceStatus::kError : TraceStatus::kRejected,
                band->message + (impossible.empty() ? "" : "; " + impossible), path);
  }
  if (!impossible.empty()) record->warnings.push_back(impossible);
  record->window_s = {band->t0_s, band->t1_s};
  return true;
}

// 5a. The fit's input: the band's samples, or their block means when the log is dense
// (fit/block_mean.h, *series says which), the secondary motion and the role's geometry.
TraceFitInput MakeFitInput(const CampaignConfig& config, const TraceProcessOptions& options,
                           const ImuData& data, const SwingAxis& axis,
                           const FreeOscillationWindow& window, const AmplitudeBand& band,
                           const std::string& name, FitSeries* series) {
  TraceFitInput input;
  *series = MakeFitSeries(
      data.t_s, axis.rate_rad_per_s, band.first_index, band.last_index, window.period_s,
      window.noise_from_rest ? window.noise_sigma_rad_per_s : 0.0, window.rest_end_s);
  input.t_s = std::move(series->t_s);
  input.rate_rad_per_s = std::move(series->rate_rad_per_s);
  input.noise_rad_per_s = series->noise_rad_per_s;
  input.secondary_motion_ratio = SecondaryMotionRatio(data, axis.axis_in_imu, band.t0_s, band.t1_s);
  input.geometry = GeometryForRole(config, options.role);
  input.label = name;
  return input;
}

// 5b. The fit, then glitches too small for the raw-series test (below half the swing) but
// isolated and far outside the fit's residual noise: the same test on the residual series
// (fit/glitch.h), whose noise is the gyro's, not the swing's. Dropped (*input loses them, a
// warning names them), and the window fitted again.
TraceFitResult FitWithResidualGlitchPass(const CampaignConfig& config,
                                         const TraceFitOptions& fit_options, TraceFitInput* input,
                                         TraceRecord* record) {
  TraceFitResult fit = FitTrace(*input, fit_options);
  if (!fit.HasFit() || fit.residual_rad_per_s.size() != input->t_s.size()) return fit;
  const std::vector<size_t> more = FindGlitches(fit.t_s, fit.residual_rad_per_s, config.fit.glitch);
  if (more.empty()) return fit;
  double largest = 0.0;
  for (size_t k : more) largest = std::max(largest, std::abs(fit.residual_rad_per_s[k]));
  char text[160];
  std::snprintf(text, sizeof(text),
                "%zu glitch sample%s ignored (isolated readings off the "
                "fit by up to %.3g rad/s) at t =",
                more.size(), more.size() == 1 ? "" : "s", largest);
  std::string warning = text;
  for (size_t i = 0; i < more.size() && i < 5; ++i) {
    std::snprintf(text, sizeof(text), "%s %.6g", i ? "," : "", input->t_s[more[i]]);
    warning += text;
  }
  record->warnings.push_back(warning + (more.size() > 5 ? ", ... s" : " s") +
                             "; nothing to do unless they were real motion (fit.glitch sets the "
                             "thresholds)");
  std::vector<double> t, rate;
  size_t next = 0;
  for (size_t k = 0; k < input->t_s.size(); ++k) {
    if (next < more.size() && more[next] == k) {
      ++next;
      continue;
    }
    t.push_back(input->t_s[k]);
    rate.push_back(input->rate_rad_per_s[k]);
  }
  input->t_s = std::move(t);
  input->rate_rad_per_s = std::move(rate);
  return FitTrace(*input, fit_options);
}

// The fit's numbers into the record, with its uncertainty budget (plus the calibration's term
// when the geometry is calibrated), its flags, warnings and the record's message.
void FillRecordFromFit(const CampaignConfig& config, const std::string& path,
                       const TraceFitResult& fit, const TraceFitInput& input,
                       const FitSeries& series, TraceRecord* record_out) {
  TraceRecord& record = *record_out;
  const std::string& name = record.file;
  const bool calibrated = config.geometry_calibration.applied;
  record.status = fit.status == TraceFitStatus::kOk         ? TraceStatus::kOk
                  : fit.status == TraceFitStatus::kRejected ? TraceStatus::kRejected
                                                            : TraceStatus::kError;
  record.message = fit.message.empty() ? "" : Renamed(fit.message, path, name);
  record.flags = fit.flags;
  if (series.block_means()) {
    char flag[64];
    std::snprintf(flag, sizeof(flag), "block_means_of_%.0f_samples", series.samples_per_point);
    record.flags.push_back(flag);
  }
  // The most important first: values no real rig gives (units), the fit's warnings (in their
  // own order), then what reading the log and finding the window noted.
  const std::vector<std::string> data_warnings = std::move(record.warnings);
  record.warnings.clear();
  if (fit.HasFit()) {  // an amplitude or radius of gyration no real rig gives: units (issue 16)
    for (const std::string& w : FitPlausibilityWarnings(
             fit.params.inertia_kg_m2, input.geometry.mass_kg, input.geometry.filar_separation_m,
             input.geometry.filar_length_m, fit.amplitude_start_deg, config.imu.format.gyro_unit)) {
      record.warnings.push_back(w);
    }
  }
  for (const std::string& w : fit.warnings) record.warnings.push_back(w);
  for (const std::string& w : data_warnings) record.warnings.push_back(w);
  record.model = ToString(fit.model);
  record.iterations = fit.iterations;
  record.secondary_motion_ratio =
      input.secondary_motion_ratio >= 0.0 ? input.secondary_motion_ratio : NAN;
  if (fit.HasFit()) {
    record.inertia_total_kg_m2 = fit.params.inertia_kg_m2;
    record.inertia_total_std_kg_m2 =
        std::hypot(fit.inertia_stat_std_kg_m2, fit.model_inadequacy_std_kg_m2);
    record.inertia_stat_std_kg_m2 = fit.inertia_stat_std_kg_m2;
    record.inertia_iid_std_kg_m2 = fit.inertia_iid_std_kg_m2;
    record.model_inadequacy_std_kg_m2 = fit.model_inadequacy_std_kg_m2;
    record.hac_bandwidth = fit.hac_bandwidth;
    record.inertia_window_kg_m2 = fit.inertia_window_kg_m2;
    record.inertia_source = fit.inertia_source;
    record.sweep = fit.sweep;
    record.rms_over_noise = fit.rms_over_noise > 0.0 ? fit.rms_over_noise : NAN;
    record.residual_autocorr_lag1 = fit.residual_autocorr_lag1;
    record.residual_ar1_phi = fit.residual_ar1_phi;
    record.prewhitened_autocorr_max = fit.prewhitened_autocorr_max;
    record.drag_coeff_kg_m2 = fit.params.drag_coeff_kg_m2;
    record.viscous_coeff_kg_m2_per_s = fit.params.viscous_coeff_kg_m2_per_s;
    record.amplitude_deg = {fit.amplitude_start_deg, fit.amplitude_end_deg};
    record.bias_rad_per_s = fit.bias_rad_per_s;
    record.residual_rms_rad_per_s = fit.residual_rms_rad_per_s;
    record.noise_rms_rad_per_s = fit.noise_rad_per_s;
    for (const UncertaintyContribution& c : fit.budget) {
      record.budget.push_back({c.name, c.contribution_kg_m2});
    }
    record.budget_total_std_kg_m2 = fit.inertia_budget_std_kg_m2;
    if (calibrated) {  // k's std moves I (and every other moment) by the same fraction
      const double term = config.geometry_calibration.factor_rel_std * fit.params.inertia_kg_m2;
      record.budget.push_back({"calibration", term});
      record.budget_total_std_kg_m2 = std::hypot(record.budget_total_std_kg_m2, term);
      record.calibrated = true;
      record.calibration_relative_std = config.geometry_calibration.factor_rel_std;
    }
    record.budget_assumed = config.uncertainties.Assumed() && !calibrated;
    UpdateTotalUncertainty(&record);
    // Every record says what the assumption adds on this rig (the console says it once).
    if (record.budget_assumed) {
      record.flags.push_back(kAssumedInputsFlag);
      record.warnings.push_back(AssumedInputsWarning(record));
    }
  }
  // An ok record's message names its first warning by its summary and how many more there are
  // (every one is in `warnings`; the console prints each on its own line).
  if (record.status == TraceStatus::kOk && !record.warnings.empty()) {
    const size_t more = record.warnings.size() - 1;
    record.message = name + ": " + WarningSummary(record.warnings.front()) +
                     (more > 0 ? " (and " + std::to_string(more) + " more warning" +
                                     (more == 1 ? "" : "s") + " in the record's warnings)"
                               : "");
  }
}

// A figure that could not be written: flagged and warned; one that was: listed in the record.
void NoteFigure(bool drawn, const std::string& figure_path, const std::string& why,
                TraceRecord* record) {
  if (!drawn) {
    record->flags.push_back("figure_failed");
    record->warnings.push_back("figure " + figure_path + " could not be written: " + why);
  } else {
    record->figures.push_back(figure_path);
  }
}

// 6. Fit-and-residual figure (only of a fit that ran), 7. I against amplitude (only when the
// sweep was evaluated: no figure, and no link, without).
void WriteTraceFigures(const CampaignConfig& config, const TraceProcessOptions& options,
                       const TraceFitResult& fit, TraceRecord* record) {
  const std::string& name = record->file;
  std::string why;
  for (const std::string& figure_path : options.figure_paths) {
    if (fit.t_s.empty()) break;
    bool drawn = false;
    if (options.compact_figure) {
      drawn = WriteReportTraceFigure(fit, name, config.units, figure_path, options.figure_width_px,
                                     options.figure_height_px, &why,
                                     record->inertia_total_std_total_kg_m2, "total");
    } else {
      TracePlotOptions figure_options;
      figure_options.title = name;
      figure_options.width_px = options.figure_width_px;
      figure_options.height_px = options.figure_height_px;
      figure_options.unit_scale = InertiaToDisplay(1.0, config.units);
      figure_options.unit_label = InertiaUnitPlotLabel(config.units);
      figure_options.inertia_std_kg_m2 = record->inertia_total_std_total_kg_m2;  // as printed
      figure_options.std_label = "total";
      drawn = WriteTraceFitFigure(fit, figure_path, figure_options, &why);
    }
    NoteFigure(drawn, figure_path, why, record);
  }
  if (!fit.HasFit() || !fit.sweep.evaluated) return;
  SweepPlotOptions sweep_options;
  sweep_options.title = name;
  sweep_options.unit_scale = InertiaToDisplay(1.0, config.units);
  sweep_options.unit_label = InertiaUnitPlotLabel(config.units);
  sweep_options.figure.width_px = options.figure_width_px;
  sweep_options.figure.height_px = options.figure_height_px;
  sweep_options.compact = options.compact_figure;  // the report explains it in the caption
  for (const std::string& figure_path : options.sweep_figure_paths) {
    const bool drawn = WriteAmplitudeSweepFigure(fit.sweep, record->inertia_total_kg_m2,
                                                 record->inertia_total_std_kg_m2, figure_path,
                                                 sweep_options, &why);
    NoteFigure(drawn, figure_path, why, record);
  }
}

// One log in memory -> its record: DropRawGlitches -> FindSwingAxis -> FindWindowAndPitch ->
// ChooseAmplitudeBand -> MakeFitInput -> FitWithResidualGlitchPass (TraceFitOptionsFor) ->
// FillRecordFromFit -> WriteTraceFigures. A failing step leaves the record failed.
TraceRecord ProcessData(const CampaignConfig& config, const std::string& path, const ImuData& raw,
                        const TraceProcessOptions& options, TraceRecord record,
                        TraceFitResult* fit_out) {
  record.warnings = raw.warnings;
  ImuData cleaned;
  const ImuData& data = DropRawGlitches(config, raw, &cleaned, &record);
  std::optional<std::array<double, 2>> override_s;
  SwingAxis axis;
  if (!FindSwingAxis(config, path, data, options, &override_s, &axis, &record)) return record;
  FreeOscillationWindow window;
  if (!FindWindowAndPitch(config, path, data, options, override_s, &axis, &window, &record)) {
    return record;
  }
  AmplitudeBand band;
  if (!ChooseAmplitudeBand(config, path, data, axis, window, &band, &record)) return record;

  // 5. Fit. The residual series is kept for the second glitch pass (and dropped after it when
  // neither a figure nor the caller wants it).
  FitSeries series;
  TraceFitInput input =
      MakeFitInput(config, options, data, axis, window, band, record.file, &series);
  TraceFitOptions fit_options = TraceFitOptionsFor(config, options.role);
  fit_options.keep_series = true;
  // A longer window exists when the amplitude band ended the fit before the free swing's end, or
  // a given window ends a period or more before the log does (the damping advice's condition).
  const double period_s = std::max(0.0, window.period_s);
  fit_options.longer_window_available =
      band.t1_s < window.t1_s - period_s ||
      (window.overridden && !data.t_s.empty() && window.t1_s < data.t_s.back() - period_s);
  fit_options.interrupt = options.interrupt;
  TraceFitResult fit = FitWithResidualGlitchPass(config, fit_options, &input, &record);
  if (options.figure_paths.empty() && fit_out == nullptr) {
    fit.t_s.clear();
    fit.measured_rate_rad_per_s.clear();
    fit.fitted_rate_rad_per_s.clear();
    fit.residual_rad_per_s.clear();
  }
  FillRecordFromFit(config, path, fit, input, series, &record);
  if (fit_out) *fit_out = fit;
  WriteTraceFigures(config, options, fit, &record);
  return record;
}

// Runs process(record) on a fresh record of `path`, timed; an exception becomes an error record.
template <typename Process>
TraceRecord Guarded(const CampaignConfig& config, const std::string& path,
                    const TraceProcessOptions& options, const Process& process) {
  const auto start = std::chrono::steady_clock::now();
  TraceRecord record;
  record.file = options.display_name.empty() ? path : options.display_name;
  record.role = options.role;
  record.model = ToString(config.fit.model);
  try {
    record = process(record);
  } catch (const std::bad_alloc&) {  // never a bare "std::bad_alloc"
    record.status = TraceStatus::kError;
    record.message = record.file +
                     ": out of memory while reading or fitting this log (is it far "
                     "larger than a pendulum log?)";
  } catch (const std::exception& e) {
    record.status = TraceStatus::kError;
    record.message = Renamed(e.what(), path, record.file);
  }
  record.fit_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return record;
}

}  // namespace

TraceRecord ProcessTrace(const CampaignConfig& config, const std::string& path,
                         const TraceProcessOptions& options) {
  return Guarded(config, path, options,
                 [&](const TraceRecord& record) { return Process(config, path, options, record); });
}

TraceRecord ProcessTraceData(const CampaignConfig& config, const ImuData& data,
                             const std::string& path, const TraceProcessOptions& options,
                             TraceFitResult* fit) {
  return Guarded(config, path, options, [&](const TraceRecord& record) {
    return ProcessData(config, path, data, options, record, fit);
  });
}

TraceFitOptions TraceFitOptionsFor(const CampaignConfig& config, TraceRole role) {
  TraceFitOptions fit_options;
  fit_options.model = config.fit.model;
  fit_options.integrator = fit_options.integrator.WithMethod(config.fit.integrator);
  // The config holds the fit's own quality and sweep options (fit/trace_options.h).
  static_cast<TraceQualityOptions&>(fit_options) = config.fit.quality;
  static_cast<AmplitudeSweepOptions&>(fit_options) = config.fit.sweep;
  const AmplitudeBandOptions band_options = AmplitudeBandOptionsFor(config);
  fit_options.max_amplitude_deg = band_options.max_amplitude_deg;
  fit_options.min_amplitude_deg =
      std::min(fit_options.min_amplitude_deg, band_options.min_amplitude_deg);
  // A calibrated geometry absorbs L, D and g (docs/physics.md §2.6): their terms are replaced by
  // the calibration's own (added to the record's budget). Without rig.uncertainties the budget
  // counts the assumed +-1 mm on L and D (pipeline/records/total_uncertainty.h), unless the rig
  // is calibrated.
  const bool calibrated = config.geometry_calibration.applied;
  const RigUncertainties uncertainties = config.uncertainties.InEffect();
  fit_options.filar_length_std_m = calibrated ? 0.0 : uncertainties.filar_length_std_m;
  fit_options.filar_separation_std_m = calibrated ? 0.0 : uncertainties.filar_separation_std_m;
  fit_options.mass_std_kg = role == TraceRole::kAircraft
                                ? std::hypot(uncertainties.mass_std_kg, config.aircraft_mass_std_kg)
                                : uncertainties.mass_std_kg;
  fit_options.gravity_std_mps2 = calibrated ? 0.0 : uncertainties.gravity_std_mps2;
  fit_options.gyro_scale_std = config.imu.gyro_scale_std;
  return fit_options;
}

SwingAxisOptions SwingAxisOptionsFor(const ImuConfig& imu) {
  SwingAxisOptions options;
  options.mode = imu.swing_axis_auto ? SwingAxisMode::kAuto : SwingAxisMode::kFixed;
  options.fixed_axis_in_imu = imu.swing_axis_in_imu;
  options.imu_to_body = imu.imu_to_body;
  options.accel_unit_si = ToSi(imu.format.accel_unit);  // the advice names the other unit
  return options;
}

}  // namespace bifilar
