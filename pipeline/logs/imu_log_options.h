// The options of reading an IMU log and the physical bounds of a reading: shared by the CSV
// reader (pipeline/logs/imu_log.h), the ULog reader (pipeline/logs/ulog.h), the DataFlash reader
// (pipeline/logs/dataflash.h) and their common last
// step (pipeline/logs/imu_log_finish.h), so none of them includes another for them.
#pragma once

#include <cstdint>
#include <string>

#include "base/bounded_read.h"

namespace bifilar {

// Physical bounds of a reading (SI, after the unit conversion). 1e4 rad/s is 95 000 rpm, 150x
// the range of the widest MEMS gyros (+-4000 deg/s); 1e5 m/s^2 is ~10 000 g, 25x the widest
// accelerometers (+-400 g). Beyond them the cell is corrupt or the unit wrong (deg/s read as
// rad/s stays below 1e4 for any real swing).
constexpr double kMaxGyroRateRadPerS = 1e4;
constexpr double kMaxAccelMps2 = 1e5;

struct ImuLogOptions {
  // Largest fraction of the data rows that may be dropped because their timestamp does not
  // increase (duplicate or out of order) before the whole file is rejected. Default 0.01 (1 %):
  // a wireless logger that reorders the odd packet is fine; a clock that jumps back or a file
  // that is two logs glued together is not.
  double max_dropped_fraction = 0.01;
  // The file must hold the accelerometer columns named in the format. Default false: when the
  // format names accelerometer columns but none of the three is in the file, the log is read
  // gyro-only with a warning (a file with only some of the three is always an error).
  bool require_accel = false;
  // Fewest data rows accepted (after repairs). Default 2.
  int min_rows = 2;
  // Size caps (bytes): the file as stored, and its text once a .csv.gz is decompressed. Defaults
  // kDefaultMaxLogMb and kDefaultMaxDecompressedLogMb MB (base/bounded_read.h); the config's
  // limits.max_log_mb and limits.max_decompressed_log_mb set them. A FIFO, device or folder is
  // refused whatever the caps.
  uint64_t max_file_bytes = static_cast<uint64_t>(kDefaultMaxLogMb * 1e6);
  uint64_t max_decompressed_bytes = static_cast<uint64_t>(kDefaultMaxDecompressedLogMb * 1e6);
  // ArduPilot DataFlash logs (pipeline/logs/dataflash.h): the IMU instance read (the `I` field of
  // IMU/GYR, or 0, 1, 2 for IMU, IMU2, IMU3 in older logs); the config's imu.dataflash.instance.
  // In [-1, 255]; default -1: the lowest instance in the log.
  int dataflash_instance = -1;

  bool Check(std::string* why) const;
};

}  // namespace bifilar
