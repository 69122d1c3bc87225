// The mark of a log written by `bifilar simulate` (issue 23): a simulated log must never pass
// for a measurement. The writer puts it in the file, the readers turn it into a warning that
// `inspect`, `fit`, results.json and the report show like any other.
//   CSV (also .csv.gz): the first line is a comment,
//     "# simulated by bifilar 0.9.0 simulate, seed 7: not a measurement"
//     (the CSV reader skips comment lines above the header; this one is not counted with them);
//   ULog: an information message 'I' with key "char[N] bifilar_simulated" and the value
//     "bifilar 0.9.0 simulate, seed 7" (other ULog readers skip it like any info message).
// The warning is "simulated by bifilar 0.9.0 simulate, seed 7: not a measurement".
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace bifilar {

inline constexpr char kSimulatedUlogInfoKey[] = "bifilar_simulated";

// "bifilar <version> simulate, seed <seed>": who wrote the log, as the mark carries it.
std::string SimulatedLogOrigin(uint64_t seed);

// The CSV comment line (without its line end) for a log of `origin`.
std::string SimulatedCsvMarkerLine(const std::string& origin);

// The warning a reader adds for a marked log ("simulated by <origin>: not a measurement"); the
// origin is cut to 120 printable characters (it comes from the file).
std::string SimulatedLogWarning(std::string_view origin);

// True when `line` (trimmed or not) is the CSV mark; *warning gets SimulatedLogWarning.
bool ParseSimulatedCsvMarker(std::string_view line, std::string* warning);

// True when `warning` is one SimulatedLogWarning made (the report counts simulated logs).
bool IsSimulatedLogWarning(std::string_view warning);

}  // namespace bifilar
