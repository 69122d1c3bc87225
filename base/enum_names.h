// The "allowed values" text of an enumeration's name table (Ceres types.h style): every enum
// table gives ToString / Parse / a names list, and messages and help print the list with this.
#pragma once

#include <string>
#include <vector>

namespace bifilar {

// "a", "a or b", "a, b or c".
inline std::string JoinAllowedValues(const std::vector<std::string>& names) {
  std::string text;
  for (size_t i = 0; i < names.size(); ++i) {
    text += i == 0 ? "" : (i + 1 == names.size() ? " or " : ", ");
    text += names[i];
  }
  return text;
}

}  // namespace bifilar
