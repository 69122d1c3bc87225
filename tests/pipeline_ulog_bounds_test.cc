// Hostile ULog files (issue 23 items 5 and 7), generated here with pipeline/logs/ulog_writer.h:
// nested array formats that would flatten to gigabytes, deep and circular nesting, thousands of
// subscriptions, a damaged size field mid-file, and a huge one-line file given to `inspect`.
// Each is refused with a message naming the file and the format, or read in one pass; the time
// and memory these take are measured by bench/ulog_bench.cc, not asserted here.
#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "base/user_error.h"
#include "pipeline/commands/log_inspect.h"
#include "pipeline/logs/imu_log.h"
#include "pipeline/logs/ulog.h"
#include "pipeline/logs/ulog_writer.h"
#include "test_support.h"

namespace bifilar {
namespace {

using test_support::Contains;
using test_support::TempDir;
using test_support::WriteFile;

using test_support::ErrorOf;

// A topic `top` whose format nests `levels` types: top -> n1 -> ... -> n<levels-1>, the last
// holding scalars; one sample of it.
std::string NestedLog(int levels) {
  UlogWriter w(0);
  const auto type = [levels](int k) {
    return k == 0 ? std::string("top") : "n" + std::to_string(k);
  };
  for (int k = 0; k + 1 < levels; ++k) {
    w.Format(type(k) + ":" + (k == 0 ? "uint64_t timestamp;" : "") + type(k + 1) + " inner;");
  }
  w.Format(type(levels - 1) + ":" + (levels == 1 ? "uint64_t timestamp;" : "") + "float x;");
  w.AddLogged("top", 0, 0);
  w.Data(0, UlogPayload().U64(5).F32(1.5f).str());
  return w.bytes();
}

TEST(UlogBounds, NestingUpToTheLimitIsReadDeeperIsRefusedByName) {
  for (int levels : {1, 33, kUlogMaxNestingDepth}) {
    UlogRequest request{"top", 0, {"timestamp"}};
    std::string leaf;
    for (int k = 1; k < levels; ++k) leaf += "inner.";
    request.fields.push_back(leaf + "x");
    const UlogContents c = ParseUlog(NestedLog(levels), "deep.ulg", request);
    ASSERT_TRUE(c.found) << levels;
    ASSERT_EQ(c.samples(), 1) << levels;
    EXPECT_EQ(c.values[1], 1.5) << levels;
  }
  UlogRequest request{"top", 0, {"timestamp"}};
  const std::string e =
      ErrorOf([&] { ParseUlog(NestedLog(kUlogMaxNestingDepth + 1), "deeper.ulg", request); });
  EXPECT_EQ(e.rfind("deeper.ulg: byte ", 0), 0u) << e;
  EXPECT_TRUE(Contains(e, "format 'top' nests types more than 64 levels deep")) << e;
  EXPECT_FALSE(Contains(e, "circular")) << e;
}

TEST(UlogBounds, CircularDefinitionIsNamedAsSuch) {
  UlogWriter w(0);
  w.Format("a:uint64_t timestamp;b x;");
  w.Format("b:c y;");
  w.Format("c:a z;");
  w.AddLogged("a", 0, 0);
  UlogRequest request{"a", 0, {"timestamp"}};
  const std::string e = ErrorOf([&] { ParseUlog(w.bytes(), "loop.ulg", request); });
  EXPECT_TRUE(Contains(e, "loop.ulg: byte ")) << e;
  EXPECT_TRUE(Contains(e, "circular definition: a -> b -> c -> a")) << e;
}

// Nested arrays of bytes: each level 255 times the last. Flattened one field per byte, level 3
// would be 16.6 M fields (GBs of names); it is refused by its size before any allocation.
TEST(UlogBounds, NestedArraysThatWouldFlattenToGigabytesAreRefusedBeforeAllocating) {
  UlogWriter w(0);
  w.Format("l0:uint8_t[255] b;");
  w.Format("l1:l0[255] a;");
  w.Format("l2:l1[255] a;");
  w.Format("l3:l2[255] a;");
  w.Format("sensor_combined:uint64_t timestamp;l3[255] blob;");
  w.AddLogged("sensor_combined", 0, 0);
  w.Data(0, UlogPayload().U64(1).str());
  w.Data(0, UlogPayload().U64(2).str());
  const std::string bytes = w.bytes();
  ASSERT_LT(bytes.size(), 1300u);  // as the report's 1.2 kB file
  UlogRequest request{"sensor_combined", 0, {"timestamp"}};
  const std::string e = ErrorOf([&] { ParseUlog(bytes, "blob.ulg", request); });
  EXPECT_EQ(e.rfind("blob.ulg: byte ", 0), 0u) << e;
  EXPECT_TRUE(Contains(e, "format 'l2' is more than 65535 bytes")) << e;
  EXPECT_TRUE(Contains(e, "more than a ULog data message can hold")) << e;

  // The same through `inspect` (which lists topics first): an error, no allocation of GBs.
  TempDir dir("bifilar_ulog_bounds");
  const InspectReport r = InspectLog(WriteFile(dir.path + "/blob.ulg", bytes), nullptr);
  EXPECT_EQ(r.kind, "ulog");
  EXPECT_TRUE(Contains(r.error, "blob.ulg")) << r.error;
  EXPECT_TRUE(Contains(r.error, "more than 65535 bytes")) << r.error;
}

// Within the size bound, long field names could still flatten to many MB of names.
TEST(UlogBounds, FlattenedNamesAreBounded) {
  UlogWriter w(0);
  const std::string long_name(3000, 'n');
  w.Format("row:uint8_t[2000] " + long_name + ";");
  w.Format("imu:uint64_t timestamp;row[16] rows;");
  w.AddLogged("imu", 0, 0);
  UlogRequest request{"imu", 0, {"timestamp"}};
  const std::string e = ErrorOf([&] { ParseUlog(w.bytes(), "names.ulg", request); });
  EXPECT_TRUE(Contains(e, "names.ulg: byte ")) << e;
  EXPECT_TRUE(Contains(e, "format 'row' flattens to 2000 or more fields")) << e;
  EXPECT_TRUE(Contains(e, "MiB")) << e;
}

// 2000 subscriptions, each with its own format and a few samples: every topic with its rate
// from one pass over the file.
TEST(UlogBounds, ThousandsOfSubscriptionsAreListedInOnePass) {
  UlogWriter w(0);
  constexpr int kTopics = 2000;
  for (int k = 0; k < kTopics; ++k) {
    w.Format("t" + std::to_string(k) + ":uint64_t timestamp;float v;");
    w.AddLogged("t" + std::to_string(k), 0, static_cast<uint16_t>(k));
  }
  for (int s = 0; s < 3; ++s) {
    for (int k = 0; k < kTopics; ++k) {
      // topic k at (k + 1) * 10 Hz: steps of 1e5 / (k + 1) us
      w.Data(static_cast<uint16_t>(k),
             UlogPayload().U64(1000000 + s * 100000 / (k + 1)).F32(0.0f).str());
    }
  }
  UlogRequest request;
  request.topic_timestamps = true;
  const UlogContents c = ParseUlog(w.bytes(), "many.ulg", request);
  ASSERT_EQ(c.subscriptions.size(), static_cast<size_t>(kTopics));
  for (int k : {0, 9, 1999}) {
    const UlogSubscription& s = c.subscriptions[k];
    EXPECT_EQ(s.samples, 3);
    EXPECT_EQ(s.first_timestamp_us, 1000000.0);
    EXPECT_EQ(s.last_timestamp_us, 1000000.0 + 2 * (100000 / (k + 1)));
  }
  TempDir dir("bifilar_ulog_bounds");
  const InspectReport r = InspectLog(WriteFile(dir.path + "/many.ulg", w.bytes()), nullptr);
  ASSERT_EQ(r.topics.size(), static_cast<size_t>(kTopics));
  EXPECT_NEAR(r.topics[0].rate_hz, 10.0, 1e-9);
  EXPECT_NEAR(r.topics[9].rate_hz, 100.0, 1e-9);
  EXPECT_TRUE(Contains(r.error, "without an IMU topic")) << r.error;
  EXPECT_LT(r.error.size(), 1000u) << "the topic list in the message is capped";
}

// A topic without a top-level timestamp, and one whose samples are too short for it: listed,
// without a rate.
TEST(UlogBounds, TopicsWithoutAUsableTimestampHaveNoRate) {
  UlogWriter w(0);
  w.Format("plain:float v;");
  w.Format("short:uint64_t timestamp;float v;");
  w.AddLogged("plain", 0, 0);
  w.AddLogged("short", 0, 1);
  for (int s = 0; s < 3; ++s) {
    w.Data(0, UlogPayload().F32(1.0f).str());
    w.Data(1, UlogPayload().U32(7).str());
  }
  UlogRequest request;
  request.topic_timestamps = true;
  const UlogContents c = ParseUlog(w.bytes(), "norate.ulg", request);
  ASSERT_EQ(c.subscriptions.size(), 2u);
  for (const UlogSubscription& s : c.subscriptions) {
    EXPECT_EQ(s.samples, 3) << s.topic;
    EXPECT_TRUE(std::isnan(s.first_timestamp_us)) << s.topic;
  }
}

// A damaged size field mid-file: the warning says how much is not read, in bytes and samples.
TEST(UlogBounds, DamagedSizeFieldSaysHowMuchIsDropped) {
  ImuData in;
  for (int k = 0; k < 400; ++k) {
    in.t_s.push_back(1.0 + 0.004 * k);
    in.gyro_in_imu.emplace_back(0.01 * k, 0.0, 0.0);
    in.accel_in_imu.emplace_back(0.0, 0.0, -9.8);
  }
  std::string bytes = FormatImuUlog(in);
  // Each sample is a 50-byte 'D' message (3 + 2 + 45) at the end of the file; damage the size
  // field of sample 68, so that it claims more than the 333 samples left hold.
  const size_t sample68 = bytes.size() - 333 * 50;
  ASSERT_EQ(bytes[sample68 + 2], 'D');
  bytes[sample68] = '\xff';
  bytes[sample68 + 1] = '\xff';
  const ImuData d = ReadUlogImu(bytes, "torn.ulg", ImuFormat());
  EXPECT_EQ(d.size(), 67u);
  ASSERT_FALSE(d.warnings.empty());
  const std::string& w = d.warnings[0];
  EXPECT_TRUE(Contains(w, "at byte " + std::to_string(sample68))) << w;
  EXPECT_TRUE(Contains(w, "claims 65535 bytes")) << w;
  EXPECT_TRUE(Contains(w, "the last " + std::to_string(333 * 50) + " bytes")) << w;
  // Estimated from the bytes per sample before the damage (other messages included): 333 +- 2 %.
  const size_t about = w.find("that is about ");
  ASSERT_NE(about, std::string::npos) << w;
  EXPECT_NEAR(std::stod(w.substr(about + 14)), 333.0, 7.0) << w;
  EXPECT_TRUE(Contains(w, "sample(s) of topic 'sensor_combined'")) << w;
  EXPECT_FALSE(Contains(w, "that message is ignored")) << w;
}

// `inspect` on a big one-line file quotes at most the start of it.
TEST(UlogBounds, InspectDoesNotEchoAHugeLine) {
  TempDir dir("bifilar_ulog_bounds");
  std::string line;
  for (int k = 0; line.size() < 2000000; ++k) line += "column" + std::to_string(k) + ",";
  const InspectReport r = InspectLog(WriteFile(dir.path + "/one_line.txt", line + "\n"), nullptr);
  EXPECT_EQ(r.kind, "text");
  EXPECT_TRUE(Contains(r.error, "no time column")) << r.error.substr(0, 300);
  // At most 400 bytes of the line, then the advice (config keys, the init command).
  EXPECT_LT(r.error.size(), 1000u) << r.error.substr(0, 300);
  EXPECT_TRUE(Contains(r.error, "column0, column1")) << r.error;
  EXPECT_TRUE(Contains(r.error, "\u2026")) << r.error;
}

// Timestamps a fit cannot use (issue 23: they ended in Ceres' "Residual and Jacobian evaluation
// failed"): refused by the reader, naming the file.
TEST(LogTimestamps, HugeOrSpreadTimestampsAreRefusedByName) {
  auto csv = [](double t0, double dt) {
    std::string text = "t,gx,gy,gz\n";
    char line[128];
    for (int k = 0; k < 50; ++k) {
      std::snprintf(line, sizeof(line), "%.17g,0.1,0,0\n", t0 + k * dt);
      text += line;
    }
    return text;
  };
  EXPECT_NO_THROW(ReadImuLogFromString(csv(1.7e9, 0.01), "unix.csv", ImuFormat()));  // Unix time
  std::string e = ErrorOf([&] { ReadImuLogFromString(csv(1e12, 0.01), "huge.csv", ImuFormat()); });
  EXPECT_EQ(e.rfind("huge.csv: timestamps near 1e+12 s are too large for samples 0.01", 0), 0u)
      << e;
  e = ErrorOf([&] { ReadImuLogFromString(csv(0.0, 1e5), "spread.csv", ImuFormat()); });
  EXPECT_EQ(e.rfind("spread.csv: the timestamps span 4.9e+06 s", 0), 0u) << e;
  // A ULog whose uint64 timestamps (us) are near 2^63.
  ImuData in;
  for (int k = 0; k < 50; ++k) {
    in.t_s.push_back(9e12 + 0.004 * k);
    in.gyro_in_imu.emplace_back(0.1, 0.0, 0.0);
    in.accel_in_imu.emplace_back(0.0, 0.0, -9.8);
  }
  e = ErrorOf([&] { ReadUlogImu(FormatImuUlog(in), "huge.ulg", ImuFormat()); });
  EXPECT_EQ(e.rfind("huge.ulg: timestamps near 9e+12 s are too large", 0), 0u) << e;
}

}  // namespace
}  // namespace bifilar
