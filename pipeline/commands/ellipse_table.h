// The moments table read by `bifilar ellipse`: a CSV file with a header row naming the columns
// pitch_deg (nose-up pitch, deg), inertia (moment about the vertical swing axis) and optionally
// std (its standard error), one row per trial or per angle. Blank lines and lines starting with
// '#' are skipped. Inertia and std are in the table's units (SI kg m^2 or slug ft^2) and are
// converted to SI on reading. Conventions: docs/physics.md section 3.
#pragma once

#include <string>
#include <vector>

#include "fit/ellipse.h"

namespace bifilar {

// Inertia units of a table or a report.
enum class InertiaUnits { kSi, kImperial };  // "si" = kg m^2, "imperial" = slug ft^2

constexpr double kKgM2PerSlugFt2 = 1.35581795;

// Parses "si" or "imperial"; false otherwise.
bool ParseInertiaUnits(const std::string& name, InertiaUnits* units);
// Multiply a value in `units` by this to get kg m^2.
double InertiaToSi(InertiaUnits units);
// "kg m^2" or "slug ft^2".
const char* InertiaUnitLabel(InertiaUnits units);

// Parses the table text; `name` (the file name) prefixes error messages. Throws UserError naming
// the line and column on: no header, missing pitch_deg or inertia column, an unknown or repeated
// column, a row with the wrong number of fields, a value that is not a number, a pitch outside
// [-180, 180], a non-finite or non-positive inertia, a missing, NaN or non-positive std, or no
// data rows.
std::vector<EllipsePoint> ParseEllipseTable(const std::string& text, const std::string& name,
                                            InertiaUnits units);

// Reads and parses a table file; throws UserError if the file cannot be read.
std::vector<EllipsePoint> ReadEllipseTable(const std::string& path, InertiaUnits units);

}  // namespace bifilar
