// One CSV record splitter and one "is the whole field a number" parser for every table bifilar
// reads (issue 36: there were four splitters with different quoting rules and six parsers).
//
// SplitCsvRecord follows RFC 4180 (section 2), with the delimiter as a parameter:
//  - fields are separated by the delimiter; a record of n delimiters has n + 1 fields, so an
//    empty record is one empty field and a trailing delimiter ends with an empty field;
//  - a field that starts with a double quote is quoted: it runs to the closing quote, and inside
//    it the delimiter, CR and LF are plain text and a doubled quote ("") stands for one quote;
//  - a record ends at CRLF (or LF): the caller passes one record, and one trailing CRLF, LF or CR
//    is dropped, so a line read with std::getline from a CRLF file splits as from an LF one (the
//    tables bifilar reads are read line by line: a quoted field holding a line break would need
//    its lines joined by the caller first);
//  - spaces are part of a field (RFC 4180: "Spaces are considered part of a field and should not
//    be ignored"); a caller that trims does so itself, after splitting.
// Where RFC 4180 says the text is malformed, the splitter is lenient and says what it does: a
// quote inside an unquoted field is kept as text, text after a closing quote up to the next
// delimiter is appended to the field, and an unterminated quoted field runs to the end.
//
// ParseNumber reads a whole field as a double: an optional sign ('+' or '-'), digits with an
// optional decimal point and an optional exponent (fast_float's "general" format, C locale, so
// the result is the correctly rounded double, as strtod's). Refused: an empty field, white space
// anywhere (trim first), anything after the number ("1.5x", "1,5"), hexadecimal ("0x10"), a sign
// after '+' ("+-1"). Subnormals (4.9e-324) are read as they are; underflow gives 0. Infinity and
// NaN ("inf", "nan", and "1e400", which overflows) are refused unless the caller asks for them
// with NonFinite::kAccept, for a reader that reports a non-finite value in its own words.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace bifilar {

// The fields of one CSV record (RFC 4180, above), unquoted.
std::vector<std::string> SplitCsvRecord(std::string_view record, char delimiter = ',');

// What ParseNumber does with infinity and NaN.
enum class NonFinite {
  kRefuse,  // false (the default): a field that is not a finite number is not a number
  kAccept,  // true with the value: the caller reports it (a log's "NaN values are not allowed")
};

// The whole `field` as a number (above); false, with *value unspecified, otherwise.
bool ParseNumber(std::string_view field, double* value, NonFinite non_finite = NonFinite::kRefuse);

}  // namespace bifilar
