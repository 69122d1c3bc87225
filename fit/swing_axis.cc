#include "fit/swing_axis.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <Eigen/Eigenvalues>

#include "base/enum_names.h"
#include "base/option_check.h"
#include "base/units.h"

namespace bifilar {
namespace {

// Index range [begin, end) of the samples with t0 <= t <= t1.
std::pair<size_t, size_t> IndexRange(const std::vector<double>& t, double t0, double t1) {
  const size_t b = std::lower_bound(t.begin(), t.end(), t0) - t.begin();
  const size_t e = std::upper_bound(t.begin(), t.end(), t1) - t.begin();
  return {b, std::max(b, e)};
}

// Gyro bias guess: the mean gyro over the quietest 0.5 s block of the log (smallest total
// variance), which is the rest segment on a log that has one.
Eigen::Vector3d QuietestBlockMean(const ImuData& data) {
  const size_t n = data.size();
  Eigen::Vector3d best_mean = Eigen::Vector3d::Zero();
  double best_var = std::numeric_limits<double>::infinity();
  size_t begin = 0;
  while (begin < n) {
    size_t end = begin;
    while (end < n && data.t_s[end] - data.t_s[begin] < 0.5) ++end;
    const size_t count = end - begin;
    if (count >= 5 || (begin == 0 && end == n)) {
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (size_t i = begin; i < end; ++i) mean += data.gyro_in_imu[i];
      mean /= static_cast<double>(count);
      double var = 0.0;
      for (size_t i = begin; i < end; ++i) var += (data.gyro_in_imu[i] - mean).squaredNorm();
      var /= static_cast<double>(count);
      if (var < best_var) {
        best_var = var;
        best_mean = mean;
      }
    }
    begin = end;
  }
  return best_mean;
}

// Samples at rest: |gyro - bias| below the threshold everywhere within +-half_width of them.
std::vector<char> RestMask(const ImuData& data, const Eigen::Vector3d& bias, double threshold,
                           double half_width) {
  const size_t n = data.size();
  std::vector<char> loud(n);
  for (size_t i = 0; i < n; ++i) loud[i] = (data.gyro_in_imu[i] - bias).norm() >= threshold;
  // Count of loud samples in the time window around each sample (two pointers).
  std::vector<char> rest(n, 0);
  size_t lo = 0, hi = 0;
  int loud_count = 0;
  for (size_t i = 0; i < n; ++i) {
    while (hi < n && data.t_s[hi] <= data.t_s[i] + half_width) loud_count += loud[hi++];
    while (data.t_s[lo] < data.t_s[i] - half_width) loud_count -= loud[lo++];
    rest[i] = loud_count == 0;
  }
  return rest;
}

// Principal direction (unit, sign arbitrary) of the gyro signal over [begin, end); nullopt when
// the signal is constant there (up to the rounding of its mean).
std::optional<Eigen::Vector3d> GyroPrincipalDirection(const ImuData& data, size_t begin,
                                                      size_t end) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (size_t i = begin; i < end; ++i) mean += data.gyro_in_imu[i];
  const double count = static_cast<double>(std::max<size_t>(1, end - begin));
  mean /= count;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (size_t i = begin; i < end; ++i) {
    const Eigen::Vector3d d = data.gyro_in_imu[i] - mean;
    cov += d * d.transpose();
  }
  const double tiny = count * std::pow(1e-12 * (1.0 + mean.norm()), 2);  // rounding of the mean
  if (!(cov.trace() > tiny) || !cov.allFinite()) return std::nullopt;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov);
  return Eigen::Vector3d(solver.eigenvectors().col(2).normalized());
}

Eigen::Vector3d BodySignedAxis(Eigen::Vector3d axis, const Eigen::Matrix3d& imu_to_body) {
  const Eigen::Vector3d body = imu_to_body * axis;
  const double key = std::abs(body.z()) > 1e-3 ? body.z() : -body.x();
  return key < 0.0 ? Eigen::Vector3d(-axis) : axis;
}

}  // namespace

constexpr EnumName<SwingAxisMode> kSwingAxisModeNames[] = {{SwingAxisMode::kAuto, "auto"},
                                                           {SwingAxisMode::kFixed, "fixed"}};
constexpr EnumName<SwingAxisSource> kSwingAxisSourceNames[] = {
    {SwingAxisSource::kAccelAtRest, "accel_rest"},
    {SwingAxisSource::kAccelOverWindow, "accel_window"},
    {SwingAxisSource::kGyroPrincipal, "gyro_principal"},
    {SwingAxisSource::kFixed, "fixed"}};

const char* ToString(SwingAxisMode mode) { return EnumToString(kSwingAxisModeNames, mode, "?"); }
const char* ToString(SwingAxisSource source) {
  return EnumToString(kSwingAxisSourceNames, source, "?");
}

bool SwingAxisOptions::Check(std::string* why) const {
  CheckFailure f;
  const double axis_norm = fixed_axis_in_imu.norm();
  // A rotation matrix: orthonormal to 1e-6, determinant not negative.
  const double orthogonality =
      imu_to_body.allFinite()
          ? (imu_to_body.transpose() * imu_to_body - Eigen::Matrix3d::Identity())
                .cwiseAbs()
                .maxCoeff()
          : NAN;
  const bool ok =
      (mode != SwingAxisMode::kFixed || (fixed_axis_in_imu.allFinite() && axis_norm > 1e-9) ||
       CheckFail("|fixed_axis_in_imu|", axis_norm, "finite and > 1e-09", &f)) &&
      CheckLe("max |imu_to_body^T imu_to_body - I|", orthogonality, 1e-6, &f) &&
      CheckGe("det(imu_to_body)", imu_to_body.determinant(), 0, &f) &&
      CheckGt("rest_rate_threshold_rad_per_s", rest_rate_threshold_rad_per_s, 0, &f) &&
      CheckGt("rest_half_width_s", rest_half_width_s, 0, &f) &&
      CheckGe("min_rest_samples", min_rest_samples, 1, &f) &&
      CheckGe("gravity_removed_below_g", gravity_removed_below_g, 0, &f) &&
      CheckLt("gravity_removed_below_g", gravity_removed_below_g, "1 - gravity_tolerance",
              1.0 - gravity_tolerance, &f) &&
      CheckIn("gravity_tolerance", gravity_tolerance, 0, 1, Ends::kOpen, &f);
  return ok || FailWith(f, why, "swing axis: ");
}

double PitchFromDownDeg(const Eigen::Vector3d& down_in_body) {
  return std::atan2(-down_in_body.x(), std::hypot(down_in_body.y(), down_in_body.z())) * kDegPerRad;
}

double RollFromDownDeg(const Eigen::Vector3d& down_in_body) {
  return std::atan2(down_in_body.y(), down_in_body.z()) * kDegPerRad;
}

namespace {

using IndexPair = std::pair<size_t, size_t>;

// Rest samples of the log and the gyro bias: a first pass with the quietest block's mean as the
// bias, a second with the mean of the first pass's rest samples.
std::vector<char> RestSamples(const ImuData& data, const SwingAxisOptions& options,
                              Eigen::Vector3d* bias_out) {
  const size_t n = data.size();
  Eigen::Vector3d bias = QuietestBlockMean(data);
  std::vector<char> rest;
  for (int pass = 0; pass < 2; ++pass) {  // second pass: bias from the first pass's rest samples
    rest = RestMask(data, bias, options.rest_rate_threshold_rad_per_s, options.rest_half_width_s);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int count = 0;
    for (size_t i = 0; i < n; ++i) {
      if (rest[i]) {
        sum += data.gyro_in_imu[i];
        ++count;
      }
    }
    if (count == 0) break;
    bias = sum / count;
  }
  *bias_out = bias;
  return rest;
}

// No rest: average over the turning points of the swing in the window (or the whole log), where
// the rate is small. There the centripetal acceleration psi'^2 r, which always points the same
// way and would tilt a plain average by ~<psi'^2> r / g (about 1 deg for a 30 deg swing with the
// IMU 0.3 m off axis), nearly vanishes, and the tangential psi'' r alternates in sign from one
// turning point to the next and averages out. Returns the sample count behind *f_sum.
int DownFromTurningPoints(const ImuData& data, IndexPair range, const Eigen::Vector3d& bias,
                          Eigen::Vector3d* f_sum) {
  const size_t n = data.size();
  Eigen::Vector3d f_all = Eigen::Vector3d::Zero();
  for (size_t i = range.first; i < range.second; ++i) f_all += data.accel_in_imu[i];
  const Eigen::Vector3d n0 =
      f_all.norm() > 0.0 ? Eigen::Vector3d(-f_all.normalized()) : Eigen::Vector3d::UnitZ();
  double peak = 0.0;
  for (size_t i = range.first; i < range.second; ++i) {
    peak = std::max(peak, std::abs((data.gyro_in_imu[i] - bias).dot(n0)));
  }
  // Turning points at +A and at -A are averaged separately (the sign of the rate's slope
  // tells them apart) and the two means weighted equally, so that one extra turning point of
  // one sign does not leave a net tangential acceleration.
  Eigen::Vector3d f_group[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  int n_group[2] = {0, 0};
  for (size_t i = std::max<size_t>(range.first, 1); i < range.second && i + 1 < n; ++i) {
    if (std::abs((data.gyro_in_imu[i] - bias).dot(n0)) <= 0.15 * peak) {
      const int g = (data.gyro_in_imu[i + 1] - data.gyro_in_imu[i - 1]).dot(n0) > 0.0 ? 1 : 0;
      f_group[g] += data.accel_in_imu[i];
      ++n_group[g];
    }
  }
  int count = n_group[0] + n_group[1];
  if (n_group[0] >= 5 && n_group[1] >= 5) {
    *f_sum = 0.5 * count * (f_group[0] / n_group[0] + f_group[1] / n_group[1]);
  } else {
    count = 0;
  }
  if (count < 10) {
    *f_sum = f_all;
    count = static_cast<int>(range.second - range.first);
  }
  return count;
}

// What a mean accelerometer reading that is not 1 g looks like, and that it is ignored:
//  - gravity removed by the logger (f + g n_est): the residual g (n_est - n) of its tilt
//    estimate is small and nearly perpendicular to the down vertical n, which is the swing
//    axis: below gravity_removed_below_g and more than 60 deg from the gyro's principal
//    direction;
//  - a unit mix-up: 1 g logged in g and read as m/s^2 (0.102 g), or in m/s^2 read as g
//    (9.81 g), within gravity_tolerance;
//  - anything else (a scale, a column or a broken sensor: the fixed-wing logs' 0.27 g).
std::string AccelNotGravityMessage(const ImuData& data, IndexPair range,
                                   const SwingAxisOptions& options, const Eigen::Vector3d& f_mean,
                                   bool down_at_rest) {
  const double g_read = f_mean.norm() / kStandardGravityMps2;  // in standard gravities
  const double tol = options.gravity_tolerance;
  bool gravity_removed = false;
  if (f_mean.allFinite() && g_read < options.gravity_removed_below_g && g_read > 0.0) {
    const std::optional<Eigen::Vector3d> principal =
        GyroPrincipalDirection(data, range.first, range.second);
    gravity_removed = principal && std::abs(principal->dot(f_mean.normalized())) < 0.5;
  }
  const char* where = down_at_rest ? "at rest" : "over the swing";
  char buf[640];
  if (!f_mean.allFinite()) {
    std::snprintf(buf, sizeof(buf), "the mean accelerometer reading %s is not finite", where);
  } else if (gravity_removed) {
    std::snprintf(buf, sizeof(buf),
                  "the accelerometer reads %.3g g (%.3g m/s^2) %s instead of 1 g: gravity "
                  "removed by the logger?",
                  g_read, f_mean.norm(), where);
  } else if (options.accel_unit_si == 1.0 && std::abs(g_read * kStandardGravityMps2 - 1.0) <= tol) {
    std::snprintf(buf, sizeof(buf),
                  "the accelerometer reads %.3g m/s^2 %s, 1/9.81 of gravity: a log in g "
                  "declared m/s^2? (set imu.accel.unit: g)",
                  f_mean.norm(), where);
  } else if (options.accel_unit_si != 1.0 && std::abs(g_read / kStandardGravityMps2 - 1.0) <= tol) {
    std::snprintf(buf, sizeof(buf),
                  "the accelerometer reads %.3g g %s, 9.81 times gravity: a log in m/s^2 "
                  "declared g? (set imu.accel.unit: m/s^2)",
                  g_read, where);
  } else {
    std::snprintf(buf, sizeof(buf),
                  "the accelerometer reads %.3g g (%.3g m/s^2) %s: neither gravity (1 g "
                  "+- %.0f %%) nor removed gravity (a small reading across the swing axis, left "
                  "when the logger removes gravity); check imu.accel.columns and imu.accel.unit",
                  g_read, f_mean.norm(), where, 100.0 * tol);
  }
  const std::string text = buf;
  return text + (text.back() == '?' ? " " : ". ") + kAccelIgnoredSentence;
}

// An accelerometer that does not read gravity is ignored with a warning: a yaw, pitch or roll
// swing needs only the gyro (the axis from its principal direction), and only a caller that
// needs the down vector (options.accel_required, or a campaign's measured pitch) turns it into
// an error. Sets *down_in_imu when the mean reading is gravity.
bool CheckAccelReadsGravity(const ImuData& data, IndexPair range, const SwingAxisOptions& options,
                            const Eigen::Vector3d& f_mean, bool down_at_rest, SwingAxis* axis,
                            std::optional<Eigen::Vector3d>* down_in_imu, std::string* why) {
  axis->rest_accel_mps2 = f_mean.norm();
  const double g_read = f_mean.norm() / kStandardGravityMps2;  // in standard gravities
  const bool gravity_ok = f_mean.allFinite() && std::abs(g_read - 1.0) <= options.gravity_tolerance;
  if (!gravity_ok) {
    const std::string message = AccelNotGravityMessage(data, range, options, f_mean, down_at_rest);
    if (options.accel_required) {
      *why = "swing axis: " + message;
      return false;
    }
    axis->warnings.push_back(message);
    axis->accel_ignored = true;
    axis->rest_samples = 0;
  }
  if (!axis->accel_ignored) *down_in_imu = Eigen::Vector3d(-f_mean / f_mean.norm());
  return true;
}

// Down vertical from the accelerometer: at rest if the log shows enough rest, else averaged over
// the window (or the whole log).
bool DownFromAccel(const ImuData& data, const SwingAxisOptions& options, bool in_window,
                   IndexPair range, SwingAxis* axis, std::optional<Eigen::Vector3d>* down_in_imu,
                   bool* down_at_rest, std::string* why) {
  const size_t n = data.size();
  Eigen::Vector3d bias;
  const std::vector<char> rest = RestSamples(data, options, &bias);
  Eigen::Vector3d f_sum = Eigen::Vector3d::Zero();
  int count = 0;
  for (size_t i = 0; i < n; ++i) {
    if (rest[i]) {
      f_sum += data.accel_in_imu[i];
      ++count;
    }
  }
  if (count >= options.min_rest_samples) {
    *down_at_rest = true;
    axis->rest_samples = count;
  } else {
    axis->notes.push_back("accelerometer: only " + std::to_string(count) +
                          " samples at rest; down vector averaged over the swing's turning "
                          "points in " +
                          (in_window ? "the window" : "the whole log"));
    count = DownFromTurningPoints(data, range, bias, &f_sum);
  }
  if (count <= 0) return true;
  return CheckAccelReadsGravity(data, range, options, f_sum / count, *down_at_rest, axis,
                                down_in_imu, why);
}

// The swing axis: fixed, the down vertical, or the gyro's principal direction.
bool ChooseAxis(const ImuData& data, const SwingAxisOptions& options, bool in_window,
                IndexPair range, const std::optional<Eigen::Vector3d>& down_in_imu,
                bool down_at_rest, SwingAxis* axis, std::string* why) {
  if (options.mode == SwingAxisMode::kFixed) {
    axis->axis_in_imu = options.fixed_axis_in_imu.normalized();
    axis->source = SwingAxisSource::kFixed;
  } else if (down_in_imu) {
    axis->axis_in_imu = *down_in_imu;
    axis->source = down_at_rest ? SwingAxisSource::kAccelAtRest : SwingAxisSource::kAccelOverWindow;
  } else {
    // Principal direction of the gyro signal over the window (or the whole log).
    const std::optional<Eigen::Vector3d> principal =
        GyroPrincipalDirection(data, range.first, range.second);
    if (!principal) {
      *why = "swing axis: the gyro signal is constant over " +
             std::string(in_window ? "the window" : "the log") + ", so it shows no swing axis";
      return false;
    }
    axis->axis_in_imu = BodySignedAxis(*principal, options.imu_to_body);
    axis->source = SwingAxisSource::kGyroPrincipal;
  }
  return true;
}

}  // namespace

bool EstimateSwingAxis(const ImuData& data, const SwingAxisOptions& options,
                       std::optional<std::pair<double, double>> window_s, SwingAxis* axis,
                       std::string* why) {
  if (!options.Check(why)) return false;
  const size_t n = data.size();
  if (n < 2 || data.gyro_in_imu.size() != n ||
      (data.has_accel() && data.accel_in_imu.size() != n)) {
    *why = "swing axis: the log needs at least 2 samples with matching gyro/accelerometer sizes";
    return false;
  }
  if (window_s && !(window_s->second > window_s->first)) {
    *why = "swing axis: window end must be after its start";
    return false;
  }
  *axis = SwingAxis();
  const auto range = window_s ? IndexRange(data.t_s, window_s->first, window_s->second)
                              : std::make_pair<size_t, size_t>(0, static_cast<size_t>(n));
  std::optional<Eigen::Vector3d> down_in_imu;
  bool down_at_rest = false;
  if (data.has_accel() && !DownFromAccel(data, options, window_s.has_value(), range, axis,
                                         &down_in_imu, &down_at_rest, why)) {
    return false;
  }
  // The pitch is reported from rest, or from the window's turning points; a whole-log average
  // (no rest, no window) includes the hand and is only used for the axis.
  if (down_in_imu && (down_at_rest || window_s)) {
    const Eigen::Vector3d down_in_body = options.imu_to_body * *down_in_imu;
    axis->pitch_measured_deg = PitchFromDownDeg(down_in_body);
    axis->roll_measured_deg = RollFromDownDeg(down_in_body);
  }
  if (!ChooseAxis(data, options, window_s.has_value(), range, down_in_imu, down_at_rest, axis,
                  why)) {
    return false;
  }
  axis->axis_in_body = options.imu_to_body * axis->axis_in_imu;
  axis->rate_rad_per_s.resize(n);
  for (size_t i = 0; i < n; ++i)
    axis->rate_rad_per_s[i] = data.gyro_in_imu[i].dot(axis->axis_in_imu);
  return true;
}

double SecondaryMotionRatio(const ImuData& data, const Eigen::Vector3d& axis_in_imu, double t0_s,
                            double t1_s) {
  const auto range = IndexRange(data.t_s, t0_s, t1_s);
  if (range.second - range.first < 2 || !(axis_in_imu.norm() > 0.0)) return 0.0;
  const Eigen::Vector3d n = axis_in_imu.normalized();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (size_t i = range.first; i < range.second; ++i) mean += data.gyro_in_imu[i];
  mean /= static_cast<double>(range.second - range.first);
  double along_ss = 0.0, orth_ss = 0.0;
  for (size_t i = range.first; i < range.second; ++i) {
    const Eigen::Vector3d d = data.gyro_in_imu[i] - mean;
    const double along = d.dot(n);
    along_ss += along * along;
    orth_ss += (d - along * n).squaredNorm();
  }
  // Below `tiny` a sum of squares is rounding of the mean, not motion.
  const double tiny =
      static_cast<double>(range.second - range.first) * std::pow(1e-12 * (1.0 + mean.norm()), 2);
  if (!(along_ss > tiny)) return orth_ss > tiny ? 1e6 : 0.0;  // no swing at all: capped, never inf
  return std::min(1e6, std::sqrt(orth_ss / along_ss));
}

}  // namespace bifilar
