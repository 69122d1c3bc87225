// The tables of the trace fit's quality and sweep options (fit/trace_options.h) and their Checks.
#include "fit/trace_options.h"

namespace bifilar {

const OptionFields<TraceQualityOptions>& TraceQualityOptions::Fields() {
  using O = TraceQualityOptions;
  static const OptionFields<O> fields = {
      {"max_rms_over_noise", "max_rms_over_noise", &O::max_rms_over_noise, RangeFiniteGt(1),
       "warn above this residual RMS / noise"},
      {"max_residual_autocorr", "max_residual_autocorr", &O::max_residual_autocorr,
       RangeIn(0, 1, Ends::kOpen), "warn above this prewhitened residual |autocorrelation|"},
      {"whiteness_lags", "whiteness_lags", &O::whiteness_lags,
       RangeIn(1, kMaxWhitenessLags, Ends::kClosed), "lags of the whiteness statistics"},
      {"max_secondary_motion_ratio", "max_secondary_motion_ratio", &O::max_secondary_motion_ratio,
       RangeFiniteGe(0), "warn above this other-axes / swing-axis energy"},
      // Its bound is max_secondary_motion_ratio (Check).
      {"reject_secondary_motion_ratio", "reject_secondary_motion_ratio",
       &O::reject_secondary_motion_ratio, kAnyValue, "reject above this secondary motion"},
      {"reject_residual_fraction", "reject_residual_fraction", &O::reject_residual_fraction,
       RangeIn(0, 1, Ends::kOpenClosed), "reject above this residual RMS / swing rate RMS"},
      {"min_periods", "min_periods", &O::min_periods, RangeIn(2, kMaxMinPeriods, Ends::kClosed),
       "periods the window must hold"},
  };
  return fields;
}

bool TraceQualityOptions::Check(CheckFailure* failure) const {
  return CheckOptionFields(*this, Fields(), failure) &&
         CheckGe("reject_secondary_motion_ratio", reject_secondary_motion_ratio,
                 "max_secondary_motion_ratio", max_secondary_motion_ratio, failure);
}

bool TraceQualityOptions::Check(std::string* why) const {
  CheckFailure f;
  return Check(&f) || FailWith(f, why);
}

const OptionFields<AmplitudeSweepOptions>& AmplitudeSweepOptions::Fields() {
  using O = AmplitudeSweepOptions;
  static const OptionFields<O> fields = {
      {"enabled", "amplitude_sweep", &O::amplitude_sweep, "refit I in amplitude bands"},
      {"min_cycles_per_band", "sweep_min_cycles_per_band", &O::sweep_min_cycles_per_band,
       RangeIn(1, 1000, Ends::kClosed), "cycles a band holds at least"},
      {"max_bands", "sweep_max_bands", &O::sweep_max_bands, RangeIn(2, 20, Ends::kClosed),
       "bands at most"},
      {"trend_z", "sweep_trend_z", &O::sweep_trend_z, RangeIn(0, 1000, Ends::kOpen),
       "|z| of the amplitude trend that counts as a trend"},
  };
  return fields;
}

bool AmplitudeSweepOptions::Check(CheckFailure* failure) const {
  return CheckOptionFields(*this, Fields(), failure);
}

bool AmplitudeSweepOptions::Check(std::string* why) const {
  CheckFailure f;
  return Check(&f) || FailWith(f, why);
}

}  // namespace bifilar
