// `bifilar inspect` and `bifilar init` (pipeline/commands/log_inspect.h,
// pipeline/config/config_template.h): the format guessed from names and data, the period of a
// simulated swing against the small-angle formula, what a file that is not a log is called, and a
// starting config that `bifilar fit` accepts as it stands.
#include <cmath>
#include <cstdlib>

#include <gtest/gtest.h>

#include "base/units.h"
#include "pendulum/model.h"
#include "pendulum/simulate.h"
#include "pipeline/commands/log_inspect.h"
#include "pipeline/config/config_template.h"
#include "pipeline/logs/imu_log_writer.h"
#include "test_support.h"

namespace bifilar {
namespace {

using test_support::ReadFile;
using test_support::TempDir;
using test_support::WriteFile;

const std::string kSource = BIFILAR_SOURCE_DIR;
const std::string kBinary = BIFILAR_BINARY;

// A swing of the sample rig: L 2.0 m, D 1.8 m, 6.75 kg, I 4 kg m^2, 5 deg release.
TraceSetup SmallSwing() {
  TraceSetup setup;
  setup.geometry.filar_length_m = 2.0;
  setup.geometry.filar_separation_m = 1.8;
  setup.geometry.mass_kg = 6.75;
  setup.params.inertia_kg_m2 = 4.0;
  setup.params.drag_coeff_kg_m2 = 0.0;
  setup.params.viscous_coeff_kg_m2_per_s = 0.002;
  setup.amplitude_rad = 5.0 * kRadPerDeg;
  return setup;
}

ImuData Simulate(const TraceSetup& setup) {
  SimulatedTrace trace;
  std::string why;
  EXPECT_TRUE(SimulateTrace(setup, SimulationOptions(), 7, &trace, &why)) << why;
  return trace.imu;
}

TEST(GuessCsvFormat, NamesAndUnitsFromHeaderAndData) {
  ImuFormat format;
  format.time_column = "time_ms";
  format.time_unit = TimeUnit::kMilliseconds;
  format.gyro_columns = {"Gyro_X (deg/s)", "Gyro_Y (deg/s)", "Gyro_Z (deg/s)"};
  format.gyro_unit = RateUnit::kDegPerS;
  format.accel_columns = {"acc_x", "acc_y", "acc_z"};
  format.accel_unit = AccelUnit::kStandardGravity;
  const FormatGuess guess = GuessCsvFormat(FormatImuLog(Simulate(SmallSwing()), format));
  ASSERT_TRUE(guess.found) << guess.why;
  EXPECT_EQ(guess.format.time_column, "time_ms");
  EXPECT_EQ(guess.format.time_unit, TimeUnit::kMilliseconds);
  EXPECT_EQ(guess.format.gyro_columns[2], "Gyro_Z (deg/s)");
  EXPECT_EQ(guess.format.gyro_unit, RateUnit::kDegPerS);
  EXPECT_EQ(guess.format.accel_columns[0], "acc_x");
  EXPECT_EQ(guess.format.accel_unit, AccelUnit::kStandardGravity);
}

TEST(GuessCsvFormat, UnitsFromTheDataAlone) {
  // Plain names: microseconds from the step (10 ms = 10000 us), deg/s from the readings' size.
  ImuFormat format;
  format.time_column = "timestamp";
  format.time_unit = TimeUnit::kMicroseconds;
  format.gyro_columns = {"wx", "wy", "wz"};
  format.gyro_unit = RateUnit::kDegPerS;
  format.accel_columns = {"", "", ""};
  TraceSetup setup = SmallSwing();
  setup.amplitude_rad = 30.0 * kRadPerDeg;  // peak rate ~0.84 rad/s = 48 deg/s
  TempDir dir;
  WriteImuLog(dir.path + "/deg.csv", Simulate(setup), format);
  // The first rows are the rest before the twist: the whole series decides the gyro unit.
  const InspectReport r = InspectLog(dir.path + "/deg.csv", nullptr);
  ASSERT_TRUE(r.error.empty()) << r.error;
  EXPECT_EQ(r.format.time_unit, TimeUnit::kMicroseconds);
  EXPECT_EQ(r.format.gyro_unit, RateUnit::kDegPerS);
  EXPECT_FALSE(r.format.has_accel());
  EXPECT_NEAR(r.amplitude_deg[0], 30.0, 3.0);  // read in the unit guessed
  // The same swing in rad/s stays rad/s.
  format.gyro_unit = RateUnit::kRadPerS;
  WriteImuLog(dir.path + "/rad.csv", Simulate(setup), format);
  const InspectReport rad = InspectLog(dir.path + "/rad.csv", nullptr);
  EXPECT_EQ(rad.format.gyro_unit, RateUnit::kRadPerS);
  EXPECT_NEAR(rad.amplitude_deg[0], 30.0, 3.0);
}

TEST(InspectLog, PeriodAndSmallAngleInertiaOfASimulatedSwing) {
  TempDir dir;
  const TraceSetup setup = SmallSwing();
  ImuFormat format;  // t, gx.., ax.. (the reader's defaults)
  WriteImuLog(dir.path + "/swing.csv", Simulate(setup), format);
  const InspectReport guessed = InspectLog(dir.path + "/swing.csv", nullptr);
  ASSERT_EQ(guessed.kind, "csv");
  ASSERT_TRUE(guessed.error.empty()) << guessed.error;
  EXPECT_FALSE(guessed.format_from_config);
  EXPECT_FALSE(guessed.guesses.empty());
  // At 5 deg the period exceeds the small-angle one by ~A^2/16 = 0.05 %; the zero-crossing
  // estimate over ~20 cycles of 100 Hz samples is good to ~0.1 %.
  const double period = SmallAnglePeriod(setup.geometry, setup.params.inertia_kg_m2);
  EXPECT_NEAR(guessed.period_s, period, 0.003 * period);
  EXPECT_NEAR(guessed.frequency_hz * guessed.period_s, 1.0, 1e-12);
  EXPECT_EQ(guessed.window_status, "ok");
  EXPECT_GT(guessed.amplitude_deg[0], 3.0);
  EXPECT_LT(guessed.amplitude_deg[0], 5.5);
  EXPECT_NEAR(std::fabs(guessed.swing_axis_in_imu[2]), 1.0, 0.01);
  EXPECT_TRUE(std::isnan(guessed.small_angle_inertia_kg_m2));  // no config, no rig

  // With a config: the small-angle inertia, within the period's error (twice, relative).
  const std::string config =
      WriteFile(dir.path + "/rig.yaml",
                "rig: {filar_length_m: 2.0, filar_separation_m: 1.8, mass_kg: 6.75}\n");
  const CampaignConfig loaded = test_support::LoadFitConfig(config);
  const InspectReport with = InspectLog(dir.path + "/swing.csv", &loaded);
  ASSERT_TRUE(with.error.empty()) << with.error;
  EXPECT_TRUE(with.format_from_config);
  EXPECT_NEAR(with.small_angle_inertia_kg_m2, 4.0, 4.0 * 0.006);
  EXPECT_DOUBLE_EQ(with.mass_used_kg, 6.75);
  const nlohmann::json j = InspectReportToJson(with);
  EXPECT_EQ(j["kind"], "csv");
  EXPECT_NEAR(j["small_angle_inertia_kg_m2"].get<double>(), 4.0, 0.024);
}

TEST(InspectLog, SaysWhatAFileIsWhenItIsNotALog) {
  TempDir dir;
  EXPECT_EQ(InspectLog(dir.path + "/nothing.csv", nullptr).kind, "missing");
  EXPECT_EQ(InspectLog(dir.path, nullptr).kind, "folder");
  EXPECT_EQ(InspectLog(WriteFile(dir.path + "/e.csv", ""), nullptr).kind, "empty");
  EXPECT_EQ(InspectLog(WriteFile(dir.path + "/b.csv",
                                 std::string("\x01\x02\x00\x7f", 4) + std::string(200, '\x03')),
                       nullptr)
                .kind,
            "binary");
  const InspectReport config = InspectLog(kSource + "/configs/prandtl_d.yaml", nullptr);
  EXPECT_EQ(config.kind, "config");
  EXPECT_NE(config.error.find("--config"), std::string::npos) << config.error;
  const InspectReport text =
      InspectLog(WriteFile(dir.path + "/notes.csv", "a,b,c\n1,2,3\n4,5,6\n"), nullptr);
  EXPECT_EQ(text.kind, "text");
  EXPECT_NE(text.error.find("no time column"), std::string::npos) << text.error;
  EXPECT_NE(text.error.find("a, b, c"), std::string::npos) << text.error;  // what it found
}

// A log whose gyro never moves: the swing-axis error is said once ("swing axis: ..."), not with
// its prefix doubled.
TEST(InspectLog, ConstantGyroSaysSwingAxisOnce) {
  TempDir dir;
  std::string text = "t,gx,gy,gz\n";
  for (int i = 0; i < 200; ++i) text += std::to_string(0.01 * i) + ",0.001,0.002,0.003\n";
  const InspectReport report = InspectLog(WriteFile(dir.path + "/still.csv", text), nullptr);
  EXPECT_NE(report.error.find("swing axis: "), std::string::npos) << report.error;
  EXPECT_EQ(report.error.find("swing axis: swing axis"), std::string::npos) << report.error;
}

TEST(InspectLog, RealUlogListsTopicsWithRates) {
  BIFILAR_REAL_DATA(path, "px4/sample_log_small.ulg");
  const InspectReport r = InspectLog(path, nullptr);
  EXPECT_EQ(r.kind, "ulog");
  bool found = false;
  for (const UlogTopicInfo& t : r.topics) {
    if (t.topic == "sensor_combined") {
      found = true;
      EXPECT_NEAR(t.rate_hz, 200.0, 5.0);  // PX4 logs sensor_combined at ~200 Hz
    }
  }
  EXPECT_TRUE(found);
  EXPECT_EQ(r.format.ulog.topic, "sensor_combined");
  EXPECT_GT(r.samples, 1000);
  // A flight log, not a swing: said plainly.
  EXPECT_NE(r.error.find("no oscillation found"), std::string::npos) << r.error;
}

TEST(InspectLog, RealQuadrotorLogGuessedAsTheAuthorsDescribeIt) {
  BIFILAR_REAL_DATA(path, "crazyflie/BaseModel_Ixx_Log-1.csv");
  const InspectReport r = InspectLog(path, nullptr);
  ASSERT_TRUE(r.error.empty()) << r.error;
  EXPECT_EQ(r.format.time_column, "t");
  EXPECT_EQ(r.format.time_unit, TimeUnit::kSeconds);
  EXPECT_EQ(r.format.gyro_columns[0], "wx");
  EXPECT_EQ(r.format.gyro_unit, RateUnit::kRadPerS);
  EXPECT_FALSE(r.format.has_accel());                  // a_d.x is a set-point, not an accelerometer
  EXPECT_NEAR(r.period_s, 2.2, 0.1);                   // the authors' rig swings at ~2.2 s
  EXPECT_GT(std::fabs(r.swing_axis_in_imu[0]), 0.95);  // an Ixx log swings about x
}

TEST(InitCommand, WritesAConfigThatFitAccepts) {
  TempDir dir;
  WriteImuLog(dir.path + "/swing.csv", Simulate(SmallSwing()), ImuFormat());
  const std::string config = dir.path + "/bifilar.yaml";
  const std::string init = kBinary + " init " + config + " --rig 2.0,1.8,6.75 --log " + dir.path +
                           "/swing.csv > " + dir.path + "/init.txt 2>&1";
  ASSERT_EQ(std::system(init.c_str()), 0) << ReadFile(dir.path + "/init.txt");
  const std::string fit = kBinary + " fit " + config + " " + dir.path + "/swing.csv --json > " +
                          dir.path + "/fit.json 2>&1";
  ASSERT_EQ(std::system(fit.c_str()), 0) << ReadFile(dir.path + "/fit.json");
  const nlohmann::json records = nlohmann::json::parse(ReadFile(dir.path + "/fit.json"));
  EXPECT_EQ(records[0]["status"], "ok");
  EXPECT_NEAR(records[0]["inertia_total_kg_m2"].get<double>(), 4.0, 0.02);

  // Never overwrites without --force; a bad --rig names the problem.
  const std::string before = ReadFile(config);
  const std::string again =
      kBinary + " init " + config + " --rig 1,0.5,1 > " + dir.path + "/again.txt 2>&1";
  EXPECT_NE(std::system(again.c_str()), 0);
  EXPECT_NE(ReadFile(dir.path + "/again.txt").find("--force"), std::string::npos);
  EXPECT_EQ(ReadFile(config), before);
  const std::string forced = kBinary + " init " + config + " --rig 1,0.5,1 --force > /dev/null";
  EXPECT_EQ(std::system(forced.c_str()), 0);
  EXPECT_NE(ReadFile(config), before);
  StartingConfigOptions options;
  std::string why;
  EXPECT_FALSE(ParseRigSpec("0.03,0.594,1", &options, &why));  // L < D: wires swapped
  EXPECT_NE(why.find("filar_length_m"), std::string::npos) << why;
  EXPECT_FALSE(ParseRigSpec("0.5,0.2", &options, &why));
  EXPECT_NE(why.find("L,D,MASS"), std::string::npos) << why;
}

}  // namespace
}  // namespace bifilar
