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

// File names in the order a reader expects: case ignored, runs of digits compared as numbers
// ("trial_2" before "Trial_10"); ties broken by the plain byte order, so the order is total.
bool NaturalLess(std::string_view a, std::string_view b);

// `text` wrapped at blanks into lines of at most `width` characters (a word longer than that
// stays whole on its own line), every line after the first starting with `indent`: the one way
// the console keeps a long message readable (issue 32: lines of 744 characters).
std::string WrapText(std::string_view text, size_t width, std::string_view indent);

}  // namespace bifilar
