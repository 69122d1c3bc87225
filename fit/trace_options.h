// The trace fit's quality thresholds and amplitude sweep: each an options struct of its own,
// declared once here, with one table (base/option_table.h) that gives each field its config key
// (`fit.quality.<key>`, `fit.amplitude_sweep.<key>`), its bound and its meaning. The trace fit
// (fit/trace_fit.h TraceFitOptions) is made of them; the campaign config
// (pipeline/config/config.h FitConfig) holds them as they are; the config reader, the messages
// and the cache key come from the tables. Defaults are the members' initialisers.
#pragma once

#include <string>

#include "base/option_table.h"

namespace bifilar {

// Limits of the count-like quality keys (also the Python module's argument ranges).
constexpr int kMaxWhitenessLags = 1000;   // whiteness_lags in [1, 1000]
constexpr double kMaxMinPeriods = 10000;  // min_periods in [2, 10000]

// `fit.quality`. Three outcomes (docs/method.md, "Quality"): `rejected` only for a fit that
// should not be used (no oscillation, a failed fit, a fit that does not follow the data, heavy
// secondary motion, i.e. the wrong axis); `ok` with warnings for the statistics below, whose
// defaults were set on real logs (a Crazyflie rig, 30 Hz) and on simulations with coloured
// noise (README, "Quality checks").
struct TraceQualityOptions {
  // Warn when the residual RMS over the noise estimate exceeds this (dimensionless); finite,
  // > 1. Noise: TraceFitInput::noise (from the rest segment) when given, else the window's own
  // sample-to-sample scatter (which underestimates coloured noise). Default 3.
  double max_rms_over_noise = 3.0;
  // Warn when the largest |autocorrelation| at lags 1..whiteness_lags of the residuals,
  // prewhitened with their own AR(1) coefficient, exceeds this (dimensionless), in (0, 1).
  // Coloured but structureless noise prewhitens to ~1/sqrt(N); a periodic misfit or sway does
  // not. Default 0.35.
  double max_residual_autocorr = 0.35;
  int whiteness_lags = 10;  // lags of the whiteness statistics (count); [1, 1000]; default 10
  // Energy on the other gyro axes relative to the swing axis (dimensionless, computed upstream
  // and passed in TraceFitInput::secondary_motion_ratio); finite, >= 0. Above the first: a
  // warning (default 0.1); above the second: rejected (heavy secondary motion, or the wrong
  // swing axis); >= the first, default 0.5 (a config that raises only the first above 0.5
  // raises the second with it: pipeline/config/config_load.cc).
  double max_secondary_motion_ratio = 0.1;
  double reject_secondary_motion_ratio = 0.5;
  // Rejected when the residual RMS exceeds this fraction of the swing rate's RMS: the fit does
  // not follow the data (dimensionless), in (0, 1]. Default 0.3.
  double reject_residual_fraction = 0.3;
  // The window must hold at least this many periods of oscillation (count); [2, 10000]; default 2.
  double min_periods = 2.0;

  // The fields: config key, member, bound. Check names the members; the config, the keys.
  static const OptionFields<TraceQualityOptions>& Fields();
  // Every bound: the table's, then reject_secondary_motion_ratio >= max_secondary_motion_ratio.
  bool Check(CheckFailure* failure) const;
  bool Check(std::string* why) const;  // *why = "<field> = <value>; must be <allowed>"
};

// `fit.amplitude_sweep` (docs/method.md, "Amplitude sweep"): after the window fit, I is refitted
// in successive bands of the window, each holding the same number of cycles (at least
// sweep_min_cycles_per_band, at most sweep_max_bands bands), with K_D and C held at the window
// fit. A trend of I with amplitude beyond its statistical error (|z| > sweep_trend_z for the
// coefficient of I_0 (1 + c A^p), p in {1, 2} chosen by the data) means the rig departs from the
// model: a warning, the result taken from the lowest-amplitude band with its std scaled by the
// bands' scatter about the trend, and a model-inadequacy term (the trend's change from that
// band's amplitude to zero) added to its uncertainty. The members keep their `sweep_` names
// because TraceFitOptions is made of this struct and the sweep code reads them there.
struct AmplitudeSweepOptions {
  bool amplitude_sweep = true;             // key `enabled`; default true
  double sweep_min_cycles_per_band = 2.0;  // key `min_cycles_per_band` (cycles); [1, 1000]
  int sweep_max_bands = 6;                 // key `max_bands` (count); [2, 20]; default 6
  double sweep_trend_z = 4.0;              // key `trend_z` (dimensionless); (0, 1000); default 4

  static const OptionFields<AmplitudeSweepOptions>& Fields();
  bool Check(CheckFailure* failure) const;  // the table's bounds
  bool Check(std::string* why) const;
};

}  // namespace bifilar
