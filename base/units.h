// One name per unit fact (issue 24): pi, degrees <-> radians, slug ft^2 <-> kg m^2, standard
// gravity, and the one enumeration of display units with its table (name, unit label, factor).
// Every layer uses these, pendulum/ and fit/ included; nothing else defines them.
//
// Keep each expression's arithmetic when using them: x * kRadPerDeg is not x * kPi / 180.0 in
// the last bit (the second rounds twice), so a site written one way stays that way.
#pragma once

#include <string>

namespace bifilar {

constexpr double kPi = 3.14159265358979323846;  // the same double as M_PI
constexpr double kDegPerRad = 180.0 / kPi;      // 57.29577951308232
constexpr double kRadPerDeg = kPi / 180.0;      // 0.017453292519943295
// Standard gravity g0 (m/s^2): the unit "g" of accelerometers and the default local gravity.
constexpr double kStandardGravityMps2 = 9.80665;
// 1 slug ft^2 in kg m^2 (docs/physics.md §4), and its inverse.
constexpr double kKgM2PerSlugFt2 = 1.35581795;
constexpr double kSlugFt2PerKgM2 = 1.0 / kKgM2PerSlugFt2;

// The units inertias are shown in (consoles, report, figures, tables); files stay SI.
enum class DisplayUnits { kSi, kImperial };  // "si" (kg m^2), "imperial" (slug ft^2)

const char* ToString(DisplayUnits units);  // "si", "imperial"
// Parses "si" or "imperial"; false otherwise.
bool ParseDisplayUnits(const std::string& name, DisplayUnits* units);
// The allowed values for messages and help: "si or imperial".
std::string DisplayUnitsAllowedValues();

// Inertia in the display units, and their name ("kg m^2" or "slug ft^2").
double InertiaToDisplay(double inertia_kg_m2, DisplayUnits units);
const char* InertiaUnitName(DisplayUnits units);
// Multiply a value in `units` by this to get kg m^2.
double InertiaToSi(DisplayUnits units);
// A message written in SI (the fit's warnings) in the display units: under kImperial every
// "<number> kg m^2" of `text` becomes "<number> slug ft^2" (3 significant digits); kSi: as is.
std::string SiTextInDisplayUnits(const std::string& text, DisplayUnits units);

}  // namespace bifilar
