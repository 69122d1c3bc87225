#include "pipeline/logs/imu_format.h"

#include <set>

#include "base/enum_names.h"
#include "base/option_check.h"
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
