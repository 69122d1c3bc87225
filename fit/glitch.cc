#include "fit/glitch.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "fit/window.h"

namespace bifilar {
namespace {

double MedianInPlace(std::vector<double>* v) {
  if (v->empty()) return 0.0;
  const size_t mid = v->size() / 2;
  std::nth_element(v->begin(), v->begin() + mid, v->end());
  double m = (*v)[mid];
  if (v->size() % 2 == 0) m = 0.5 * (m + *std::max_element(v->begin(), v->begin() + mid));
  return m;
}

// The four samples nearest to k in index (two on each side inside the series, else the next
// ones on the other side), for n >= 5.
void Neighbours(size_t k, size_t n, size_t idx[4]) {
  size_t first = k >= 2 ? k - 2 : 0;
  if (first + 4 >= n) first = n - 5;
  int j = 0;
  for (size_t i = first; i <= first + 4; ++i) {
    if (i != k) idx[j++] = i;
  }
}

}  // namespace

bool GlitchOptions::Check(std::string* why) const {
  if (!(threshold_sigmas >= 0.0) || !std::isfinite(threshold_sigmas)) {
    *why = "glitch: threshold_sigmas must be >= 0 (0 disables the search)";
    return false;
  }
  if (!(range_factor >= 0.0) || !(excursion_fraction >= 0.0) || !std::isfinite(range_factor) ||
      !std::isfinite(excursion_fraction)) {
    *why = "glitch: range_factor and excursion_fraction must be finite and >= 0";
    return false;
  }
  if (!(max_fraction > 0.0 && max_fraction <= 1.0)) {
    *why = "glitch: max_fraction must be in (0, 1]";
    return false;
  }
  return true;
}

std::vector<size_t> FindGlitches(const std::vector<double>& t, const std::vector<double>& x,
                                 const GlitchOptions& options) {
  std::vector<size_t> out;
  const size_t n = t.size();
  if (options.threshold_sigmas <= 0.0 || n < 6 || x.size() != n) return out;
  // Normalised residual of each sample against the cubic through its neighbours.
  std::vector<double> e(n, 0.0);
  size_t idx[4];
  for (size_t k = 0; k < n; ++k) {
    Neighbours(k, n, idx);
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
  for (size_t k = 0; k < n; ++k) {
    if (!(std::abs(e[k]) > threshold)) continue;
    Neighbours(k, n, idx);
    double lo = x[idx[0]], hi = x[idx[0]];
    for (int i = 1; i < 4; ++i) {
      lo = std::min(lo, x[idx[i]]);
      hi = std::max(hi, x[idx[i]]);
    }
    const double outside = std::max(x[k] - hi, lo - x[k]);  // beyond the neighbours' range
    if (outside > options.range_factor * (hi - lo) && outside > options.excursion_fraction * excursion) {
      out.push_back(k);
    }
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
  std::snprintf(buf, sizeof(buf), "%zu glitch sample%s ignored (single gyro readings far outside "
                "the swing, up to %.3g rad/s) at t =", indices.size(),
                indices.size() == 1 ? "" : "s", largest);
  std::string text = buf;
  const size_t shown = std::min<size_t>(indices.size(), 5);
  for (size_t i = 0; i < shown; ++i) {
    std::snprintf(buf, sizeof(buf), "%s %.6g", i ? "," : "", data.t_s[indices[i]]);
    text += buf;
  }
  if (shown < indices.size()) text += ", ...";
  return text + " s";
}

}  // namespace bifilar
