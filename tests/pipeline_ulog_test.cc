// PX4 ULog reader (pipeline/logs/ulog.h) and writer (pipeline/logs/ulog_writer.h): the real PX4
// logs in px4/ of the data folder (tests/test_support.h) against a reference reader's numbers,
// files written here with dropouts, appended sections, nested types and a cut-short tail, bad input
// (always an error naming the file, never a crash), the config keys, and a simulated campaign
// processed from .ulg and .csv.
#include "pipeline/logs/ulog.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "base/user_error.h"
#include "pipeline/campaign/campaign.h"
#include "pipeline/commands/simulate_spec.h"
#include "pipeline/config/config.h"
#include "pipeline/logs/imu_log.h"
#include "pipeline/logs/imu_log_writer.h"
#include "pipeline/logs/ulog_writer.h"
#include "test_support.h"

namespace bifilar {
namespace {

using test_support::Contains;
using test_support::ReadFile;
using test_support::WriteFile;

namespace fs = std::filesystem;

std::string TempDir() {
  char tmpl[] = "/tmp/bifilar_ulog_test_XXXXXX";
  return mkdtemp(tmpl);
}

// The UserError message of `f()`, or "" when it does not throw.
using test_support::ErrorOf;

ImuFormat Topic(const std::string& topic, int multi_id = 0) {
  ImuFormat format;
  EXPECT_TRUE(UlogTopicDefaults(topic, &format.ulog));
  format.ulog.multi_id = multi_id;
  return format;
}

// ---- The real logs, against a reference reader ----
//
// Reference numbers: the TypeScript reader @foxglove/ulog 2.3.2 (npm), iterating the data
// messages of each subscription (count, first and last `timestamp`). PX4's pyulog reads the
// appended sections of sample_appended_multiple.ulg too: they hold only 'M' (hard-fault)
// messages, so both readers give the same sensor_combined series.

struct Reference {
  const char* file;
  const char* topic;
  int multi_id;
  long samples;
  uint64_t first_us, last_us;
};

constexpr Reference kReferences[] = {
    {"sample_log_small.ulg", "sensor_combined", 0, 1298, 20326716, 26822868},
    {"sample_log_small.ulg", "vehicle_angular_velocity", 0, 1812, 20327115, 26825710},
    {"sample_log_small.ulg", "sensor_gyro", 1, 6, 21311176, 26311140},
    {"sample_appended_multiple.ulg", "sensor_combined", 0, 2373, 12262822, 21880422},
};

TEST(Ulog, RealLogsMatchTheReferenceReader) {
  for (const Reference& ref : kReferences) {
    // The real PX4 logs (BSD-3, from PX4's pyulog test data).
    BIFILAR_REAL_DATA(path, "px4/" + std::string(ref.file));
    const std::string bytes = ReadFile(path);
    UlogRequest request;
    request.topic = ref.topic;
    request.multi_id = ref.multi_id;
    request.fields = {"timestamp"};
    const UlogContents c = ParseUlog(bytes, path, request);
    ASSERT_TRUE(c.found) << ref.topic;
    ASSERT_EQ(c.samples(), ref.samples) << ref.file << " " << ref.topic;
    EXPECT_EQ(static_cast<uint64_t>(c.values.front()), ref.first_us) << ref.topic;
    EXPECT_EQ(static_cast<uint64_t>(c.values.back()), ref.last_us) << ref.topic;
  }
}

TEST(Ulog, RealLogReadsAsImuDataByItsMagic) {
  BIFILAR_REAL_DATA(path, "px4/sample_log_small.ulg");
  const ImuData d = ReadImuLog(path, ImuFormat());  // CSV defaults: the magic picks ULog
  ASSERT_EQ(d.size(), 1298u);
  ASSERT_TRUE(d.has_accel());
  EXPECT_DOUBLE_EQ(d.t_s.front(), 20.326716);
  EXPECT_DOUBLE_EQ(d.t_s.back(), 26.822868);
  // First sample as the reference reader decodes it (float32 values).
  EXPECT_EQ(d.gyro_in_imu[0].x(), static_cast<double>(0.002968383487313986f));
  EXPECT_EQ(d.accel_in_imu[0].z(), static_cast<double>(-9.63424301147461f));
  // The log has one 30 ms dropout: a warning, no invented samples.
  ASSERT_EQ(d.warnings.size(), 1u);
  EXPECT_TRUE(Contains(d.warnings[0], "1 logging dropout(s)")) << d.warnings[0];
  EXPECT_TRUE(Contains(d.warnings[0], "30 ms")) << d.warnings[0];

  const ImuData v = ReadImuLog(path, Topic("vehicle_angular_velocity"));
  EXPECT_EQ(v.size(), 1812u);
  EXPECT_FALSE(v.has_accel());
  EXPECT_EQ(v.gyro_in_imu[0].z(), static_cast<double>(-0.07620742917060852f));
}

TEST(Ulog, RealLogMissingTopicOrFieldListsWhatThereIs) {
  BIFILAR_REAL_DATA(path, "px4/sample_log_small.ulg");
  ImuFormat format;
  format.ulog.topic = "sensor_combined_x";
  std::string e = ErrorOf([&] { ReadImuLog(path, format); });
  EXPECT_EQ(e.rfind(path + ": no ULog topic 'sensor_combined_x'", 0), 0u) << e;
  EXPECT_TRUE(Contains(e, "sensor_gyro (multi_id 0 1 2)")) << e;
  EXPECT_TRUE(Contains(e, "vehicle_angular_velocity")) << e;

  e = ErrorOf([&] { ReadImuLog(path, Topic("sensor_gyro", 7)); });
  EXPECT_TRUE(Contains(e, "no ULog topic 'sensor_gyro' (multi_id 7)")) << e;

  format = ImuFormat();
  format.ulog.gyro_fields[2] = "gyro_rad[3]";
  e = ErrorOf([&] { ReadImuLog(path, format); });
  EXPECT_TRUE(Contains(e, "has no field 'gyro_rad[3]'")) << e;
  EXPECT_TRUE(Contains(e, "its fields are: timestamp, gyro_rad[0], gyro_rad[1], gyro_rad[2]")) << e;
}

TEST(Ulog, RealLogCutOrDamagedNeverCrashes) {
  BIFILAR_REAL_DATA(path, "px4/sample_log_small.ulg");
  const std::string good = ReadFile(path);
  std::mt19937 rng(5);
  for (int trial = 0; trial < 400; ++trial) {
    std::string bytes = good;
    if (trial < 100) {
      bytes.resize(std::uniform_int_distribution<size_t>(0, good.size())(rng));
    } else {
      for (int f = 0; f < 1 + trial % 3; ++f) {
        const size_t at = std::uniform_int_distribution<size_t>(0, bytes.size() - 1)(rng);
        bytes[at] = static_cast<char>(std::uniform_int_distribution<int>(0, 255)(rng));
      }
    }
    try {
      const ImuData d = ReadUlogImu(bytes, "real.ulg", ImuFormat());
      EXPECT_LE(d.size(), 1298u) << trial;
      for (size_t k = 1; k < d.size(); ++k) ASSERT_GT(d.t_s[k], d.t_s[k - 1]) << trial;
    } catch (const UserError& e) {
      ASSERT_EQ(std::string(e.what()).rfind("real.ulg: ", 0), 0u) << e.what();
    }
  }
  // Cut in the data section: read up to the cut, with a warning naming the byte.
  const ImuData half = ReadUlogImu(good.substr(0, good.size() / 2 + 1), "half.ulg", ImuFormat());
  EXPECT_GT(half.size(), 100u);
  EXPECT_LT(half.size(), 1298u);
  ASSERT_FALSE(half.warnings.empty());
  EXPECT_TRUE(Contains(half.warnings[0], "the log ends inside a message at byte"))
      << half.warnings[0];
}

// ---- Files written here ----

// A log of `n` samples at 250 Hz: gyro x = k/1000, accel z = -9.8.
ImuData Samples(int n, double t0_s = 1.0, double dt_s = 0.004) {
  ImuData d;
  for (int k = 0; k < n; ++k) {
    d.t_s.push_back(t0_s + k * dt_s);
    d.gyro_in_imu.emplace_back(k / 1000.0, -0.5, 0.25);
    d.accel_in_imu.emplace_back(0.0, 0.125, -9.8);
  }
  return d;
}

// Where the first message after the header and the flag bits starts.
constexpr size_t kFirstMessage = 16 + 3 + 40;

// One sensor_combined sample as FormatImuUlog lays it out (45 bytes: trailing padding dropped).
std::string SensorCombined(uint64_t t_us, float gx) {
  return UlogPayload()
      .U64(t_us)
      .F32(gx)
      .F32(-0.5f)
      .F32(0.25f)
      .U32(4000)
      .I32(0)
      .F32(0.0f)
      .F32(0.125f)
      .F32(-9.8f)
      .U32(4000)
      .U8(0)
      .str();
}

// A writer with the sensor_combined format and subscription of FormatImuUlog, and other topics.
UlogWriter SensorCombinedWriter() {
  UlogWriter w(123);
  w.Info("sys_name", "test");
  w.Format(
      "sensor_combined:uint64_t timestamp;float[3] gyro_rad;uint32_t gyro_integral_dt;"
      "int32_t accelerometer_timestamp_relative;float[3] accelerometer_m_s2;"
      "uint32_t accelerometer_integral_dt;uint8_t accelerometer_clipping;uint8_t[3] _padding0;");
  w.Format("cpuload:uint64_t timestamp;float load;");
  w.Parameter("SENS_BOARD_ROT", 0.0f);
  w.AddLogged("cpuload", 0, 0);
  w.AddLogged("sensor_combined", 0, 1);
  return w;
}

TEST(UlogWriter, RoundTripsAnImuLog) {
  const ImuData in = Samples(200);
  const ImuData out = ReadUlogImu(FormatImuUlog(in), "rt.ulg", ImuFormat());
  ASSERT_EQ(out.size(), in.size());
  for (size_t k = 0; k < in.size(); ++k) {
    EXPECT_NEAR(out.t_s[k], in.t_s[k], 0.5e-6);  // whole microseconds
    EXPECT_EQ(out.gyro_in_imu[k].x(),
              static_cast<double>(static_cast<float>(in.gyro_in_imu[k].x())));
    EXPECT_EQ(out.accel_in_imu[k].z(), static_cast<double>(-9.8f));
  }
  EXPECT_TRUE(out.warnings.empty());
  // Gyro-only data becomes vehicle_angular_velocity.
  ImuData gyro_only = in;
  gyro_only.accel_in_imu.clear();
  const ImuData g =
      ReadUlogImu(FormatImuUlog(gyro_only), "g.ulg", Topic("vehicle_angular_velocity"));
  EXPECT_EQ(g.size(), 200u);
  EXPECT_FALSE(g.has_accel());
}

TEST(UlogReader, OtherMessagesAndTopicsAreSkipped) {
  UlogWriter w = SensorCombinedWriter();
  for (int k = 0; k < 10; ++k) {
    w.Data(0, UlogPayload().U64(1000 + k).F32(0.5f).str());
    w.Data(1, SensorCombined(1000000 + 4000 * k, k * 0.5f));
    if (k == 3) w.Sync();
    if (k == 5) w.Logging('6', 1000, "takeoff");
    if (k == 6) w.Message('Z', "a message type from the future");
    if (k == 7) w.Info("ver_sw", "abc");
  }
  const ImuData d = ReadUlogImu(w.bytes(), "mixed.ulg", ImuFormat());
  ASSERT_EQ(d.size(), 10u);
  EXPECT_DOUBLE_EQ(d.t_s[9], 1.036);
  EXPECT_EQ(d.gyro_in_imu[9].x(), 4.5);
  EXPECT_TRUE(d.warnings.empty());
}

TEST(UlogReader, DropoutsAreGapsInTime) {
  UlogWriter w = SensorCombinedWriter();
  for (int k = 0; k < 20; ++k) {
    if (k == 10) w.Dropout(120);  // 30 samples lost at 250 Hz
    const uint64_t t = 1000000 + 4000 * (k < 10 ? k : k + 30);
    w.Data(1, SensorCombined(t, 0.0f));
  }
  const ImuData d = ReadUlogImu(w.bytes(), "drop.ulg", ImuFormat());
  ASSERT_EQ(d.size(), 20u);  // nothing interpolated
  EXPECT_NEAR(d.t_s[10] - d.t_s[9], 0.124, 1e-9);
  ASSERT_EQ(d.warnings.size(), 1u);
  EXPECT_TRUE(Contains(d.warnings[0], "1 logging dropout(s) ('O' messages, 120 ms in all"))
      << d.warnings[0];
}

TEST(UlogReader, NestedTypesArraysAndPadding) {
  UlogWriter w(0);
  // `vec` is used before it is defined (allowed); padding inside a nested type is kept in its
  // layout, a trailing padding field of the topic is not logged.
  w.Format("pair:uint64_t timestamp;vec[2] v;int16_t k;uint8_t[6] _padding0;");
  w.Format("vec:float[2] xy;uint8_t _padding0;double d;");
  w.AddLogged("pair", 3, 7);
  for (int s = 0; s < 3; ++s) {
    UlogPayload p;
    p.U64(10 + s);
    for (int i = 0; i < 2; ++i) p.F32(1.0f + i + s).F32(-1.0f - i).U8(0xAA).F64(100.0 * i + s);
    p.U16(static_cast<uint16_t>(-5 - s));  // int16_t k; the 6 padding bytes are not logged
    w.Data(7, p.str());
  }
  UlogRequest request{"pair", 3, {"timestamp", "v[1].xy[0]", "v[1].d", "k"}};
  const UlogContents c = ParseUlog(w.bytes(), "nested.ulg", request);
  ASSERT_TRUE(c.found);
  const std::vector<std::string> fields = {"timestamp",  "v[0].xy[0]", "v[0].xy[1]", "v[0].d",
                                           "v[1].xy[0]", "v[1].xy[1]", "v[1].d",     "k"};
  EXPECT_EQ(c.fields, fields);
  ASSERT_EQ(c.samples(), 3);
  EXPECT_EQ(c.values[4 * 2 + 0], 12.0);
  EXPECT_EQ(c.values[4 * 2 + 1], 4.0);    // 1 + 1 + s
  EXPECT_EQ(c.values[4 * 2 + 2], 102.0);  // 100 * 1 + s
  EXPECT_EQ(c.values[4 * 2 + 3], -7.0);
}

TEST(UlogReader, AppendedSectionsAreReadAndACutMessageDropped) {
  UlogWriter w = SensorCombinedWriter();
  for (int k = 0; k < 5; ++k) w.Data(1, SensorCombined(1000000 + 4000 * k, 1.0f));
  // The logger stopped in the middle of a message; then data was appended (PX4 appends a
  // hard-fault dump this way), to be read as part of the data section.
  UlogWriter torn(0);
  torn.Data(1, SensorCombined(9999999, 9.0f));
  w.Raw(torn.bytes().substr(kFirstMessage, 30));
  ASSERT_TRUE(w.BeginAppendedSection());
  for (int k = 5; k < 9; ++k) w.Data(1, SensorCombined(1000000 + 4000 * k, 2.0f));
  w.Raw(torn.bytes().substr(kFirstMessage, 10));
  ASSERT_TRUE(w.BeginAppendedSection());
  w.Data(1, SensorCombined(1000000 + 4000 * 9, 3.0f));

  const ImuData d = ReadUlogImu(w.bytes(), "appended.ulg", ImuFormat());
  ASSERT_EQ(d.size(), 10u);  // 5 before, 4 + 1 appended, the torn ones dropped
  EXPECT_EQ(d.gyro_in_imu[4].x(), 1.0);
  EXPECT_EQ(d.gyro_in_imu[5].x(), 2.0);
  EXPECT_EQ(d.gyro_in_imu[9].x(), 3.0);
  EXPECT_TRUE(d.warnings.empty()) << d.warnings[0];
}

TEST(UlogReader, CutShortTailIsReadToTheLastWholeMessage) {
  UlogWriter w = SensorCombinedWriter();
  for (int k = 0; k < 10; ++k) w.Data(1, SensorCombined(1000000 + 4000 * k, 0.0f));
  std::string bytes = w.bytes();
  bytes.resize(bytes.size() - 7);
  const ImuData d = ReadUlogImu(bytes, "cut.ulg", ImuFormat());
  EXPECT_EQ(d.size(), 9u);
  ASSERT_EQ(d.warnings.size(), 1u);
  const size_t last = bytes.size() + 7 - (3 + 2 + 45);
  EXPECT_TRUE(Contains(d.warnings[0], "ends inside a message at byte " + std::to_string(last)))
      << d.warnings[0];
}

TEST(UlogReader, TimestampsGoingBackAreRepairedLikeCsv) {
  ImuData in = Samples(200);
  std::swap(in.t_s[50], in.t_s[51]);  // a packet out of order
  const ImuData from_ulog = ReadUlogImu(FormatImuUlog(in), "back.ulg", ImuFormat());
  ImuLogWriteOptions csv_options;
  csv_options.significant_digits = 12;
  const ImuData from_csv =
      ReadImuLogFromString(FormatImuLog(in, ImuFormat(), csv_options), "back.csv", ImuFormat());
  ASSERT_EQ(from_ulog.size(), from_csv.size());
  ASSERT_EQ(from_ulog.size(), 199u);
  for (size_t k = 0; k < from_csv.size(); ++k) EXPECT_NEAR(from_ulog.t_s[k], from_csv.t_s[k], 1e-9);
  ASSERT_EQ(from_ulog.warnings.size(), 1u);
  ASSERT_EQ(from_csv.warnings.size(), 1u);
  EXPECT_TRUE(
      Contains(from_csv.warnings[0], "1 of 200 samples had a timestamp that did not increase"));
  EXPECT_TRUE(
      Contains(from_ulog.warnings[0], "1 of 200 samples had a timestamp that did not increase"))
      << from_ulog.warnings[0];
  EXPECT_TRUE(Contains(from_ulog.warnings[0], "sample 52")) << from_ulog.warnings[0];
  // Too many going back: rejected, as CSV.
  for (int k = 100; k < 110; k += 2) std::swap(in.t_s[k], in.t_s[k + 1]);
  const std::string e = ErrorOf([&] { ReadUlogImu(FormatImuUlog(in), "many.ulg", ImuFormat()); });
  EXPECT_TRUE(Contains(e, "many.ulg: 6 of 200 samples")) << e;
  EXPECT_TRUE(Contains(e, "the file is rejected")) << e;
}

TEST(UlogReader, BadInputNamesTheFileAndByte) {
  const std::string good = FormatImuUlog(Samples(20));
  auto error = [](const std::string& bytes) {
    return ErrorOf([&] { ReadUlogImu(bytes, "bad.ulg", ImuFormat()); });
  };
  EXPECT_TRUE(Contains(error(good.substr(0, 10)), "bad.ulg: byte 10: the file is 10 bytes long"));
  EXPECT_TRUE(
      Contains(error("ULog\x01\x12\x36" + good.substr(7)), "bad.ulg: byte 0: not a ULog file"));
  std::string flags = good;
  flags[16 + 3 + 8] = 2;  // an unknown incompatible flag bit
  EXPECT_TRUE(Contains(error(flags), "bad.ulg: byte 27: unknown incompatible flag bits"));
  // A data message for a msg_id nobody subscribed.
  std::string orphan = good;
  UlogWriter extra(0);
  extra.Data(42, std::string(8, '\0'));
  orphan += extra.bytes().substr(kFirstMessage);
  EXPECT_TRUE(
      Contains(error(orphan), "byte " + std::to_string(good.size()) + ": data for msg_id 42"));
  // A data message of the wrong size for its format.
  UlogWriter w2 = SensorCombinedWriter();
  w2.Data(1, SensorCombined(1, 0.0f) + "abcd");
  EXPECT_TRUE(Contains(ErrorOf([&] { ReadUlogImu(w2.bytes(), "bad.ulg", ImuFormat()); }),
                       "holds 49 bytes; its format defines 48 (45 without trailing padding)"));
  // NaN in a requested field.
  UlogWriter w3 = SensorCombinedWriter();
  w3.Data(1, SensorCombined(1, std::nanf("")));
  EXPECT_TRUE(
      Contains(ErrorOf([&] { ReadUlogImu(w3.bytes(), "bad.ulg", ImuFormat()); }),
               "sample 1 of the ULog topic 'sensor_combined' (multi_id 0) has gyro_rad[0] = nan"));
  // Circular and undefined nested types.
  UlogWriter w4(0);
  w4.Format("a:uint64_t timestamp;b x;");
  w4.Format("b:a y;");
  w4.AddLogged("a", 0, 0);
  UlogRequest request{"a", 0, {"timestamp"}};
  EXPECT_TRUE(Contains(ErrorOf([&] { ParseUlog(w4.bytes(), "loop.ulg", request); }), "circular"));
  UlogWriter w5(0);
  w5.Format("a:uint64_t timestamp;c x;");
  w5.AddLogged("a", 0, 0);
  EXPECT_TRUE(Contains(ErrorOf([&] { ParseUlog(w5.bytes(), "undef.ulg", request); }),
                       "type 'c' is used but never defined"));
  // Forced containers.
  ImuFormat ulog;
  ulog.container = LogContainer::kUlog;
  EXPECT_TRUE(
      Contains(ErrorOf([&] { ReadImuLogFromString("t,gx,gy,gz\n0,0,0,0\n", "x.csv", ulog); }),
               "x.csv: byte 0: not a ULog file"));
  ImuFormat csv;
  csv.container = LogContainer::kCsv;
  EXPECT_TRUE(
      Contains(ErrorOf([&] { ReadImuLogFromString(good, "x.ulg", csv); }), "not a text CSV file"));
}

// Every truncation and many random byte flips of a small file: each read either succeeds with
// strictly increasing finite data or throws a UserError naming the file. Never a crash.
TEST(UlogReader, FuzzedFilesNeverCrash) {
  UlogWriter w = SensorCombinedWriter();
  for (int k = 0; k < 12; ++k) {
    if (k == 6) w.Dropout(8);
    w.Data(0, UlogPayload().U64(1000 + k).F32(0.5f).str());
    w.Data(1, SensorCombined(1000000 + 4000 * k, k * 0.5f));
  }
  const std::string good = w.bytes();
  auto check = [](const std::string& bytes, const std::string& what) {
    try {
      const ImuData d = ReadUlogImu(bytes, "fuzz.ulg", ImuFormat());
      for (size_t k = 0; k < d.size(); ++k) {
        ASSERT_TRUE(std::isfinite(d.t_s[k]) && d.gyro_in_imu[k].allFinite()) << what;
        if (k > 0) {
          ASSERT_GT(d.t_s[k], d.t_s[k - 1]) << what;
        }
      }
    } catch (const UserError& e) {
      ASSERT_EQ(std::string(e.what()).rfind("fuzz.ulg: ", 0), 0u) << what << ": " << e.what();
    }
  };
  int errors = 0;
  for (size_t n = 0; n <= good.size(); ++n) {
    check(good.substr(0, n), "truncated to " + std::to_string(n));
    errors +=
        ErrorOf([&] { ReadUlogImu(good.substr(0, n), "fuzz.ulg", ImuFormat()); }).empty() ? 0 : 1;
  }
  EXPECT_GT(errors, 0);
  std::mt19937 rng(11);
  for (int trial = 0; trial < 3000; ++trial) {
    std::string bytes = good;
    const int flips = 1 + trial % 4;
    for (int f = 0; f < flips; ++f) {
      const size_t at = std::uniform_int_distribution<size_t>(0, bytes.size() - 1)(rng);
      bytes[at] =
          static_cast<char>(bytes[at] ^ (1 << std::uniform_int_distribution<int>(0, 7)(rng)));
    }
    check(bytes, "trial " + std::to_string(trial));
  }
}

// ---- Config ----

TEST(UlogConfig, KeysAndTopicDefaults) {
  const std::string dir = TempDir();
  auto load = [&](const std::string& imu) {
    WriteFile(dir + "/c.yaml",
              "rig: {filar_length_m: 2, filar_separation_m: 1, mass_kg: 2}\nimu:\n" + imu);
    ConfigLoadOptions options;
    options.require_runs = false;
    return LoadCampaignConfig(dir + "/c.yaml", options);
  };
  CampaignConfig c = load("  format: ulog\n");
  EXPECT_EQ(c.imu.format.container, LogContainer::kUlog);
  EXPECT_EQ(c.imu.format.ulog.topic, "sensor_combined");
  EXPECT_EQ(c.imu.format.ulog.accel_fields[2], "accelerometer_m_s2[2]");
  c = load("  ulog: {topic: sensor_gyro, multi_id: 2}\n");
  EXPECT_EQ(c.imu.format.container, LogContainer::kAuto);
  EXPECT_EQ(c.imu.format.ulog.gyro_fields[1], "y");
  EXPECT_EQ(c.imu.format.ulog.multi_id, 2);
  EXPECT_TRUE(c.imu.format.ulog.accel_fields[0].empty());
  c = load("  ulog:\n    topic: vehicle_angular_velocity\n    time_field: timestamp_sample\n");
  EXPECT_EQ(c.imu.format.ulog.gyro_fields[0], "xyz[0]");
  EXPECT_EQ(c.imu.format.ulog.time_field, "timestamp_sample");
  c = load("  ulog: {topic: my_imu, gyro_fields: [p, q, r], accel_fields: [ax, ay, az]}\n");
  EXPECT_EQ(c.imu.format.ulog.gyro_fields[2], "r");
  EXPECT_EQ(c.imu.format.ulog.accel_fields[0], "ax");
  c = load("  accel: null\n");
  EXPECT_TRUE(c.imu.format.ulog.accel_fields[0].empty());
  EXPECT_TRUE(Contains(ErrorOf([&] { load("  format: px4\n"); }),
                       "'imu.format' must be auto, csv or ulog"));
  EXPECT_TRUE(Contains(ErrorOf([&] { load("  ulog: {topic: my_imu}\n"); }),
                       "'imu.ulog.gyro_fields' is needed"));
  EXPECT_TRUE(Contains(ErrorOf([&] { load("  ulog: {multi_id: 300}\n"); }),
                       "imu.ulog.multi_id = 300; must be in [0, 255]"));
  EXPECT_TRUE(
      Contains(ErrorOf([&] { load("  ulog: {topik: x}\n"); }), "unknown key 'imu.ulog.topik'"));
  std::error_code ec;
  fs::remove_all(dir, ec);
}

// ---- End to end: a simulated campaign as .ulg and as .csv, same seed ----

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  if (at == std::string::npos)
    ADD_FAILURE() << "sample spec changed: '" << from << "' not found";
  else
    text.replace(at, from.size(), to);
  return text;
}

TEST(UlogCampaign, SimulatedUlogGivesTheSameInertiasAsCsv) {
  const std::string dir = TempDir();
  std::string spec = ReadFile(std::string(BIFILAR_SOURCE_DIR) + "/configs/simulate_prandtl_d.yaml");
  spec = Replace(
      spec,
      "pitch_deg: [-80, -70, -60, -50, -40, -30, -20, -10, 0, 10, 20, 30, 40, 50, 60, 70, 80, 90]",
      "pitch_deg: [-60, 0, 90]");
  spec = Replace(spec, "trials_per_pitch: 3", "trials_per_pitch: 1");
  spec = Replace(spec, "tare_logs: 3", "tare_logs: 1");
  spec = Replace(spec, "free_s: [35, 45]", "free_s: [20, 25]");
  const std::string csv_spec = Replace(spec, "gzip: true", "gzip: false");
  const std::string ulog_spec = Replace(spec, "gzip: true", "gzip: false\n  ulog: true");
  RunSimulateCampaign(ParseSimulateSpec(csv_spec, "csv_spec.yaml"), dir + "/csv");
  RunSimulateCampaign(ParseSimulateSpec(ulog_spec, "ulog_spec.yaml"), dir + "/ulg");
  ASSERT_TRUE(fs::exists(dir + "/ulg/pitch_0/trial_1.ulg"));
  ASSERT_TRUE(LooksLikeUlog(ReadFile(dir + "/ulg/pitch_0/trial_1.ulg")));

  auto run = [&](const std::string& sub, const std::string& ext) {
    WriteFile(dir + "/" + sub + ".yaml",
              "rig:\n  filar_length_m: 2.0\n  filar_separation_m: 1.8\n  mass_kg: 1.25\n"
              "  inertia: {tare: {logs: " +
                  sub + "/tare/*." + ext +
                  "}}\n"
                  "aircraft: {mass_kg: 5.5}\n"
                  "runs: {root: " +
                  sub + ", pattern: \"pitch_{pitch_deg}/*." + ext + "\"}\n");
    CampaignOptions options;
    options.out_dir = dir + "/out_" + sub;
    options.jobs = 2;
    options.figures = false;
    options.write_report = false;
    return RunCampaign(LoadCampaignConfig(dir + "/" + sub + ".yaml"), options);
  };
  const CampaignResult csv = run("csv", "csv");
  const CampaignResult ulg = run("ulg", "ulg");
  ASSERT_EQ(csv.traces.size(), 4u);
  ASSERT_EQ(ulg.traces.size(), 4u);
  for (size_t i = 0; i < csv.traces.size(); ++i) {
    const TraceRecord& a = csv.traces[i];
    const TraceRecord& b = ulg.traces[i];
    ASSERT_TRUE(a.ok()) << a.file << ": " << a.message;
    ASSERT_TRUE(b.ok()) << b.file << ": " << b.message;
    EXPECT_EQ(fs::path(a.file).replace_extension().string(),
              fs::path(b.file).replace_extension().string());
    // The same samples, stored as float32 (7 digits) and whole microseconds instead of 9-digit
    // text: the inertias differ by ~3e-4 of the fit's std (measured); allow 0.01 of it.
    EXPECT_NEAR(a.inertia_total_kg_m2, b.inertia_total_kg_m2, 0.01 * a.inertia_total_std_kg_m2)
        << a.file;
  }
  std::error_code ec;
  fs::remove_all(dir, ec);
}

}  // namespace
}  // namespace bifilar
