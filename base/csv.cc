// The CSV record splitter (RFC 4180) and the whole-field number parser (fast_float): base/csv.h
// states the rules.
#include "base/csv.h"

#include <cmath>
#include <system_error>

#include <fast_float/fast_float.h>

namespace bifilar {

std::vector<std::string> SplitCsvRecord(std::string_view record, char delimiter) {
  // One trailing record end (CRLF, LF or a lone CR) is not part of the last field.
  if (!record.empty() && record.back() == '\n') record.remove_suffix(1);
  if (!record.empty() && record.back() == '\r') record.remove_suffix(1);
  std::vector<std::string> fields;
  std::string field;
  size_t i = 0;
  while (true) {
    if (i < record.size() && record[i] == '"') {  // a quoted field
      ++i;
      while (i < record.size()) {
        if (record[i] == '"') {
          if (i + 1 < record.size() && record[i + 1] == '"') {  // "" is one quote
            field += '"';
            i += 2;
            continue;
          }
          ++i;  // the closing quote
          break;
        }
        field += record[i++];
      }
    }
    // Unquoted text, or text after a closing quote (lenient), up to the delimiter.
    while (i < record.size() && record[i] != delimiter) field += record[i++];
    fields.push_back(std::move(field));
    field.clear();
    if (i >= record.size()) return fields;
    ++i;  // the delimiter: another field follows, empty at the end
  }
}

bool ParseNumber(std::string_view field, double* value, NonFinite non_finite) {
  const char* first = field.data();
  const char* last = field.data() + field.size();
  // fast_float, as std::from_chars, takes no leading '+'; a sign after it stays refused.
  if (first != last && *first == '+') {
    ++first;
    if (first != last && (*first == '+' || *first == '-')) return false;
  }
  if (first == last) return false;
  const fast_float::from_chars_result result = fast_float::from_chars(first, last, *value);
  if (result.ec != std::errc() || result.ptr != last) return false;
  return non_finite == NonFinite::kAccept || std::isfinite(*value);
}

}  // namespace bifilar
