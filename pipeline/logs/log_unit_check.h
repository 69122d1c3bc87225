// The units `inspect` and `init` guess for a CSV log (pipeline/commands/log_inspect.h), checked
// against what a pendulum can do before they are offered: a period of 0.3-10 s and an amplitude
// below 90 deg. The guess from the names or the first rows (median time step, size of the
// readings) can be off by a factor the data alone cannot tell: a 2 kHz log with time in ms has a
// median step of 0.5, like a 2 Hz log in s; a gyro in mrad/s reads 17.45 times larger than the same
// swing in deg/s. The swing itself tells them apart: its period in samples does not depend on the
// units, and its amplitude is the integral of the rate over a half-cycle.
//
// Also checked: that the "rate" columns are rates. A pendulum's rate swings about zero and is
// zero whenever the body is held still; angle columns (roll, pitch, yaw logged as p, q, r) swing
// about the attitude and stay at the twist while the body is held before the release.
#pragma once

#include <string>
#include <vector>

#include "pendulum/imu_data.h"
#include "pipeline/logs/imu_format.h"

namespace bifilar {

// What a pendulum can do (and what a hand release gives): periods of bifilar rigs are 0.3-10 s;
// the twist stays below 90 deg (beyond it the wires near each other and the rig tilts); a swing
// below 0.3 deg is lost in the noise of any MEMS gyro. Releases are usually 5-30 deg: among
// several units that all give a pendulum, the one nearest that band is offered, the others
// named beside it.
constexpr double kMinPendulumPeriodS = 0.3;
constexpr double kMaxPendulumPeriodS = 10.0;
constexpr double kMaxPendulumAmplitudeDeg = 90.0;
constexpr double kMinPendulumAmplitudeDeg = 0.3;
constexpr double kTypicalReleaseLowDeg = 5.0;
constexpr double kTypicalReleaseHighDeg = 30.0;

// The swing on the gyro axis that moves most, measured in the units the series was read with.
struct SwingShape {
  bool found = false;          // at least four half-cycles of a consistent length
  int axis = -1;               // 0, 1, 2: IMU x, y, z
  double period_s = NAN;       // twice the median half-cycle
  double amplitude_rad = NAN;  // largest half of |integral of the rate over a half-cycle|
  int half_cycles = 0;
  double center = NAN;      // middle of the axis' range (0.5 % and 99.5 % percentiles)
  double half_range = NAN;  // half that range
  double held_s = 0.0;      // longest still stretch away from the center (s)
  double held_level = NAN;  // its level, in the reading's units
};
SwingShape MeasureSwing(const ImuData& data);

// One reading of the log's numbers: its units, and the swing they make of it.
struct UnitReading {
  TimeUnit time = TimeUnit::kSeconds;
  RateUnit gyro = RateUnit::kRadPerS;
  double period_s = NAN;
  double amplitude_deg = NAN;
  bool plausible = false;  // a pendulum: period and amplitude in the ranges above
};

struct UnitCheck {
  bool swing_found = false;
  // The columns hold angles, not rates: why (empty when they look like rates).
  std::string angles;
  // Every reading tried; `best` indexes the one offered (the guess itself when no reading is
  // plausible).
  std::vector<UnitReading> readings;
  int best = -1;
  bool changed = false;  // the offered units differ from the guess
  std::string note;      // for the guess line: "period 2.10 s, amplitude 3.0 deg; ..."
  std::string warning;   // no reading is a pendulum: what it is, and the keys to set
};

// `data` read with `guessed` (time and gyro units); `time_named`, `gyro_named`: that unit came
// from the column names and is kept. Never throws.
UnitCheck CheckUnitsAgainstSwing(const ImuData& data, const ImuFormat& guessed, bool time_named,
                                 bool gyro_named);

}  // namespace bifilar
