// IMU CSV reader: units, tolerated oddities, repairs with warnings, and one test per bad input
// (each error must name the file, and the line/column where there is one).
#include "pipeline/logs/imu_log.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <unistd.h>

#include <gtest/gtest.h>

#include "base/gzip.h"
#include "base/units.h"
#include "base/user_error.h"
#include "pendulum/simulate.h"
#include "pipeline/logs/imu_log_writer.h"
#include "test_support.h"

namespace bifilar {
namespace {

using test_support::Contains;

// The UserError message of reading `text`, or "" when it reads.
std::string ErrorOf(const std::string& text, const ImuFormat& format = ImuFormat(),
                    const ImuLogOptions& options = ImuLogOptions()) {
  try {
    ReadImuLogFromString(text, "log.csv", format, options);
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}

std::string Rows(int n, double dt = 0.01) {
  std::string s;
  char buf[128];
  for (int k = 0; k < n; ++k) {
    std::snprintf(buf, sizeof(buf), "%.4f,%.3f,%.3f,%.3f,0.1,-0.2,-9.8\n", k * dt, 0.001 * k,
                  -0.002 * k, 0.5);
    s += buf;
  }
  return s;
}

const std::string kHeader = "t,gx,gy,gz,ax,ay,az\n";

TEST(ImuLog, ReadsBasicLogInSi) {
  const ImuData d = ReadImuLogFromString(kHeader + Rows(5), "log.csv", ImuFormat());
  ASSERT_EQ(d.size(), 5u);
  ASSERT_TRUE(d.has_accel());
  EXPECT_DOUBLE_EQ(d.t_s[3], 0.03);
  EXPECT_DOUBLE_EQ(d.gyro_in_imu[3].x(), 0.003);
  EXPECT_DOUBLE_EQ(d.gyro_in_imu[3].y(), -0.006);
  EXPECT_DOUBLE_EQ(d.accel_in_imu[3].z(), -9.8);
  EXPECT_TRUE(d.warnings.empty());
}

TEST(ImuLog, ConvertsUnits) {
  ImuFormat f;
  f.time_unit = TimeUnit::kMilliseconds;
  f.gyro_unit = RateUnit::kDegPerS;
  f.accel_unit = AccelUnit::kStandardGravity;
  const ImuData d =
      ReadImuLogFromString(kHeader + "10,180,0,-90,0,0,-1\n20,0,0,0,0,0,1\n", "ms.csv", f);
  EXPECT_DOUBLE_EQ(d.t_s[0], 0.010);
  EXPECT_DOUBLE_EQ(d.t_s[1], 0.020);
  EXPECT_DOUBLE_EQ(d.gyro_in_imu[0].x(), kPi);
  EXPECT_DOUBLE_EQ(d.gyro_in_imu[0].z(), -kPi / 2);
  EXPECT_DOUBLE_EQ(d.accel_in_imu[0].z(), -kStandardGravityMps2);
  f.time_unit = TimeUnit::kMicroseconds;
  const ImuData u = ReadImuLogFromString(
      kHeader + "1700000000000000,0,0,0,0,0,1\n1700000000010000,0,0,0,0,0,1\n", "us.csv", f);
  EXPECT_DOUBLE_EQ(u.t_s[0], 1.7e9);
  EXPECT_NEAR(u.t_s[1] - u.t_s[0], 0.01, 1e-6);  // epoch microseconds keep ~0.2 us resolution
}

TEST(ImuLog, CustomNamesExtraColumnsQuotesSpacesCrlfBom) {
  ImuFormat f;
  f.time_column = "time";
  f.gyro_columns = {"wx", "wy", "wz"};
  f.accel_columns = {"", "", ""};
  f.delimiter = ';';
  const std::string text =
      "\xEF\xBB\xBF\"temp\"; \"wz\" ;wy;\"time\";wx;counter\r\n"
      "\r\n"
      "21.5; 3 ;2;0.5;+1;7\r\n"
      "   \r\n"
      "21.6;\"6\";5;0.6;4;8\r\n";
  const ImuData d = ReadImuLogFromString(text, "custom.csv", f);
  ASSERT_EQ(d.size(), 2u);
  EXPECT_FALSE(d.has_accel());
  EXPECT_DOUBLE_EQ(d.t_s[1], 0.6);
  EXPECT_EQ(d.gyro_in_imu[0], Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(d.gyro_in_imu[1], Eigen::Vector3d(4, 5, 6));
  EXPECT_TRUE(d.warnings.empty());
}

TEST(ImuLog, CommentLinesAboveHeaderAndSpaceAlignedColumns) {
  const ImuData d = ReadImuLogFromString("# logger v2\n// rate 100 Hz\n\n" + kHeader + Rows(3),
                                         "c.csv", ImuFormat());
  EXPECT_EQ(d.size(), 3u);
  ASSERT_EQ(d.warnings.size(), 1u);
  EXPECT_TRUE(Contains(d.warnings[0], "skipped 2 comment line(s)")) << d.warnings[0];
  EXPECT_TRUE(Contains(ErrorOf("# only a comment\n"), "no header row, only 1 comment line"));
  ImuFormat f;
  f.delimiter = ' ';
  const ImuData s = ReadImuLogFromString(
      "  t    gx    gy   gz  ax ay az\n 0.00  1.0  2.0  3.0 0 0 1\n\t0.01  4.0 5.0  6.0 0 0 1\n",
      "aligned.txt", f);
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s.gyro_in_imu[1], Eigen::Vector3d(4, 5, 6));
}

TEST(ImuLog, GapsKeepRealTimestamps) {
  const ImuData d = ReadImuLogFromString(
      kHeader + "0,0,0,0,0,0,1\n0.01,0,0,0,0,0,1\n0.05,0,0,0,0,0,1\n", "gap.csv", ImuFormat());
  ASSERT_EQ(d.size(), 3u);
  EXPECT_DOUBLE_EQ(d.t_s[2], 0.05);
  EXPECT_TRUE(d.warnings.empty());
}

TEST(ImuLog, TrailingJunkRowsSkippedWithWarning) {
  const std::string text = kHeader + Rows(200) + "# logger stopped\nEND,,,\n0.99,0.1";  // cut line
  const ImuData d = ReadImuLogFromString(text, "tail.csv", ImuFormat());
  EXPECT_EQ(d.size(), 200u);
  ASSERT_EQ(d.warnings.size(), 1u);
  EXPECT_TRUE(Contains(d.warnings[0], "skipped 3 trailing")) << d.warnings[0];
  EXPECT_TRUE(Contains(d.warnings[0], "line 202")) << d.warnings[0];
}

TEST(ImuLog, NonNumericCellInTheMiddleIsAnError) {
  std::string text = kHeader + Rows(3) + "0.03,0.1,abc,0.2,0,0,1\n" + "0.04,0,0,0,0,0,1\n";
  const std::string e = ErrorOf(text);
  EXPECT_TRUE(Contains(e, "log.csv:5:3")) << e;  // line 5 (header is 1), column 3
  EXPECT_TRUE(Contains(e, "'gy'")) << e;
  EXPECT_TRUE(Contains(e, "'abc'")) << e;
  // An empty cell and a number with trailing garbage are non-numeric too.
  EXPECT_TRUE(Contains(ErrorOf(kHeader + "0,0,,0,0,0,1\n0.01,0,0,0,0,0,1\n"), "log.csv:2:3"));
  EXPECT_TRUE(Contains(ErrorOf(kHeader + "0,0,1.5x,0,0,0,1\n0.01,0,0,0,0,0,1\n"), "'1.5x'"));
  // A short row in the middle.
  EXPECT_TRUE(Contains(ErrorOf(kHeader + "0,0,1\n0.01,0,0,0,0,0,1\n"), "log.csv:2"));
}

TEST(ImuLog, NanAndInfAreErrors) {
  for (const char* bad : {"nan", "NaN", "inf", "-inf", "Infinity"}) {
    const std::string e =
        ErrorOf(kHeader + "0,0,0,0,0,0,1\n0.01,0," + bad + ",0,0,0,1\n0.02,0,0,0,0,0,1\n");
    EXPECT_TRUE(Contains(e, "log.csv:3:3")) << bad << ": " << e;
    EXPECT_TRUE(Contains(e, "NaN and infinite")) << e;
  }
  // Even in the last row.
  EXPECT_TRUE(Contains(ErrorOf(kHeader + "0,0,0,0,0,0,1\n0.01,0,0,0,0,0,nan\n"), "log.csv:3:7"));
}

TEST(ImuLog, EmptyFile) {
  EXPECT_TRUE(Contains(ErrorOf(""), "log.csv: the file is empty"));
  EXPECT_TRUE(Contains(ErrorOf("\n \r\n\n"), "the file is empty"));
}

TEST(ImuLog, HeaderOnly) {
  EXPECT_TRUE(Contains(ErrorOf(kHeader), "log.csv:1: header only, no data rows"));
  EXPECT_TRUE(Contains(ErrorOf(kHeader + "\n\n"), "header only"));
  // One row only: below min_rows.
  EXPECT_TRUE(Contains(ErrorOf(kHeader + "0,0,0,0,0,0,1\n"), "only 1 usable data row"));
}

TEST(ImuLog, MissingOrMisnamedColumnListsColumnsFound) {
  const std::string e = ErrorOf("t,gx,gyro_y,gz,ax,ay,az\n" + Rows(3));
  EXPECT_TRUE(Contains(e, "log.csv:1: missing column 'gy'")) << e;
  EXPECT_TRUE(Contains(e, "columns found: 't', 'gx', 'gyro_y', 'gz', 'ax', 'ay', 'az'")) << e;
  // Wrong delimiter: a hint.
  const std::string d = ErrorOf("t;gx;gy;gz\n0;0;0;0\n");
  EXPECT_TRUE(Contains(d, "is the delimiter ';'")) << d;
  // No header at all.
  EXPECT_TRUE(Contains(ErrorOf(Rows(3)), "no header row")) << ErrorOf(Rows(3));
  // A column named twice.
  EXPECT_TRUE(Contains(ErrorOf("t,gx,gy,gz,gx,ax,ay,az\n0,0,0,0,0,0,0,1\n"), "appears twice"));
}

TEST(ImuLog, AccelerometerColumns) {
  // Gyro-only file with the default format: read gyro-only with a warning.
  const ImuData d = ReadImuLogFromString("t,gx,gy,gz\n0,0,0,0\n0.01,0,0,0\n", "g.csv", ImuFormat());
  EXPECT_FALSE(d.has_accel());
  ASSERT_EQ(d.warnings.size(), 1u);
  EXPECT_TRUE(Contains(d.warnings[0], "gyro-only"));
  ImuLogOptions o;
  o.require_accel = true;
  EXPECT_TRUE(Contains(ErrorOf("t,gx,gy,gz\n0,0,0,0\n0.01,0,0,0\n", ImuFormat(), o),
                       "missing column 'ax'"));
  // Only some accelerometer columns: always an error.
  EXPECT_TRUE(
      Contains(ErrorOf("t,gx,gy,gz,ax,ay\n0,0,0,0,0,0\n0.01,0,0,0,0,0\n"), "missing column 'az'"));
}

TEST(ImuLog, NonIncreasingTimestampsRepairedWithWarning) {
  // 300 rows; a duplicate, a swapped pair and a forward glitch: 3 samples dropped (1 %).
  std::string text = kHeader;
  char buf[96];
  for (int k = 0; k < 300; ++k) {
    double t = 0.01 * k;
    if (k == 50) t = 0.49;    // duplicate of row 49
    if (k == 100) t = 1.015;  // 1.00 and 1.015 are swapped with the next... (1.01 below)
    if (k == 101) t = 1.005;  // out of order
    if (k == 200) t = 50.0;   // forward glitch
    std::snprintf(buf, sizeof(buf), "%.4f,%d,0,0,0,0,1\n", t, k);
    text += buf;
  }
  const ImuData d = ReadImuLogFromString(text, "rep.csv", ImuFormat());
  EXPECT_EQ(d.size(), 297u);
  for (size_t i = 1; i < d.size(); ++i) ASSERT_GT(d.t_s[i], d.t_s[i - 1]);
  ASSERT_EQ(d.warnings.size(), 1u);
  EXPECT_TRUE(Contains(d.warnings[0], "dropped 3 of 300")) << d.warnings[0];
  // The glitch row (gx = 200) is the one dropped, not everything after it.
  EXPECT_DOUBLE_EQ(d.t_s.back(), 2.99);
  for (const auto& g : d.gyro_in_imu) EXPECT_NE(g.x(), 200.0);
}

TEST(ImuLog, TooManyNonIncreasingTimestampsRejected) {
  // Packets out of order all through the file: every 50th row repeats the time before it.
  auto with_duplicates = [](int n, int every) {
    std::string s = kHeader;
    char buf[96];
    for (int k = 0; k < n; ++k) {
      const double t = (k % every == every - 1) ? 0.01 * (k - 1) : 0.01 * k;
      std::snprintf(buf, sizeof(buf), "%.4f,0,0,0,0,0,1\n", t);
      s += buf;
    }
    return s;
  };
  const std::string e = ErrorOf(with_duplicates(200, 2));
  EXPECT_TRUE(Contains(e, "log.csv: 100 of 200 samples")) << e;
  EXPECT_TRUE(Contains(e, "more than 1 %")) << e;
  // Just above the limit: 2 of 100 dropped.
  const std::string two = with_duplicates(100, 50);
  EXPECT_TRUE(Contains(ErrorOf(two), "2 of 100")) << ErrorOf(two);
  ImuLogOptions lenient;
  lenient.max_dropped_fraction = 0.05;
  EXPECT_EQ(ErrorOf(two, ImuFormat(), lenient), "");
}

TEST(ImuLog, TimeSeriesEndsAtAFooter) {
  // Real loggers (the Crazyflie logs) end with a blank line, then summary rows whose time is
  // numeric again but jumps back, and text in other columns.
  const std::string footer = "\n,,,,,,\n2.089,0.0,0.011,0.0,0,0,1\n0.0,0,0,0,0,0,1\n";
  const ImuData d = ReadImuLogFromString(kHeader + Rows(100) + footer, "f.csv", ImuFormat());
  EXPECT_EQ(d.size(), 100u);
  ASSERT_EQ(d.warnings.size(), 1u);
  EXPECT_TRUE(Contains(d.warnings[0],
                       "time series ends at line 102 (a blank line, then a non-numeric row)"))
      << d.warnings[0];
  EXPECT_TRUE(Contains(d.warnings[0], "3 row(s) after it")) << d.warnings[0];
  // A non-numeric row, then numeric rows jumping back.
  const ImuData n = ReadImuLogFromString(kHeader + Rows(100) + "Flip Data,,,,,,\n0.5,0,0,0,0,0,1\n",
                                         "n.csv", ImuFormat());
  EXPECT_EQ(n.size(), 100u);
  EXPECT_TRUE(Contains(n.warnings.at(0), "(a non-numeric row")) << n.warnings[0];
  // Time jumping back with no break: a second log appended (a clock reset).
  const ImuData c = ReadImuLogFromString(kHeader + Rows(100) + Rows(60), "c.csv", ImuFormat());
  EXPECT_EQ(c.size(), 100u);
  EXPECT_TRUE(
      Contains(c.warnings.at(0), "time series ends at line 102 (time jumps back from 0.99 to 0"))
      << c.warnings[0];
  EXPECT_TRUE(Contains(c.warnings.at(0), "60 row(s)")) << c.warnings[0];
  // A NaN in a footer row does not matter: the series ended before it.
  EXPECT_EQ(
      ReadImuLogFromString(kHeader + Rows(10) + "\n0,nan,0,0,0,0,1\n", "x.csv", ImuFormat()).size(),
      10u);
  // A blank line inside the data (the series goes on) is still just skipped.
  const ImuData b =
      ReadImuLogFromString(kHeader + Rows(3) + "\n0.05,0,0,0,0,0,1\n", "b.csv", ImuFormat());
  EXPECT_EQ(b.size(), 4u);
  EXPECT_TRUE(b.warnings.empty());
}

class ImuLogFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("bifilar_imu_log_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string Write(const std::string& name, const std::string& bytes) {
    const auto path = dir_ / name;
    std::ofstream(path, std::ios::binary) << bytes;
    return path.string();
  }
  std::string ErrorOfFile(const std::string& path) {
    try {
      ReadImuLog(path, ImuFormat());
    } catch (const UserError& e) {
      return e.what();
    }
    return "";
  }
  std::filesystem::path dir_;
};

TEST_F(ImuLogFiles, ReadsFileAndTryVariant) {
  const std::string path = Write("ok.csv", kHeader + Rows(10));
  EXPECT_EQ(ReadImuLog(path, ImuFormat()).size(), 10u);
  ImuData d;
  std::string error;
  EXPECT_TRUE(TryReadImuLog(path, ImuFormat(), ImuLogOptions(), &d, &error));
  EXPECT_EQ(d.size(), 10u);
  const std::string empty = Write("empty.csv", "");
  EXPECT_FALSE(TryReadImuLog(empty, ImuFormat(), ImuLogOptions(), &d, &error));
  EXPECT_TRUE(Contains(error, empty + ": the file is empty")) << error;
}

TEST_F(ImuLogFiles, BinaryFile) {
  std::string bytes = "\x89PNG\r\n\x1a\n";
  bytes += std::string(64, '\0');
  for (int i = 0; i < 512; ++i) bytes += static_cast<char>(i * 37 % 256);
  const std::string path = Write("image.csv", bytes);
  const std::string e = ErrorOfFile(path);
  EXPECT_TRUE(Contains(e, path + ": not a text CSV file")) << e;
  // Control bytes without NUL (e.g. a compressed file).
  std::string ctrl;
  for (int i = 0; i < 400; ++i) ctrl += static_cast<char>(1 + i % 30);
  EXPECT_TRUE(Contains(ErrorOfFile(Write("ctrl.csv", ctrl)), "not a text CSV file"));
}

TEST_F(ImuLogFiles, UnreadableFile) {
  const std::string missing = (dir_ / "missing.csv").string();
  EXPECT_TRUE(Contains(ErrorOfFile(missing), missing + ": cannot open the log"))
      << ErrorOfFile(missing);
  EXPECT_TRUE(Contains(ErrorOfFile(dir_.string()), "is a folder"));
  if (::geteuid() != 0) {  // root reads anything
    const std::string locked = Write("locked.csv", kHeader + Rows(3));
    std::filesystem::permissions(locked, std::filesystem::perms::none);
    EXPECT_TRUE(Contains(ErrorOfFile(locked), "cannot open the log"));
  }
}

// A .csv.gz log reads exactly like its plain twin; the writer compresses deterministically; a
// truncated gzip file is an error naming the file, never a silently short log.
TEST_F(ImuLogFiles, GzipLogsReadLikePlainOnes) {
  const std::string text = kHeader + Rows(200);
  const std::string plain = Write("plain.csv", text);
  const std::string gz = Write("packed.csv.gz", GzipCompress(text));
  // Reproducible: a gzip header (RFC 1952) with no name and no time, so the same text gives
  // the same bytes on any day: ID1 ID2 CM (1f 8b 08), FLG 0 (no FNAME), MTIME (bytes 4..7) 0.
  const std::string packed = GzipCompress(text);
  ASSERT_GE(packed.size(), 18u);  // a 10-byte header and an 8-byte trailer at least
  EXPECT_EQ(static_cast<unsigned char>(packed[0]), 0x1f);
  EXPECT_EQ(static_cast<unsigned char>(packed[1]), 0x8b);
  EXPECT_EQ(static_cast<unsigned char>(packed[2]), 8);  // deflate
  EXPECT_EQ(static_cast<unsigned char>(packed[3]), 0) << "FLG: no file name, comment, extra";
  for (int i = 4; i < 8; ++i) EXPECT_EQ(packed[i], '\0') << "MTIME byte " << i;
  EXPECT_LT(packed.size(), text.size());  // it compresses
  // And it is gzip: inflating gives the text back.
  std::string unpacked, why;
  ASSERT_TRUE(GzipDecompress(packed, &unpacked, &why, InputCap{kMaxConfigBytes, "test", ""}))
      << why;
  EXPECT_EQ(unpacked, text);
  const ImuData a = ReadImuLog(plain, ImuFormat());
  const ImuData b = ReadImuLog(gz, ImuFormat());
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a.t_s[i], b.t_s[i]);
    EXPECT_EQ(a.gyro_in_imu[i], b.gyro_in_imu[i]);
  }
  // The writer picks gzip from the extension.
  const std::string written = (dir_ / "written.csv.gz").string();
  WriteImuLog(written, a, ImuFormat());
  std::string head(2, '\0');
  std::ifstream(written, std::ios::binary).read(&head[0], 2);
  EXPECT_TRUE(LooksGzipped(head));
  EXPECT_EQ(ReadImuLog(written, ImuFormat()).size(), a.size());
  // Truncated in the middle of the stream.
  const std::string cut = Write("cut.csv.gz", packed.substr(0, packed.size() / 2));
  const std::string e = ErrorOfFile(cut);
  EXPECT_TRUE(Contains(e, cut + ": not a valid gzip file")) << e;
}

// Round trip through the simulator and the CSV writer in non-SI units: the reader must give the
// simulator's samples back to the writer's precision (9 significant digits).
TEST_F(ImuLogFiles, SimulatedLogRoundTrip) {
  TraceSetup setup;
  setup.geometry.filar_length_m = 2.0;
  setup.geometry.filar_separation_m = 0.7;
  setup.geometry.mass_kg = 10.0;
  setup.params.inertia_kg_m2 = 0.8;
  SimulationOptions options;
  options.timeline.free_s = {10.0, 10.0};
  SimulatedTrace trace;
  std::string why;
  ASSERT_TRUE(SimulateTrace(setup, options, 3, &trace, &why)) << why;
  ImuFormat f;
  f.time_unit = TimeUnit::kMilliseconds;
  f.gyro_unit = RateUnit::kDegPerS;
  f.accel_unit = AccelUnit::kStandardGravity;
  const std::string path = (dir_ / "sim.csv").string();
  WriteImuLog(path, trace.imu, f);
  const ImuData d = ReadImuLog(path, f);
  ASSERT_EQ(d.size(), trace.imu.size());
  EXPECT_TRUE(d.warnings.empty());
  for (size_t i = 0; i < d.size(); ++i) {
    ASSERT_NEAR(d.t_s[i], trace.imu.t_s[i], 1e-9 * (1.0 + std::abs(trace.imu.t_s[i])));
    ASSERT_LT((d.gyro_in_imu[i] - trace.imu.gyro_in_imu[i]).norm(),
              1e-8 * (1.0 + trace.imu.gyro_in_imu[i].norm()));
    ASSERT_LT((d.accel_in_imu[i] - trace.imu.accel_in_imu[i]).norm(), 1e-7);
  }
}

}  // namespace
}  // namespace bifilar
