#include "pipeline/logs/imu_log_options.h"

namespace bifilar {

bool ImuLogOptions::Check(std::string* why) const {
  if (!(max_dropped_fraction >= 0.0 && max_dropped_fraction <= 1.0)) {
    *why = "max_dropped_fraction must be in [0, 1]";
    return false;
  }
  if (min_rows < 1) {
    *why = "min_rows must be at least 1";
    return false;
  }
  if (max_file_bytes < 1 || max_decompressed_bytes < 1) {
    *why = "max_file_bytes and max_decompressed_bytes must be at least 1";
    return false;
  }
  if (dataflash_instance < -1 || dataflash_instance > 255) {
    *why = "dataflash_instance must be in [0, 255] (or -1: the lowest in the log)";
    return false;
  }
  return true;
}

}  // namespace bifilar
