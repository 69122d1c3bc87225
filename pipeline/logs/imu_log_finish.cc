#include "pipeline/logs/imu_log_finish.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

#include "base/text_format.h"
#include "base/user_error.h"

namespace bifilar {
namespace {

// Bounds on the timestamps of a log (FinishImuLog): its span (11.6 days), and the resolution of
// a double at the largest timestamp, at most this fraction of the median sample step (Unix
// time in s, 1.7e9, resolves 4e-7 s: fine for a 1 kHz log).
constexpr double kMaxLogSpanS = 1e6;
constexpr double kMinStepsPerResolution = 1e-3;

}  // namespace

ImuData FinishImuLog(const std::string& name, const ImuLogOptions& options,
                     const std::vector<double>& values, int needed,
                     const std::vector<int>& row_line,
                     [[maybe_unused]] const std::vector<double>& scale, bool with_accel,
                     ImuData data) {
  const size_t rows = row_line.size();
  // Timestamps must increase. A sample whose time does not exceed the last kept one is dropped,
  // unless the last kept one was itself a forward glitch (the new time fits between the two
  // before), in which case the glitch is replaced.
  // A jump back in time after which no row ever passes the last two kept times ends the time
  // series (a footer of numeric summary rows, or a second log appended): the rest is ignored
  // with a warning. (The second-last, so that a forward glitch in the last kept row is repaired
  // below instead.)
  std::vector<double> later_max(rows + 1, -HUGE_VAL);  // max time over rows r.. (suffix)
  for (size_t r = rows; r-- > 0;)
    later_max[r] = std::max(later_max[r + 1], values[r * needed + kImuRowTime]);
  std::vector<size_t> keep;
  keep.reserve(rows);
  size_t dropped = 0;
  int first_drop_line = 0;
  for (size_t r = 0; r < rows; ++r) {
    const double t = values[r * needed + kImuRowTime];
    if (keep.empty() || t > values[keep.back() * needed + kImuRowTime]) {
      keep.push_back(r);
      continue;
    }
    if (keep.size() >= 2 &&
        !(later_max[r] > values[keep[keep.size() - 2] * needed + kImuRowTime])) {
      data.warnings.push_back(
          "the time series ends at line " + std::to_string(row_line[r]) +
          " (time jumps back from " +
          Fmt("%g", values[keep.back() * needed + kImuRowTime] / scale[kImuRowTime]) + " to " +
          Fmt("%g", t / scale[kImuRowTime]) + " and never passes it again); " +
          std::to_string(rows - r) + " row(s) from there are ignored");
      break;
    }
    if (dropped++ == 0) first_drop_line = row_line[r];
    if (keep.size() >= 2 && t > values[keep[keep.size() - 2] * needed + kImuRowTime])
      keep.back() = r;
  }
  if (dropped > 0) {
    const double fraction = static_cast<double>(dropped) / static_cast<double>(rows);
    const std::string what = std::to_string(dropped) + " of " + std::to_string(rows) +
                             " samples had a timestamp that did not increase (first near line " +
                             std::to_string(first_drop_line) + ")";
    if (fraction > options.max_dropped_fraction) {
      char limit[32];
      std::snprintf(limit, sizeof(limit), "%g", 100.0 * options.max_dropped_fraction);
      throw UserError(
          name + ": " + what + "; more than " + limit +
          " % of the samples, so the file is rejected (clock reset, or several logs in one "
          "file?)");
    }
    data.warnings.push_back("dropped " + what);
  }
  if (static_cast<int>(keep.size()) < options.min_rows) {
    throw UserError(name + ": only " + std::to_string(keep.size()) +
                    " usable data row(s); at least " + std::to_string(options.min_rows) +
                    " needed");
  }

  // Timestamps a fit can use: finite, a span of at most kMaxLogSpanS, and small enough that a
  // double resolves the sample steps (the integrator's steps are relative to t): a clock in the
  // wrong unit or a corrupt timestamp otherwise ends deep inside the solver.
  {
    const double first = values[keep.front() * needed + kImuRowTime];
    const double last = values[keep.back() * needed + kImuRowTime];
    if (!std::isfinite(first) || !std::isfinite(last)) {
      throw UserError(name + ": a timestamp is not a finite number");
    }
    if (last - first > kMaxLogSpanS) {
      throw UserError(name + ": the timestamps span " + Fmt("%g", last - first) + " s (from " +
                      Fmt("%g", first) + " to " + Fmt("%g", last) + " s), more than " +
                      Fmt("%g", kMaxLogSpanS) + " s: check the time column and its unit " +
                      "(imu.time.unit), or a corrupt timestamp");
    }
    if (keep.size() >= 2) {
      std::vector<double> steps(keep.size() - 1);
      for (size_t i = 1; i < keep.size(); ++i) {
        steps[i - 1] =
            values[keep[i] * needed + kImuRowTime] - values[keep[i - 1] * needed + kImuRowTime];
      }
      std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
      const double step = steps[steps.size() / 2];
      const double largest = std::max(std::abs(first), std::abs(last));
      const double resolution = largest * std::numeric_limits<double>::epsilon();
      if (resolution > kMinStepsPerResolution * step) {
        throw UserError(name + ": timestamps near " + Fmt("%g", largest) + " s are too large for " +
                        "samples " + Fmt("%g", step) +
                        " s apart (a number that large is resolved " + "only to " +
                        Fmt("%g", resolution) + " s); subtract the start time from the " +
                        "time column, or check its unit (imu.time.unit)");
      }
    }
  }

  data.t_s.resize(keep.size());
  data.gyro_in_imu.resize(keep.size());
  if (with_accel) data.accel_in_imu.resize(keep.size());
  for (size_t i = 0; i < keep.size(); ++i) {
    const double* v = &values[keep[i] * needed];
    data.t_s[i] = v[0];
    data.gyro_in_imu[i] = Eigen::Vector3d(v[1], v[2], v[3]);
    if (with_accel) data.accel_in_imu[i] = Eigen::Vector3d(v[4], v[5], v[6]);
  }
  return data;
}

}  // namespace bifilar
