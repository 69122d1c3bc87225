// The moments table read by `bifilar ellipse`: a CSV file with a header row naming the columns
// pitch_deg (nose-up pitch, deg), inertia (moment about the vertical swing axis) and optionally
// std (its standard error), one row per trial or per angle. Blank lines and lines starting with
// '#' are skipped. Inertia and std are in the table's units (SI kg m^2 or slug ft^2) and are
// converted to SI on reading. Conventions: docs/physics.md section 3.
#pragma once

#include <string>
#include <vector>

#include "base/units.h"
#include "fit/ellipse.h"

namespace bifilar {

// Parses the table text; `name` (the file name) prefixes error messages. Throws UserError naming
// the line and column on: no header, missing pitch_deg or inertia column, an unknown or repeated
// column, a row with the wrong number of fields, a value that is not a number, a pitch outside
// [-180, 180], a non-finite or non-positive inertia, a missing, NaN or non-positive std, or no
// data rows.
std::vector<EllipsePoint> ParseEllipseTable(const std::string& text, const std::string& name,
                                            DisplayUnits units);

// Reads and parses a table file; throws UserError if the file cannot be read.
std::vector<EllipsePoint> ReadEllipseTable(const std::string& path, DisplayUnits units);

}  // namespace bifilar
