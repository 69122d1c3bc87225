// ArduPilot DataFlash reader (pipeline/logs/dataflash.h) and writer
// (pipeline/logs/dataflash_writer.h): every format character against the values written, FMTU
// units and multipliers, IMU instances (I field, IMU/IMU2, TimeMS in old logs, GYR with ACC),
// FMT redefinitions and unknown messages, resync past bad sync bytes and garbage, a log cut
// mid-message, bad input (always an error naming the file and what was found), random damage
// (never a crash), and a simulated swing fitted from .bin and from CSV.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "base/units.h"
#include "base/user_error.h"
#include "pipeline/commands/fit_command.h"
#include "pipeline/logs/dataflash.h"
#include "pipeline/logs/dataflash_writer.h"
#include "pipeline/logs/imu_log.h"
#include "pipeline/logs/imu_log_writer.h"
#include "test_support.h"

namespace bifilar {
namespace {

using test_support::Bifilar;
using test_support::Contains;
using test_support::ReadFile;
using test_support::TempDir;
using test_support::WriteFile;

std::string ErrorOf(const std::string& bytes, const std::string& name,
                    const ImuLogOptions& options = ImuLogOptions()) {
  try {
    ReadDataflashImu(bytes, name, options);
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}

// A new-style IMU message (TimeUS,I,GyrX..AccZ,...) of instance `instance` at `t_us`.
std::string ImuBody(uint64_t t_us, int instance, double gx, double gy, double gz) {
  DataflashPayload p;
  p.U64(t_us).U8(static_cast<uint8_t>(instance));
  p.F32(static_cast<float>(gx)).F32(static_cast<float>(gy)).F32(static_cast<float>(gz));
  p.F32(0.0f).F32(0.0f).F32(-9.8f);
  p.U32(0).U32(0).F32(25.0f).U8(1).U8(1).U16(1000).U16(1000);
  return p.str();
}

constexpr int kImu = 48;
constexpr char kImuFormat[] = "QBffffffIIfBBHH";
constexpr char kImuLabels[] = "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ,EG,EA,T,GH,AH,GHz,AHz";

// A log of `n` IMU messages at 100 Hz per instance, instances 0..instances-1 interleaved; gyro x
// of instance i at sample k is 0.01 k + i.
std::string NewStyleLog(int n, int instances) {
  DataflashWriter w;
  w.Format(kImu, "IMU", kImuFormat, kImuLabels);
  for (int k = 0; k < n; ++k) {
    for (int i = 0; i < instances; ++i) {
      w.Message(kImu, ImuBody(1000000 + 10000 * k, i, 0.01 * k + i, 0.5, -0.25));
    }
  }
  return w.bytes();
}

TEST(DataflashReader, EveryFormatCharacterDecodes) {
  DataflashWriter w;
  // 16 characters at most per FMT: two messages cover all 21 (strings between numbers, so every
  // width is checked by the offset of the field after it).
  w.Format(200, "TST1", "bBhHiIfdnNcCeELM", "b,B,h,H,i,I,f,d,n,N,c,C,e,E,L,M");
  w.Format(201, "TST2", "qQaZf", "q,Q,a,Z,f2");
  DataflashPayload p1;
  p1.I8(-7).U8(250).I16(-30000).U16(60000).I32(-2000000000).U32(4000000000u).F32(1.5f);
  p1.F64(-2.25).Text("abcd", 4).Text("sixteen chars!!", 16);
  p1.I16(-12345).U16(54321).I32(-1234567).U32(3456789012u).I32(-353456789).U8(6);
  w.Message(200, p1.str());
  DataflashPayload p2;
  p2.I64(-(int64_t{1} << 60)).U64(uint64_t{1} << 63);
  for (int i = 0; i < 32; ++i) p2.I16(static_cast<int16_t>(i));
  p2.Text("a Z string", 64).F32(-3.0f);
  w.Message(201, p2.str());

  DataflashRequest r1;
  r1.message = "TST1";
  r1.fields = {"b", "B", "h", "H", "i", "I", "f", "d", "c", "C", "e", "E", "L", "M"};
  const DataflashContents c1 = ParseDataflash(w.bytes(), "t.bin", r1);
  ASSERT_EQ(c1.rows(), 1);
  const std::vector<double> want = {-7,        250,         -30000,      60000,   -2e9,
                                    4e9,       1.5,         -2.25,       -123.45, 543.21,
                                    -12345.67, 34567890.12, -35.3456789, 6};
  for (size_t k = 0; k < want.size(); ++k) {
    EXPECT_NEAR(c1.values[k], want[k], 1e-9 * std::max(1.0, std::abs(want[k]))) << r1.fields[k];
  }
  DataflashRequest r2;
  r2.message = "TST2";
  r2.fields = {"q", "Q", "f2"};
  const DataflashContents c2 = ParseDataflash(w.bytes(), "t.bin", r2);
  ASSERT_EQ(c2.rows(), 1);
  EXPECT_EQ(c2.values[0], -std::ldexp(1.0, 60));
  EXPECT_EQ(c2.values[1], std::ldexp(1.0, 63));
  EXPECT_EQ(c2.values[2], -3.0);  // after a[32] (64 bytes) and Z (64 bytes)
  EXPECT_TRUE(c2.warnings.empty());
  // A string field is not a number: the error names the message, the field and its type.
  r2.fields = {"Z"};
  EXPECT_TRUE(Contains(ErrorOf(w.bytes(), "t.bin"), "without IMU"));
  try {
    ParseDataflash(w.bytes(), "t.bin", r2);
    ADD_FAILURE() << "no error";
  } catch (const UserError& e) {
    EXPECT_TRUE(Contains(e.what(), "t.bin: message TST2")) << e.what();
    EXPECT_TRUE(Contains(e.what(), "field 'Z' of type 'Z' (a string), not a number")) << e.what();
  }
}

TEST(DataflashReader, FmtuUnitsAndMultipliers) {
  DataflashWriter w;
  w.UnitFormats();
  w.Format(202, "MAG", "Qhc", "TimeUS,MagX,Temp");
  w.Unit('G', "Gauss");
  w.Unit('O', "degC");
  w.Multiplier('C', 1e-3);
  w.FormatUnits(202, "sGO", "FCB");
  w.Message(202, DataflashPayload().U64(5).I16(-1500).I16(2512).str());
  DataflashRequest r;
  r.message = "MAG";
  r.fields = {"TimeUS", "MagX", "Temp"};
  const DataflashContents c = ParseDataflash(w.bytes(), "m.bin", r);
  ASSERT_EQ(c.rows(), 1);
  EXPECT_EQ(c.values[1], -1500);         // 'h': as stored; FMTU multiplier C (1e-3) beside it
  EXPECT_DOUBLE_EQ(c.values[2], 25.12);  // 'c': stored x100
  EXPECT_EQ(c.field_units[1], "Gauss");
  EXPECT_EQ(c.field_units[2], "degC");
  EXPECT_DOUBLE_EQ(c.field_multipliers[0], 1e-6);  // ArduPilot's table: F
  EXPECT_DOUBLE_EQ(c.field_multipliers[1], 1e-3);  // from the MULT message
  EXPECT_DOUBLE_EQ(c.field_multipliers[2], 1e-2);  // B: the raw value x 1e-2, as 'c' already is
}

TEST(DataflashReader, GyroInDegPerSecondByFmtuIsReadInRadPerSecond) {
  DataflashWriter w;
  w.UnitFormats();
  w.Format(kImu, "IMU", kImuFormat, kImuLabels);
  w.FormatUnits(kImu, "s#kkkooo--O--zz", "F-000000-----00");
  for (int k = 0; k < 10; ++k) w.Message(kImu, ImuBody(10000 * k, 0, 90.0, 0, 0));
  const ImuData d = ReadDataflashImu(w.bytes(), "deg.bin");
  ASSERT_EQ(d.size(), 10u);
  EXPECT_NEAR(d.gyro_in_imu[3][0], 90.0 * kRadPerDeg, 1e-12);
  EXPECT_NEAR(d.t_s[3], 0.03, 1e-15);
  EXPECT_NEAR(d.accel_in_imu[3][2], -9.8, 1e-6);
}

TEST(DataflashReader, InstancesByFieldDefaultTheLowestAndChosenByOption) {
  const std::string log = NewStyleLog(20, 3);
  const ImuData first = ReadDataflashImu(log, "three.bin");
  ASSERT_EQ(first.size(), 20u);
  EXPECT_NEAR(first.gyro_in_imu[5][0], 0.05, 1e-7);
  bool said = false;
  for (const std::string& w : first.warnings) said = said || Contains(w, "3 IMU instances");
  EXPECT_TRUE(said);
  ImuLogOptions options;
  options.dataflash_instance = 2;
  const ImuData third = ReadDataflashImu(log, "three.bin", options);
  ASSERT_EQ(third.size(), 20u);
  EXPECT_NEAR(third.gyro_in_imu[5][0], 2.05, 1e-6);
  options.dataflash_instance = 4;
  const std::string e = ErrorOf(log, "three.bin", options);
  EXPECT_TRUE(Contains(e, "three.bin: no IMU instance 4")) << e;
  EXPECT_TRUE(Contains(e, "0 (IMU, 20 messages), 1 (IMU, 20 messages), 2 (IMU, 20 messages)")) << e;
  // inspect's listing: counts, rate and instances.
  const DataflashContents c = ParseDataflash(log, "three.bin");
  const DataflashMessageInfo* imu = c.Find("IMU");
  ASSERT_NE(imu, nullptr);
  EXPECT_EQ(imu->count, 60);
  EXPECT_EQ(imu->instance_field, "I");
  EXPECT_EQ(imu->instances.size(), 3u);
  EXPECT_NEAR(imu->rate_hz(), 59.0 / 0.19, 1e-9);
}

TEST(DataflashReader, OldLogsWithTimeMsAndImu2) {
  DataflashWriter w;
  w.Format(4, "IMU", "Iffffff", "TimeMS,GyrX,GyrY,GyrZ,AccX,AccY,AccZ");
  w.Format(22, "IMU2", "Iffffff", "TimeMS,GyrX,GyrY,GyrZ,AccX,AccY,AccZ");
  for (int k = 0; k < 15; ++k) {
    for (int i : {0, 1}) {
      DataflashPayload p;
      p.U32(20 * k + 7).F32(0.1f * k + i).F32(0).F32(0).F32(0).F32(0).F32(-9.81f);
      w.Message(i == 0 ? 4 : 22, p.str());
    }
  }
  ImuLogOptions options;
  options.dataflash_instance = 1;
  const ImuData d = ReadDataflashImu(w.bytes(), "old.bin", options);
  ASSERT_EQ(d.size(), 15u);
  EXPECT_NEAR(d.t_s[2], 0.047, 1e-15);  // TimeMS
  EXPECT_NEAR(d.gyro_in_imu[2][0], 1.2, 1e-6);
}

TEST(DataflashReader, GyrWithAccWhenThereIsNoImu) {
  DataflashWriter w;
  w.Format(222, "GYR", "QBQfff", "TimeUS,I,SampleUS,GyrX,GyrY,GyrZ");
  w.Format(221, "ACC", "QBQfff", "TimeUS,I,SampleUS,AccX,AccY,AccZ");
  for (int k = 0; k < 40; ++k) {
    w.Message(222, DataflashPayload()
                       .U64(900 + 1000 * k)
                       .U8(0)
                       .U64(1000 * k)
                       .F32(0.001f * k)
                       .F32(0)
                       .F32(0)
                       .str());
    if (k % 4 == 0) {
      w.Message(221, DataflashPayload()
                         .U64(900 + 1000 * k)
                         .U8(0)
                         .U64(1000 * k)
                         .F32(0)
                         .F32(0)
                         .F32(-0.1f * k)
                         .str());
    }
  }
  const ImuData d = ReadDataflashImu(w.bytes(), "gyr.bin");
  ASSERT_EQ(d.size(), 40u);
  EXPECT_NEAR(d.t_s[10], 0.010, 1e-15);  // SampleUS
  EXPECT_TRUE(d.has_accel());
  EXPECT_NEAR(d.accel_in_imu[9][2], -0.8, 1e-6);  // nearest ACC: sample 8
  EXPECT_NEAR(d.accel_in_imu[11][2], -1.2, 1e-6);
}

TEST(DataflashReader, UnknownMessagesAndFmtRedefinitionsAreFollowed) {
  DataflashWriter w;
  w.Format(kImu, "IMU", kImuFormat, kImuLabels);
  w.Format(150, "XYZW", "QZZZ", "TimeUS,A,B,C");  // 3 + 200 bytes, never decoded
  for (int k = 0; k < 10; ++k) {
    w.Message(kImu, ImuBody(10000 * k, 0, 0.1 * k, 0, 0));
    w.Message(150, DataflashPayload().U64(k).Text("x", 64).Text("y", 64).Text("z", 64).str());
  }
  // The IMU redefined with TimeUS after an extra field: messages after it use the new layout.
  w.Format(kImu, "IMU", "BQBffffff", "Extra,TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ");
  for (int k = 10; k < 20; ++k) {
    w.Message(kImu, DataflashPayload()
                        .U8(9)
                        .U64(10000 * k)
                        .U8(0)
                        .F32(0.1f * k)
                        .F32(0)
                        .F32(0)
                        .F32(0)
                        .F32(0)
                        .F32(-9.8f)
                        .str());
  }
  const ImuData d = ReadDataflashImu(w.bytes(), "redefined.bin");
  ASSERT_EQ(d.size(), 20u);
  EXPECT_NEAR(d.gyro_in_imu[15][0], 1.5, 1e-6);
  EXPECT_NEAR(d.t_s[15], 0.15, 1e-15);
  EXPECT_TRUE(d.warnings.empty()) << d.warnings.front();
}

TEST(DataflashReader, BadSyncBytesAndGarbageAreSkippedAndCounted) {
  DataflashWriter w;
  w.Format(kImu, "IMU", kImuFormat, kImuLabels);
  for (int k = 0; k < 30; ++k) {
    if (k == 10) w.Raw(std::string("\x01\x02\xA3\x95\x30garbage", 12));  // 12 bytes
    if (k == 20) {
      // A message whose sync bytes are damaged (a3 96): skipped whole. The messages before the
      // garbage and before it are kept (in step, of a type whose length framed messages before).
      std::string bad = "\xA3\x96" + std::string(1, static_cast<char>(kImu)) +
                        ImuBody(10000 * k, 0, 0.1 * k, 0, 0);
      w.Raw(bad);
      continue;
    }
    w.Message(kImu, ImuBody(10000 * k, 0, 0.1 * k, 0, 0));
  }
  const ImuData d = ReadDataflashImu(w.bytes(), "garbled.bin");
  ASSERT_EQ(d.size(), 29u);
  EXPECT_NEAR(d.gyro_in_imu[19][0], 1.9, 1e-6);  // kept: in step before the damaged sync
  EXPECT_NEAR(d.gyro_in_imu[20][0], 2.1, 1e-6);  // sample 20 was lost
  const DataflashContents c = ParseDataflash(w.bytes(), "garbled.bin");
  const int imu_length = 3 + 8 + 1 + 6 * 4 + 4 + 4 + 4 + 1 + 1 + 2 + 2;
  EXPECT_EQ(c.skipped_bytes, static_cast<uint64_t>(12 + imu_length));
  ASSERT_FALSE(d.warnings.empty());
  EXPECT_TRUE(Contains(d.warnings[0], "skipped " + std::to_string(12 + imu_length) +
                                          " byte(s) that are not part of a whole message, in 2 "
                                          "place(s)"))
      << d.warnings[0];
}

TEST(DataflashReader, LogCutMidMessageIsReadToTheLastWholeMessage) {
  const std::string whole = NewStyleLog(50, 1);
  const std::string cut = whole.substr(0, whole.size() - 20);
  const ImuData d = ReadDataflashImu(cut, "cut.bin");
  EXPECT_EQ(d.size(), 49u);
  ASSERT_FALSE(d.warnings.empty());
  EXPECT_EQ(d.warnings[0], "the log ends inside a IMU message at byte " +
                               std::to_string(whole.size() - 54) +
                               " (34 of its 54 bytes): the logger stopped mid-write; read to the "
                               "last whole message");
}

TEST(DataflashReader, BadInputIsAnErrorNamingTheFileAndWhatWasFound) {
  TempDir dir("bifilar_dataflash");
  // Not DataFlash: bytes, and text.
  std::string noise(4000, '\0');
  std::mt19937_64 rng(5);
  for (char& c : noise) c = static_cast<char>(rng() % 160);  // no a3 95 possible
  const std::string not_df = WriteFile(dir.path + "/noise.bin", noise);
  std::string e = ErrorOf(noise, not_df);
  EXPECT_TRUE(Contains(e, not_df + ": not an ArduPilot DataFlash log: no message found")) << e;
  const std::string text = WriteFile(dir.path + "/text.BIN", "hello, this is no log\n");
  ImuData data;
  ASSERT_FALSE(TryReadImuLog(text, ImuFormat(), ImuLogOptions(), &data, &e));
  EXPECT_TRUE(Contains(e, "not an ArduPilot DataFlash log")) << e;
  EXPECT_TRUE(Contains(e, "nor is it a CSV log")) << e;
  // Empty.
  const std::string empty = WriteFile(dir.path + "/empty.bin", "");
  ASSERT_FALSE(TryReadImuLog(empty, ImuFormat(), ImuLogOptions(), &data, &e));
  EXPECT_TRUE(Contains(e, empty + ": the file is empty (expected an ArduPilot DataFlash log)"))
      << e;
  // No IMU message: the messages found are listed.
  DataflashWriter w;
  w.Format(91, "MSG", "QZ", "TimeUS,Message");
  w.Message(91, DataflashPayload().U64(1).Text("ArduCopter V4.5.0", 64).str());
  e = ErrorOf(w.bytes(), "noimu.bin");
  EXPECT_TRUE(Contains(e, "noimu.bin: an ArduPilot DataFlash log without IMU (or GYR) messages"))
      << e;
  EXPECT_TRUE(Contains(e, "Messages found: FMT (2), MSG (1)")) << e;
  // An FMT that makes the IMU longer than its messages: no IMU header is followed by a message.
  DataflashWriter longer;
  longer.Format(kImu, "IMU", kImuFormat, kImuLabels, 120);
  for (int k = 0; k < 20; ++k) longer.Message(kImu, ImuBody(10000 * k, 0, 0, 0, 0));
  e = ErrorOf(longer.bytes(), "long.bin");
  EXPECT_TRUE(Contains(e, "long.bin: the FMT of IMU (type 48, byte 0") ||
              Contains(e, "long.bin: the FMT of IMU (type 48, byte 89"))
      << e;
  EXPECT_TRUE(Contains(e, "defines the message as 120 bytes")) << e;
  // An FMT whose length is too short for its format.
  DataflashWriter shorter;
  shorter.Format(kImu, "IMU", kImuFormat, kImuLabels, 20);
  for (int k = 0; k < 20; ++k) shorter.Message(kImu, ImuBody(10000 * k, 0, 0, 0, 0).substr(0, 17));
  e = ErrorOf(shorter.bytes(), "short.bin");
  EXPECT_TRUE(Contains(e, "short.bin: the FMT of IMU")) << e;
  EXPECT_TRUE(Contains(e,
                       "its length 20 is too short for its format 'QBffffffIIfBBHH', which needs "
                       "3 + 51 = 54 bytes"))
      << e;
  // An FMT with a length below its header: ignored, its messages are garbage, said so.
  DataflashWriter tiny;
  tiny.Format(kImu, "IMU", kImuFormat, kImuLabels, 2);
  for (int k = 0; k < 5; ++k) tiny.Message(kImu, ImuBody(10000 * k, 0, 0, 0, 0));
  e = ErrorOf(tiny.bytes(), "tiny.bin");
  EXPECT_TRUE(Contains(e, "tiny.bin: an ArduPilot DataFlash log without IMU")) << e;
}

TEST(DataflashReader, RandomDamageNeverCrashes) {
  const std::string log = NewStyleLog(200, 2);
  std::mt19937_64 rng(11);
  int read = 0, refused = 0;
  for (int trial = 0; trial < 300; ++trial) {
    std::string bytes = log;
    const int kind = trial % 4;
    if (kind == 0) bytes.resize(rng() % bytes.size());
    if (kind == 1)
      for (int i = 0; i < 20; ++i) bytes[rng() % bytes.size()] = static_cast<char>(rng());
    if (kind == 2)
      bytes.insert(rng() % bytes.size(), std::string(1 + rng() % 300, static_cast<char>(0xA3)));
    if (kind == 3) {
      const size_t at = rng() % 400;  // inside the FMT: lengths, formats, labels
      bytes[at] = static_cast<char>(rng());
    }
    try {
      const ImuData d = ReadDataflashImu(bytes, "damaged.bin");
      for (size_t k = 0; k < d.size(); ++k) ASSERT_TRUE(d.gyro_in_imu[k].allFinite());
      ++read;
    } catch (const UserError& e) {
      EXPECT_TRUE(Contains(e.what(), "damaged.bin")) << e.what();
      ++refused;
    }
  }
  EXPECT_GT(read, 100);
  EXPECT_EQ(read + refused, 300);
}

TEST(DataflashWriter, GyroOnlyAsGyrAndGzipRoundTrip) {
  ImuData data;
  for (int k = 0; k < 50; ++k) {
    data.t_s.push_back(0.0123456 * k);
    data.gyro_in_imu.emplace_back(0.1 * std::sin(0.2 * k), -0.2, 0.3 * k);
  }
  TempDir dir("bifilar_dataflash_gz");
  WriteImuDataflash(dir.path + "/g.bin.gz", data, "bifilar test, seed 1");
  const ImuData back = ReadImuLog(dir.path + "/g.bin.gz", ImuFormat());
  ASSERT_EQ(back.size(), data.size());
  EXPECT_FALSE(back.has_accel());
  for (size_t k = 0; k < data.size(); ++k) {
    EXPECT_EQ(back.t_s[k], std::llround(data.t_s[k] * 1e6) * 1e-6);  // whole microseconds
    for (int a = 0; a < 3; ++a) {
      EXPECT_EQ(back.gyro_in_imu[k][a], static_cast<float>(data.gyro_in_imu[k][a]));  // float32
    }
  }
  EXPECT_EQ(back.warnings.front(), "simulated by bifilar test, seed 1: not a measurement");
  EXPECT_NE(ParseDataflash(FormatImuDataflash(data), "g.bin").Find("GYR"), nullptr);
}

TEST(DataflashConfig, InstanceKey) {
  TempDir dir("bifilar_dataflash_config");
  const std::string rig = "rig: {filar_length_m: 2.0, filar_separation_m: 1.0, mass_kg: 6}\n";
  const CampaignConfig plain = test_support::LoadFitConfig(WriteFile(dir.path + "/a.yaml", rig));
  EXPECT_EQ(plain.LogOptions().dataflash_instance, -1);
  const CampaignConfig one = test_support::LoadFitConfig(
      WriteFile(dir.path + "/b.yaml", rig + "imu:\n  dataflash: {instance: 1}\n"));
  EXPECT_EQ(one.LogOptions().dataflash_instance, 1);
  for (const std::string& bad : {std::string("imu:\n  dataflash: {instance: 256}\n"),
                                 std::string("imu:\n  dataflash: {instance: -1}\n"),
                                 std::string("imu:\n  dataflash: {instanse: 1}\n")}) {
    const std::string path = WriteFile(dir.path + "/c.yaml", rig + bad);
    try {
      test_support::LoadFitConfig(path);
      ADD_FAILURE() << "accepted: " << bad;
    } catch (const UserError& e) {
      EXPECT_TRUE(Contains(e.what(), "c.yaml")) << e.what();
      EXPECT_TRUE(Contains(e.what(), "instan")) << e.what();
    }
  }
}

// The simulated swing written by `bifilar simulate --trace x.bin`, and the same samples as CSV
// (17 digits: the float32 values and whole microseconds the .bin holds, exactly): the fitted I
// agrees to 1e-9 relative (the same data, so the same fit; 1e-9 leaves room for the last
// digits of a text round trip). And against the CSV simulate writes (9 digits), as the ULog test.
TEST(DataflashCampaign, SimulatedSwingAsBinGivesTheSameInertiaAsCsv) {
  TempDir dir("bifilar_dataflash_fit");
  const std::string sim = " --inertia-kg-m2 0.4 --mass-kg 6 -L 2 -D 1 --duration-s 30 --seed 3";
  ASSERT_EQ(Bifilar(dir, "simulate --trace " + dir.path + "/s.bin" + sim).exit_code, 0);
  ASSERT_EQ(Bifilar(dir, "simulate --trace " + dir.path + "/s9.csv" + sim).exit_code, 0);
  const ImuData from_bin = ReadImuLog(dir.path + "/s.bin", ImuFormat());
  ImuLogWriteOptions digits;
  digits.significant_digits = 17;
  WriteImuLog(dir.path + "/s17.csv", from_bin, ImuFormat(), digits);
  WriteFile(dir.path + "/c.yaml",
            "rig: {filar_length_m: 2.0, filar_separation_m: 1.0, mass_kg: 6}\n");
  FitCommandOptions options;
  options.config_path = dir.path + "/c.yaml";
  options.logs = {dir.path + "/s.bin", dir.path + "/s17.csv", dir.path + "/s9.csv"};
  const FitCommandResult r = RunFit(options);
  ASSERT_EQ(r.records.size(), 3u);
  for (const TraceRecord& t : r.records) ASSERT_TRUE(t.ok()) << t.file << ": " << t.message;
  const double bin = r.records[0].inertia_total_kg_m2, csv = r.records[1].inertia_total_kg_m2;
  EXPECT_NEAR(bin / csv - 1.0, 0.0, 1e-9);
  EXPECT_NEAR(bin, 0.4, 5 * r.records[0].inertia_total_std_kg_m2);
  EXPECT_NEAR(bin, r.records[2].inertia_total_kg_m2, 0.01 * r.records[2].inertia_total_std_kg_m2);
  bool marked = false;
  for (const std::string& w : r.records[0].warnings)
    marked = marked || Contains(w, "simulated by bifilar");
  EXPECT_TRUE(marked);
  // inspect lists the messages.
  const auto shown = Bifilar(dir, "inspect " + dir.path + "/s.bin");
  EXPECT_EQ(shown.exit_code, 0) << shown.err;
  EXPECT_TRUE(Contains(shown.out, "s.bin: dataflash")) << shown.out;
  EXPECT_TRUE(Contains(shown.out, "instances (I): 0 (3770, 99.3 Hz)")) << shown.out;
}

// Issue 33 item 7: every gyro and accelerometer field's unit is checked (not only GyrX's); a
// gyro field of string type is called so; an instance value no instance can have is named.
TEST(DataflashReader, EveryFieldsUnitAndTypeAndDamagedInstancesAreNamed) {
  for (const char* units : {"s#EoEooo--O--zz", "s#EEdooo--O--zz", "s#EEEoko--O--zz"}) {
    DataflashWriter w;
    w.UnitFormats();
    w.Format(kImu, "IMU", kImuFormat, kImuLabels);
    w.FormatUnits(kImu, units, "F-000000-----00");
    for (int k = 0; k < 10; ++k) w.Message(kImu, ImuBody(10000 * k, 0, 0.1, 0, 0));
    const std::string e = ErrorOf(w.bytes(), "units.bin");
    EXPECT_TRUE(Contains(e, "is declared in")) << units << ": " << e;
    EXPECT_TRUE(Contains(e, "not read as")) << units << ": " << e;
  }
  DataflashWriter z;
  z.Format(kImu, "IMU", "QBZff", "TimeUS,I,GyrX,GyrY,GyrZ");
  DataflashPayload p;
  p.U64(1).U8(0).Text("x", 64).F32(0).F32(0);
  z.Message(kImu, p.str());
  z.Message(kImu, p.str());
  const std::string typed = ErrorOf(z.bytes(), "typed.bin");
  EXPECT_TRUE(Contains(typed, "field 'GyrX' of type 'Z' (a string), not a number")) << typed;
  // Every IMU message with I = 200 + 1e6 style damage (here 255 + 1 does not fit a byte: a float).
  DataflashWriter f;
  f.Format(kImu, "IMU", "Qffff", "TimeUS,I,GyrX,GyrY,GyrZ");
  for (int k = 0; k < 5; ++k) {
    f.Message(kImu, DataflashPayload().U64(10000 * k).F32(1e6f).F32(0).F32(0).F32(0).str());
  }
  const std::string inst = ErrorOf(f.bytes(), "instance.bin");
  EXPECT_TRUE(Contains(inst, "none with an instance the reader can use")) << inst;
  EXPECT_TRUE(Contains(inst, "1e+06")) << inst;
  EXPECT_FALSE(Contains(inst, "without IMU")) << inst;
}

}  // namespace
}  // namespace bifilar
