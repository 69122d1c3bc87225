// Issue 33 (items 5 and 7) and 32 (item 10): the format `inspect` and `init` guess for a log is
// what `fit` reads (exact-case column names), its units are checked against what a pendulum can
// do (simulated swings written in mrad/s, ms at 2 kHz, us at 4 kHz, angles for rates), header
// names are echoed clean, `init` never writes a config `fit` rejects, and a damaged DataFlash
// log is read with its damage named.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>

#include <gtest/gtest.h>

#include "base/units.h"
#include "pendulum/simulate.h"
#include "pipeline/commands/inspect_command.h"
#include "pipeline/commands/log_inspect.h"
#include "pipeline/logs/dataflash.h"
#include "pipeline/logs/dataflash_writer.h"
#include "pipeline/logs/imu_log_writer.h"
#include "test_support.h"

namespace bifilar {
namespace {

using test_support::Contains;
using test_support::ReadFile;
using test_support::TempDir;
using test_support::WriteFile;

// The sample rig of pipeline_inspect_test: L 2.0 m, D 1.8 m, 6.75 kg, I 4 kg m^2 (period 2.42 s),
// released at `amplitude_deg`, sampled at `rate_hz`.
ImuData Swing(double amplitude_deg, double rate_hz = 100.0) {
  TraceSetup setup;
  setup.geometry.filar_length_m = 2.0;
  setup.geometry.filar_separation_m = 1.8;
  setup.geometry.mass_kg = 6.75;
  setup.params.inertia_kg_m2 = 4.0;
  setup.params.drag_coeff_kg_m2 = 0.0;
  setup.params.viscous_coeff_kg_m2_per_s = 0.002;
  setup.amplitude_rad = amplitude_deg * kRadPerDeg;
  SimulationOptions options;
  options.sensor.sample_rate_hz = rate_hz;
  options.sensor.time_jitter_sigma_s = std::min(options.sensor.time_jitter_sigma_s, 0.1 / rate_hz);
  options.timeline = FixedTimeline(2.0, 1.0, 1.5, 30.0);
  SimulatedTrace trace;
  std::string why;
  EXPECT_TRUE(SimulateTrace(setup, options, 7, &trace, &why)) << why;
  return trace.imu;
}

ImuFormat GyroOnly(const std::string& time = "t") {
  ImuFormat f;
  f.time_column = time;
  f.accel_columns = {"", "", ""};
  return f;
}

TEST(LogGuess, AnExactCaseColumnWinsAndACaseOnlyMatchIsAmbiguous) {
  const std::string text = "t,GX,GY,GZ,gx,gy,gz\n0,1,2,3,4,5,6\n0.01,1,2,3,4,5,6\n";
  ColumnChoice choice;
  choice.gyro = {"gx", "gy", "gz"};
  const FormatGuess exact = GuessCsvFormat(text, choice);
  ASSERT_TRUE(exact.found) << exact.why;
  EXPECT_EQ(exact.format.gyro_columns[0], "gx");  // not GX, the first case-insensitive match
  choice.gyro = {"GX", "GY", "GZ"};
  EXPECT_EQ(GuessCsvFormat(text, choice).format.gyro_columns[2], "GZ");
  choice.gyro = {"Gx", "gy", "gz"};
  const FormatGuess ambiguous = GuessCsvFormat(text, choice);
  EXPECT_FALSE(ambiguous.found);
  EXPECT_TRUE(Contains(ambiguous.why, "ambiguous")) << ambiguous.why;
  EXPECT_TRUE(Contains(ambiguous.why, "'GX', 'gx'")) << ambiguous.why;
  choice = ColumnChoice();
  choice.time = "T";  // one cell differs only in case: taken
  choice.gyro = {"gx", "gy", "gz"};
  EXPECT_EQ(GuessCsvFormat(text, choice).format.time_column, "t");
}

TEST(LogGuess, MilliradiansPerSecondAreNotTakenForDegrees) {
  // A 3 deg swing in mrad/s peaks at ~135: read as deg/s it would be a 52 deg swing (the issue's
  // 59 deg at its period), which the first-rows guess offered.
  TempDir dir;
  ImuFormat f = GyroOnly();
  f.gyro_unit = RateUnit::kMilliradPerS;
  WriteImuLog(dir.path + "/mrad.csv", Swing(3.0), f);
  const InspectReport r = InspectLog(dir.path + "/mrad.csv", nullptr);
  ASSERT_TRUE(r.error.empty()) << r.error;
  EXPECT_EQ(r.format.gyro_unit, RateUnit::kMilliradPerS);
  EXPECT_NEAR(r.amplitude_deg[0], 3.0, 0.3);
  // The other reading that is also a pendulum is named beside the guess.
  bool named = false;
  for (const std::string& g : r.guesses) named = named || Contains(g, "deg/s: period");
  EXPECT_TRUE(named);
  // The same swing in deg/s stays deg/s.
  f.gyro_unit = RateUnit::kDegPerS;
  WriteImuLog(dir.path + "/deg.csv", Swing(3.0), f);
  EXPECT_EQ(InspectLog(dir.path + "/deg.csv", nullptr).format.gyro_unit, RateUnit::kDegPerS);
}

TEST(LogGuess, FastLogsInMillisecondsAndMicrosecondsAreReadInThem) {
  TempDir dir;
  const double period = 2.4277;  // the rig's period at 10 deg (inspect of the 100 Hz log)
  // 2 kHz in ms: a median step of 0.5 (the "guessed as seconds").
  ImuFormat ms = GyroOnly();
  ms.time_unit = TimeUnit::kMilliseconds;
  WriteImuLog(dir.path + "/ms.csv", Swing(10.0, 2000.0), ms);
  const InspectReport a = InspectLog(dir.path + "/ms.csv", nullptr);
  ASSERT_TRUE(a.error.empty()) << a.error;
  EXPECT_EQ(a.format.time_unit, TimeUnit::kMilliseconds);
  EXPECT_NEAR(a.period_s, period, 0.02 * period);
  // 4 kHz in us: a median step of 250, guessed as ms from the first rows.
  ImuFormat us = GyroOnly();
  us.time_unit = TimeUnit::kMicroseconds;
  WriteImuLog(dir.path + "/us.csv", Swing(10.0, 4000.0), us);
  const InspectReport b = InspectLog(dir.path + "/us.csv", nullptr);
  ASSERT_TRUE(b.error.empty()) << b.error;
  EXPECT_EQ(b.format.time_unit, TimeUnit::kMicroseconds);
  EXPECT_NEAR(b.period_s, period, 0.02 * period);
}

TEST(LogGuess, AngleColumnsNamedPqrAreNotTakenForRates) {
  // Roll, pitch and yaw in deg, logged as p, q, r: the integral of the simulated rates.
  const ImuData swing = Swing(10.0);
  std::string text = "t,p,q,r\n";
  double angle[3] = {0, 0, 0};
  for (size_t i = 0; i < swing.size(); ++i) {
    if (i > 0) {
      for (int a = 0; a < 3; ++a) {
        angle[a] += 0.5 * (swing.gyro_in_imu[i][a] + swing.gyro_in_imu[i - 1][a]) *
                    (swing.t_s[i] - swing.t_s[i - 1]);
      }
    }
    char row[160];
    std::snprintf(row, sizeof(row), "%.6f,%.6f,%.6f,%.6f\n", swing.t_s[i], angle[0] / kRadPerDeg,
                  angle[1] / kRadPerDeg, angle[2] / kRadPerDeg);
    text += row;
  }
  TempDir dir;
  const std::string path = WriteFile(dir.path + "/angles.csv", text);
  const InspectReport r = InspectLog(path, nullptr);
  EXPECT_TRUE(Contains(r.error, "look like angles")) << r.error;
  InitCommandOptions init;
  init.path = dir.path + "/bifilar.yaml";
  init.log = path;
  init.rig = "2.0,1.8,6.75";
  EXPECT_THROW(RunInit(init), UserError);
  EXPECT_FALSE(std::filesystem::exists(init.path));
}

TEST(LogGuess, HeaderNamesAreEchoedWithoutTerminalControls) {
  EXPECT_EQ(EchoedName("g\x1b[31mx"), "g?[31mx");
  EXPECT_EQ(EchoedName("gx\xc2\x85"), "gx?");  // NEL: valid UTF-8, a line break
  EXPECT_EQ(EchoedName("\xcf\x89_x (\xc2\xb0/s)"), "\xcf\x89_x (\xc2\xb0/s)");  // kept
  EXPECT_EQ(EchoedName("a\xff"), "a?");
  EXPECT_TRUE(Contains(DescribeUnprintable("gx\xc2\x85"), "U+0085 (NEL"));
  TempDir dir;
  std::string text = "t,g\x1b]0;title\x07x,gy,gz\n";
  for (int i = 0; i < 50; ++i) text += std::to_string(0.01 * i) + ",0,0,0\n";
  const std::string path = WriteFile(dir.path + "/esc.csv", text);
  const std::string shown = InspectReportText(InspectLog(path, nullptr));
  EXPECT_FALSE(Contains(shown, "\x1b")) << shown;
  EXPECT_FALSE(Contains(shown, "\x07")) << shown;
}

TEST(LogGuess, InitNeverWritesAConfigFitRejects) {
  TempDir dir;
  const ImuData swing = Swing(10.0);
  InitCommandOptions init;
  init.rig = "2.0,1.8,6.75";
  // " wx" and "wx ": one name once unquoted, twice in the header for `fit`.
  std::string text = "t, wx,wy,wz,wx \n";
  for (size_t i = 0; i < swing.size(); ++i) {
    char row[160];
    std::snprintf(row, sizeof(row), "%.5f,%.6f,%.6f,%.6f,%.6f\n", swing.t_s[i],
                  swing.gyro_in_imu[i][0], swing.gyro_in_imu[i][1], swing.gyro_in_imu[i][2],
                  swing.gyro_in_imu[i][0]);
    text += row;
  }
  init.log = WriteFile(dir.path + "/padded.csv", text);
  init.path = dir.path + "/padded.yaml";
  EXPECT_THROW(RunInit(init), UserError);
  EXPECT_FALSE(std::filesystem::exists(init.path));
  // An unreadable .bin: refused, not a config without a word.
  init.log = WriteFile(dir.path + "/noise.bin", std::string(1000, '\x9a'));
  init.path = dir.path + "/noise.yaml";
  EXPECT_THROW(RunInit(init), UserError);
  EXPECT_FALSE(std::filesystem::exists(init.path));
  // A 4.1 MB time column name: refused (the config would pass the loader's 4 MB cap).
  std::string big = "time" + std::string(4100000, 'x') + ",gx,gy,gz\n";
  for (size_t i = 0; i < swing.size(); ++i) {
    big += std::to_string(swing.t_s[i]) + "," + std::to_string(swing.gyro_in_imu[i][0]) + "," +
           std::to_string(swing.gyro_in_imu[i][1]) + "," + std::to_string(swing.gyro_in_imu[i][2]) +
           "\n";
  }
  init.log = WriteFile(dir.path + "/big.csv", big);
  init.path = dir.path + "/big.yaml";
  try {
    RunInit(init);
    ADD_FAILURE() << "init wrote a config with a 4 MB name";
  } catch (const UserError& e) {
    EXPECT_TRUE(Contains(e.what(), "4100004 bytes")) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(init.path));
  // A NEL in a name survives the YAML (written \u0085), and fit's reader reads the log with it.
  std::string nel = "t,gx\xc2\x85,gy,gz\n";
  for (size_t i = 0; i < swing.size(); ++i) {
    nel += std::to_string(swing.t_s[i]) + "," + std::to_string(swing.gyro_in_imu[i][0]) + "," +
           std::to_string(swing.gyro_in_imu[i][1]) + "," + std::to_string(swing.gyro_in_imu[i][2]) +
           "\n";
  }
  init.log = WriteFile(dir.path + "/nel.csv", nel);
  init.path = dir.path + "/nel.yaml";
  ASSERT_NO_THROW(RunInit(init));
  EXPECT_EQ(test_support::LoadFitConfig(init.path).imu.format.gyro_columns[0], "gx\xc2\x85");
}

// `data` as DataFlash with the float `from` of one gyro value replaced by `to` (one flipped
// bit's worth of damage); the byte where it was.
std::string DamagedDataflash(const ImuData& data, size_t sample, float to, size_t* at) {
  std::string bytes = FormatImuDataflash(data);
  const float from = static_cast<float>(data.gyro_in_imu[sample][2]);
  char pattern[4];
  std::memcpy(pattern, &from, 4);
  *at = bytes.find(std::string(pattern, 4));
  EXPECT_NE(*at, std::string::npos);
  std::memcpy(&bytes[*at], &to, 4);
  return bytes;
}

TEST(LogGuess, ADamagedDataflashGyroValueIsAGlitchNamedByMessageAndByte) {
  const ImuData swing = Swing(10.0);
  size_t at = 0;
  const std::string bytes = DamagedDataflash(swing, 100, -9.2e36f, &at);
  const ImuData read = ReadDataflashImu(bytes, "damaged.bin");
  EXPECT_EQ(read.size(), swing.size() - 1);
  bool named = false;
  for (const std::string& w : read.warnings) {
    named = named || (Contains(w, "dropped as glitches") && Contains(w, "message 101") &&
                      Contains(w, "-9.2e+36"));
  }
  EXPECT_TRUE(named);
  const std::string nan_bytes = DamagedDataflash(swing, 200, NAN, &at);
  EXPECT_EQ(ReadDataflashImu(nan_bytes, "nan.bin").size(), swing.size() - 1);
}

TEST(LogGuess, DataflashRatesOnlyForRegularTimedStreams) {
  DataflashMessageInfo burst;
  burst.count = burst.timed = 571;
  burst.first_time_s = 0.0;
  burst.last_time_s = 228.0;
  burst.max_step_s = 200.0;  // a burst at the start, a change 200 s later
  EXPECT_EQ(burst.rate_hz(), 0.0);
  DataflashMessageInfo imu = burst;
  imu.max_step_s = 0.45;
  EXPECT_NEAR(imu.rate_hz(), 570 / 228.0, 1e-12);
  DataflashMessageInfo untimed;
  untimed.count = 100;
  EXPECT_EQ(untimed.rate_hz(), 0.0);
}

// Issue 32 item 6: the accelerometer advice agrees with the unit in use. A log whose
// accelerometer reads 0.109 (gravity / 9 in no unit of ours) was guessed in g, then told "a log
// in g declared m/s^2? (set imu.accel.unit: g)".
TEST(LogGuess, AccelerometerAdviceNeverNamesTheUnitInUse) {
  ImuData swing = Swing(10.0);
  for (Eigen::Vector3d& f : swing.accel_in_imu) f /= 90.0;  // |f| ~ 0.109 m/s^2
  TempDir dir;
  ImuFormat format;  // t, gx.., ax.. in m/s^2
  WriteImuLog(dir.path + "/small_f.csv", swing, format);
  const InspectReport guessed = InspectLog(dir.path + "/small_f.csv", nullptr);
  EXPECT_EQ(guessed.format.accel_unit, AccelUnit::kMetresPerS2);  // not g: 0.109 is not 1 g
  const std::string text = InspectReportText(guessed);
  EXPECT_FALSE(Contains(text, "set imu.accel.unit: g")) << text;
  // Declared g: the reading is 1.07 m/s^2, and the advice must not be to declare g.
  const std::string config =
      WriteFile(dir.path + "/g.yaml",
                "rig: {filar_length_m: 2.0, filar_separation_m: 1.8, mass_kg: 6.75}\n"
                "imu:\n  accel: {columns: [ax, ay, az], unit: g}\n");
  const CampaignConfig loaded = test_support::LoadFitConfig(config);
  const std::string declared = InspectReportText(InspectLog(dir.path + "/small_f.csv", &loaded));
  EXPECT_TRUE(Contains(declared, "accelerometer")) << declared;
  EXPECT_FALSE(Contains(declared, "set imu.accel.unit: g")) << declared;
}

}  // namespace
}  // namespace bifilar
