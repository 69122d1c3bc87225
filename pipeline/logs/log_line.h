// How a line of an IMU log (CSV, TSV, space-separated) is cut into cells: one rule for the log
// reader (imu_log.cc), the format guess (format_guess.cc) and a watched stream
// (pipeline/watch/sample_parser.cc), so that the columns a guess or a stream names are the ones
// the reader finds. Not RFC 4180 (base/csv.h, for tables): a logger quotes names, never a
// delimiter inside one, so quotes are trimmed off a cell, not interpreted; with the delimiter ' '
// runs of spaces and tabs are one separator (loggers pad columns). Views into the line, no copy:
// this is the reader's hot path (~420 MB/s, docs/developers.md).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace bifilar {

// `cell` without surrounding spaces, tabs and carriage returns.
std::string_view TrimLogCell(std::string_view cell);

// `cell` trimmed, then without one pair of surrounding quotes ("" or ''), trimmed again.
std::string_view UnquoteLogCell(std::string_view cell);

// Splits `line` on `delim` into `fields` (views into line, not trimmed).
void SplitLogLine(std::string_view line, char delim, std::vector<std::string_view>* fields);

// The cells of `line`, each unquoted (UnquoteLogCell), as strings.
std::vector<std::string> LogLineCells(std::string_view line, char delim);

}  // namespace bifilar
