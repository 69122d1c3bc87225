// MAVLink frames to IMU samples (mavlink.h has the format and the rules).
#include "pipeline/live/mavlink.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <boost/crc.hpp>

namespace bifilar::live {
namespace {

constexpr std::size_t kV1HeaderBytes = 6;   // magic, len, seq, sysid, compid, msgid
constexpr std::size_t kV2HeaderBytes = 10;  // magic, len, incompat, compat, seq, sysid, compid,
                                            // msgid (3 bytes, little-endian)
constexpr std::size_t kChecksumBytes = 2;
constexpr std::size_t kLongestPayload = 255;

uint64_t LittleEndian(const uint8_t* p, int bytes) {
  uint64_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
int16_t Int16At(const uint8_t* p) { return static_cast<int16_t>(LittleEndian(p, 2)); }
double FloatAt(const uint8_t* p) {
  const uint32_t bits = static_cast<uint32_t>(LittleEndian(p, 4));
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

bool IsMagic(uint8_t b) { return b == kMavlink1Magic || b == kMavlink2Magic; }

// One frame's header fields, whichever version.
struct FrameHeader {
  std::size_t header_bytes = 0;
  std::size_t payload_bytes = 0;
  std::size_t total_bytes = 0;  // header + payload + checksum (+ signature)
  int msgid = 0;
  int sysid = 0;
  int compid = 0;
  bool unknown_incompat = false;
};

// The header at p (n bytes available, p[0] a magic byte); false when more bytes are needed.
bool ReadHeader(const uint8_t* p, std::size_t n, FrameHeader* h) {
  if (p[0] == kMavlink1Magic) {
    if (n < kV1HeaderBytes) return false;
    h->header_bytes = kV1HeaderBytes;
    h->payload_bytes = p[1];
    h->sysid = p[3];
    h->compid = p[4];
    h->msgid = p[5];
    h->total_bytes = kV1HeaderBytes + h->payload_bytes + kChecksumBytes;
    return true;
  }
  if (n < kV2HeaderBytes) return false;
  h->header_bytes = kV2HeaderBytes;
  h->payload_bytes = p[1];
  const uint8_t incompat = p[2];
  h->unknown_incompat = (incompat & ~kMavlinkIncompatSigned) != 0;
  h->sysid = p[5];
  h->compid = p[6];
  h->msgid = static_cast<int>(LittleEndian(p + 7, 3));
  h->total_bytes = kV2HeaderBytes + h->payload_bytes + kChecksumBytes +
                   ((incompat & kMavlinkIncompatSigned) ? kMavlinkSignatureBytes : 0);
  return true;
}

// The IMU sample of a checked frame's payload (zero-filled to `payload`'s full length); false
// for a HIGHRES_IMU frame that brings no new gyro reading.
bool DecodeImu(const FrameHeader& h, const uint8_t* payload, const MavlinkDecoderOptions& o,
               MavlinkImuSample* s) {
  s->msgid = h.msgid;
  s->sysid = h.sysid;
  s->compid = h.compid;
  s->has_accel = true;
  s->imu_instance = 0;
  if (h.msgid == kMavlinkMsgidHighresImu) {
    s->t_s = static_cast<double>(LittleEndian(payload, 8)) * 1e-6;
    for (int i = 0; i < 3; ++i) {
      s->accel_m_per_s2[i] = FloatAt(payload + 8 + 4 * i);
      s->gyro_rad_per_s[i] = FloatAt(payload + 20 + 4 * i);
    }
    const uint16_t updated = static_cast<uint16_t>(LittleEndian(payload + 60, 2));
    s->imu_instance = payload[62];
    // fields_updated 0: a sender that does not keep the bitmap; every field is taken as new.
    if (updated == 0) return true;
    s->has_accel = (updated & kHighresImuUpdatedAccel) == kHighresImuUpdatedAccel;
    return (updated & kHighresImuUpdatedGyro) != 0;
  }
  const bool scaled = h.msgid == kMavlinkMsgidScaledImu;
  const std::size_t at = scaled ? 4 : 8;  // after time_boot_ms (uint32) or time_usec (uint64)
  s->t_s = scaled ? static_cast<double>(LittleEndian(payload, 4)) * 1e-3
                  : static_cast<double>(LittleEndian(payload, 8)) * 1e-6;
  const double gyro_scale = scaled ? 1e-3 : o.raw_imu_gyro_rad_per_s_per_count;
  const double accel_scale =
      scaled ? 1e-3 * kStandardGravityMps2 : o.raw_imu_accel_m_per_s2_per_count;
  for (int i = 0; i < 3; ++i) {
    s->accel_m_per_s2[i] = Int16At(payload + at + 2 * i) * accel_scale;
    s->gyro_rad_per_s[i] = Int16At(payload + at + 6 + 2 * i) * gyro_scale;
  }
  if (!scaled) s->imu_instance = payload[26];
  return true;
}

enum class Attempt { kNeedMore, kNotAFrame, kFrame };

// An IMU frame at p (n bytes available, header h read): kFrame when whole with a good
// checksum; kNotAFrame (and *bad_crc) when its checksum does not match.
Attempt CheckImuFrame(const uint8_t* p, std::size_t n, const FrameHeader& h, bool* bad_crc) {
  if (n < h.total_bytes) return Attempt::kNeedMore;
  const std::size_t checked = h.header_bytes + h.payload_bytes;
  *bad_crc =
      MavlinkCrc(p + 1, checked - 1, MavlinkCrcExtra(h.msgid)) != LittleEndian(p + checked, 2);
  return *bad_crc ? Attempt::kNotAFrame : Attempt::kFrame;
}

// Whether an IMU frame with a good checksum starts inside the `total` bytes at p (n bytes
// available): kFrame if one does, kNotAFrame if none, kNeedMore when one may but is not whole.
Attempt CheckedFrameInside(const uint8_t* p, std::size_t n, std::size_t total) {
  for (std::size_t q = 1; q < total; ++q) {
    if (!IsMagic(p[q])) continue;
    FrameHeader inner;
    if (!ReadHeader(p + q, n - q, &inner)) return Attempt::kNeedMore;
    if (inner.unknown_incompat || MavlinkCrcExtra(inner.msgid) < 0) continue;
    bool bad_crc = false;
    const Attempt a = CheckImuFrame(p + q, n - q, inner, &bad_crc);
    if (a != Attempt::kNotAFrame) return a;
  }
  return Attempt::kNotAFrame;
}

// A frame of a message not read here, whose checksum cannot be checked: kFrame when the byte
// after it starts a frame and no IMU frame with a good checksum starts inside it (so a false
// start in garbage never swallows a real IMU frame).
Attempt CheckOtherFrame(const uint8_t* p, std::size_t n, const FrameHeader& h) {
  if (n < h.total_bytes + 1) return Attempt::kNeedMore;
  if (!IsMagic(p[h.total_bytes])) return Attempt::kNotAFrame;
  const Attempt inside = CheckedFrameInside(p, n, h.total_bytes);
  if (inside == Attempt::kNeedMore) return Attempt::kNeedMore;
  return inside == Attempt::kFrame ? Attempt::kNotAFrame : Attempt::kFrame;
}

// An IMU frame whose checksum matched is taken unless another IMU frame with a good checksum
// starts inside it: a frame cut short whose checksum came right by chance (1 in 256 when only
// the last byte is missing) would otherwise swallow the whole frame after it.
Attempt CheckImuFrameAlone(const uint8_t* p, std::size_t n, const FrameHeader& h, bool* bad_crc) {
  const Attempt a = CheckImuFrame(p, n, h, bad_crc);
  if (a != Attempt::kFrame) return a;
  const Attempt inside = CheckedFrameInside(p, n, h.total_bytes);
  if (inside == Attempt::kNeedMore) return Attempt::kNeedMore;
  return inside == Attempt::kFrame ? Attempt::kNotAFrame : Attempt::kFrame;
}

}  // namespace

bool MavlinkDecoderOptions::Check(std::string* why) const {
  for (const double v : {raw_imu_gyro_rad_per_s_per_count, raw_imu_accel_m_per_s2_per_count}) {
    if (!std::isfinite(v) || v <= 0) {
      *why = "MAVLink RAW_IMU scales must be finite and > 0 (gyro rad/s and accel m/s² per count)";
      return false;
    }
  }
  return true;
}

uint16_t MavlinkCrc(const uint8_t* bytes, std::size_t size, int crc_extra) {
  // CRC-16/MCRF4XX: polynomial 0x1021, initial 0xFFFF, input and output reflected, no final xor.
  boost::crc_optimal<16, 0x1021, 0xFFFF, 0, true, true> x25;
  x25.process_bytes(bytes, size);
  if (crc_extra >= 0 && crc_extra <= 0xFF) x25.process_byte(static_cast<unsigned char>(crc_extra));
  return x25.checksum();
}

int MavlinkCrcExtra(int msgid) {
  switch (msgid) {
    case kMavlinkMsgidHighresImu:
      return kMavlinkCrcExtraHighresImu;
    case kMavlinkMsgidScaledImu:
      return kMavlinkCrcExtraScaledImu;
    case kMavlinkMsgidRawImu:
      return kMavlinkCrcExtraRawImu;
    default:
      return -1;
  }
}

std::vector<MavlinkImuSample> MavlinkDecoder::Feed(const std::string& bytes) {
  pending_ += bytes;
  std::vector<MavlinkImuSample> samples;
  const auto* data = reinterpret_cast<const uint8_t*>(pending_.data());
  const std::size_t size = pending_.size();
  std::size_t pos = 0;
  while (pos < size) {
    const uint8_t* p = data + pos;
    const std::size_t n = size - pos;
    FrameHeader h;
    Attempt attempt = Attempt::kNotAFrame;
    bool bad_crc = false;
    if (!IsMagic(p[0])) {
      attempt = Attempt::kNotAFrame;
    } else if (!ReadHeader(p, n, &h)) {
      attempt = Attempt::kNeedMore;
    } else if (h.unknown_incompat) {
      attempt = Attempt::kNotAFrame;
    } else if (MavlinkCrcExtra(h.msgid) < 0) {
      attempt = CheckOtherFrame(p, n, h);
      if (attempt == Attempt::kFrame) ++counters_.unknown_msgid;
    } else {
      attempt = CheckImuFrameAlone(p, n, h, &bad_crc);
      if (bad_crc) ++counters_.bad_crc;
      if (attempt == Attempt::kFrame) {
        ++counters_.frames_ok;
        uint8_t payload[kLongestPayload] = {};  // zero-filled: MAVLink 2 truncation
        std::memcpy(payload, p + h.header_bytes, h.payload_bytes);
        MavlinkImuSample s{};
        if (DecodeImu(h, payload, options_, &s)) {
          samples.push_back(s);
        } else {
          ++counters_.stale_gyro;
        }
      }
    }
    if (attempt == Attempt::kNeedMore) break;
    if (attempt == Attempt::kFrame) {
      pos += h.total_bytes;
    } else {
      ++counters_.bytes_skipped;
      ++pos;
    }
  }
  pending_.erase(0, pos);
  return samples;
}

}  // namespace bifilar::live
