// Column guessing on the namings real loggers use (issue 26): a log whose time and gyro columns
// are renamed (and rescaled to the units the name implies) must be recognised by `inspect` and
// `init --log`, and read to the same series as the original. Once on a simulated log, once on a
// real Crazyflie log (label realdata).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "base/units.h"
#include "pipeline/commands/inspect_command.h"
#include "pipeline/commands/log_inspect.h"
#include "pipeline/logs/imu_log.h"
#include "tests/test_support.h"

namespace bifilar {
namespace {

using test_support::Bifilar;
using test_support::CliRun;
using test_support::LoadFitConfig;
using test_support::ReadFile;
using test_support::TempDir;
using test_support::WriteFile;

struct Naming {
  std::string time;
  double time_per_s;  // the time column's value of one second (1, 1e3, 1e6)
  std::array<std::string, 3> gyro;
  double gyro_per_rad_s;  // the gyro columns' value of 1 rad/s (1 or 180/pi)
};

// At least 15 namings: the ones the issue lists as missed (xGyro/ZGyro, p q r, roll_rate...), the
// ones guessed before, and time with its unit in the name or in brackets.
const std::vector<Naming>& Namings() {
  static const std::vector<Naming> namings = {
      {"Time", 1e3, {"xGyro", "yGyro", "ZGyro"}, kDegPerRad},  // the fixed-wing logger
      {"TimeUS", 1e6, {"GyrX", "GyrY", "GyrZ"}, 1.0},          // ArduPilot names
      {"TimeMS", 1e3, {"GyroX", "GyroY", "GyroZ"}, 1.0},
      {"timestamp", 1.0, {"gyro_x", "gyro_y", "gyro_z"}, 1.0},
      {"Time [ms]", 1e3, {"gyr_x", "gyr_y", "gyr_z"}, 1.0},
      {"time (s)", 1.0, {"gyroX", "gyroY", "gyroZ"}, 1.0},
      {"t", 1.0, {"p", "q", "r"}, 1.0},
      {"time", 1.0, {"roll_rate", "pitch_rate", "yaw_rate"}, 1.0},
      {"TIME", 1.0, {"Roll_Rate", "Pitch_Rate", "Yaw_Rate"}, kDegPerRad},
      {"Time [us]", 1e6, {"omega_x", "omega_y", "omega_z"}, 1.0},
      {"timestamp", 1.0, {"AngVelX", "AngVelY", "AngVelZ"}, 1.0},
      {"timestamp", 1.0, {"gyro_rad[0]", "gyro_rad[1]", "gyro_rad[2]"}, 1.0},  // PX4 ulog2csv
      {"time (s)", 1.0, {"Gyro X (deg/s)", "Gyro Y (deg/s)", "Gyro Z (deg/s)"}, kDegPerRad},
      {"Time", 1.0, {"XGYRO", "YGYRO", "ZGYRO"}, 1.0},
      {"elapsed", 1.0, {"w_x", "w_y", "w_z"}, 1.0},
      {"t", 1.0, {"x_gyro", "y_gyro", "z_gyro"}, kDegPerRad},
      {"TimeUS", 1e6, {"gyroscope_x", "gyroscope_y", "gyroscope_z"}, 1.0},
  };
  return namings;
}

std::vector<std::string> Split(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  for (char c : line + ",") {
    if (c == ',') {
      cells.push_back(cell);
      cell.clear();
    } else if (c != '\r') {
      cell += c;
    }
  }
  return cells;
}

// `text` (a CSV with comment lines above the header) with the columns `time` and `gyro` renamed
// and rescaled as `naming` says; rows of another width (a footer) are kept as they are.
std::string Renamed(const std::string& text, const std::string& time,
                    const std::array<std::string, 3>& gyro, const Naming& naming) {
  std::string out;
  size_t start = 0;
  std::vector<std::string> header;
  std::vector<double> scale;
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(start, end - start);
    start = end + 1;
    if (header.empty() && (line.empty() || line[0] == '#')) {
      out += line + "\n";
      continue;
    }
    std::vector<std::string> cells = Split(line);
    if (header.empty()) {
      header = cells;
      scale.assign(cells.size(), 0.0);
      for (size_t i = 0; i < cells.size(); ++i) {
        if (cells[i] == time) cells[i] = naming.time, scale[i] = naming.time_per_s;
        for (int a = 0; a < 3; ++a) {
          if (cells[i] == gyro[a]) cells[i] = naming.gyro[a], scale[i] = naming.gyro_per_rad_s;
        }
      }
    } else if (cells.size() == header.size()) {
      for (size_t i = 0; i < cells.size(); ++i) {
        char* stop = nullptr;
        const double v = std::strtod(cells[i].c_str(), &stop);
        if (scale[i] != 0.0 && !cells[i].empty() && *stop == '\0') {
          char number[40];
          std::snprintf(number, sizeof number, "%.17g", v * scale[i]);
          cells[i] = number;
        }
      }
    }
    std::string joined;
    for (size_t i = 0; i < cells.size(); ++i) joined += (i ? "," : "") + cells[i];
    out += joined + "\n";
  }
  return out;
}

// Largest relative difference between two series, relative to the largest |value|.
double MaxRelative(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return INFINITY;
  double scale = 0, diff = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    scale = std::max(scale, std::fabs(a[i]));
    diff = std::max(diff, std::fabs(a[i] - b[i]));
  }
  return scale > 0 ? diff / scale : diff;
}

std::vector<double> Axis(const ImuData& d, int a) {
  std::vector<double> v;
  for (const Eigen::Vector3d& w : d.gyro_in_imu) v.push_back(w[a]);
  return v;
}

// Every naming: inspect recognises it, its time and gyro read as the original's, and init --log
// writes a config that loads with the same format.
void ExpectEveryNamingRecognised(const std::string& original_path, const std::string& time,
                                 const std::array<std::string, 3>& gyro, const std::string& rig) {
  const std::string text = ReadFile(original_path);
  const InspectReport original = InspectLog(original_path, nullptr);
  ASSERT_TRUE(original.is_log()) << original.error;
  const ImuData reference = ReadImuLogFromString(text, original_path, original.format);
  TempDir dir;
  int n = 0;
  for (const Naming& naming : Namings()) {
    SCOPED_TRACE(naming.time + " / " + naming.gyro[0]);
    const std::string path = WriteFile(dir.path + "/log" + std::to_string(n++) + ".csv",
                                       Renamed(text, time, gyro, naming));
    const InspectReport report = InspectLog(path, nullptr);
    ASSERT_TRUE(report.is_log()) << report.error;
    EXPECT_EQ(report.format.time_column, naming.time);
    EXPECT_EQ(report.format.gyro_columns, naming.gyro);
    const ImuData data = ReadImuLogFromString(ReadFile(path), path, report.format);
    EXPECT_LT(MaxRelative(data.t_s, reference.t_s), 1e-9);
    for (int a = 0; a < 3; ++a) EXPECT_LT(MaxRelative(Axis(data, a), Axis(reference, a)), 1e-9);
    InitCommandOptions init;
    init.path = path + ".yaml";
    init.log = path;
    init.rig = rig;
    RunInit(init);
    const CampaignConfig config = LoadFitConfig(init.path);
    EXPECT_EQ(config.imu.format.time_column, naming.time);
    EXPECT_EQ(config.imu.format.gyro_columns, naming.gyro);
    EXPECT_EQ(config.imu.format.time_unit, report.format.time_unit);
    EXPECT_EQ(config.imu.format.gyro_unit, report.format.gyro_unit);
  }
  EXPECT_GE(n, 15);
}

// A simulated swing (CLI `simulate --trace`: t, gx, gy, gz, ax, ay, az).
std::string SimulatedLog(const TempDir& dir) {
  const CliRun sim = Bifilar(dir, "simulate --trace " + dir.path +
                                      "/sim.csv --inertia-kg-m2 0.05 "
                                      "--mass-kg 1.5 -L 1.0 -D 0.4 --duration-s 40 --seed 3");
  EXPECT_EQ(sim.exit_code, 0) << sim.err;
  return dir.path + "/sim.csv";
}

TEST(ColumnNaming, SimulatedLogUnderEveryNaming) {
  TempDir dir;
  ExpectEveryNamingRecognised(SimulatedLog(dir), "t", {"gx", "gy", "gz"}, "1.0,0.4,1.5");
}

TEST(ColumnNaming, RealCrazyflieLogUnderEveryNaming) {
  BIFILAR_REAL_DATA(folder, "crazyflie");
  ExpectEveryNamingRecognised(folder + "/BaseModel_Ixx_Log-1.csv", "t", {"wx", "wy", "wz"},
                              "0.594,0.030,0.0343");
}

// The fixed-wing logger of the issue (Time in ms, xGyro/yGyro/ZGyro in deg/s, xAcc...): init
// writes a config from the log alone, and fit gives the simulated inertia.
TEST(ColumnNaming, FixedWingHeaderInitThenFit) {
  TempDir dir;
  const std::string sim = SimulatedLog(dir);
  std::string text = Renamed(ReadFile(sim), "t", {"gx", "gy", "gz"}, Namings()[0]);
  for (const auto& [from, to] : {std::make_pair(",ax,", ",xAcc,"), std::make_pair(",ay,", ",yAcc,"),
                                 std::make_pair(",az", ",zAcc")}) {
    text.replace(text.find(from), std::string(from).size(), to);
  }
  const std::string log = WriteFile(dir.path + "/YawInertiaPendel01.csv", text);
  const CliRun init = Bifilar(dir, "init " + dir.path + "/c.yaml --rig 1.0,0.4,1.5 --log " + log);
  ASSERT_EQ(init.exit_code, 0) << init.err;
  EXPECT_NE(init.out.find("time column 'Time' in ms"), std::string::npos) << init.out;
  EXPECT_NE(init.out.find("in deg/s"), std::string::npos) << init.out;
  EXPECT_NE(init.out.find("xAcc"), std::string::npos) << init.out;
  const CliRun fit = Bifilar(dir, "fit " + dir.path + "/c.yaml " + log + " --json");
  ASSERT_EQ(fit.exit_code, 0) << fit.err;
  const nlohmann::json records = nlohmann::json::parse(fit.out);
  ASSERT_EQ(records.size(), 1u);
  EXPECT_NEAR(records[0]["inertia_total_kg_m2"].get<double>(), 0.05, 0.05 * 0.01);
}

// Columns no guess can place: the message lists them, names the config keys and the init command;
// init --time --gyro then writes a config that fits.
TEST(ColumnNaming, UnguessableColumnsAreNamedByInitFlags) {
  TempDir dir;
  const std::string sim = SimulatedLog(dir);
  Naming odd{"zeit", 1.0, {"dreh_a", "dreh_b", "dreh_c"}, 1.0};
  const std::string log =
      WriteFile(dir.path + "/odd.csv", Renamed(ReadFile(sim), "t", {"gx", "gy", "gz"}, odd));
  const CliRun inspect = Bifilar(dir, "inspect " + log);
  EXPECT_NE(inspect.exit_code, 0);
  const std::string said = inspect.out + inspect.err;
  for (const char* needle : {"zeit, dreh_a, dreh_b, dreh_c", "imu.time", "imu.gyro",
                             "bifilar init --log LOG --time T --gyro X,Y,Z"}) {
    EXPECT_NE(said.find(needle), std::string::npos) << needle << "\n" << said;
  }
  const CliRun refused =
      Bifilar(dir, "init " + dir.path + "/c.yaml --rig 1.0,0.4,1.5 --log " + log);
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_NE((refused.out + refused.err).find("imu.gyro"), std::string::npos) << refused.err;
  const CliRun init = Bifilar(dir, "init " + dir.path + "/c.yaml --rig 1.0,0.4,1.5 --log " + log +
                                       " --time zeit --gyro dreh_a,dreh_b,dreh_c");
  ASSERT_EQ(init.exit_code, 0) << init.err;
  const CliRun fit = Bifilar(dir, "fit " + dir.path + "/c.yaml " + log + " --json");
  ASSERT_EQ(fit.exit_code, 0) << fit.err;
  EXPECT_NEAR(nlohmann::json::parse(fit.out)[0]["inertia_total_kg_m2"].get<double>(), 0.05, 0.0005);
  // A named column that is not there, and --gyro with two names: errors naming them.
  const CliRun missing = Bifilar(dir, "init " + dir.path + "/d.yaml --rig 1.0,0.4,1.5 --log " +
                                          log + " --time zeit --gyro dreh_a,dreh_b,dreh_x");
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_NE(missing.err.find("no column 'dreh_x'"), std::string::npos) << missing.err;
  const CliRun two = Bifilar(
      dir, "init " + dir.path + "/e.yaml --rig 1.0,0.4,1.5 --log " + log + " --gyro dreh_a,dreh_b");
  EXPECT_NE(two.exit_code, 0);
  EXPECT_NE(two.err.find("--gyro takes three column names"), std::string::npos) << two.err;
}

// A header and five rows of small readings (time steps of 0.01).
std::string SmallCsv(const std::string& header) {
  const size_t width = std::count(header.begin(), header.end(), ',') + 1;
  std::string text = header + "\n";
  for (int r = 0; r < 5; ++r) {
    text += std::to_string(0.01 * r);
    for (size_t c = 1; c < width; ++c) text += "," + std::to_string(0.1 * ((r + c) % 3) - 0.1);
    text += "\n";
  }
  return text;
}

// What the guess must not take: p without q and r, a pressure column, numbered columns with a
// fourth beside them (motor speeds w1..w4, a quaternion q0..q3).
TEST(ColumnNaming, NoFalsePositives) {
  using Gyro = std::array<std::string, 3>;
  struct Case {
    std::string header;
    bool found;
    Gyro gyro;
    Gyro accel;
  };
  const std::vector<Case> cases = {
      {"time,p,alt,gyro_x,gyro_y,gyro_z", true, {"gyro_x", "gyro_y", "gyro_z"}, {"", "", ""}},
      {"time,p,temp,baro_alt", false, {}, {}},
      {"time,pressure,q,r", false, {}, {}},
      {"time,pressure,p,q,r", true, {"p", "q", "r"}, {"", "", ""}},
      {"t,p,q,r,w1,w2,w3,w4", true, {"p", "q", "r"}, {"", "", ""}},
      {"t,q0,q1,q2,q3,roll_rate,pitch_rate,yaw_rate",
       true,
       {"roll_rate", "pitch_rate", "yaw_rate"},
       {"", "", ""}},
      {"t,gx,gy,gz,a1,a2,a3,a4", true, {"gx", "gy", "gz"}, {"", "", ""}},
      {"Time,xGyro,yGyro,ZGyro,xAcc,yAcc,zAcc,Pressure",
       true,
       {"xGyro", "yGyro", "ZGyro"},
       {"xAcc", "yAcc", "zAcc"}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.header);
    const FormatGuess guess = GuessCsvFormat(SmallCsv(c.header));
    ASSERT_EQ(guess.found, c.found) << guess.why;
    if (!c.found) {
      EXPECT_NE(guess.why.find("imu.gyro"), std::string::npos) << guess.why;
      EXPECT_NE(guess.why.find(c.header.substr(c.header.rfind(',') + 1)), std::string::npos)
          << guess.why;
      continue;
    }
    EXPECT_EQ(guess.format.gyro_columns, c.gyro);
    EXPECT_EQ(guess.format.accel_columns, c.accel);
  }
}

}  // namespace
}  // namespace bifilar
