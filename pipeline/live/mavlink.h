// MAVLink 1 and 2 frames to IMU samples, for `bifilar watch` (issue 34): a PX4 or ArduPilot
// flight controller streams its own IMU over serial or UDP (pipeline/live/byte_stream.h).
// Messages read (field order, units and CRC_EXTRA from MAVLink's message_definitions/v1.0/
// common.xml):
//   HIGHRES_IMU (id 105, CRC_EXTRA 93; PX4): time_usec, xacc.. m/s², xgyro.. rad/s.
//   SCALED_IMU  (id 26, CRC_EXTRA 170; ArduPilot): time_boot_ms, xacc.. mG, xgyro.. mrad/s.
//   RAW_IMU     (id 27, CRC_EXTRA 144; ArduPilot): time_usec; "raw" units in the standard, but
//               ArduPilot fills it with the same mG and mrad/s as SCALED_IMU (see mavlink.cc);
//               it is read with those scales (MavlinkDecoderOptions::raw_imu_*).
// Other message ids are counted (unknown_msgid) and skipped. A frame is checked with the
// X.25 CRC (CRC-16/MCRF4XX) over header and payload plus the message's CRC_EXTRA; a bad
// checksum is counted and skipped (never a sample), and the search for the next frame restarts
// one byte after the rejected start byte. Bytes that are not part of a frame are counted as
// bytes_skipped. MAVLink 2 signed frames (incompat flag 0x01) carry 13 signature bytes after
// the checksum: skipped, not verified. Payloads truncated of their trailing zero bytes (MAVLink
// 2) are zero-filled back to full length.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace bifilar::live {

inline constexpr uint8_t kMavlink1Magic = 0xFE;
inline constexpr uint8_t kMavlink2Magic = 0xFD;
inline constexpr int kMavlinkMsgidScaledImu = 26;
inline constexpr int kMavlinkMsgidRawImu = 27;
inline constexpr int kMavlinkMsgidHighresImu = 105;

struct MavlinkImuSample {
  double t_s;  // the sender's clock: time_usec or time_boot_ms, in seconds
  double gyro_rad_per_s[3];
  double accel_m_per_s2[3];
  bool has_accel;  // false when HIGHRES_IMU's fields_updated says the accel fields are stale
  int msgid;
  int sysid;
  int compid;
};

struct MavlinkCounters {
  long frames_ok = 0;      // frames with a good checksum (IMU or not)
  long bad_crc = 0;        // frames whose checksum did not match (skipped)
  long unknown_msgid = 0;  // good frames of a message that is not an IMU message read here
  long bytes_skipped = 0;  // bytes outside any good frame (garbage, rejected frame starts)
};

class MavlinkDecoder {
 public:
  // Decodes every whole frame in the bytes received so far (these appended to what an earlier
  // call left over: a frame may be split across calls anywhere, byte by byte); the IMU samples
  // in arrival order.
  std::vector<MavlinkImuSample> Feed(const std::string& bytes);
  const MavlinkCounters& counters() const { return counters_; }

 private:
  std::string pending_;  // bytes not yet decoded: at most one partial frame (<= 280 bytes)
  MavlinkCounters counters_;
};

}  // namespace bifilar::live
