#include "base/text_format.h"

#include <cstdio>

namespace bifilar {

std::string Fmt(const char* format, double v) {
  char buf[96];
  const int n = std::snprintf(buf, sizeof buf, format, v);
  if (n < 0) return std::string();
  if (static_cast<size_t>(n) < sizeof buf) return std::string(buf, static_cast<size_t>(n));
  std::string out(static_cast<size_t>(n) + 1, '\0');
  std::snprintf(out.data(), out.size(), format, v);
  out.resize(static_cast<size_t>(n));
  return out;
}

}  // namespace bifilar
