// Reading one IMU CSV log into ImuData (SI units, IMU axes; pendulum/imu_data.h).
//
// The file is a CSV with one header row; the columns are found by the names in ImuFormat
// (pipeline/logs/imu_format.h) and converted to SI with its units. What the reader tolerates, and
// what it rejects (UserError naming the file, line and column):
//   - extra columns are ignored; header names may be quoted ("t") or padded with spaces;
//   - CRLF line ends, a UTF-8 byte-order mark and blank lines are accepted; comment lines
//     ('#', '%', '//') above the header are skipped with a warning; with delimiter ' ', runs of
//     spaces separate columns (whitespace-aligned logs);
//   - the time series ends at a break that nothing continues: a blank line followed by a
//     non-numeric row, a blank line or non-numeric row followed by rows whose time jumps back,
//     or a jump back in time that no later row recovers from (a footer of summary rows, a second
//     log appended). The rest is ignored with a warning in ImuData::warnings that names the line;
//   - trailing rows that are not numbers (a line cut short when the logger stopped) are skipped
//     with a warning;
//   - a non-numeric cell followed by rows that continue the time series is an error
//     (file:line:column);
//   - NaN or inf anywhere is an error, and so is a value no sensor reads: a gyro rate beyond
//     kMaxGyroRateRadPerS or a specific force beyond kMaxAccelMps2 (a corrupt cell or a wrong
//     unit), naming the line and column;
//   - timestamps that do not increase (duplicates, a packet out of order, a glitch) are repaired
//     by dropping the offending sample, with a warning; more than
//     ImuLogOptions::max_dropped_fraction of the samples dropped is an error;
//   - gaps (dropped packets) are normal: the real timestamps are kept, nothing is resampled;
//   - an empty file, a header without data, a missing column (the message lists the columns
//     found), a binary file and an unreadable file each give their own clear error.
// The whole file is read at once and numbers are parsed with fast_float (no streams per field).
#pragma once

#include <cstdint>
#include <string>

#include "pendulum/imu_data.h"
#include "pipeline/logs/imu_format.h"
#include "pipeline/logs/imu_log_options.h"

namespace bifilar {

// Reads `path`. Throws UserError (message starts with the path) on any bad input listed above.
ImuData ReadImuLog(const std::string& path, const ImuFormat& format,
                   const ImuLogOptions& options = ImuLogOptions());

// The same parser on text already in memory; `name` stands for the file name in messages.
ImuData ReadImuLogFromString(const std::string& text, const std::string& name,
                             const ImuFormat& format,
                             const ImuLogOptions& options = ImuLogOptions());

// Non-throwing form for batch use: returns false and fills *error (the same one-line message
// ReadImuLog would throw) instead of throwing. *data is only valid when true is returned.
bool TryReadImuLog(const std::string& path, const ImuFormat& format, const ImuLogOptions& options,
                   ImuData* data, std::string* error);

}  // namespace bifilar
