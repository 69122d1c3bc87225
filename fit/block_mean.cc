#include "fit/block_mean.h"

#include <algorithm>
#include <cmath>

#include "base/option_check.h"

namespace bifilar {

bool BlockMeanOptions::Check(std::string* why) const {
  CheckFailure f;
  return (CheckGe("max_points", max_points, 1000, &f) &&
          CheckFiniteGe("min_blocks_per_period", min_blocks_per_period, 100, &f)) ||
         FailWith(f, why);
}

double BlockMeanSpan(size_t n, double duration_s, double period_s,
                     const BlockMeanOptions& options) {
  if (n < 2 || !(duration_s > 0.0) || !(period_s > 0.0) || !std::isfinite(duration_s) ||
      !std::isfinite(period_s) || n <= options.max_points) {
    return 0.0;
  }
  const double step_s = duration_s / static_cast<double>(n - 1);
  const double needed = std::ceil(static_cast<double>(n) / static_cast<double>(options.max_points));
  const double allowed = std::floor(period_s / step_s / options.min_blocks_per_period);
  const double k = std::min(needed, allowed);
  if (!(k >= 2.0)) return 0.0;
  return (k - 0.5) * step_s;
}

void BlockMeans(const std::vector<double>& t_s, const std::vector<double>& value, size_t first,
                size_t last, double span_s, std::vector<double>* t_out,
                std::vector<double>* value_out) {
  t_out->clear();
  value_out->clear();
  if (span_s <= 0.0) {
    t_out->assign(t_s.begin() + first, t_s.begin() + last + 1);
    value_out->assign(value.begin() + first, value.begin() + last + 1);
    return;
  }
  size_t i = first;
  while (i <= last) {
    const double end = t_s[i] + span_s;
    double t_sum = 0.0, v_sum = 0.0;
    size_t count = 0;
    // Sums relative to the block's first time: full precision for logs with large timestamps.
    const double t_ref = t_s[i];
    while (i <= last && (count == 0 || t_s[i] < end)) {
      t_sum += t_s[i] - t_ref;
      v_sum += value[i];
      ++count;
      ++i;
    }
    t_out->push_back(t_ref + t_sum / static_cast<double>(count));
    value_out->push_back(v_sum / static_cast<double>(count));
  }
}

FitSeries MakeFitSeries(const std::vector<double>& t_s, const std::vector<double>& rate_rad_per_s,
                        size_t first, size_t last, double period_s, double noise_rad_per_s,
                        double rest_end_s, const BlockMeanOptions& options) {
  FitSeries series;
  series.noise_rad_per_s = noise_rad_per_s;
  const size_t n = last - first + 1;
  const double span_s = BlockMeanSpan(n, t_s[last] - t_s[first], period_s, options);
  BlockMeans(t_s, rate_rad_per_s, first, last, span_s, &series.t_s, &series.rate_rad_per_s);
  if (span_s <= 0.0) return series;
  series.samples_per_point = static_cast<double>(n) / static_cast<double>(series.t_s.size());
  if (noise_rad_per_s > 0.0) {
    // The rest's own block means: their scatter is the noise of a fitted point.
    const size_t rest_last =
        static_cast<size_t>(std::upper_bound(t_s.begin(), t_s.end(), rest_end_s) - t_s.begin());
    std::vector<double> rest_t, rest_mean;
    if (rest_last >= 2)
      BlockMeans(t_s, rate_rad_per_s, 0, rest_last - 1, span_s, &rest_t, &rest_mean);
    if (rest_mean.size() >= 20) {
      double mean = 0.0, sq = 0.0;
      for (double v : rest_mean) mean += v;
      mean /= static_cast<double>(rest_mean.size());
      for (double v : rest_mean) sq += (v - mean) * (v - mean);
      series.noise_rad_per_s = std::sqrt(sq / static_cast<double>(rest_mean.size() - 1));
    } else {
      series.noise_rad_per_s = noise_rad_per_s / std::sqrt(series.samples_per_point);
    }
    if (!(series.noise_rad_per_s > 0.0) || !std::isfinite(series.noise_rad_per_s)) {
      series.noise_rad_per_s = noise_rad_per_s / std::sqrt(series.samples_per_point);
    }
  }
  return series;
}

}  // namespace bifilar
