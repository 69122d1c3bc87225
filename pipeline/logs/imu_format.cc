#include "pipeline/logs/imu_format.h"

#include <set>

#include "base/option_check.h"
#include "base/units.h"

namespace bifilar {

bool ParseTimeUnit(const std::string& name, TimeUnit* unit) {
  if (name == "s") *unit = TimeUnit::kSeconds;
  else if (name == "ms") *unit = TimeUnit::kMilliseconds;
  else if (name == "us") *unit = TimeUnit::kMicroseconds;
  else return false;
  return true;
}

bool ParseRateUnit(const std::string& name, RateUnit* unit) {
  if (name == "rad/s") *unit = RateUnit::kRadPerS;
  else if (name == "deg/s") *unit = RateUnit::kDegPerS;
  else return false;
  return true;
}

bool ParseAccelUnit(const std::string& name, AccelUnit* unit) {
  if (name == "m/s^2") *unit = AccelUnit::kMetresPerS2;
  else if (name == "g") *unit = AccelUnit::kStandardGravity;
  else return false;
  return true;
}

const char* ToString(TimeUnit unit) {
  switch (unit) {
    case TimeUnit::kSeconds: return "s";
    case TimeUnit::kMilliseconds: return "ms";
    case TimeUnit::kMicroseconds: return "us";
  }
  return "?";
}

const char* ToString(RateUnit unit) { return unit == RateUnit::kRadPerS ? "rad/s" : "deg/s"; }
const char* ToString(AccelUnit unit) { return unit == AccelUnit::kMetresPerS2 ? "m/s^2" : "g"; }

double ToSi(TimeUnit unit) {
  switch (unit) {
    case TimeUnit::kSeconds: return 1.0;
    case TimeUnit::kMilliseconds: return 1e-3;
    case TimeUnit::kMicroseconds: return 1e-6;
  }
  return 1.0;
}

double ToSi(RateUnit unit) { return unit == RateUnit::kRadPerS ? 1.0 : kRadPerDeg; }
double ToSi(AccelUnit unit) { return unit == AccelUnit::kMetresPerS2 ? 1.0 : kStandardGravityMps2; }

bool ImuFormat::Check(std::string* why) const {
  CheckFailure f;
  std::set<std::string> names;
  // A column name: not empty, and not the name of another column.
  auto add = [&](const std::string& name, const std::string& field) {
    if (name.empty()) return CheckFailText(field, name, "a column name", &f);
    return names.insert(name).second ||
           CheckFailText(field, name, "a column not used by another field", &f);
  };
  static const char* const kAxes[3] = {"[0]", "[1]", "[2]"};
  bool ok = add(time_column, "time_column");
  for (int k = 0; ok && k < 3; ++k)
    ok = add(gyro_columns[k], std::string("gyro_columns") + kAxes[k]);
  const int accel_named =
      !accel_columns[0].empty() + !accel_columns[1].empty() + !accel_columns[2].empty();
  ok = ok &&
       (accel_named == 0 || accel_named == 3 ||
        CheckFail("accel_columns (names given)", accel_named, "0 or 3 (all three or none)", &f));
  for (int k = 0; ok && accel_named == 3 && k < 3; ++k) {
    ok = add(accel_columns[k], std::string("accel_columns") + kAxes[k]);
  }
  ok = ok && ((delimiter != '\n' && delimiter != '"' && delimiter != '.' && delimiter != '-') ||
              CheckFailText("delimiter", std::string(1, delimiter),
                            "a separator such as ',' ';' or tab", &f));
  return ok || FailWith(f, why);
}

}  // namespace bifilar
