#include "base/json_error.h"

#include <string_view>

namespace bifilar {

std::string DescribeJsonError(const std::exception& e) {
  std::string_view text = e.what();
  constexpr std::string_view kPrefix = "[json.exception.";
  if (text.substr(0, kPrefix.size()) == kPrefix) {
    const size_t end = text.find("] ");
    if (end != std::string_view::npos) text.remove_prefix(end + 2);
  }
  std::string out;
  // JSON_DIAGNOSTICS puts the key path in parentheses first: "(/a/0/b) type must be ...".
  if (!text.empty() && text.front() == '(') {
    const size_t close = text.find(") ");
    if (close != std::string_view::npos) {
      const std::string_view where = text.substr(1, close - 1);
      out = where.empty() ? "at the top level: " : "at key " + std::string(where) + ": ";
      text.remove_prefix(close + 2);
    }
  }
  constexpr size_t kMaxLength = 300;
  for (char c : text.substr(0, kMaxLength)) {
    const unsigned char u = static_cast<unsigned char>(c);
    out += (u < 32 || u >= 127) ? '?' : c;
  }
  if (text.size() > kMaxLength) out += "...";
  return out;
}

}  // namespace bifilar
