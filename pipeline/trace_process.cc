#include "pipeline/trace_process.h"

#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>

#include "fit/swing_axis.h"
#include "fit/trace_fit.h"
#include "fit/window.h"
#include "pipeline/imu_log.h"
#include "pipeline/user_error.h"

#if __has_include("fit/trace_plot.h")
#include "fit/trace_plot.h"
#define BIFILAR_HAVE_TRACE_PLOT 1
#endif

namespace bifilar {

const char* ToString(TraceStatus status) {
  switch (status) {
    case TraceStatus::kOk: return "ok";
    case TraceStatus::kRejected: return "rejected";
    case TraceStatus::kError: return "error";
  }
  return "error";
}

bool ParseTraceStatus(const std::string& name, TraceStatus* status) {
  if (name == "ok") *status = TraceStatus::kOk;
  else if (name == "rejected") *status = TraceStatus::kRejected;
  else if (name == "error") *status = TraceStatus::kError;
  else return false;
  return true;
}

const char* ToString(TraceRole role) { return role == TraceRole::kTare ? "tare" : "aircraft"; }

std::optional<std::array<double, 2>> ConfigWindowFor(const CampaignConfig& config,
                                                     const std::string& path) {
  const std::string target = std::filesystem::path(path).lexically_normal().string();
  for (const auto& [key, window] : config.fit.windows_s) {
    if ((!config.runs.root.empty() && ResolvePath(config.runs.root, key) == target) ||
        ResolvePath(config.folder, key) == target) {
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
  if (!TryReadImuLog(path, config.imu.format, ImuLogOptions(), &data, &why)) {
    return fail(TraceStatus::kError, why);
  }

  // 2. Swing axis (and the pitch, from the accelerometer at rest).
  const std::optional<std::array<double, 2>> override_s =
      options.window_s ? options.window_s : ConfigWindowFor(config, path);
  SwingAxisOptions axis_options;
  axis_options.mode = config.imu.swing_axis_auto ? SwingAxisMode::kAuto : SwingAxisMode::kFixed;
  axis_options.fixed_axis_in_imu = config.imu.swing_axis_in_imu;
  axis_options.imu_to_body = config.imu.imu_to_body;
  std::optional<std::pair<double, double>> axis_window;
  if (override_s) axis_window = std::make_pair((*override_s)[0], (*override_s)[1]);
  SwingAxis axis;
  if (!EstimateSwingAxis(data, axis_options, axis_window, &axis, &why)) {
    return fail(TraceStatus::kError, why);
  }

  // 3. Free-oscillation window.
  WindowOptions window_options;
  window_options.min_periods = config.fit.quality.min_periods;
  const FreeOscillationWindow window =
      override_s ? ApplyWindowOverride(data.t_s, axis.rate_rad_per_s, (*override_s)[0],
                                       (*override_s)[1], window_options, name)
                 : FindFreeOscillationWindow(data.t_s, axis.rate_rad_per_s, window_options, name);
  if (!window.IsUsable()) {
    return fail(window.status == WindowStatus::kError ? TraceStatus::kError : TraceStatus::kRejected,
                window.message);
  }
  // No rest seen: the accelerometer averaged over the window still gives the pitch.
  if (!axis.pitch_measured_deg && data.has_accel() && !axis_window) {
    SwingAxis again;
    if (EstimateSwingAxis(data, axis_options, std::make_pair(window.t0_s, window.t1_s), &again,
                          &why)) {
      axis.pitch_measured_deg = again.pitch_measured_deg;
    }
  }
  record.pitch_measured_deg = axis.pitch_measured_deg;

  // 4. Amplitude band.
  AmplitudeBandOptions band_options;
  band_options.max_amplitude_deg = config.fit.max_amplitude_deg.value_or(kDefaultMaxAmplitudeDeg);
  band_options.min_amplitude_deg = config.fit.min_amplitude_deg.value_or(0.0);
  band_options.min_periods = config.fit.quality.min_periods;
  const AmplitudeBand band =
      TrimToAmplitudeBand(data.t_s, axis.rate_rad_per_s, window, band_options, name);
  record.window_s = {window.t0_s, window.t1_s};
  if (!band.IsUsable()) {
    return fail(band.status == WindowStatus::kError ? TraceStatus::kError : TraceStatus::kRejected,
                band.message);
  }
  record.window_s = {band.t0_s, band.t1_s};

  // 5. Fit.
  TraceFitInput input;
  input.t_s.assign(data.t_s.begin() + band.first_index, data.t_s.begin() + band.last_index + 1);
  input.rate_rad_per_s.assign(axis.rate_rad_per_s.begin() + band.first_index,
                              axis.rate_rad_per_s.begin() + band.last_index + 1);
  input.noise_rad_per_s = window.noise_from_rest ? window.noise_sigma_rad_per_s : 0.0;
  input.secondary_motion_ratio =
      SecondaryMotionRatio(data, axis.axis_in_imu, band.t0_s, band.t1_s);
  input.geometry = options.role == TraceRole::kTare ? config.TareGeometry()
                                                    : config.AircraftGeometry();
  input.label = name;
  TraceFitOptions fit_options;
  fit_options.model = config.fit.model;
  const QualityThresholds& q = config.fit.quality;
  fit_options.max_rms_over_noise = q.max_rms_over_noise;
  fit_options.max_residual_autocorr = q.max_residual_autocorr;
  fit_options.whiteness_lags = q.whiteness_lags;
  fit_options.max_secondary_motion_ratio = q.max_secondary_motion_ratio;
  fit_options.min_periods = q.min_periods;
  fit_options.max_amplitude_deg = band_options.max_amplitude_deg;
  fit_options.min_amplitude_deg = std::min(fit_options.min_amplitude_deg, band_options.min_amplitude_deg);
  fit_options.filar_length_std_m = config.uncertainties.filar_length_std_m;
  fit_options.filar_separation_std_m = config.uncertainties.filar_separation_std_m;
  fit_options.mass_std_kg = options.role == TraceRole::kTare
                                ? config.uncertainties.mass_std_kg
                                : std::hypot(config.uncertainties.mass_std_kg,
                                             config.aircraft_mass_std_kg);
  fit_options.gravity_std_mps2 = config.uncertainties.gravity_std_mps2;
  fit_options.keep_series = !options.figure_paths.empty();
  const TraceFitResult fit = FitTrace(input, fit_options);

  record.status = fit.status == TraceFitStatus::kOk         ? TraceStatus::kOk
                  : fit.status == TraceFitStatus::kRejected ? TraceStatus::kRejected
                                                            : TraceStatus::kError;
  record.message = fit.message.empty() ? "" : Renamed(fit.message, path, name);
  record.flags = fit.flags;
  record.model = ToString(fit.model);
  record.iterations = fit.iterations;
  if (fit.status != TraceFitStatus::kError) {
    record.inertia_total_kg_m2 = fit.params.inertia_kg_m2;
    record.inertia_total_std_kg_m2 = fit.inertia_stat_std_kg_m2;
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
  }
  if (record.status == TraceStatus::kOk && !data.warnings.empty()) {
    record.message = name + ": " + data.warnings.front() +
                     (data.warnings.size() > 1 ? " (+" + std::to_string(data.warnings.size() - 1) +
                                                     " more warnings)"
                                               : "");
  }

  // 6. Figure (only of a fit that ran).
#ifdef BIFILAR_HAVE_TRACE_PLOT
  for (const std::string& figure_path : options.figure_paths) {
    if (fit.t_s.empty()) break;
    TracePlotOptions figure_options;
    figure_options.title = name;
    if (!WriteTraceFitFigure(fit, figure_path, figure_options, &why)) {
      record.flags.push_back("figure_failed");
    }
  }
#endif
  return record;
}

}  // namespace

TraceRecord ProcessTrace(const CampaignConfig& config, const std::string& path,
                         const TraceProcessOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  TraceRecord record;
  record.file = options.display_name.empty() ? path : options.display_name;
  record.role = options.role;
  record.model = ToString(config.fit.model);
  try {
    record = Process(config, path, options, record);
  } catch (const std::exception& e) {
    record.status = TraceStatus::kError;
    record.message = Renamed(e.what(), path, record.file);
  }
  record.fit_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return record;
}

}  // namespace bifilar
