// MAVLink frames of the IMU messages that pipeline/live/mavlink.h reads, for feeders: the tests
// and benchmarks of `bifilar watch` replay a simulated log as a flight controller would send it.
// Units and field order as mavlink.h states them; integer fields are rounded to the nearest
// count and saturated at the int16 range, as a sender would.
#pragma once

#include <cstdint>
#include <string>

#include "pipeline/live/mavlink.h"

namespace bifilar::live {

struct MavlinkFrameOptions {
  int version = 2;             // 1 (magic 0xFE) or 2 (0xFD)
  int sysid = 1;               // 0..255
  int compid = 1;              // 0..255
  int seq = 0;                 // 0..255
  bool truncate_zeros = true;  // MAVLink 2: drop the payload's trailing zero bytes (keeps one)
  // MAVLink 2: mark the frame signed and append 13 signature bytes. They are placeholders (the
  // decoder skips signatures without verifying them), enough to test the framing.
  bool signed_frame = false;
};

// The frame of `payload` (the full payload of message `msgid`, extensions included; MAVLink 1
// keeps only `base_length` bytes, the fields before the extensions) with its checksum.
std::string EncodeMavlinkFrame(int msgid, const std::string& payload, std::size_t base_length,
                               const MavlinkFrameOptions& options);

// One sample as a whole frame of each message (t_s → time_usec or time_boot_ms).
std::string EncodeHighresImu(const MavlinkImuSample& sample, uint16_t fields_updated,
                             const MavlinkFrameOptions& options);
std::string EncodeScaledImu(const MavlinkImuSample& sample, const MavlinkFrameOptions& options);
std::string EncodeRawImu(const MavlinkImuSample& sample, const MavlinkDecoderOptions& scales,
                         const MavlinkFrameOptions& options);

}  // namespace bifilar::live
