// One table per enumeration (Ceres types.h style: LinearSolverTypeToString /
// StringToLinearSolverType): a constexpr array of {value, name} rows gives ToString, Parse, the
// list of names (CLI choices) and the "allowed values" text of messages and help, so that a
// name is written once. Usage, in the enum's .cc file:
//
//   constexpr EnumName<TimeUnit> kTimeUnitNames[] = {{TimeUnit::kSeconds, "s"}, ...};
//   const char* ToString(TimeUnit u) { return EnumToString(kTimeUnitNames, u); }
//   bool ParseTimeUnit(const std::string& s, TimeUnit* u) { return ParseEnum(kTimeUnitNames, s, u);
//   } std::string TimeUnitAllowedValues() { return EnumAllowedValues(kTimeUnitNames); }
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace bifilar {

// A row of a name table. A table may use a row type of its own with more columns (display
// units also carry their inertia unit): the functions below need only `value` and `name`.
template <typename Enum>
struct EnumName {
  Enum value;
  const char* name;
};

// "a", "a or b", "a, b or c".
inline std::string JoinAllowedValues(const std::vector<std::string>& names) {
  std::string text;
  for (size_t i = 0; i < names.size(); ++i) {
    text += i == 0 ? "" : (i + 1 == names.size() ? " or " : ", ");
    text += names[i];
  }
  return text;
}

// The name of `value`; `unknown` for a value the table lacks (a cast integer).
template <typename Row, size_t N>
const char* EnumToString(const Row (&table)[N], decltype(Row::value) value,
                         const char* unknown = "unknown") {
  for (const Row& row : table) {
    if (row.value == value) return row.name;
  }
  return unknown;
}

// The value named `name` (exact match); false, `*value` untouched, for any other text.
template <typename Row, size_t N>
bool ParseEnum(const Row (&table)[N], const std::string& name, decltype(Row::value)* value) {
  for (const Row& row : table) {
    if (name == row.name) {
      *value = row.value;
      return true;
    }
  }
  return false;
}

// The names in table order (CLI11 IsMember choices, help texts).
template <typename Row, size_t N>
std::vector<std::string> EnumNames(const Row (&table)[N]) {
  std::vector<std::string> names;
  for (const Row& row : table) names.push_back(row.name);
  return names;
}

// "a, b or c" for messages and help.
template <typename Row, size_t N>
std::string EnumAllowedValues(const Row (&table)[N]) {
  return JoinAllowedValues(EnumNames(table));
}

}  // namespace bifilar
