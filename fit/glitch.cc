#include "fit/glitch.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "base/option_check.h"
#include "base/statistics.h"
#include "fit/window.h"

namespace bifilar {
namespace {

// The four samples nearest to the span [k, k + m) outside it: two on each side inside the
// series, else more on the other side; for n >= m + 4. With m = 1, the neighbours of sample k.
void Neighbours(size_t k, size_t m, size_t n, size_t idx[4]) {
  size_t before = std::min<size_t>(k, 2), after = std::min<size_t>(n - k - m, 2);
  if (before < 2)
    after = 4 - before;
  else if (after < 2)
    before = 4 - after;
  int j = 0;
  for (size_t i = k - before; i < k; ++i) idx[j++] = i;
  for (size_t i = k + m; i < k + m + after; ++i) idx[j++] = i;
}

}  // namespace

const OptionFields<GlitchOptions>& GlitchOptions::Fields() {
  using O = GlitchOptions;
  static const OptionFields<O> fields = {
      {"enabled", "enabled", &O::enabled, "search for glitches"},
      {"threshold_sigmas", "threshold_sigmas", &O::threshold_sigmas,
       RangeIn(3, 1000, Ends::kClosed), "residual threshold (robust sigmas)"},
      {"range_factor", "range_factor", &O::range_factor, RangeIn(1, 100, Ends::kClosed),
       "distance beyond the neighbours' range (x that range)"},
      {"excursion_fraction", "excursion_fraction", &O::excursion_fraction,
       RangeIn(0, 10, Ends::kClosed), "... and beyond the series' excursion (x it)"},
      {"max_fraction", "max_fraction", &O::max_fraction, RangeIn(0, 0.1, Ends::kOpenClosed),
       "more glitches than this fraction of the samples: none"},
  };
  return fields;
}

bool GlitchOptions::Check(CheckFailure* failure) const {
  return CheckOptionFields(*this, Fields(), failure);
}

bool GlitchOptions::Check(std::string* why) const {
  CheckFailure f;
  return Check(&f) || FailWith(f, why, "glitch: ");
}

std::vector<size_t> FindGlitches(const std::vector<double>& t, const std::vector<double>& x,
                                 const GlitchOptions& options) {
  std::vector<size_t> out;
  const size_t n = t.size();
  if (!options.enabled || options.threshold_sigmas <= 0.0 || n < 6 || x.size() != n) return out;
  // Normalised residual of each sample against the cubic through its neighbours.
  std::vector<double> e(n, 0.0);
  size_t idx[4];
  for (size_t k = 0; k < n; ++k) {
    Neighbours(k, 1, n, idx);
    e[k] = NeighbourCubicResidual(t, x, k, idx);
  }
  // Robust scale with its floors.
  std::vector<double> work(n);
  for (size_t k = 0; k < n; ++k) work[k] = std::abs(e[k]);
  double scale = 1.482602218505602 * MedianInPlace(&work);
  work = x;
  const double median = MedianInPlace(&work);
  double quantum = HUGE_VAL;
  for (size_t k = 0; k < n; ++k) {
    work[k] = std::abs(x[k] - median);
    if (k > 0 && x[k] != x[k - 1]) quantum = std::min(quantum, std::abs(x[k] - x[k - 1]));
  }
  if (!std::isfinite(quantum)) return out;  // constant series
  // The swing's excursion: the 99th percentile of |x - median|, blind to up to 1 % glitches.
  const size_t q99 = std::min(n - 1, static_cast<size_t>(0.99 * static_cast<double>(n)));
  std::nth_element(work.begin(), work.begin() + q99, work.end());
  const double excursion = work[q99];
  scale = std::max({scale, 1e-3 * excursion, quantum});
  const double threshold = options.threshold_sigmas * scale;
  // Sample j against the cubic through idx: far outside the noise, and beyond the neighbours'
  // range by more than range_factor times that range and excursion_fraction of the swing.
  auto stands_out = [&](size_t j, const size_t idx[4], double residual) {
    if (!(std::abs(residual) > threshold)) return false;
    double lo = x[idx[0]], hi = x[idx[0]];
    for (int i = 1; i < 4; ++i) {
      lo = std::min(lo, x[idx[i]]);
      hi = std::max(hi, x[idx[i]]);
    }
    const double outside = std::max(x[j] - hi, lo - x[j]);  // beyond the neighbours' range
    return outside > options.range_factor * (hi - lo) &&
           outside > options.excursion_fraction * excursion;
  };
  std::vector<char> flagged(n, 0);
  for (size_t k = 0; k < n; ++k) {
    Neighbours(k, 1, n, idx);
    if (stands_out(k, idx, e[k])) flagged[k] = 1;
  }
  // Short runs: two glitches adjacent (m = 2) or one sample apart (m = 3) widen each other's
  // neighbour range, so neither stands out alone. The span [k, k + m) is tested against the four
  // samples around it; its first and last samples must both stand out (a smooth swing's peak
  // cannot, as for one sample), and a middle sample is dropped only when it stands out too.
  for (size_t m = 2; m <= 3 && n >= m + 4; ++m) {
    for (size_t k = 0; k + m <= n; ++k) {
      const size_t last = k + m - 1;
      if (flagged[k] || flagged[last]) continue;
      Neighbours(k, m, n, idx);
      if (!stands_out(k, idx, NeighbourCubicResidual(t, x, k, idx)) ||
          !stands_out(last, idx, NeighbourCubicResidual(t, x, last, idx))) {
        continue;
      }
      for (size_t j = k; j <= last; ++j) {
        if (j == k || j == last || stands_out(j, idx, NeighbourCubicResidual(t, x, j, idx))) {
          flagged[j] = 1;
        }
      }
    }
  }
  for (size_t k = 0; k < n; ++k) {
    if (flagged[k]) out.push_back(k);
  }
  if (static_cast<double>(out.size()) > options.max_fraction * static_cast<double>(n)) out.clear();
  return out;
}

std::vector<size_t> FindGyroGlitches(const ImuData& data, const GlitchOptions& options) {
  std::vector<size_t> all;
  if (data.gyro_in_imu.size() != data.size()) return all;
  std::vector<double> axis(data.size());
  for (int a = 0; a < 3; ++a) {
    for (size_t k = 0; k < data.size(); ++k) axis[k] = data.gyro_in_imu[k][a];
    const std::vector<size_t> found = FindGlitches(data.t_s, axis, options);
    all.insert(all.end(), found.begin(), found.end());
  }
  std::sort(all.begin(), all.end());
  all.erase(std::unique(all.begin(), all.end()), all.end());
  return all;
}

ImuData WithoutSamples(const ImuData& data, const std::vector<size_t>& indices) {
  ImuData out;
  out.warnings = data.warnings;
  const size_t n = data.size();
  out.t_s.reserve(n);
  out.gyro_in_imu.reserve(n);
  if (data.has_accel()) out.accel_in_imu.reserve(n);
  size_t next = 0;
  for (size_t k = 0; k < n; ++k) {
    if (next < indices.size() && indices[next] == k) {
      ++next;
      continue;
    }
    out.t_s.push_back(data.t_s[k]);
    out.gyro_in_imu.push_back(data.gyro_in_imu[k]);
    if (data.has_accel()) out.accel_in_imu.push_back(data.accel_in_imu[k]);
  }
  return out;
}

std::string DescribeGlitches(const ImuData& data, const std::vector<size_t>& indices) {
  if (indices.empty()) return "";
  double largest = 0.0;
  for (size_t k : indices) largest = std::max(largest, data.gyro_in_imu[k].cwiseAbs().maxCoeff());
  char buf[128];
  std::snprintf(buf, sizeof(buf),
                "%zu glitch sample%s ignored (gyro readings far outside the "
                "swing, alone or in runs of 2-3, up to %.3g rad/s) at t =",
                indices.size(), indices.size() == 1 ? "" : "s", largest);
  std::string text = buf;
  const size_t shown = std::min<size_t>(indices.size(), 5);
  for (size_t i = 0; i < shown; ++i) {
    std::snprintf(buf, sizeof(buf), "%s %.6g", i ? "," : "", data.t_s[indices[i]]);
    text += buf;
  }
  if (shown < indices.size()) text += ", ...";
  return text + " s; nothing to do unless they were real motion (fit.glitch sets the thresholds)";
}

}  // namespace bifilar
