#include "pipeline/logs/imu_log_options.h"

#include "base/option_check.h"

namespace bifilar {

bool ImuLogOptions::Check(std::string* why) const {
  CheckFailure f;
  const bool ok =
      CheckIn("max_dropped_fraction", max_dropped_fraction, 0, 1, Ends::kClosed, &f) &&
      CheckGe("min_rows", min_rows, 1, &f) &&
      CheckGe("max_file_bytes", static_cast<double>(max_file_bytes), 1, &f) &&
      CheckGe("max_decompressed_bytes", static_cast<double>(max_decompressed_bytes), 1, &f) &&
      ((dataflash_instance >= -1 && dataflash_instance <= 255) ||
       CheckFail("dataflash_instance", dataflash_instance,
                 "in [0, 255] (or -1: the lowest in the log)", &f));
  return ok || FailWith(f, why);
}

}  // namespace bifilar
