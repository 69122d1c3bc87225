// One number formatted with a printf format ("%.4g", "%8.3f"): the one helper behind the
// figures' labels and the commands' tables.
#pragma once

#include <string>

namespace bifilar {

// `format` holds one double conversion; the result is never cut short.
std::string Fmt(const char* format, double v);

}  // namespace bifilar
