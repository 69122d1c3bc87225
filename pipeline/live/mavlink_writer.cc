// MAVLink frames of the IMU messages, for feeders (mavlink_writer.h).
#include "pipeline/live/mavlink_writer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace bifilar::live {
namespace {

void PutLittleEndian(uint64_t v, int bytes, std::string* out, std::size_t at) {
  for (int i = 0; i < bytes; ++i) (*out)[at + i] = static_cast<char>((v >> (8 * i)) & 0xFF);
}
void PutFloat(double v, std::string* out, std::size_t at) {
  const float f = static_cast<float>(v);
  uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  PutLittleEndian(bits, 4, out, at);
}
// The nearest int16 count of value / scale, saturated (NaN → 0).
void PutCount(double value, double scale, std::string* out, std::size_t at) {
  double count = std::round(value / scale);
  if (!std::isfinite(count)) count = std::isnan(count) ? 0 : count;
  count = std::clamp(count, double{std::numeric_limits<int16_t>::min()},
                     double{std::numeric_limits<int16_t>::max()});
  PutLittleEndian(static_cast<uint16_t>(static_cast<int16_t>(count)), 2, out, at);
}
uint64_t Microseconds(double t_s) { return static_cast<uint64_t>(std::llround(t_s * 1e6)); }

}  // namespace

std::string EncodeMavlinkFrame(int msgid, const std::string& payload, std::size_t base_length,
                               const MavlinkFrameOptions& o) {
  std::string body = o.version == 1 ? payload.substr(0, base_length) : payload;
  if (o.version != 1 && o.truncate_zeros) {
    while (body.size() > 1 && body.back() == '\0') body.pop_back();
  }
  std::string frame;
  if (o.version == 1) {
    frame = {static_cast<char>(kMavlink1Magic), static_cast<char>(body.size()),
             static_cast<char>(o.seq),          static_cast<char>(o.sysid),
             static_cast<char>(o.compid),       static_cast<char>(msgid)};
  } else {
    frame = {static_cast<char>(kMavlink2Magic),
             static_cast<char>(body.size()),
             static_cast<char>(o.signed_frame ? kMavlinkIncompatSigned : 0),
             0,
             static_cast<char>(o.seq),
             static_cast<char>(o.sysid),
             static_cast<char>(o.compid),
             static_cast<char>(msgid & 0xFF),
             static_cast<char>((msgid >> 8) & 0xFF),
             static_cast<char>((msgid >> 16) & 0xFF)};
  }
  frame += body;
  // A message not read here gets CRC_EXTRA 0: a frame the decoder cannot check anyway.
  const uint16_t crc = MavlinkCrc(reinterpret_cast<const uint8_t*>(frame.data()) + 1,
                                  frame.size() - 1, std::max(MavlinkCrcExtra(msgid), 0));
  frame += static_cast<char>(crc & 0xFF);
  frame += static_cast<char>(crc >> 8);
  if (o.version != 1 && o.signed_frame) {
    // link id, 6-byte timestamp, 6-byte signature: placeholders (not verified by the decoder).
    for (std::size_t i = 0; i < kMavlinkSignatureBytes; ++i) frame += static_cast<char>(0xA0 + i);
  }
  return frame;
}

std::string EncodeHighresImu(const MavlinkImuSample& s, uint16_t fields_updated,
                             const MavlinkFrameOptions& o) {
  std::string p(kMavlinkHighresImuBytes, '\0');
  PutLittleEndian(Microseconds(s.t_s), 8, &p, 0);
  for (int i = 0; i < 3; ++i) {
    PutFloat(s.accel_m_per_s2[i], &p, 8 + 4 * i);
    PutFloat(s.gyro_rad_per_s[i], &p, 20 + 4 * i);
  }
  PutLittleEndian(fields_updated, 2, &p, 60);
  p[62] = static_cast<char>(s.imu_instance);
  return EncodeMavlinkFrame(kMavlinkMsgidHighresImu, p, kMavlinkHighresImuBaseBytes, o);
}

std::string EncodeScaledImu(const MavlinkImuSample& s, const MavlinkFrameOptions& o) {
  std::string p(kMavlinkScaledImuBytes, '\0');
  PutLittleEndian(static_cast<uint32_t>(std::llround(s.t_s * 1e3)), 4, &p, 0);
  for (int i = 0; i < 3; ++i) {
    PutCount(s.accel_m_per_s2[i], 1e-3 * kStandardGravityMps2, &p, 4 + 2 * i);
    PutCount(s.gyro_rad_per_s[i], 1e-3, &p, 10 + 2 * i);
  }
  return EncodeMavlinkFrame(kMavlinkMsgidScaledImu, p, kMavlinkScaledImuBaseBytes, o);
}

std::string EncodeRawImu(const MavlinkImuSample& s, const MavlinkDecoderOptions& scales,
                         const MavlinkFrameOptions& o) {
  std::string p(kMavlinkRawImuBytes, '\0');
  PutLittleEndian(Microseconds(s.t_s), 8, &p, 0);
  for (int i = 0; i < 3; ++i) {
    PutCount(s.accel_m_per_s2[i], scales.raw_imu_accel_m_per_s2_per_count, &p, 8 + 2 * i);
    PutCount(s.gyro_rad_per_s[i], scales.raw_imu_gyro_rad_per_s_per_count, &p, 14 + 2 * i);
  }
  p[26] = static_cast<char>(s.imu_instance);
  return EncodeMavlinkFrame(kMavlinkMsgidRawImu, p, kMavlinkRawImuBaseBytes, o);
}

}  // namespace bifilar::live
