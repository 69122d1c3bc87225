#include "pipeline/logs/log_unit_check.h"

#include <algorithm>
#include <cmath>

#include "base/statistics.h"
#include "base/text_format.h"
#include "base/units.h"

namespace bifilar {
namespace {

// The value below which `fraction` of `v` lies (v is copied).
double Percentile(std::vector<double> v, double fraction) {
  if (v.empty()) return NAN;
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(fraction * v.size()));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

// Half-cycles of x - center: sign changes confirmed by a swing beyond +-hysteresis. Returns the
// indices of the zero crossings (the last sign change before each confirmed swing).
std::vector<size_t> ZeroCrossings(const std::vector<double>& x, double center, double hysteresis) {
  std::vector<size_t> crossings;
  int state = 0;  // -1 below -hysteresis, +1 above +hysteresis
  size_t last_change = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    const double d = x[i] - center;
    if (i > 0 && (d > 0) != (x[i - 1] - center > 0)) last_change = i;
    const int s = d > hysteresis ? 1 : d < -hysteresis ? -1 : 0;
    if (s != 0 && s != state) {
      if (state != 0) crossings.push_back(last_change);
      state = s;
    }
  }
  return crossings;
}

// The longest still stretch of x (blocks of `block` samples whose std is under 5 % of the half
// range) whose level lies more than half the half range from the center.
void HeldAwayFromCenter(const std::vector<double>& t, const std::vector<double>& x, size_t block,
                        SwingShape* shape) {
  block = std::max<size_t>(block, 5);
  double run_s = 0, run_level = 0;
  int run_blocks = 0;
  for (size_t b = 0; b + block <= x.size(); b += block) {
    double sum = 0, sum2 = 0;
    for (size_t i = b; i < b + block; ++i) {
      sum += x[i];
      sum2 += x[i] * x[i];
    }
    const double mean = sum / block;
    const double sd = std::sqrt(std::max(0.0, sum2 / block - mean * mean));
    const bool held =
        sd < 0.05 * shape->half_range && std::fabs(mean - shape->center) > 0.5 * shape->half_range;
    if (held && run_blocks > 0 &&
        std::fabs(mean - run_level / run_blocks) < 0.1 * shape->half_range) {
      run_s += t[b + block - 1] - t[b - 1];
      run_level += mean;
      ++run_blocks;
    } else if (held) {
      run_s = t[b + block - 1] - t[b];
      run_level = mean;
      run_blocks = 1;
    } else {
      run_blocks = 0;
      run_s = 0;
    }
    if (run_blocks > 0 && run_s > shape->held_s) {
      shape->held_s = run_s;
      shape->held_level = run_level / run_blocks;
    }
  }
}

// The swing reading `r` makes of a shape measured in the guessed units.
void Evaluate(const SwingShape& shape, const ImuFormat& guessed, UnitReading* r) {
  const double time_scale = ToSi(r->time) / ToSi(guessed.time_unit);
  const double rate_scale = ToSi(r->gyro) / ToSi(guessed.gyro_unit);
  r->period_s = shape.period_s * time_scale;
  r->amplitude_deg = shape.amplitude_rad * time_scale * rate_scale / kRadPerDeg;
  r->plausible = r->period_s >= kMinPendulumPeriodS && r->period_s <= kMaxPendulumPeriodS &&
                 r->amplitude_deg >= kMinPendulumAmplitudeDeg &&
                 r->amplitude_deg < kMaxPendulumAmplitudeDeg;
}

// How far (in log units) an amplitude lies from the usual releases; 0 inside the band.
double DistanceFromUsualRelease(double amplitude_deg) {
  if (amplitude_deg < kTypicalReleaseLowDeg) return std::log(kTypicalReleaseLowDeg / amplitude_deg);
  if (amplitude_deg > kTypicalReleaseHighDeg)
    return std::log(amplitude_deg / kTypicalReleaseHighDeg);
  return 0.0;
}

std::string ReadingText(const UnitReading& r) {
  return std::string(ToString(r.time)) + " and " + ToString(r.gyro) +
         Fmt(": period %.3g s, amplitude %.3g deg", r.period_s, r.amplitude_deg);
}

// Angles rather than rates: a still stretch held away from the swing's center (the twist held
// before the release), or a center beyond the range (the readings never change sign).
std::string LooksLikeAngles(const SwingShape& shape) {
  if (shape.found && shape.held_s >= 0.5 * shape.period_s) {
    return Fmt("read as rates, they stay at %.3g for %.1f s", shape.held_level, shape.held_s) +
           Fmt(" while they swing about %.3g (+-%.3g): a rate is zero while the body is held, "
               "an angle stays at the twist",
               shape.center, shape.half_range);
  }
  if (std::fabs(shape.center) > shape.half_range) {
    return Fmt(
        "the readings swing about %.3g (+-%.3g) and never change sign: a pendulum's rate "
        "swings about zero, an angle about the attitude",
        shape.center, shape.half_range);
  }
  return "";
}

}  // namespace

SwingShape MeasureSwing(const ImuData& data) {
  SwingShape shape;
  if (data.size() < 20) return shape;
  std::vector<double> x(data.size());
  for (int a = 0; a < 3; ++a) {
    for (size_t i = 0; i < data.size(); ++i) x[i] = data.gyro_in_imu[i][a];
    const double lo = Percentile(x, 0.005), hi = Percentile(x, 0.995);
    if (!(0.5 * (hi - lo) > (shape.axis < 0 ? 0.0 : shape.half_range))) continue;
    shape.axis = a;
    shape.center = 0.5 * (hi + lo);
    shape.half_range = 0.5 * (hi - lo);
  }
  if (shape.axis < 0) return shape;
  for (size_t i = 0; i < data.size(); ++i) x[i] = data.gyro_in_imu[i][shape.axis];
  const std::vector<size_t> crossings = ZeroCrossings(x, shape.center, 0.3 * shape.half_range);
  if (crossings.size() < 5) return shape;
  std::vector<double> halves;
  for (size_t k = 1; k < crossings.size(); ++k) {
    halves.push_back(data.t_s[crossings[k]] - data.t_s[crossings[k - 1]]);
  }
  const double half = UpperMedian(halves, NAN);
  int consistent = 0;
  double largest = 0;
  for (size_t k = 1; k < crossings.size(); ++k) {
    if (std::fabs(halves[k - 1] - half) > 0.3 * half) continue;
    ++consistent;
    double integral = 0;  // trapezoids of (x - center) dt over the half-cycle
    for (size_t i = crossings[k - 1] + 1; i <= crossings[k]; ++i) {
      integral += 0.5 * (x[i] + x[i - 1] - 2 * shape.center) * (data.t_s[i] - data.t_s[i - 1]);
    }
    largest = std::max(largest, 0.5 * std::fabs(integral));
  }
  shape.half_cycles = consistent;
  if (consistent < 4 || !(half > 0)) return shape;
  // Still stretches are judged in blocks of an eighth of a period, the units aside.
  const size_t half_samples = (crossings.back() - crossings.front()) / (crossings.size() - 1);
  HeldAwayFromCenter(data.t_s, x, half_samples / 4, &shape);
  shape.found = true;
  shape.period_s = 2 * half;
  shape.amplitude_rad = largest;
  return shape;
}

UnitCheck CheckUnitsAgainstSwing(const ImuData& data, const ImuFormat& guessed, bool time_named,
                                 bool gyro_named) {
  UnitCheck check;
  const SwingShape shape = MeasureSwing(data);
  if (shape.axis >= 0 && shape.half_range > 0) check.angles = LooksLikeAngles(shape);
  check.swing_found = shape.found;
  if (!shape.found || !check.angles.empty()) return check;
  const std::vector<TimeUnit> times =
      time_named ? std::vector<TimeUnit>{guessed.time_unit}
                 : std::vector<TimeUnit>{TimeUnit::kSeconds, TimeUnit::kMilliseconds,
                                         TimeUnit::kMicroseconds};
  const std::vector<RateUnit> rates =
      gyro_named
          ? std::vector<RateUnit>{guessed.gyro_unit}
          : std::vector<RateUnit>{RateUnit::kRadPerS, RateUnit::kDegPerS, RateUnit::kMilliradPerS};
  int guess_index = -1;
  for (TimeUnit t : times) {
    for (RateUnit g : rates) {
      UnitReading r;
      r.time = t;
      r.gyro = g;
      Evaluate(shape, guessed, &r);
      if (t == guessed.time_unit && g == guessed.gyro_unit)
        guess_index = static_cast<int>(check.readings.size());
      check.readings.push_back(r);
    }
  }
  // The plausible reading nearest the usual releases; the guess wins a tie.
  for (int k = 0; k < static_cast<int>(check.readings.size()); ++k) {
    const UnitReading& r = check.readings[k];
    if (!r.plausible) continue;
    const double d = DistanceFromUsualRelease(r.amplitude_deg);
    const double best_d = check.best < 0
                              ? INFINITY
                              : DistanceFromUsualRelease(check.readings[check.best].amplitude_deg);
    if (d < best_d || (d == best_d && k == guess_index)) check.best = k;
  }
  if (check.best < 0) {
    check.best = guess_index;
    const UnitReading& g = check.readings[guess_index];
    check.warning = "no unit makes this log a pendulum: read in " + ReadingText(g) +
                    Fmt(" (a pendulum: %g-%g s, ", kMinPendulumPeriodS, kMaxPendulumPeriodS) +
                    Fmt("%g-%g deg)", kMinPendulumAmplitudeDeg, kMaxPendulumAmplitudeDeg) +
                    "; check the columns, and set imu.time.unit (s, ms, us) and imu.gyro.unit (" +
                    RateUnitAllowedValues() + ") in the config";
    return check;
  }
  const UnitReading& best = check.readings[check.best];
  check.changed = check.best != guess_index;
  check.note = Fmt("checked against the swing: period %.3g s, amplitude %.3g deg", best.period_s,
                   best.amplitude_deg);
  for (int k = 0; k < static_cast<int>(check.readings.size()); ++k) {
    const UnitReading& r = check.readings[k];
    // Only the readings nearly as likely as the one offered are named beside it.
    if (k == check.best || !r.plausible ||
        DistanceFromUsualRelease(r.amplitude_deg) >
            DistanceFromUsualRelease(best.amplitude_deg) + std::log(3.0)) {
      continue;
    }
    check.note +=
        "; in " + ReadingText(r) + ", also a pendulum: check imu.time.unit and imu.gyro.unit";
  }
  return check;
}

}  // namespace bifilar
