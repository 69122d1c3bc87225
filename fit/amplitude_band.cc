// The amplitude band of a window (fit/window.h, issue 3 item 4): the angle extremes of the swing
// (the rate integrated between its zero crossings, the half-cycles of window_steps.h) and the
// window trimmed to the part whose amplitude lies inside the band. The window itself is found by
// window.cc.
#include <algorithm>
#include <cmath>
#include <utility>

#include "base/option_check.h"
#include "base/text_format.h"
#include "base/units.h"
#include "fit/window.h"
#include "fit/window_steps.h"

namespace bifilar {

std::vector<AngleExtreme> AngleExtremes(const std::vector<double>& t, const std::vector<double>& r,
                                        const FreeOscillationWindow& w) {
  using namespace window;  // the shared steps (window_steps.h)
  std::vector<AngleExtreme> out;
  if (t.size() != r.size() || t.empty() || w.last_index >= t.size() ||
      w.last_index <= w.first_index)
    return out;
  const size_t b = w.first_index, e = w.last_index + 1;
  std::vector<double> x(t.size(), 0.0);
  for (size_t k = b; k < e; ++k) x[k] = r[k] - w.rest_bias_rad_per_s;
  // Cumulative trapezoid angle.
  std::vector<double> psi(t.size(), 0.0);
  for (size_t k = b + 1; k < e; ++k)
    psi[k] = psi[k - 1] + 0.5 * (x[k] + x[k - 1]) * (t[k] - t[k - 1]);
  double range = 0.0;
  for (size_t k = b; k < e; ++k) range = std::max(range, std::abs(x[k]));
  const double h = std::max(4.0 * w.noise_sigma_rad_per_s, 1e-6 * range);
  std::vector<HalfCycle> cycles = HalfCycles(t, x, b, e, h);
  // A glitch that splits a half-cycle (MergeGlitchSplits) would add two false extremes.
  if (w.period_s > 0.0) {
    const double half = 0.5 * w.period_s;
    const double tol = WindowOptions().half_period_tolerance;
    cycles = MergeGlitchSplits(cycles, WindowOptions().blip_fraction * half,
                               [&](const HalfCycle&, const HalfCycle& before,
                                   const HalfCycle& after, const HalfCycle*, const HalfCycle*) {
                                 return before.duration() < (1.0 - tol) * half ||
                                        after.duration() < (1.0 - tol) * half;
                               });
  }
  // Angle at each interior zero crossing (start of every half-cycle but the first).
  std::vector<std::pair<double, double>> ext;  // (t, psi)
  for (size_t j = 1; j < cycles.size(); ++j) {
    const double tc = cycles[j].start_s;
    size_t k = std::upper_bound(t.begin() + b, t.begin() + e, tc) - t.begin();
    if (k <= b || k >= e) continue;
    const double f = (tc - t[k - 1]) / (t[k] - t[k - 1]);
    ext.emplace_back(tc, psi[k - 1] + f * (psi[k] - psi[k - 1]));
  }
  if (ext.size() < 2) return out;
  for (size_t j = 0; j < ext.size(); ++j) {
    double ref;
    if (j == 0)
      ref = ext[1].second;
    else if (j + 1 == ext.size())
      ref = ext[j - 1].second;
    else
      ref = 0.5 * (ext[j - 1].second + ext[j + 1].second);
    out.push_back({ext[j].first, 0.5 * std::abs(ext[j].second - ref) * kDegPerRad});
  }
  // The end extremes have one neighbour, so the value above is the mean of two successive
  // extremes; with four or more, extrapolate the decay geometrically from the interior ones.
  const size_t m = out.size();
  if (m >= 4) {
    auto extrapolate = [](double a1, double a2) { return a2 > 0.0 ? a1 * a1 / a2 : a1; };
    out[0].amplitude_deg = extrapolate(out[1].amplitude_deg, out[2].amplitude_deg);
    out[m - 1].amplitude_deg = extrapolate(out[m - 2].amplitude_deg, out[m - 3].amplitude_deg);
  }
  return out;
}

bool AmplitudeBandOptions::Check(std::string* why) const {
  CheckFailure f;
  const bool ok =
      CheckGe("min_amplitude_deg", min_amplitude_deg, 0, &f) &&
      CheckGt("max_amplitude_deg", max_amplitude_deg, "min_amplitude_deg", min_amplitude_deg, &f) &&
      CheckGt("min_periods", min_periods, 0, &f);
  return ok || FailWith(f, why, "amplitude band: ");
}

AmplitudeBand TrimToAmplitudeBand(const std::vector<double>& t, const std::vector<double>& r,
                                  const FreeOscillationWindow& w, const AmplitudeBandOptions& o,
                                  const std::string& name) {
  using namespace window;  // the shared steps (window_steps.h)
  AmplitudeBand band;
  std::string why;
  if (!o.Check(&why)) {
    band.status = WindowStatus::kError;
    band.message = Prefix(name) + why;
    return band;
  }
  if (!w.IsUsable()) {
    band.status = w.status;
    band.message = w.message;
    return band;
  }
  band.extremes = AngleExtremes(t, r, w);
  const auto& ex = band.extremes;
  if (ex.empty()) {
    band.message = Prefix(name) + "amplitude: fewer than two swing extremes inside the window";
    return band;
  }
  size_t first = 0, end = ex.size();
  while (first < ex.size() && ex[first].amplitude_deg > o.max_amplitude_deg) ++first;
  while (end > 0 && ex[end - 1].amplitude_deg < o.min_amplitude_deg) --end;
  if (first >= end) {
    band.message = Prefix(name) +
                   Fmt("amplitude from %.2f to %.2f deg never inside the band [%g, %g] deg",
                       ex.front().amplitude_deg, ex.back().amplitude_deg, o.min_amplitude_deg,
                       o.max_amplitude_deg) +
                   (ex.back().amplitude_deg > o.max_amplitude_deg
                        ? " (twist less, log longer, or widen fit.max_amplitude_deg)"
                        : " (twist more, or lower fit.min_amplitude_deg)");
    return band;
  }
  const size_t last = end - 1;
  band.t0_s = w.t0_s;
  band.t1_s = w.t1_s;
  if (first > 0) {
    band.t0_s = ex[first].t_s;
    band.trimmed_start = true;
  }
  if (last + 1 < ex.size()) {
    band.t1_s = ex[last].t_s;
    band.trimmed_end = true;
  }
  band.amplitude_start_deg = ex[first].amplitude_deg;
  band.amplitude_end_deg = ex[last].amplitude_deg;
  band.first_index = FirstAtOrAfter(t, band.t0_s);
  band.last_index = LastAtOrBefore(t, band.t1_s);
  if (band.t1_s - band.t0_s < o.min_periods * w.period_s) {
    band.message =
        Prefix(name) +
        Fmt("only %.2f periods inside the amplitude band [%g, %g] deg",
            (band.t1_s - band.t0_s) / w.period_s, o.min_amplitude_deg, o.max_amplitude_deg) +
        Fmt(" (amplitude %.2f to %.2f deg over the window)", ex.front().amplitude_deg,
            ex.back().amplitude_deg);
    return band;
  }
  band.status = WindowStatus::kOk;
  return band;
}

}  // namespace bifilar
