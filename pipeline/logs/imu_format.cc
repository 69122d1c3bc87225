#include "pipeline/logs/imu_format.h"

#include <set>

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
  std::set<std::string> names;
  auto add = [&](const std::string& name, const char* what) {
    if (name.empty()) {
      *why = std::string(what) + " column name is empty";
      return false;
    }
    if (!names.insert(name).second) {
      *why = "column '" + name + "' is used twice";
      return false;
    }
    return true;
  };
  if (!add(time_column, "time")) return false;
  for (const auto& c : gyro_columns) if (!add(c, "gyro")) return false;
  const int accel_named = !accel_columns[0].empty() + !accel_columns[1].empty() + !accel_columns[2].empty();
  if (accel_named != 0 && accel_named != 3) {
    *why = "accelerometer columns: give all three or none";
    return false;
  }
  if (accel_named == 3) for (const auto& c : accel_columns) if (!add(c, "accelerometer")) return false;
  if (delimiter == '\n' || delimiter == '"' || delimiter == '.' || delimiter == '-') {
    *why = "delimiter must be a separator such as ',' ';' or tab";
    return false;
  }
  return true;
}

}  // namespace bifilar
