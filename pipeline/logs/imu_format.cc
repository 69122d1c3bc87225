#include "pipeline/logs/imu_format.h"

#include <set>

#include "base/enum_names.h"
#include "base/units.h"

namespace bifilar {

namespace {

constexpr EnumName<TimeUnit> kTimeUnitNames[] = {
    {TimeUnit::kSeconds, "s"}, {TimeUnit::kMilliseconds, "ms"}, {TimeUnit::kMicroseconds, "us"}};
constexpr EnumName<RateUnit> kRateUnitNames[] = {{RateUnit::kRadPerS, "rad/s"},
                                                 {RateUnit::kDegPerS, "deg/s"}};
constexpr EnumName<AccelUnit> kAccelUnitNames[] = {{AccelUnit::kMetresPerS2, "m/s^2"},
                                                   {AccelUnit::kStandardGravity, "g"}};
constexpr EnumName<LogContainer> kLogContainerNames[] = {
    {LogContainer::kAuto, "auto"}, {LogContainer::kCsv, "csv"}, {LogContainer::kUlog, "ulog"}};

}  // namespace

bool ParseTimeUnit(const std::string& name, TimeUnit* unit) { return ParseEnum(kTimeUnitNames, name, unit); }
bool ParseRateUnit(const std::string& name, RateUnit* unit) { return ParseEnum(kRateUnitNames, name, unit); }
bool ParseAccelUnit(const std::string& name, AccelUnit* unit) { return ParseEnum(kAccelUnitNames, name, unit); }
bool ParseLogContainer(const std::string& name, LogContainer* container) {
  return ParseEnum(kLogContainerNames, name, container);
}

const char* ToString(TimeUnit unit) { return EnumToString(kTimeUnitNames, unit, "?"); }
const char* ToString(RateUnit unit) { return EnumToString(kRateUnitNames, unit, "?"); }
const char* ToString(AccelUnit unit) { return EnumToString(kAccelUnitNames, unit, "?"); }
const char* ToString(LogContainer container) { return EnumToString(kLogContainerNames, container, "?"); }

std::string TimeUnitAllowedValues() { return EnumAllowedValues(kTimeUnitNames); }
std::string RateUnitAllowedValues() { return EnumAllowedValues(kRateUnitNames); }
std::string AccelUnitAllowedValues() { return EnumAllowedValues(kAccelUnitNames); }
std::string LogContainerAllowedValues() { return EnumAllowedValues(kLogContainerNames); }

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
