// Issue 8, "a reader for real files": single-sample glitches neither reject a trace nor move its
// window; an accelerometer with gravity removed is ignored with a warning; a --window in the
// log's own unit, an all-noise log, a footer-only log, a spike on zeros and absurd gyro values
// each get a clear reason naming the file (through `bifilar fit`, exit code 1).
#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "pipeline/config/config.h"
#include "pipeline/trace/trace_process.h"
#include "tests/test_support.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;
const std::string kSource = BIFILAR_SOURCE_DIR;
using test_support::Contains;
using test_support::LoadFitConfig;
using test_support::ReadFile;
using test_support::SimulateQuadrotor;
using test_support::WriteFile;
const std::string kQuadrotorFit = test_support::QuadrotorFitConfig();

// Each test's own folder, removed at the end.
struct TempDir : test_support::TempDir {
  TempDir() : test_support::TempDir("bifilar_robust_input") {}
};

// Runs bifilar; returns the exit code, *output gets stdout and stderr.
int Cli(const TempDir& dir, const std::string& args, std::string* output) {
  const std::string log = dir.path + "/cli.txt";
  const int status =
      std::system((std::string(BIFILAR_BINARY) + " " + args + " > " + log + " 2>&1").c_str());
  *output = ReadFile(log);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string GlitchWarning(const TraceRecord& r) {
  for (const std::string& w : r.warnings) {
    if (Contains(w, "glitch")) return w;
  }
  return "";
}

// A 50 rad/s and a 5 rad/s glitch inside the free swing of each of 8 logs: every trace stays
// `ok`, I stays within its std of the glitch-free fit, the window start moves by less than two
// of the longest sample steps (160 ms), and the record says which sample was ignored.
TEST(Glitches, NeitherRejectNorMoveTheWindowNorBiasI) {
  TempDir dir;
  WriteFile(dir.path + "/fit.yaml", kQuadrotorFit);
  const CampaignConfig config = LoadFitConfig(dir.path + "/fit.yaml");
  const std::string clean = SimulateQuadrotor(dir, 0, 5.0);
  for (const double rate : {50.0, 5.0}) {
    const std::string spiked = SimulateQuadrotor(dir, 1, rate);
    for (const char* pitch : {"pitch_0", "pitch_90"}) {
      for (int k = 1; k <= 4; ++k) {
        const std::string file = std::string("/") + pitch + "/trial_" + std::to_string(k) + ".csv";
        const TraceRecord a = ProcessTrace(config, clean + file, {});
        const TraceRecord b = ProcessTrace(config, spiked + file, {});
        ASSERT_EQ(a.status, TraceStatus::kOk) << file << ": " << a.message;
        EXPECT_EQ(GlitchWarning(a), "") << file;  // nothing found in a clean log
        EXPECT_EQ(b.status, TraceStatus::kOk) << rate << " rad/s " << file << ": " << b.message;
        EXPECT_LE(std::abs(b.inertia_total_kg_m2 - a.inertia_total_kg_m2),
                  a.inertia_total_std_kg_m2)
            << rate << " rad/s " << file;
        EXPECT_LE(std::abs(b.window_s[0] - a.window_s[0]), 2 * 0.160) << rate << " rad/s " << file;
        const std::string w = GlitchWarning(b);
        EXPECT_TRUE(Contains(w, "1 glitch sample ignored")) << file << ": " << w;
        char size[32];
        std::snprintf(size, sizeof(size), "up to %g rad/s", rate);
        EXPECT_TRUE(Contains(w, size)) << w;
      }
    }
  }
}

// A glitch below half the swing (0.2 rad/s on a ~1 rad/s swing) passes the raw-series test, but
// stands far outside the fit's residual noise (~0.004 rad/s): the residual pass drops it and
// refits, so I stays within its std of the clean fit.
TEST(Glitches, SmallerGlitchesAreFoundOnTheFitResidual) {
  TempDir dir;
  WriteFile(dir.path + "/fit.yaml", kQuadrotorFit);
  const CampaignConfig config = LoadFitConfig(dir.path + "/fit.yaml");
  const std::string clean = SimulateQuadrotor(dir, 0, 5.0);
  for (const int k : {1, 3}) {
    const std::string path = clean + "/pitch_0/trial_" + std::to_string(k) + ".csv";
    std::istringstream in(ReadFile(path));
    std::string line, text;
    bool done = false;
    std::getline(in, line);
    text = line + "\n";  // header t,wx,wy,wz,...
    while (std::getline(in, line)) {
      double t = 0, wx = 0, wy = 0, wz = 0;
      char rest[512] = "";
      if (!done &&
          std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf%511s", &t, &wx, &wy, &wz, rest) >= 4 &&
          t > 15.0) {
        char row[640];
        std::snprintf(row, sizeof(row), "%.17g,%.17g,%.17g,%.17g%s", t, wx, wy, wz + 0.2, rest);
        line = row;
        done = true;
      }
      text += line + "\n";
    }
    ASSERT_TRUE(done);
    WriteFile(dir.path + "/small.csv", text);
    const TraceRecord a = ProcessTrace(config, path, {});
    const TraceRecord b = ProcessTrace(config, dir.path + "/small.csv", {});
    ASSERT_EQ(a.status, TraceStatus::kOk) << a.message;
    ASSERT_EQ(b.status, TraceStatus::kOk) << b.message;
    EXPECT_TRUE(Contains(GlitchWarning(b), "off the fit")) << GlitchWarning(b);
    EXPECT_LE(std::abs(b.inertia_total_kg_m2 - a.inertia_total_kg_m2), a.inertia_total_std_kg_m2)
        << k;
  }
}

// The fixed-wing preset logs its accelerometer with gravity removed (0.07-0.26 g): read with the
// accelerometer configured, each log is fitted gyro-only with a warning that suggests
// imu.accel: null, and gives the same I as with imu.accel: null.
TEST(GravityRemovedAccelerometer, IgnoredWithAWarning) {
  TempDir dir;
  const std::string command = std::string(BIFILAR_BINARY) + " simulate " + kSource +
                              "/configs/simulate_nonideal_rig.yaml --out " + dir.path +
                              "/logs > /dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0);
  const std::string common =
      "rig: {filar_length_m: 0.74, filar_separation_m: 0.16, mass_kg: 3.34}\n"
      "imu:\n  time: {column: t, unit: ms}\n  gyro: {columns: [gx, gy, gz], unit: deg/s}\n";
  WriteFile(dir.path + "/with.yaml", common + "  accel: {columns: [ax, ay, az], unit: g}\n");
  WriteFile(dir.path + "/null.yaml", common + "  accel: null\n");
  const CampaignConfig with_accel = LoadFitConfig(dir.path + "/with.yaml");
  const CampaignConfig gyro_only = LoadFitConfig(dir.path + "/null.yaml");
  for (const char* pitch : {"pitch_0", "pitch_90"}) {
    for (int k = 1; k <= 2; ++k) {
      const std::string path = dir.path + "/logs/" + pitch + "/trial_" + std::to_string(k) + ".csv";
      const TraceRecord a = ProcessTrace(with_accel, path, {});
      const TraceRecord b = ProcessTrace(gyro_only, path, {});
      ASSERT_EQ(a.status, TraceStatus::kOk) << path << ": " << a.message;
      ASSERT_EQ(b.status, TraceStatus::kOk) << path << ": " << b.message;
      EXPECT_EQ(a.inertia_total_kg_m2, b.inertia_total_kg_m2) << path;
      EXPECT_FALSE(a.pitch_measured_deg.has_value()) << path;
      bool warned = false;
      for (const std::string& w : a.warnings) {
        warned = warned || (Contains(w, "gravity removed") && Contains(w, "imu.accel: null"));
      }
      EXPECT_TRUE(warned) << path;
    }
  }
}

// --- Bad logs through `bifilar fit`: exit code 1, the file named, a reason a user can act on.

const char kGyroFit[] =
    "rig: {filar_length_m: 2.0, filar_separation_m: 1.8, mass_kg: 6.75}\n"
    "imu:\n  time: {column: t, unit: s}\n  gyro: {columns: [gx, gy, gz], unit: rad/s}\n"
    "  accel: null\n";

// 30 s at 100 Hz: t, gx, gy, gz from `rate(k)` (z) and `other(k)` (x, y).
template <typename Rate, typename Other>
std::string GyroLog(const Rate& rate, const Other& other, int n = 3000) {
  std::string text = "t,gx,gy,gz\n";
  char row[160];
  for (int k = 0; k < n; ++k) {
    std::snprintf(row, sizeof(row), "%.2f,%.17g,%.17g,%.17g\n", 0.01 * k, other(k), other(k + n),
                  rate(k));
    text += row;
  }
  return text;
}

TEST(BadLogs, AllNoiseSaysNoOscillation) {
  TempDir dir;
  WriteFile(dir.path + "/fit.yaml", kGyroFit);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.004);
  WriteFile(dir.path + "/noise.csv",
            GyroLog([&](int) { return noise(rng); }, [&](int) { return noise(rng); }));
  std::string out;
  EXPECT_EQ(Cli(dir, "fit " + dir.path + "/fit.yaml " + dir.path + "/noise.csv", &out), 1) << out;
  EXPECT_TRUE(Contains(out, "noise.csv")) << out;
  EXPECT_TRUE(Contains(out, "no oscillation found")) << out;
  EXPECT_FALSE(Contains(out, "nan")) << out;
}

TEST(BadLogs, FooterOnlySaysNoNumericRows) {
  TempDir dir;
  WriteFile(dir.path + "/fit.yaml", kGyroFit);
  WriteFile(dir.path + "/footer.csv", "t,gx,gy,gz\n\nFlip Data,1,2,3\nImpact Data,4,5,6\n");
  std::string out;
  EXPECT_EQ(Cli(dir, "fit " + dir.path + "/fit.yaml " + dir.path + "/footer.csv", &out), 1) << out;
  EXPECT_TRUE(Contains(out, "footer.csv: error: no numeric data rows after the header")) << out;
  EXPECT_TRUE(Contains(out, "footer.csv:3:1: column 't' holds 'Flip Data'")) << out;
}

TEST(BadLogs, SingleSpikeOnZerosSaysNoOscillation) {
  TempDir dir;
  WriteFile(dir.path + "/fit.yaml", kGyroFit);
  WriteFile(dir.path + "/spike.csv",
            GyroLog([](int k) { return k == 1500 ? 50.0 : 0.0; }, [](int) { return 0.0; }));
  std::string out;
  EXPECT_EQ(Cli(dir, "fit " + dir.path + "/fit.yaml " + dir.path + "/spike.csv", &out), 1) << out;
  EXPECT_TRUE(Contains(out, "spike.csv")) << out;
  EXPECT_TRUE(Contains(out, "no oscillation found")) << out;
  EXPECT_FALSE(Contains(out, "nan")) << out;
}

TEST(BadLogs, AbsurdGyroValuesNameLineAndColumn) {
  TempDir dir;
  WriteFile(dir.path + "/fit.yaml", kGyroFit);
  // Everywhere (no "amplitude from inf to inf"), and in one sample of a good swing (no glitch
  // repair of a value no gyro gives: the file is corrupt or its unit wrong).
  WriteFile(dir.path + "/huge.csv",
            GyroLog([](int k) { return 1e300 * std::sin(0.03 * k); }, [](int) { return 0.0; }));
  WriteFile(dir.path + "/one.csv",
            GyroLog([](int k) { return k == 700 ? 1e300 : 0.5 * std::sin(0.03 * k); },
                    [](int) { return 0.0; }));
  std::string out;
  EXPECT_EQ(Cli(dir, "fit " + dir.path + "/fit.yaml " + dir.path + "/huge.csv", &out), 1) << out;
  EXPECT_TRUE(Contains(out, "huge.csv:3:4: column 'gz'")) << out;  // line 3: the first non-zero
  EXPECT_TRUE(Contains(out, "beyond any gyro (|rate| <= 1e4 rad/s)")) << out;
  EXPECT_FALSE(Contains(out, "inf")) << out;
  EXPECT_EQ(Cli(dir, "fit " + dir.path + "/fit.yaml " + dir.path + "/one.csv", &out), 1) << out;
  EXPECT_TRUE(Contains(out, "one.csv:702:4: column 'gz' holds")) << out;
  EXPECT_TRUE(Contains(out, "= 1e+300 rad/s, beyond any gyro")) << out;
}

// A --window given in the file's own time unit (ms) or beyond the log's end says so, in seconds,
// instead of "gyro signal is constant".
TEST(BadLogs, WindowOutsideTheLogInItsOwnTerms) {
  TempDir dir;
  WriteFile(dir.path + "/fit.yaml",
            "rig: {filar_length_m: 2.0, filar_separation_m: 1.8, mass_kg: 6.75}\n"
            "imu:\n  time: {column: t, unit: ms}\n  gyro: {columns: [gx, gy, gz], unit: rad/s}\n"
            "  accel: null\n");
  std::string text = "t,gx,gy,gz\n";
  char row[128];
  for (int k = 0; k <= 13000; ++k) {  // 0-130 s in ms at 100 Hz, a 2 s swing
    std::snprintf(row, sizeof(row), "%d,0,0,%.9g\n", 10 * k,
                  0.5 * std::exp(-0.002 * k) * std::sin(0.0314159 * k));
    text += row;
  }
  WriteFile(dir.path + "/ms.csv", text);
  std::string out;
  EXPECT_EQ(
      Cli(dir, "fit " + dir.path + "/fit.yaml " + dir.path + "/ms.csv --window 5000:60000", &out),
      1)
      << out;
  EXPECT_TRUE(Contains(out,
                       "ms.csv: error: window 5000-60000 s is outside the log (0-130 s); "
                       "--window takes seconds"))
      << out;
  EXPECT_TRUE(Contains(out, "if these are ms, give 5:60")) << out;
  EXPECT_FALSE(Contains(out, "constant")) << out;
  EXPECT_EQ(
      Cli(dir, "fit " + dir.path + "/fit.yaml " + dir.path + "/ms.csv --window 200:300", &out), 1)
      << out;
  EXPECT_TRUE(Contains(out,
                       "window 200-300 s is outside the log (0-130 s); --window takes "
                       "seconds"))
      << out;
  EXPECT_TRUE(Contains(out, "; its start 200 s is after the log's end")) << out;
  // Past the log's end only (an end of 1e9 meaning "to the end"): clamped, with a warning naming
  // the end (issue 15 item 8; it was "outside the log").
  EXPECT_EQ(Cli(dir, "fit " + dir.path + "/fit.yaml " + dir.path + "/ms.csv --window 5:1e9", &out),
            0)
      << out;
  EXPECT_TRUE(Contains(out,
                       "--window 5-1e+09 s: its end 1e+09 s is after the log's "
                       "end 130 s; clamped to 5-130 s"))
      << out;
  // Inside the log, in seconds: fitted.
  EXPECT_EQ(Cli(dir, "fit " + dir.path + "/fit.yaml " + dir.path + "/ms.csv --window 5:60", &out),
            0)
      << out;
}

}  // namespace
}  // namespace bifilar
