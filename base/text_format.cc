#include "base/text_format.h"

#include <cctype>
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

bool NaturalLess(std::string_view a, std::string_view b) {
  auto digit = [](char c) { return c >= '0' && c <= '9'; };
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (digit(a[i]) && digit(b[j])) {
      size_t ie = i, je = j;
      while (ie < a.size() && digit(a[ie])) ++ie;
      while (je < b.size() && digit(b[je])) ++je;
      // Compare the runs as numbers: leading zeros skipped, then length, then digits.
      size_t is = i, js = j;
      while (is + 1 < ie && a[is] == '0') ++is;
      while (js + 1 < je && b[js] == '0') ++js;
      if (ie - is != je - js) return ie - is < je - js;
      const int c = a.substr(is, ie - is).compare(b.substr(js, je - js));
      if (c != 0) return c < 0;
      i = ie;
      j = je;
      continue;
    }
    const int ca = std::tolower(static_cast<unsigned char>(a[i]));
    const int cb = std::tolower(static_cast<unsigned char>(b[j]));
    if (ca != cb) return ca < cb;
    ++i;
    ++j;
  }
  if ((i < a.size()) != (j < b.size())) return j < b.size();
  return a < b;
}

std::string WrapText(std::string_view text, size_t width, std::string_view indent) {
  // The first line keeps the text's own leading blanks (a console line's indent), and every
  // line the blanks between its words (a table's columns); a break drops the blanks it replaces.
  size_t at = text.find_first_not_of(' ');
  if (at == std::string_view::npos) return std::string(text);
  std::string out, line(text.substr(0, at));
  bool fresh = true;  // no word on `line` yet
  while (at < text.size()) {
    const size_t word_at = text.find_first_not_of(' ', at);
    if (word_at == std::string_view::npos) break;
    const std::string_view gap = text.substr(at, word_at - at);
    const size_t blank = text.find(' ', word_at);
    const std::string_view word = text.substr(
        word_at, blank == std::string_view::npos ? std::string_view::npos : blank - word_at);
    at = blank == std::string_view::npos ? text.size() : blank;
    if (!fresh && line.size() + gap.size() + word.size() > width) {
      out += line + "\n";
      line = std::string(indent);
      fresh = true;
    }
    if (!fresh) line += gap;
    line += word;
    fresh = false;
  }
  return out + line;
}

}  // namespace bifilar
