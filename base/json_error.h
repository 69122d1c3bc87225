// nlohmann::json exceptions in plain words for messages that reach the user (issue 9 item 13):
// no "[json.exception.type_error.302]" code, the place in the document named as a key path
// (the library is built with JSON_DIAGNOSTICS, see CMakeLists.txt), bytes that are not printable
// ASCII shown as '?'. The caller names the file and says what to do.
#pragma once

#include <exception>
#include <string>

namespace bifilar {

// "[json.exception.type_error.302] (/traces/0/window_s/0) type must be number, but is string"
//   -> "at key /traces/0/window_s/0: type must be number, but is string";
// "[json.exception.parse_error.101] parse error at line 2, column 1: syntax error ..."
//   -> "parse error at line 2, column 1: syntax error ...". Other exceptions: their what(),
// made printable.
std::string DescribeJsonError(const std::exception& e);

}  // namespace bifilar
