// One number formatted with a printf format ("%.4g", "%8.3f"): the one helper behind the
// figures' labels and the commands' tables; and a file's text made safe to echo.
#pragma once

#include <string>
#include <string_view>

namespace bifilar {

// `format` holds one double conversion (or two, three, four for the overloads); the result is
// never cut short.
std::string Fmt(const char* format, double v);
std::string Fmt(const char* format, double a, double b);
std::string Fmt(const char* format, double a, double b, double c);
std::string Fmt(const char* format, double a, double b, double c, double d);

// `v` rounded to `digits` significant digits, the number "%.<digits>g" prints (NaN and
// infinities as they are): a derived value shown in a message without its rounding noise.
double RoundedToDigits(double v, int digits);

// A file's own text echoed in a message: at most `max_bytes` bytes of `s`, every byte outside
// printable ASCII (32-126) as '?', and "..." when cut.
std::string PrintableAscii(std::string_view s, size_t max_bytes);

}  // namespace bifilar
