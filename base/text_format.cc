#include "base/text_format.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace bifilar {

namespace {

template <typename... Doubles>
std::string FormatDoubles(const char* format, Doubles... v) {
  char buf[96];
  const int n = std::snprintf(buf, sizeof buf, format, v...);
  if (n < 0) return std::string();
  if (static_cast<size_t>(n) < sizeof buf) return std::string(buf, static_cast<size_t>(n));
  std::string out(static_cast<size_t>(n) + 1, '\0');
  std::snprintf(out.data(), out.size(), format, v...);
  out.resize(static_cast<size_t>(n));
  return out;
}

}  // namespace

std::string Fmt(const char* format, double v) { return FormatDoubles(format, v); }
std::string Fmt(const char* format, double a, double b) { return FormatDoubles(format, a, b); }
std::string Fmt(const char* format, double a, double b, double c) {
  return FormatDoubles(format, a, b, c);
}
std::string Fmt(const char* format, double a, double b, double c, double d) {
  return FormatDoubles(format, a, b, c, d);
}

double RoundedToDigits(double v, int digits) {
  if (!std::isfinite(v)) return v;
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*g", digits, v);
  return std::strtod(buffer, nullptr);
}

std::string PrintableAscii(std::string_view s, size_t max_bytes) {
  std::string out;
  for (char c : s.substr(0, max_bytes)) {
    out += (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) ? '?' : c;
  }
  if (s.size() > max_bytes) out += "...";
  return out;
}

}  // namespace bifilar
