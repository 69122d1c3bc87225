#include "base/units.h"

#include "base/enum_names.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace bifilar {
namespace {

// The one table of display units: name (config `units`, --units), inertia unit.
struct DisplayUnitsRow {
  DisplayUnits value;
  const char* name;
  const char* inertia_unit;
};
constexpr DisplayUnitsRow kDisplayUnitsTable[] = {
    {DisplayUnits::kSi, "si", "kg m^2"},
    {DisplayUnits::kImperial, "imperial", "slug ft^2"},
};

const DisplayUnitsRow& RowOf(DisplayUnits units) {
  for (const DisplayUnitsRow& row : kDisplayUnitsTable) {
    if (row.value == units) return row;
  }
  return kDisplayUnitsTable[0];
}

}  // namespace

const char* ToString(DisplayUnits units) { return RowOf(units).name; }

bool ParseDisplayUnits(const std::string& name, DisplayUnits* units) {
  return ParseEnum(kDisplayUnitsTable, name, units);
}

std::string DisplayUnitsAllowedValues() { return EnumAllowedValues(kDisplayUnitsTable); }

double InertiaToDisplay(double inertia_kg_m2, DisplayUnits units) {
  return units == DisplayUnits::kSi ? inertia_kg_m2 : inertia_kg_m2 * kSlugFt2PerKgM2;
}

const char* InertiaUnitName(DisplayUnits units) { return RowOf(units).inertia_unit; }

double InertiaToSi(DisplayUnits units) {
  return units == DisplayUnits::kSi ? 1.0 : kKgM2PerSlugFt2;
}

std::string SiTextInDisplayUnits(const std::string& text, DisplayUnits units) {
  if (units != DisplayUnits::kImperial) return text;
  const std::string si = " kg m^2";
  std::string out;
  size_t at = 0;
  for (size_t hit = text.find(si); hit != std::string::npos; hit = text.find(si, hit + 1)) {
    size_t start = hit;
    while (start > at && (std::isdigit(static_cast<unsigned char>(text[start - 1])) ||
                          std::strchr(".eE+-", text[start - 1]) != nullptr)) {
      --start;
    }
    char* stop = nullptr;
    const double value = start < hit ? std::strtod(text.c_str() + start, &stop) : NAN;
    if (stop != text.c_str() + hit || !std::isfinite(value)) continue;  // not "<number> kg m^2"
    char buffer[64];
    std::snprintf(buffer, sizeof(buffer), "%.3g slug ft^2", InertiaToDisplay(value, units));
    out.append(text, at, start - at);
    out += buffer;
    at = hit + si.size();
  }
  out.append(text, at, std::string::npos);
  return out;
}

}  // namespace bifilar
