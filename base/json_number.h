// NaN -> JSON null: the one way every JSON writer puts a double (results.json, ellipse.json,
// tensor sections, plans). JSON has no NaN or infinity; an undefined number is null.
#pragma once

#include <cmath>

#include <nlohmann/json.hpp>

namespace bifilar {

// `value` as a JSON number when finite, else null.
inline nlohmann::json JsonNumber(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

}  // namespace bifilar
