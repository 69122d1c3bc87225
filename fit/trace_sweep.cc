// Step 8 of FitTrace (fit/trace_fit_steps.h): the amplitude sweep (I refitted in equal-cycle
// bands of the window, and the trend of I against A^p, p chosen by the data) and its rule: a trend
// gives the lowest-amplitude band's I, its std scaled by the bands' scatter about the trend, with
// a model-inadequacy term; without one, bands that scatter beyond their stds scale the
// statistical std by the Birge ratio about a constant (docs/method.md §4).
#include <algorithm>
#include <cmath>
#include <vector>

#include "fit/amplitude_trend.h"
#include "fit/distributions.h"
#include "fit/trace_fit_steps.h"

namespace bifilar {
namespace trace {
namespace {

// One band [first, last) of the window: I refitted from the window fit's state at the band's
// first sample, K_D and C held. ok false when the fit or its std fails.
AmplitudeSweepBand FitBand(const TraceFitInput& input, const TraceFitOptions& options,
                           const double* p, double scale, const Trajectory& traj, double period_s,
                           size_t first, size_t last, SolveBudget* budget) {
  const std::vector<int> free = {kTraceInertia, kTraceAngle0, kTraceRate0, kTraceBias};
  const bool fixed[2] = {true, true};
  AmplitudeSweepBand band;
  band.num_samples = static_cast<int>(last - first);
  const std::vector<double> t(input.t_s.begin() + first, input.t_s.begin() + last);
  const std::vector<double> rate(input.rate_rad_per_s.begin() + first,
                                 input.rate_rad_per_s.begin() + last);
  band.t0_s = t.front();
  band.t1_s = t.back();
  band.cycles = (band.t1_s - band.t0_s) / period_s;
  TraceRateCost cost(&t, &rate, options.model, input.geometry, options.integrator, scale);
  double q[kNumTraceParams];
  std::copy(p, p + kNumTraceParams, q);
  q[kTraceAngle0] = traj.angle_rad[first];
  q[kTraceRate0] = traj.rate_rad_per_s[first];
  const SolveOutcome lm = SolveLm(cost, options.max_iterations, fixed, false, q, budget);
  if (!lm.ok) return band;
  const FreeParamStd stat = StatisticalStd(cost, q, free);
  {
    std::vector<double> rr(t.size());
    const double residual_rms = std::sqrt(2.0 * Cost(cost, q, &rr) / static_cast<double>(t.size()));
    const double signal_rms = RmsAboutMean(cost.last_trajectory().rate_rad_per_s);
    band.residual_fraction = signal_rms > 0.0 ? residual_rms / signal_rms : HUGE_VAL;
  }
  const auto [a0, a1] = AmplitudeAtEnds(t, cost.last_trajectory(), period_s);
  band.amplitude_start_deg = a0;
  band.amplitude_end_deg = a1;
  band.amplitude_mean_deg = 0.5 * (a0 + a1);
  band.inertia_kg_m2 = scale * q[kTraceInertia];
  band.angle0_rad = q[kTraceAngle0];
  band.rate0_rad_per_s = q[kTraceRate0];
  band.bias_rad_per_s = q[kTraceBias];
  band.inertia_std_kg_m2 = stat.ok ? scale * stat.hac[0] : 0.0;
  band.ok = lm.ok && stat.ok && band.inertia_std_kg_m2 > 0.0 && std::isfinite(band.inertia_kg_m2);
  return band;
}

// Consistency of the fitted bands with one constant I: chi^2 about their weighted mean, and the
// Birge scale of the statistical std.
void TestConstant(const std::vector<const AmplitudeSweepBand*>& good, AmplitudeSweep* sweep) {
  double wsum = 0.0, wi = 0.0;
  for (const AmplitudeSweepBand* b : good) {
    const double w = 1.0 / (b->inertia_std_kg_m2 * b->inertia_std_kg_m2);
    wsum += w;
    wi += w * b->inertia_kg_m2;
  }
  const double mean = wi / wsum;
  for (const AmplitudeSweepBand* b : good)
    sweep->chi2_constant += std::pow((b->inertia_kg_m2 - mean) / b->inertia_std_kg_m2, 2);
  sweep->chi2_dof = static_cast<int>(good.size()) - 1;
  // The std is scaled whenever the bands scatter more than their stds (the PDG rule); the
  // flag says so only when the scatter is significant at 5 %.
  if (sweep->chi2_constant > sweep->chi2_dof)
    sweep->std_scale = std::sqrt(sweep->chi2_constant / sweep->chi2_dof);
  sweep->bands_disagree = sweep->chi2_constant > ChiSquareQuantile(0.95, sweep->chi2_dof);
}

// The trend over the fitted bands: the weighted curve I_j = I_0 (1 + c A_j^p), p chosen by the
// data (FitAmplitudeShape), its std scaled by the Birge ratio about the curve; the
// lowest-amplitude band; the constancy test. With a trend, the bands' scatter is judged about the
// curve: its Birge ratio becomes the std scale (about a constant it would count the trend twice).
// Leaves sweep->evaluated false (with a note) when the bands cannot support a curve.
void FitTrend(const TraceFitOptions& options, double ref, AmplitudeSweep* sweep) {
  std::vector<const AmplitudeSweepBand*> good;
  for (size_t j = 0; j < sweep->bands.size(); ++j) {
    const AmplitudeSweepBand& b = sweep->bands[j];
    if (!b.ok) continue;
    good.push_back(&b);
    if (sweep->low_band < 0 ||
        b.amplitude_mean_deg < sweep->bands[sweep->low_band].amplitude_mean_deg)
      sweep->low_band = static_cast<int>(j);
  }
  if (good.size() < 2) {
    sweep->note = "fewer than 2 bands could be fitted";
    return;
  }
  std::vector<AmplitudePoint> points;
  for (const AmplitudeSweepBand* b : good)
    points.push_back({b->amplitude_mean_deg, b->inertia_kg_m2, b->inertia_std_kg_m2});
  AmplitudePowerFit trend;
  if (!FitAmplitudeShape(points, ref, &trend)) {
    sweep->note = "the bands do not span a range of amplitudes";
    return;
  }
  sweep->evaluated = true;
  TestConstant(good, sweep);
  sweep->trend_exponent = trend.exponent;
  sweep->trend_coeff = trend.coeff;
  sweep->trend_coeff_std = trend.coeff_std;
  sweep->trend_z = trend.z;
  sweep->trend_chi2 = trend.chi2;
  sweep->trend_dof = trend.dof;
  sweep->trend_scale = trend.birge;
  sweep->trend_percent_per_10deg = trend.percent_per_10deg;
  sweep->inertia_zero_amplitude_kg_m2 = trend.inertia_zero_amplitude_kg_m2;
  sweep->trend_detected = std::abs(sweep->trend_z) > options.sweep_trend_z;
  if (sweep->trend_detected) {
    sweep->std_scale = trend.birge;
    sweep->bands_disagree = trend.dof > 0 && trend.chi2 > ChiSquareQuantile(0.95, trend.dof);
  }
}

}  // namespace

AmplitudeSweep RunAmplitudeSweep(const TraceFitInput& input, const TraceFitOptions& options,
                                 const double* p, double scale, const Trajectory& traj,
                                 double period_s, SolveBudget* budget) {
  AmplitudeSweep sweep;
  const double t0 = input.t_s.front(), t1 = input.t_s.back();
  const double cycles = period_s > 0.0 ? (t1 - t0) / period_s : 0.0;
  const double min_cycles = options.sweep_min_cycles_per_band;
  const int bands =
      std::min(options.sweep_max_bands, static_cast<int>(std::floor(cycles / min_cycles)));
  if (bands < 2) {
    sweep.note = "the window holds " + Fmt("%.1f", cycles) + " cycles; a sweep needs 2 bands of " +
                 Fmt("%g", options.sweep_min_cycles_per_band) + " cycles";
    return sweep;
  }
  // Bands of equal duration, hence equal cycles, in time order; one under 20 samples is skipped.
  const size_t n = input.t_s.size();
  size_t first = 0;
  for (int j = 0; j < bands; ++j) {
    const double tb = j + 1 == bands ? HUGE_VAL : t0 + (t1 - t0) * (j + 1) / bands;
    size_t last = first;
    while (last < n && input.t_s[last] < tb) ++last;  // band = [first, last)
    if (last - first >= 20)
      sweep.bands.push_back(FitBand(input, options, p, scale, traj, period_s, first, last, budget));
    first = last;
  }
  FitTrend(options, scale, &sweep);
  return sweep;
}

std::vector<double> BandFittedRate(const TraceFitInput& input, const TraceFitOptions& options,
                                   const double* p, double scale, const AmplitudeSweepBand& band,
                                   size_t* first) {
  const auto begin = std::lower_bound(input.t_s.begin(), input.t_s.end(), band.t0_s);
  *first = static_cast<size_t>(begin - input.t_s.begin());
  if (band.num_samples < 2 || *first + band.num_samples > input.t_s.size() || *begin != band.t0_s) {
    return {};
  }
  const std::vector<double> t(begin, begin + band.num_samples);
  const std::vector<double> rate(input.rate_rad_per_s.begin() + *first,
                                 input.rate_rad_per_s.begin() + *first + band.num_samples);
  TraceRateCost cost(&t, &rate, options.model, input.geometry, options.integrator, scale);
  double q[kNumTraceParams];
  std::copy(p, p + kNumTraceParams, q);
  q[kTraceInertia] = band.inertia_kg_m2 / scale;
  q[kTraceAngle0] = band.angle0_rad;
  q[kTraceRate0] = band.rate0_rad_per_s;
  q[kTraceBias] = band.bias_rad_per_s;
  std::vector<double> r(t.size());
  if (!std::isfinite(Cost(cost, q, &r))) return {};
  for (size_t k = 0; k < r.size(); ++k) r[k] += rate[k];  // fitted = measured + (fitted - measured)
  return r;
}

std::string AmplitudeAction(const TraceFitOptions& options) {
  if (options.max_amplitude_deg < 90.0) {
    return "swing lower, or lower fit.max_amplitude_deg (--max-amplitude, now " +
           Fmt("%g", options.max_amplitude_deg) + " deg)";
  }
  return "swing lower, or set fit.max_amplitude_deg (--max-amplitude)";
}

SweepRule ApplySweepRule(const AmplitudeSweep& sweep, const Solution& solution,
                         const StatisticalUncertainty& stat, const TraceFitOptions& options) {
  SweepRule rule;
  rule.inertia_kg_m2 = solution.params.inertia_kg_m2;
  rule.inertia_stat_std_kg_m2 = stat.inertia_std_kg_m2;
  if (sweep.evaluated && sweep.std_scale > 1.0) rule.inertia_stat_std_kg_m2 *= sweep.std_scale;
  if (sweep.bands_disagree) rule.findings.flags.push_back("bands_disagree");
  if (!sweep.trend_detected) return rule;
  // The result comes from the lowest-amplitude band, its std scaled by the bands' scatter about
  // the trend (std_scale is the trend's Birge ratio here); the change the trend predicts from
  // that band's amplitude to zero, |I(A_low) - I(0)|, is the model-inadequacy term
  // (docs/method.md §4).
  const AmplitudeSweepBand* low = &sweep.bands[sweep.low_band];
  rule.inertia_kg_m2 = low->inertia_kg_m2;
  rule.inertia_stat_std_kg_m2 = low->inertia_std_kg_m2 * sweep.std_scale;
  rule.inertia_source = "low_amplitude_band";
  rule.model_inadequacy_std_kg_m2 =
      std::abs(sweep.TrendAt(low->amplitude_mean_deg) - sweep.TrendAt(0.0));
  // The first sentence is the warning's one-line summary with its action (the console and the
  // report show it; the rest is the detail).
  rule.findings.Warn(
      "amplitude_trend",
      "I changes with amplitude (" + Fmt("%+.3g", sweep.trend_percent_per_10deg) +
          " % per 10 deg, z = " + Fmt("%.1f", sweep.trend_z) +
          "): the rig departs from the model; " + AmplitudeAction(options) +
          ". I depends on the amplitude beyond its statistical error between " +
          Fmt("%.1f", sweep.bands.back().amplitude_mean_deg) + " and " +
          Fmt("%.1f", sweep.bands.front().amplitude_mean_deg) + " deg (I_0 (1 + c A^" +
          Fmt("%g", sweep.trend_exponent) +
          ") fits best); I is taken from the lowest-amplitude band (" +
          Fmt("%.1f", low->amplitude_mean_deg) + " deg)" +
          (sweep.std_scale > 1.0 ? ", its std scaled by " + Fmt("%.2g", sweep.std_scale) +
                                       " for the bands' scatter about the trend,"
                                 : std::string()) +
          " with a model-inadequacy std of " + Fmt("%.2g", rule.model_inadequacy_std_kg_m2) +
          " kg m^2 (the trend's change from that amplitude to zero).");
  return rule;
}

}  // namespace trace
}  // namespace bifilar
