#include "pipeline/logs/imu_format.h"

#include <cstdio>
#include <set>

#include "base/enum_names.h"
#include "base/option_check.h"
#include "base/units.h"

namespace bifilar {

namespace {

constexpr EnumName<TimeUnit> kTimeUnitNames[] = {
    {TimeUnit::kSeconds, "s"}, {TimeUnit::kMilliseconds, "ms"}, {TimeUnit::kMicroseconds, "us"}};
constexpr EnumName<RateUnit> kRateUnitNames[] = {{RateUnit::kRadPerS, "rad/s"},
                                                 {RateUnit::kDegPerS, "deg/s"},
                                                 {RateUnit::kMilliradPerS, "mrad/s"}};
constexpr EnumName<AccelUnit> kAccelUnitNames[] = {{AccelUnit::kMetresPerS2, "m/s^2"},
                                                   {AccelUnit::kStandardGravity, "g"}};
constexpr EnumName<LogContainer> kLogContainerNames[] = {
    {LogContainer::kAuto, "auto"}, {LogContainer::kCsv, "csv"}, {LogContainer::kUlog, "ulog"}};

}  // namespace

bool ParseTimeUnit(const std::string& name, TimeUnit* unit) {
  return ParseEnum(kTimeUnitNames, name, unit);
}
bool ParseRateUnit(const std::string& name, RateUnit* unit) {
  return ParseEnum(kRateUnitNames, name, unit);
}
bool ParseAccelUnit(const std::string& name, AccelUnit* unit) {
  return ParseEnum(kAccelUnitNames, name, unit);
}
bool ParseLogContainer(const std::string& name, LogContainer* container) {
  return ParseEnum(kLogContainerNames, name, container);
}

const char* ToString(TimeUnit unit) { return EnumToString(kTimeUnitNames, unit, "?"); }
const char* ToString(RateUnit unit) { return EnumToString(kRateUnitNames, unit, "?"); }
const char* ToString(AccelUnit unit) { return EnumToString(kAccelUnitNames, unit, "?"); }
const char* ToString(LogContainer container) {
  return EnumToString(kLogContainerNames, container, "?");
}

std::string TimeUnitAllowedValues() { return EnumAllowedValues(kTimeUnitNames); }
std::string RateUnitAllowedValues() { return EnumAllowedValues(kRateUnitNames); }
std::string AccelUnitAllowedValues() { return EnumAllowedValues(kAccelUnitNames); }
std::string LogContainerAllowedValues() { return EnumAllowedValues(kLogContainerNames); }

namespace {

// The code point of the UTF-8 sequence at s[i] and its length in *n; false when the bytes there
// are not a valid (shortest-form, non-surrogate) UTF-8 sequence.
bool DecodeUtf8(std::string_view s, size_t i, char32_t* cp, size_t* n) {
  const unsigned char c = static_cast<unsigned char>(s[i]);
  if (c < 0x80) {
    *cp = c;
    *n = 1;
    return true;
  }
  *n = c >= 0xC2 && c <= 0xDF ? 2 : c >= 0xE0 && c <= 0xEF ? 3 : c >= 0xF0 && c <= 0xF4 ? 4 : 0;
  if (*n == 0 || i + *n > s.size()) return false;
  char32_t v = c & (0x7F >> *n);
  for (size_t k = 1; k < *n; ++k) {
    const unsigned char b = static_cast<unsigned char>(s[i + k]);
    if ((b & 0xC0) != 0x80) return false;
    v = (v << 6) | (b & 0x3F);
  }
  const char32_t min_of_length[] = {0, 0, 0x80, 0x800, 0x10000};
  if (v < min_of_length[*n] || v > 0x10FFFF || (v >= 0xD800 && v <= 0xDFFF)) return false;
  *cp = v;
  return true;
}

// A code point that acts on a terminal or a line instead of showing a letter.
bool IsControl(char32_t cp) {
  return cp < 0x20 || (cp >= 0x7F && cp <= 0x9F) || cp == 0x2028 || cp == 0x2029 ||
         (cp >= 0x200B && cp <= 0x200F) || (cp >= 0x202A && cp <= 0x202E) ||
         (cp >= 0x2066 && cp <= 0x2069) || cp == 0xFEFF;
}

}  // namespace

std::string EchoedName(std::string_view s, size_t max_bytes) {
  std::string out;
  size_t i = 0;
  while (i < s.size() && out.size() < max_bytes) {
    char32_t cp = 0;
    size_t n = 1;
    if (!DecodeUtf8(s, i, &cp, &n)) {
      out += '?';
      ++i;
      continue;
    }
    if (IsControl(cp) || out.size() + n > max_bytes) {
      out += '?';
    } else {
      out.append(s.substr(i, n));
    }
    i += n;
  }
  if (i < s.size()) out += "...";
  return out;
}

std::string DescribeUnprintable(std::string_view s) {
  for (size_t i = 0; i < s.size();) {
    char32_t cp = 0;
    size_t n = 1;
    char text[96];
    if (!DecodeUtf8(s, i, &cp, &n)) {
      std::snprintf(text, sizeof(text), "byte 0x%02x at byte %zu (invalid UTF-8)",
                    static_cast<unsigned char>(s[i]), i);
      return text;
    }
    if (IsControl(cp)) {
      const char* name = cp == 0x85                 ? " (NEL, a line break)"
                         : cp == 0x1B               ? " (ESC)"
                         : cp == 0x2028             ? " (LS, a line break)"
                         : cp == 0x2029             ? " (PS, a line break)"
                         : cp == '\n' || cp == '\r' ? " (a line break)"
                                                    : " (a control character)";
      std::snprintf(text, sizeof(text), "U+%04X%s at byte %zu", static_cast<unsigned>(cp), name, i);
      return text;
    }
    i += n;
  }
  return "";
}

double ToSi(TimeUnit unit) {
  switch (unit) {
    case TimeUnit::kSeconds:
      return 1.0;
    case TimeUnit::kMilliseconds:
      return 1e-3;
    case TimeUnit::kMicroseconds:
      return 1e-6;
  }
  return 1.0;
}

double ToSi(RateUnit unit) {
  switch (unit) {
    case RateUnit::kRadPerS:
      return 1.0;
    case RateUnit::kDegPerS:
      return kRadPerDeg;
    case RateUnit::kMilliradPerS:
      return 1e-3;
  }
  return 1.0;
}
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
