// The last step of reading an IMU log, shared by the CSV reader (pipeline/logs/imu_log.cc) and the
// ULog reader (pipeline/logs/ulog.cc), so both repair timestamps and warn the same way.
#pragma once

#include <string>
#include <vector>

#include "pendulum/imu_data.h"
#include "pipeline/logs/imu_log_options.h"

namespace bifilar {

// The slot of the time in a row of samples (the CSV reader's needed columns, FinishImuLog's
// `values`): time 0, gyro x y z 1-3, accel x y z 4-6.
constexpr int kImuRowTime = 0;

// `values` holds the samples row-major, `needed` per row (4: t, gyro x y z; 7: + accel x y z),
// in SI; `row_line[r]` is where row r is in the file (a CSV line; the ULog reader passes the
// sample number and reworded the warnings); `scale[0]` is the SI factor of the file's time unit.
// Repairs timestamps that do not increase (ImuLogOptions::max_dropped_fraction), checks
// ImuLogOptions::min_rows and fills `data` (whose warnings are kept). Throws UserError naming
// `name`.
ImuData FinishImuLog(const std::string& name, const ImuLogOptions& options,
                     const std::vector<double>& values, int needed,
                     const std::vector<int>& row_line, const std::vector<double>& scale,
                     bool with_accel, ImuData data);

}  // namespace bifilar
