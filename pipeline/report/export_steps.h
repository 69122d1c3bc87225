// The inertial blocks of pipeline/report/export.cc, shared with --into (export_into.cc): private
// to the export unit.
#pragma once

#include <array>
#include <string>

#include "pipeline/report/export.h"

namespace bifilar {

// Where the inertial origin goes: `xyz` in the file's frame (m) and what the comment says of it.
struct InertialOrigin {
  std::array<double, 3> xyz = {0, 0, 0};
  std::string note;  // "the <origin> is ..."; "" for the default text (the CG or 0 0 0)
};

// The origin from the inertia's CG (aircraft.cg_m) in `format`'s frame, or 0 0 0 without one.
InertialOrigin DefaultOrigin(const ExportInertia& in, ExportFormat format, ExportFrame frame);

// Export's comment and the <inertial> element of URDF, SDF or MJCF (its `<inertial .../>` only),
// each line ending in "\n". Throws UserError when a component or the mass is missing.
std::string InertialBlock(const ExportInertia& in, ExportFormat format, ExportFrame frame,
                          const InertialOrigin& origin);

// The first text of every comment export writes (the mark that export wrote a file or block).
constexpr const char* kExportMark = "<!-- bifilar export of ";

}  // namespace bifilar
