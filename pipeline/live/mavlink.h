// MAVLink 1 and 2 frames to IMU samples, for `bifilar watch` (issue 34): a PX4 or ArduPilot
// flight controller streams its own IMU over serial or UDP (pipeline/live/byte_stream.h).
// Messages read; field order, units and CRC_EXTRA checked against MAVLink's
// message_definitions/v1.0/common.xml (tests/pipeline_live_mavlink_test.cc recomputes each
// CRC_EXTRA from the field list):
//   HIGHRES_IMU (id 105, CRC_EXTRA 93; PX4): time_usec, xacc.. m/s², xgyro.. rad/s,
//               fields_updated; extension: id (the IMU instance).
//   SCALED_IMU  (id 26, CRC_EXTRA 170; ArduPilot, PX4): time_boot_ms, xacc.. mG,
//               xgyro.. mrad/s.
//   RAW_IMU     (id 27, CRC_EXTRA 144; ArduPilot): time_usec, xacc.., xgyro.. in "raw" units
//               in the standard. ArduPilot fills it with the same scaling as SCALED_IMU (its
//               GCS_MAVLINK::send_raw_imu sends accel * 1000 / GRAVITY_MSS and gyro * 1000 of
//               the first IMU), so it is read by default as mG and mrad/s; a sender with other
//               raw units needs its scales in MavlinkDecoderOptions.
// Wire format: MAVLink 2 sorts the fields by type size (largest first, stable) and appends the
// extension fields; its payload may be cut of trailing zero bytes (zero-filled back here).
// A frame of these messages is checked with the X.25 CRC (CRC-16/MCRF4XX) over header and
// payload plus the message's CRC_EXTRA; a bad checksum is counted and skipped (never a sample),
// and the search for a frame restarts one byte after the rejected start byte. Frames of other
// messages cannot be checked (their CRC_EXTRA is not known here): one is taken as a frame when
// the byte after it starts another frame, and counted as unknown_msgid; otherwise its start
// byte is garbage. No frame is taken (checked or not) when an IMU frame with a good checksum
// starts inside it, so a false start in garbage, or a frame cut short whose checksum came
// right by chance, never swallows a good frame; such a frame waits (in pending_bytes) until
// the frame inside it is whole, a few frames' time in a live stream. Bytes outside accepted frames
// are counted as bytes_skipped. Signed MAVLink 2 frames (incompat flag 0x01) carry 13 signature
// bytes after the checksum: skipped, not verified. A frame with an incompat flag this decoder does
// not know is not read (MAVLink's rule), its bytes count as skipped. Values are passed on as sent
// (a NaN stays a NaN for the caller to count). A sender may send one IMU as several messages
// (ArduPilot: RAW_IMU and SCALED_IMU when both streams are on): the caller keeps one msgid, sysid,
// compid and imu_instance.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "base/units.h"

namespace bifilar::live {

inline constexpr uint8_t kMavlink1Magic = 0xFE;
inline constexpr uint8_t kMavlink2Magic = 0xFD;
inline constexpr int kMavlinkMsgidScaledImu = 26;
inline constexpr int kMavlinkMsgidRawImu = 27;
inline constexpr int kMavlinkMsgidHighresImu = 105;
inline constexpr uint8_t kMavlinkCrcExtraScaledImu = 170;
inline constexpr uint8_t kMavlinkCrcExtraRawImu = 144;
inline constexpr uint8_t kMavlinkCrcExtraHighresImu = 93;
// Payload lengths: with the extension fields, and without (the MAVLink 1 length).
inline constexpr std::size_t kMavlinkHighresImuBytes = 63, kMavlinkHighresImuBaseBytes = 62;
inline constexpr std::size_t kMavlinkScaledImuBytes = 24, kMavlinkScaledImuBaseBytes = 22;
inline constexpr std::size_t kMavlinkRawImuBytes = 29, kMavlinkRawImuBaseBytes = 26;
// MAVLink 2 incompat flag: the frame is signed (13 signature bytes follow the checksum).
inline constexpr uint8_t kMavlinkIncompatSigned = 0x01;
inline constexpr std::size_t kMavlinkSignatureBytes = 13;
// HIGHRES_IMU fields_updated bits (HIGHRES_IMU_UPDATED_FLAGS): xacc, yacc, zacc; xgyro..zgyro.
inline constexpr uint16_t kHighresImuUpdatedAccel = 0x0007;
inline constexpr uint16_t kHighresImuUpdatedGyro = 0x0038;

struct MavlinkImuSample {
  double t_s;  // the sender's clock: time_usec or time_boot_ms, in seconds
  double gyro_rad_per_s[3];
  double accel_m_per_s2[3];
  bool has_accel;  // false when HIGHRES_IMU's fields_updated marks the accel fields as old
  int msgid;
  int sysid;
  int compid;
  int imu_instance = 0;  // the `id` extension of HIGHRES_IMU and RAW_IMU (0: first IMU)
};

struct MavlinkCounters {
  long frames_ok = 0;      // IMU frames (the three messages above) with a good checksum
  long bad_crc = 0;        // IMU frames whose checksum did not match (skipped)
  long unknown_msgid = 0;  // frames of other messages (skipped; checksum not checkable)
  long bytes_skipped = 0;  // bytes outside accepted frames (garbage, rejected frame starts)
  long stale_gyro = 0;     // HIGHRES_IMU frames whose fields_updated marks no gyro axis as new
};

struct MavlinkDecoderOptions {
  // RAW_IMU scales: the SI value of one count. Default: ArduPilot's (mrad/s and mG).
  double raw_imu_gyro_rad_per_s_per_count = 1e-3;
  double raw_imu_accel_m_per_s2_per_count = 1e-3 * kStandardGravityMps2;
  // Both scales finite and > 0.
  bool Check(std::string* why) const;
};

// The MAVLink X.25 checksum (CRC-16/MCRF4XX, Boost.CRC's crc_optimal) of `size` bytes, then of
// the byte crc_extra when it is 0..255 (a frame's checksum: its bytes after the start byte).
uint16_t MavlinkCrc(const uint8_t* bytes, std::size_t size, int crc_extra = -1);

// CRC_EXTRA of the IMU messages read here; -1 for any other msgid.
int MavlinkCrcExtra(int msgid);

class MavlinkDecoder {
 public:
  MavlinkDecoder() = default;
  explicit MavlinkDecoder(const MavlinkDecoderOptions& options) : options_(options) {}
  // Decodes every whole frame in the bytes received so far (these appended to what an earlier
  // call left over: a frame may be split across calls anywhere, byte by byte); the IMU samples
  // in arrival order.
  std::vector<MavlinkImuSample> Feed(const std::string& bytes);
  const MavlinkCounters& counters() const { return counters_; }
  // Bytes held back: the start of a frame not yet whole, or of one that waits for a frame
  // starting inside it (at most two frames, 2 x 280 bytes + 1).
  std::size_t pending_bytes() const { return pending_.size(); }

 private:
  MavlinkDecoderOptions options_;
  std::string pending_;
  MavlinkCounters counters_;
};

}  // namespace bifilar::live
