// One IMU log file -> one trace record: read the CSV, find the swing axis and the measured pitch,
// the free-oscillation window and the amplitude band, fit the pendulum model, draw the
// fit-and-residual figure and I against amplitude (pipeline/figures/sweep_plot.h). Used by `bifilar
// process` (for every log of a campaign, from worker threads) and by `bifilar fit`. Any failure of
// one file becomes status `error` with a message naming the file; nothing throws out of
// ProcessTrace. Conventions: docs/physics.md §2 (psi, I total = rig + aircraft), §3 (pitch).
#pragma once

#include <array>
#include <atomic>
#include <optional>
#include <string>
#include <vector>

#include "fit/swing_axis.h"
#include "fit/trace_fit.h"
#include "pendulum/imu_data.h"
#include "pipeline/config/config.h"
#include "pipeline/records/trace_record.h"

namespace bifilar {

// Default upper bound of the amplitude band (deg) when the config sets none: the whole free
// oscillation is fitted, and the amplitude sweep (docs/method.md) decides whether the rig departs
// from the model at large amplitude; fit.max_amplitude_deg stays as an override.
constexpr double kDefaultMaxAmplitudeDeg = 90.0;

struct TraceProcessOptions {
  // Chooses the suspended mass: aircraft + rig, rig alone, or rig + reference.
  TraceRole role = TraceRole::kAircraft;
  std::string display_name;  // `file` of the record; default: the path
  // Window override [t0, t1] (s); takes precedence over the config's per-file windows.
  std::optional<std::array<double, 2>> window_s;
  // Write the fit-and-residual figure to each of these (.svg or .png); empty = no figure.
  std::vector<std::string> figure_paths;
  // true: the report's compact line-only thumbnail (a few ms) and a sweep figure without legend;
  // false: pipeline/figures/trace_plot.h's full figure (a symbol per sample) and the sweep with its
  // legend.
  bool compact_figure = false;
  // Write the amplitude-sweep figure (pipeline/figures/sweep_plot.h: I against amplitude) to each
  // of these (.svg or .png) when the sweep was evaluated; a trace without a sweep gets none.
  std::vector<std::string> sweep_figure_paths;
  int figure_width_px = 1100, figure_height_px = 700;  // page size of both figures (px)
  // Set (by Ctrl-C) to stop the fit between solver iterations (TraceFitOptions::interrupt): the
  // record is then an error saying "interrupted". Not owned; nullptr: never.
  const std::atomic<bool>* interrupt = nullptr;
};

// Processes one log. Never throws: every failure is a record with status error naming the file.
TraceRecord ProcessTrace(const CampaignConfig& config, const std::string& path,
                         const TraceProcessOptions& options);

// The same processing on a log already in memory (the Python module's fit_trace): `path` names
// it in messages and picks its fit.windows entry. When `fit` is not null it receives the trace
// fit with its fitted and residual series (left default when no fit ran). Never throws.
TraceRecord ProcessTraceData(const CampaignConfig& config, const ImuData& data,
                             const std::string& path, const TraceProcessOptions& options,
                             TraceFitResult* fit = nullptr);

// The window override of the config for `path` (as given: relative to the working folder or
// absolute), if any: keys of fit.windows are resolved relative to runs.root and to the config
// folder, and matched as canonical paths (CanonicalLogPath), so `bifilar fit` given
// `./pitch_0/trial_1.csv` or an absolute path finds the entry `bifilar process` finds.
std::optional<std::array<double, 2>> ConfigWindowFor(const CampaignConfig& config,
                                                     const std::string& path);

// `path` absolute, with symbolic links, "." and ".." resolved as far as it exists
// (std::filesystem::weakly_canonical); the lexically normal absolute path when that fails.
std::string CanonicalLogPath(const std::string& path);

// The swing-axis settings of the config's `imu` section (auto or fixed axis, mounting).
SwingAxisOptions SwingAxisOptionsFor(const ImuConfig& imu);

// The trace fit's settings of the config for a trace of `role`: model, integrator, quality
// thresholds, amplitude sweep and band, and the input uncertainties of the budget (none for L, D
// and g when the geometry is calibrated; the aircraft's mass std added for an aircraft trace).
// keep_series and interrupt are left at their defaults.
TraceFitOptions TraceFitOptionsFor(const CampaignConfig& config, TraceRole role);

}  // namespace bifilar
