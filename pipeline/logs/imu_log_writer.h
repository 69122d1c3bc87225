// Writing one IMU log (pendulum/imu_data.h, SI) as CSV in a given ImuFormat
// (pipeline/logs/imu_format.h): the inverse of pipeline/logs/imu_log.h. One header row with the
// format's column names, then one row per sample, values converted from SI to the format's units
// and printed with a fixed number of significant digits ("%.{digits}g", C locale), so the
// same data always gives the same bytes and reading it back gives the values to that precision.
// The file is written to a temporary name beside it and renamed (never half-written).
#pragma once

#include <string>

#include "pendulum/imu_data.h"
#include "pipeline/logs/imu_format.h"

namespace bifilar {

struct ImuLogWriteOptions {
  // Significant digits of the gyro and accelerometer values (6 is already far below any MEMS
  // IMU's noise; 17 round-trips doubles exactly). Timestamps always get at least 10 (1 us at
  // 1000 s). In [6, 17], default 9.
  int significant_digits = 9;
  // Line end: "\n" (default) or "\r\n".
  std::string line_end = "\n";

  bool Check(std::string* why) const;
};

// The CSV text of `data` (throws UserError when the format or data is inconsistent: accel
// columns named but no accel data, mismatched lengths, non-finite values).
std::string FormatImuLog(const ImuData& data, const ImuFormat& format,
                         const ImuLogWriteOptions& options = ImuLogWriteOptions());

// FormatImuLog + WriteFileAtomically (base/atomic_file.h).
// A path ending in ".gz" is written gzip-compressed (base/gzip.h); the reader inflates it.
void WriteImuLog(const std::string& path, const ImuData& data, const ImuFormat& format,
                 const ImuLogWriteOptions& options = ImuLogWriteOptions());

}  // namespace bifilar
