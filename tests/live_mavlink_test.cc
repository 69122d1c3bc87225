// The MAVLink IMU decoder (pipeline/live/mavlink.h) against the standard: CRC_EXTRA and the
// wire layout recomputed from common.xml's field lists, round trips of the three messages in
// MAVLink 1 and 2 (truncated and signed), bad checksums, garbage and frames split anywhere.
#include <algorithm>
#include <cstring>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "base/units.h"
#include "pipeline/live/mavlink.h"
#include "pipeline/live/mavlink_writer.h"
#include "tests/live_feed.h"

namespace bifilar::live {
namespace {

using testing::AsMavlinkSamples;
using testing::ExpectHighresEqual;
using testing::HighresFrames;
using testing::SimulatedSwing;

// A message as common.xml (message_definitions/v1.0, mavlink/mavlink) declares it: fields in
// declaration order, those after <extensions/> apart.
struct XmlMessage {
  std::string name;
  int msgid;
  std::vector<std::pair<std::string, std::string>> fields;      // type, name
  std::vector<std::pair<std::string, std::string>> extensions;  // type, name
};

const std::vector<XmlMessage>& CommonXmlImuMessages() {
  static const std::vector<XmlMessage> messages = {
      {"SCALED_IMU",
       26,
       {{"uint32_t", "time_boot_ms"},
        {"int16_t", "xacc"},
        {"int16_t", "yacc"},
        {"int16_t", "zacc"},
        {"int16_t", "xgyro"},
        {"int16_t", "ygyro"},
        {"int16_t", "zgyro"},
        {"int16_t", "xmag"},
        {"int16_t", "ymag"},
        {"int16_t", "zmag"}},
       {{"int16_t", "temperature"}}},
      {"RAW_IMU",
       27,
       {{"uint64_t", "time_usec"},
        {"int16_t", "xacc"},
        {"int16_t", "yacc"},
        {"int16_t", "zacc"},
        {"int16_t", "xgyro"},
        {"int16_t", "ygyro"},
        {"int16_t", "zgyro"},
        {"int16_t", "xmag"},
        {"int16_t", "ymag"},
        {"int16_t", "zmag"}},
       {{"uint8_t", "id"}, {"int16_t", "temperature"}}},
      {"HIGHRES_IMU",
       105,
       {{"uint64_t", "time_usec"},
        {"float", "xacc"},
        {"float", "yacc"},
        {"float", "zacc"},
        {"float", "xgyro"},
        {"float", "ygyro"},
        {"float", "zgyro"},
        {"float", "xmag"},
        {"float", "ymag"},
        {"float", "zmag"},
        {"float", "abs_pressure"},
        {"float", "diff_pressure"},
        {"float", "pressure_alt"},
        {"float", "temperature"},
        {"uint16_t", "fields_updated"}},
       {{"uint8_t", "id"}}},
  };
  return messages;
}

int TypeBytes(const std::string& type) {
  if (type == "uint64_t" || type == "double") return 8;
  if (type == "uint32_t" || type == "float") return 4;
  if (type == "uint16_t" || type == "int16_t") return 2;
  return 1;
}

// MAVLink's wire order: the base fields sorted by type size, largest first (a stable sort),
// then the extensions in declaration order.
std::vector<std::pair<std::string, std::string>> WireOrder(const XmlMessage& m) {
  auto order = m.fields;
  std::stable_sort(order.begin(), order.end(), [](const auto& a, const auto& b) {
    return TypeBytes(a.first) > TypeBytes(b.first);
  });
  return order;
}

uint16_t Crc(const std::string& text) {
  return MavlinkCrc(reinterpret_cast<const uint8_t*>(text.data()), text.size());
}

TEST(MavlinkStandard, CrcExtraRecomputedFromTheCommonXmlFieldLists) {
  // mavgen's rule: the CRC of "NAME " then "type name " of each base field in wire order,
  // folded to one byte (low ^ high).
  for (const XmlMessage& m : CommonXmlImuMessages()) {
    std::string text = m.name + " ";
    for (const auto& [type, name] : WireOrder(m)) text += type + " " + name + " ";
    const uint16_t crc = Crc(text);
    const int extra = (crc & 0xFF) ^ (crc >> 8);
    EXPECT_EQ(extra, MavlinkCrcExtra(m.msgid)) << m.name;
  }
  EXPECT_EQ(MavlinkCrcExtra(kMavlinkMsgidHighresImu), 93);
  EXPECT_EQ(MavlinkCrcExtra(kMavlinkMsgidScaledImu), 170);
  EXPECT_EQ(MavlinkCrcExtra(kMavlinkMsgidRawImu), 144);
  EXPECT_EQ(MavlinkCrcExtra(0), -1);  // HEARTBEAT: not read here
}

TEST(MavlinkStandard, CrcIsX25) {
  // CRC-16/MCRF4XX's check value: the CRC of "123456789" is 0x6F91.
  EXPECT_EQ(Crc("123456789"), 0x6F91);
}

// Each field of the payload laid out from the field list (not from the decoder's offsets)
// gets a distinct value; the decoded sample must carry the right ones.
TEST(MavlinkStandard, DecoderReadsTheFieldsWhereTheWireOrderPutsThem) {
  for (const XmlMessage& m : CommonXmlImuMessages()) {
    auto order = WireOrder(m);
    order.insert(order.end(), m.extensions.begin(), m.extensions.end());
    std::string payload;
    std::size_t base_bytes = 0;
    int k = 0;
    for (const auto& [type, name] : order) {
      ++k;
      uint64_t bits = 0;
      if (type == "float") {
        const float f = 0.5f * k;  // xacc 1.0, yacc 1.5, ... (exact in float)
        std::memcpy(&bits, &f, sizeof f);
      } else if (name == "fields_updated") {
        bits = kHighresImuUpdatedAccel | kHighresImuUpdatedGyro;
      } else {
        bits = 100 * k;  // the times, counts and id: distinct
      }
      for (int b = 0; b < TypeBytes(type); ++b)
        payload += static_cast<char>((bits >> 8 * b) & 0xFF);
      if (k == static_cast<int>(m.fields.size())) base_bytes = payload.size();
    }
    MavlinkDecoder decoder;
    const auto samples =
        decoder.Feed(EncodeMavlinkFrame(m.msgid, payload, base_bytes, MavlinkFrameOptions()));
    ASSERT_EQ(samples.size(), 1u) << m.name;
    const MavlinkImuSample& s = samples[0];
    // In wire order the time is field 1, the accelerations 2..4 and the rates 5..7.
    if (m.msgid == kMavlinkMsgidHighresImu) {
      EXPECT_DOUBLE_EQ(s.t_s, 100e-6);
      EXPECT_EQ(s.accel_m_per_s2[0], 1.0);
      EXPECT_EQ(s.accel_m_per_s2[2], 2.0);
      EXPECT_EQ(s.gyro_rad_per_s[0], 2.5);
      EXPECT_EQ(s.gyro_rad_per_s[2], 3.5);
      EXPECT_EQ(s.imu_instance, 1600 % 256);  // id, field 16
    } else {
      const double t_scale = m.msgid == kMavlinkMsgidScaledImu ? 1e-3 : 1e-6;
      EXPECT_DOUBLE_EQ(s.t_s, 100 * t_scale);
      EXPECT_DOUBLE_EQ(s.accel_m_per_s2[0], 200 * 1e-3 * kStandardGravityMps2);
      EXPECT_DOUBLE_EQ(s.accel_m_per_s2[2], 400 * 1e-3 * kStandardGravityMps2);
      EXPECT_DOUBLE_EQ(s.gyro_rad_per_s[0], 500 * 1e-3);
      EXPECT_DOUBLE_EQ(s.gyro_rad_per_s[2], 700 * 1e-3);
      if (m.msgid == kMavlinkMsgidRawImu) {
        EXPECT_EQ(s.imu_instance, 1100 % 256);  // id, field 11
      }
    }
    EXPECT_EQ(decoder.counters().frames_ok, 1);
  }
}

// The sample a frame of `msgid` carries of `sent`: values rounded as the message stores them.
MavlinkImuSample AsSent(const MavlinkImuSample& sent, int msgid) {
  MavlinkImuSample s = sent;
  s.msgid = msgid;
  for (int k = 0; k < 3; ++k) {
    if (msgid == kMavlinkMsgidHighresImu) {
      s.gyro_rad_per_s[k] = static_cast<float>(sent.gyro_rad_per_s[k]);
      s.accel_m_per_s2[k] = static_cast<float>(sent.accel_m_per_s2[k]);
    } else {
      const double g = 1e-3 * kStandardGravityMps2;
      s.gyro_rad_per_s[k] = std::round(sent.gyro_rad_per_s[k] / 1e-3) * 1e-3;
      s.accel_m_per_s2[k] = std::round(sent.accel_m_per_s2[k] / g) * g;
    }
  }
  s.t_s = msgid == kMavlinkMsgidScaledImu ? std::llround(sent.t_s * 1e3) * 1e-3
                                          : std::llround(sent.t_s * 1e6) * 1e-6;
  return s;
}

void ExpectSame(const MavlinkImuSample& want, const MavlinkImuSample& got) {
  EXPECT_EQ(got.msgid, want.msgid);
  EXPECT_DOUBLE_EQ(got.t_s, want.t_s);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(got.gyro_rad_per_s[k], want.gyro_rad_per_s[k], 1e-15);
    EXPECT_NEAR(got.accel_m_per_s2[k], want.accel_m_per_s2[k], 1e-14);
  }
  EXPECT_EQ(got.sysid, want.sysid);
  EXPECT_EQ(got.compid, want.compid);
  EXPECT_EQ(got.has_accel, want.has_accel);
}

std::string FromHex(const std::string& hex) {
  std::string bytes;
  for (std::size_t i = 0; i + 1 < hex.size(); i += 2) {
    bytes += static_cast<char>(std::stoi(hex.substr(i, 2), nullptr, 16));
  }
  return bytes;
}

// Two frames built outside this code (a Python transcription of pymavlink's x25crc and frame
// packing, struct.pack of the fields in wire order): the decoder reads them, the writer makes
// the same bytes.
TEST(MavlinkStandard, FramesFromTheReferenceAlgorithm) {
  // MAVLink 2 HIGHRES_IMU, seq 7, sys 1, comp 1: time_usec 1e6, acc (0.5, -1.25, -9.75) m/s²,
  // gyro (0.125, -0.0625, 2.5) rad/s, fields_updated 0x3F; truncated to 61 bytes.
  const std::string highres = FromHex(
      "fd3d000007010169000040420f00000000000000003f0000a0bf00001cc10000003e000080bd000020400000"
      "00000000000000000000000000000000000000000000000000003f6aad");
  // MAVLink 1 SCALED_IMU, seq 7: time_boot_ms 2500, acc (10, -20, -1000) mG,
  // gyro (125, -63, 2500) mrad/s.
  const std::string scaled =
      FromHex("fe160701011ac40900000a00ecff18fc7d00c1ffc40900000000000053f7");
  MavlinkDecoder decoder;
  const auto got = decoder.Feed(highres + scaled);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(decoder.counters().bad_crc, 0);
  MavlinkImuSample want{
      1.0, {0.125, -0.0625, 2.5}, {0.5, -1.25, -9.75}, true, kMavlinkMsgidHighresImu, 1, 1};
  ExpectSame(want, got[0]);
  const double mg = 1e-3 * kStandardGravityMps2;
  MavlinkImuSample want_scaled{2.5,  {0.125, -0.063, 2.5},   {10 * mg, -20 * mg, -1000 * mg},
                               true, kMavlinkMsgidScaledImu, 1,
                               1};
  ExpectSame(want_scaled, got[1]);
  MavlinkFrameOptions o;
  o.seq = 7;
  EXPECT_EQ(EncodeHighresImu(want, 0x3F, o), highres);
  o.version = 1;
  EXPECT_EQ(EncodeScaledImu(want_scaled, o), scaled);
}

std::string Frame(const MavlinkImuSample& s, int msgid, const MavlinkFrameOptions& o) {
  if (msgid == kMavlinkMsgidHighresImu) {
    return EncodeHighresImu(s, kHighresImuUpdatedAccel | kHighresImuUpdatedGyro, o);
  }
  if (msgid == kMavlinkMsgidScaledImu) return EncodeScaledImu(s, o);
  return EncodeRawImu(s, MavlinkDecoderOptions(), o);
}

TEST(MavlinkDecoder, RoundTripOfTheThreeMessagesInMavlink1And2) {
  const auto samples = AsMavlinkSamples(SimulatedSwing(3.0, 100.0, 3));
  ASSERT_GT(samples.size(), 250u);
  for (const int msgid : {kMavlinkMsgidHighresImu, kMavlinkMsgidScaledImu, kMavlinkMsgidRawImu}) {
    for (const int version : {1, 2}) {
      for (const bool signed_frame : {false, true}) {
        if (version == 1 && signed_frame) continue;
        MavlinkFrameOptions o;
        o.version = version;
        o.signed_frame = signed_frame;
        o.sysid = 7;
        o.compid = 200;
        std::string stream;
        for (const auto& s : samples) stream += Frame(s, msgid, o);
        MavlinkDecoder decoder;
        const auto got = decoder.Feed(stream);
        ASSERT_EQ(got.size(), samples.size()) << msgid << " v" << version;
        for (std::size_t i = 0; i < got.size(); ++i) {
          MavlinkImuSample want = AsSent(samples[i], msgid);
          want.sysid = 7;
          want.compid = 200;
          ExpectSame(want, got[i]);
        }
        EXPECT_EQ(decoder.counters().frames_ok, static_cast<long>(samples.size()));
        EXPECT_EQ(decoder.counters().bad_crc, 0);
        EXPECT_EQ(decoder.counters().bytes_skipped, 0);
        EXPECT_EQ(decoder.pending_bytes(), 0u);
      }
    }
  }
}

TEST(MavlinkDecoder, TruncatedPayloadsAreZeroFilled) {
  // A sample at rest on the z axis: HIGHRES_IMU's mag, pressure, temperature and id are zero,
  // so MAVLink 2 cuts the payload after fields_updated (62 bytes of 63); SCALED_IMU and
  // RAW_IMU, with zero rates and accelerations on y and z, are cut after xgyro.
  MavlinkImuSample s{};
  s.t_s = 12.5;
  s.gyro_rad_per_s[0] = 0.25;
  s.accel_m_per_s2[0] = 1.0;
  s.has_accel = true;
  s.sysid = s.compid = 1;
  for (const int msgid : {kMavlinkMsgidHighresImu, kMavlinkMsgidScaledImu, kMavlinkMsgidRawImu}) {
    const std::string frame = Frame(s, msgid, MavlinkFrameOptions());
    const std::size_t full = msgid == kMavlinkMsgidHighresImu  ? kMavlinkHighresImuBytes
                             : msgid == kMavlinkMsgidScaledImu ? kMavlinkScaledImuBytes
                                                               : kMavlinkRawImuBytes;
    EXPECT_LT(static_cast<uint8_t>(frame[1]), full) << msgid;  // really truncated
    MavlinkDecoder decoder;
    const auto got = decoder.Feed(frame);
    ASSERT_EQ(got.size(), 1u) << msgid;
    ExpectSame(AsSent(s, msgid), got[0]);
  }
  // All zero but the first byte: a payload of one byte.
  MavlinkImuSample zero{};
  zero.t_s = 1e-6;  // time_usec 1
  zero.has_accel = true;
  zero.sysid = zero.compid = 1;
  const std::string tiny = EncodeRawImu(zero, MavlinkDecoderOptions(), MavlinkFrameOptions());
  EXPECT_EQ(tiny[1], 1);
  MavlinkDecoder decoder;
  const auto got = decoder.Feed(tiny);
  ASSERT_EQ(got.size(), 1u);
  ExpectSame(AsSent(zero, kMavlinkMsgidRawImu), got[0]);
}

// Every single-bit error in a frame: never a sample from it; the good frame after it is read.
TEST(MavlinkDecoder, AFlippedBitIsNeverASample) {
  const auto samples = AsMavlinkSamples(SimulatedSwing(1.0, 100.0, 4));
  for (const int version : {1, 2}) {
    MavlinkFrameOptions o;
    o.version = version;
    const std::string bad_source = Frame(samples[0], kMavlinkMsgidHighresImu, o);
    const std::string good = Frame(samples[1], kMavlinkMsgidHighresImu, o);
    for (std::size_t bit = 0; bit < 8 * bad_source.size(); ++bit) {
      std::string bad = bad_source;
      bad[bit / 8] = static_cast<char>(bad[bit / 8] ^ (1 << (bit % 8)));
      MavlinkDecoder decoder;
      const auto got = decoder.Feed(bad + good + good);
      ASSERT_GE(got.size(), 1u) << "bit " << bit;
      for (const auto& s : got) ExpectHighresEqual(samples[1], s);
      const std::size_t header = version == 1 ? 6 : 10;
      if (bit / 8 >= header) {  // payload or checksum: a checksum error, both good frames read
        EXPECT_EQ(decoder.counters().bad_crc, 1) << "bit " << bit;
        EXPECT_EQ(got.size(), 2u) << "bit " << bit;
        EXPECT_EQ(decoder.counters().bytes_skipped, static_cast<long>(bad.size()));
      }
    }
  }
}

TEST(MavlinkDecoder, GarbageBetweenFramesIsCountedAndSkipped) {
  const auto samples = AsMavlinkSamples(SimulatedSwing(2.0, 100.0, 5));
  const auto frames = HighresFrames(samples);
  std::mt19937_64 rng(34);
  // Garbage without a start byte: every garbage byte counted, exactly.
  std::string stream;
  long garbage = 0;
  for (const auto& f : frames) {
    const int n = std::uniform_int_distribution<int>(0, 40)(rng);
    for (int i = 0; i < n; ++i) {
      stream += static_cast<char>(std::uniform_int_distribution<int>(0, 0xFC)(rng));
    }
    garbage += n;
    stream += f;
  }
  MavlinkDecoder decoder;
  auto got = decoder.Feed(stream);
  ASSERT_EQ(got.size(), samples.size());
  for (std::size_t i = 0; i < got.size(); ++i) ExpectHighresEqual(samples[i], got[i]);
  EXPECT_EQ(decoder.counters().bytes_skipped, garbage);
  EXPECT_EQ(decoder.counters().bad_crc, 0);
  // Any bytes, start bytes included (false starts): every frame still read, nothing invented.
  stream.clear();
  for (const auto& f : frames) {
    const int n = std::uniform_int_distribution<int>(0, 300)(rng);
    for (int i = 0; i < n; ++i) {
      stream += static_cast<char>(std::uniform_int_distribution<int>(0, 255)(rng));
    }
    stream += f;
  }
  stream += std::string(300, '\0');  // flushes a false start held at the end
  MavlinkDecoder any;
  got = any.Feed(stream);
  ASSERT_EQ(got.size(), samples.size());
  for (std::size_t i = 0; i < got.size(); ++i) ExpectHighresEqual(samples[i], got[i]);
  EXPECT_GT(any.counters().bytes_skipped, 0);
}

// A realistic mix: MAVLink 1 and 2, signed, truncated, other messages (HEARTBEAT, ATTITUDE
// with checksums this decoder cannot check) and garbage.
std::string MixedStream(const std::vector<MavlinkImuSample>& samples) {
  std::string stream = "\x01\x02 modem noise";
  for (std::size_t i = 0; i < samples.size(); ++i) {
    MavlinkFrameOptions o;
    o.version = i % 5 == 0 ? 1 : 2;
    o.signed_frame = i % 7 == 3;
    o.seq = static_cast<int>(i % 256);
    stream += Frame(samples[i], kMavlinkMsgidHighresImu, o);
    if (i % 10 == 0) stream += EncodeMavlinkFrame(0, std::string(9, '\x05'), 9, o);     // HEARTBEAT
    if (i % 10 == 5) stream += EncodeMavlinkFrame(30, std::string(28, '\x11'), 28, o);  // ATTITUDE
  }
  return stream;
}

TEST(MavlinkDecoder, FramesSplitAnywhereGiveTheSameSamples) {
  const auto samples = AsMavlinkSamples(SimulatedSwing(2.0, 100.0, 6));
  const std::string stream = MixedStream(samples);
  MavlinkDecoder whole;
  const auto want = whole.Feed(stream);
  ASSERT_EQ(want.size(), samples.size());
  for (std::size_t i = 0; i < want.size(); ++i) ExpectHighresEqual(samples[i], want[i]);
  EXPECT_EQ(whole.counters().unknown_msgid, 40);  // 20 HEARTBEAT, 20 ATTITUDE
  EXPECT_EQ(whole.counters().bytes_skipped, 14);  // the modem noise
  // Byte by byte, and in random chunks (as a serial read returns them).
  MavlinkDecoder by_byte;
  std::vector<MavlinkImuSample> got;
  for (const char c : stream) {
    for (const auto& s : by_byte.Feed(std::string(1, c))) got.push_back(s);
  }
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < got.size(); ++i) ExpectHighresEqual(samples[i], got[i]);
  std::mt19937_64 rng(7);
  MavlinkDecoder by_chunk;
  got.clear();
  for (std::size_t at = 0; at < stream.size();) {
    const std::size_t n = std::uniform_int_distribution<std::size_t>(1, 200)(rng);
    for (const auto& s : by_chunk.Feed(stream.substr(at, n))) got.push_back(s);
    at += n;
  }
  ASSERT_EQ(got.size(), want.size());
  for (const auto* d : {&by_byte, &by_chunk}) {
    EXPECT_EQ(d->counters().frames_ok, whole.counters().frames_ok);
    EXPECT_EQ(d->counters().unknown_msgid, whole.counters().unknown_msgid);
    EXPECT_EQ(d->counters().bytes_skipped, whole.counters().bytes_skipped);
  }
}

// A frame cut before its last checksum byte, where the next frame's start byte happens to be
// that byte (1 in 256): both checksums match, and the whole frame after it wins.
TEST(MavlinkDecoder, ACutFrameWhoseChecksumCameRightDoesNotSwallowTheNext) {
  const auto samples = AsMavlinkSamples(SimulatedSwing(20.0, 100.0, 8));
  MavlinkFrameOptions v1;
  v1.version = 1;
  std::string cut;
  for (const auto& s : samples) {
    const std::string frame = EncodeScaledImu(s, v1);
    if (static_cast<uint8_t>(frame.back()) == kMavlink2Magic) {
      cut = frame.substr(0, frame.size() - 1);
      break;
    }
  }
  ASSERT_FALSE(cut.empty()) << "no frame of the swing has the checksum byte wanted";
  const auto frames = HighresFrames(samples);
  MavlinkDecoder decoder;
  std::vector<MavlinkImuSample> got;
  for (const char c : cut + frames[0] + frames[1]) {  // byte by byte: the worst case
    for (const auto& s : decoder.Feed(std::string(1, c))) got.push_back(s);
  }
  ASSERT_EQ(got.size(), 2u);
  ExpectHighresEqual(samples[0], got[0]);
  ExpectHighresEqual(samples[1], got[1]);
  EXPECT_EQ(decoder.counters().bytes_skipped, static_cast<long>(cut.size()));
}

TEST(MavlinkDecoder, HighresFieldsUpdatedMarksOldReadings) {
  MavlinkImuSample s{};
  s.t_s = 2.0;
  s.gyro_rad_per_s[2] = 0.5;
  s.accel_m_per_s2[2] = -9.8;
  MavlinkFrameOptions o;
  MavlinkDecoder decoder;
  // Gyro new, accel old; nothing marked (a sender without the bitmap: all new); only the
  // magnetometer new (the gyro reading is a repeat: no sample).
  auto got = decoder.Feed(EncodeHighresImu(s, kHighresImuUpdatedGyro, o) +
                          EncodeHighresImu(s, 0, o) + EncodeHighresImu(s, 0x01C0, o));
  ASSERT_EQ(got.size(), 2u);
  EXPECT_FALSE(got[0].has_accel);
  EXPECT_TRUE(got[1].has_accel);
  EXPECT_EQ(decoder.counters().stale_gyro, 1);
  EXPECT_EQ(decoder.counters().frames_ok, 3);
}

TEST(MavlinkDecoder, RawImuScalesAreTheUsers) {
  MavlinkDecoderOptions scales;
  std::string why;
  ASSERT_TRUE(scales.Check(&why));
  scales.raw_imu_gyro_rad_per_s_per_count = 1.0 / 16.4 * kRadPerDeg;      // a ±2000 °/s ADC count
  scales.raw_imu_accel_m_per_s2_per_count = kStandardGravityMps2 / 2048;  // ±16 g
  MavlinkImuSample s{};
  s.t_s = 3.0;
  s.gyro_rad_per_s[1] = 100 * scales.raw_imu_gyro_rad_per_s_per_count;
  s.accel_m_per_s2[2] = -2048 * scales.raw_imu_accel_m_per_s2_per_count;
  MavlinkDecoder decoder(scales);
  const auto got = decoder.Feed(EncodeRawImu(s, scales, MavlinkFrameOptions()));
  ASSERT_EQ(got.size(), 1u);
  EXPECT_DOUBLE_EQ(got[0].gyro_rad_per_s[1], s.gyro_rad_per_s[1]);
  EXPECT_DOUBLE_EQ(got[0].accel_m_per_s2[2], -kStandardGravityMps2);
  scales.raw_imu_gyro_rad_per_s_per_count = 0;
  EXPECT_FALSE(scales.Check(&why));
  EXPECT_NE(why.find("RAW_IMU"), std::string::npos);
}

TEST(MavlinkDecoder, UnknownIncompatFlagsAreNotRead) {
  MavlinkImuSample s{};
  s.t_s = 1.0;
  std::string frame = Frame(s, kMavlinkMsgidHighresImu, MavlinkFrameOptions());
  frame[2] = 0x02;  // an incompat flag from a future MAVLink
  MavlinkDecoder decoder;
  EXPECT_TRUE(decoder.Feed(frame).empty());
  EXPECT_EQ(decoder.counters().frames_ok, 0);
  EXPECT_EQ(decoder.counters().bytes_skipped, static_cast<long>(frame.size()));
}

}  // namespace
}  // namespace bifilar::live
