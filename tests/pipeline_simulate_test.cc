// `bifilar simulate` end to end: the spec reader (strict keys, ranges, units), the CSV writer
// (units, round trip), byte-identical reruns, truth.json consistency, the CLI's exit codes.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "pipeline/imu_log_writer.h"
#include "pipeline/simulate_spec.h"
#include "pipeline/user_error.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

std::string ReadText(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  std::stringstream ss;
  ss << file.rdbuf();
  return ss.str();
}

fs::path TempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() /
                       ("bifilar_sim_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

// A small campaign: 2 pitches x 2 trials + 1 tare log, 6 s of free oscillation each.
const char* kSmallSpec = R"(
seed: 5
geometry: {filar_length_m: 2.0, filar_separation_m: 1.8}
aircraft: {mass_kg: 5.5, ix_slug_ft2: 2.3596, iz_slug_ft2: 2.8477, ixz_slug_ft2: 0.0178}
rig: {mass_kg: 1.2, imu_mass_kg: 0.05, inertia_kg_m2: 0.25, tare_logs: 1}
campaign: {pitch_deg: [-30, 60], trials_per_pitch: 2}
timeline: {free_s: 6, rest_before_s: [1, 2]}
format: {time_unit: ms, gyro_unit: deg/s, accel_unit: g, gyro_columns: [wx, wy, wz]}
)";

std::string ErrorOf(const std::string& yaml) {
  try {
    ParseSimulateSpec(yaml, "spec.yaml");
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}

TEST(SimulateSpec, SampleConfigParses) {
  const SimulateSpec spec =
      ReadSimulateSpec(std::string(BIFILAR_SOURCE_DIR) + "/configs/simulate_prandtl_d.yaml");
  ASSERT_TRUE(spec.has_campaign);
  EXPECT_EQ(spec.campaign.pitch_deg.size(), 18u);
  EXPECT_EQ(spec.campaign.trials_per_pitch, 3);
  EXPECT_NEAR(spec.campaign.aircraft.ix_kg_m2, 2.3596 * 1.35581795, 1e-12);
  EXPECT_NEAR(spec.campaign.aircraft.ixz_kg_m2, 0.0178 * 1.35581795, 1e-12);
  EXPECT_EQ(spec.options.model, PendulumModel::kFull);
  std::string why;
  EXPECT_TRUE(spec.campaign.Check(&why)) << why;
}

TEST(SimulateSpec, BadInputNamesTheKeyAndLine) {
  const std::string base = "geometry: {filar_length_m: 2.0, filar_separation_m: 1.8}\n";
  struct Case {
    std::string yaml, expect;
  };
  const std::vector<Case> cases = {
      {base + "sensor: {sample_rat_hz: 100}\n", "spec.yaml:2:10: unknown key 'sensor.sample_rat_hz'"},
      {base + "bogus: 1\n", "unknown key 'bogus'"},
      {"geometry: {filar_length_m: 1.5, filar_separation_m: 1.8}\n",
       "'geometry.filar_length_m' = 1.5 must be greater than 'geometry.filar_separation_m'"},
      {"geometry: {filar_length_m: -1, filar_separation_m: 1.8}\n",
       "spec.yaml:1:28: 'geometry.filar_length_m' = -1 is out of range; allowed (0, 1000]"},
      {base + "sensor: {sample_rate_hz: 0}\n", "'sensor.sample_rate_hz' = 0 is out of range"},
      {base + "timeline: {free_s: 0}\n", "'timeline.free_s'"},
      {base + "timeline: {free_s: [50, 40]}\n", "'timeline.free_s' = [50, 40] is out of range"},
      {base + "format: {time_unit: min}\n", "unknown unit 'min' for 'format.time_unit'; allowed s, ms, us"},
      {base + "format: {gyro_unit: rpm}\n", "unknown unit 'rpm' for 'format.gyro_unit'"},
      {base + "format: {accel_unit: ft/s^2}\n", "unknown unit 'ft/s^2' for 'format.accel_unit'"},
      {base + "model: exact\n", "unknown model 'exact'"},
      {base + "trace: {inertia_kg_m2: 0}\n", "'trace.inertia_kg_m2' = 0 is out of range"},
      {base + "trace: {mass_kg: -3}\n", "'trace.mass_kg' = -3 is out of range"},
      {base + "aircraft: {mass_kg: 5, ix_kg_m2: 1, iz_kg_m2: 1, ixz_kg_m2: 0}\n",
       "missing required key 'rig'"},
      {base + "aircraft: {mass_kg: 0, ix_kg_m2: 1, iz_kg_m2: 1, ixz_kg_m2: 0}\n",
       "'aircraft.mass_kg' = 0 is out of range"},
      {base + "aircraft: {mass_kg: 5, iz_kg_m2: 1, ixz_kg_m2: 0}\n",
       "missing required key 'aircraft.ix_kg_m2' (or 'aircraft.ix_slug_ft2')"},
      {base + "aircraft: {mass_kg: 5, ix_kg_m2: 1, iz_kg_m2: 1, ixz_kg_m2: 0}\n"
              "rig: {mass_kg: 1, inertia_kg_m2: -0.2}\ncampaign: {pitch_deg: [0]}\n",
       "'rig.inertia_kg_m2' = -0.2 is out of range"},
      {base + "aircraft: {mass_kg: 5, ix_kg_m2: 1, iz_kg_m2: 1, ixz_kg_m2: 0}\n"
              "rig: {mass_kg: 1, inertia_kg_m2: 0.2}\ncampaign: {pitch_deg: [0, 100]}\n",
       "'campaign.pitch_deg' has 100; allowed [-90, 90]"},
      {"geometry: [1, 2]\n", "'geometry' must be a mapping"},
  };
  for (const Case& c : cases) {
    const std::string message = ErrorOf(c.yaml);
    EXPECT_NE(message.find(c.expect), std::string::npos)
        << "yaml:\n" << c.yaml << "message: " << message << "\nexpected: " << c.expect;
  }
}

TEST(SimulateWriter, UnitsAndRoundTrip) {
  ImuData data;
  data.t_s = {0.0, 0.0101, 0.0199};
  data.gyro_in_imu = {Eigen::Vector3d(0.1, -0.2, 0.3), Eigen::Vector3d(0, 0, 1),
                      Eigen::Vector3d(1e-4, 2, -3)};
  data.accel_in_imu = {Eigen::Vector3d(0, 0, -9.80665), Eigen::Vector3d(1, 2, 3),
                       Eigen::Vector3d(-1, 0.5, 9.80665)};
  ImuFormat format;
  format.time_unit = TimeUnit::kMilliseconds;
  format.gyro_unit = RateUnit::kDegPerS;
  format.accel_unit = AccelUnit::kStandardGravity;
  format.delimiter = ';';
  const std::string text = FormatImuLog(data, format);
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "t;gx;gy;gz;ax;ay;az");
  for (size_t k = 0; k < 3; ++k) {
    ASSERT_TRUE(std::getline(in, line));
    std::vector<double> v;
    std::stringstream row(line);
    std::string cell;
    while (std::getline(row, cell, ';')) v.push_back(std::stod(cell));
    ASSERT_EQ(v.size(), 7u);
    // 9 significant digits: relative round-trip error below 1e-8.
    EXPECT_NEAR(v[0] * 1e-3, data.t_s[k], 1e-12);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(v[1 + i] * kDeg, data.gyro_in_imu[k][i], 1e-8 * std::abs(data.gyro_in_imu[k][i]) + 1e-15);
      EXPECT_NEAR(v[4 + i] * 9.80665, data.accel_in_imu[k][i], 1e-8 * std::abs(data.accel_in_imu[k][i]) + 1e-15);
    }
  }
  // No accelerometer: only four columns.
  ImuFormat gyro_only;
  gyro_only.accel_columns = {"", "", ""};
  EXPECT_EQ(FormatImuLog(data, gyro_only).substr(0, 12), "t,gx,gy,gz\n0");
  // A non-finite value is refused, never written.
  data.gyro_in_imu[1].x() = NAN;
  EXPECT_THROW(FormatImuLog(data, format), UserError);
}

TEST(SimulateCampaign, SameSeedSameBytesAndTruthConsistent) {
  const SimulateSpec spec = ParseSimulateSpec(kSmallSpec, "small.yaml");
  const fs::path a = TempDir("a"), b = TempDir("b"), c = TempDir("c");
  const SimulateRunSummary summary = RunSimulateCampaign(spec, a.string());
  EXPECT_EQ(summary.files_written, 5);
  RunSimulateCampaign(spec, b.string());
  SimulateSpec other = spec;
  other.seed = 6;
  RunSimulateCampaign(other, c.string());
  const std::vector<std::string> files = {"pitch_-30/trial_1.csv", "pitch_-30/trial_2.csv",
                                          "pitch_60/trial_1.csv", "pitch_60/trial_2.csv",
                                          "tare/tare_1.csv", "truth.json"};
  for (const auto& f : files) {
    ASSERT_TRUE(fs::exists(a / f)) << f;
    EXPECT_EQ(ReadText(a / f), ReadText(b / f)) << f;
    EXPECT_NE(ReadText(a / f), ReadText(c / f)) << f;
  }
  // Header in the spec's format; no temporary files left behind.
  EXPECT_EQ(ReadText(a / files[0]).substr(0, 20), "t,wx,wy,wz,ax,ay,az\n");
  for (const auto& entry : fs::recursive_directory_iterator(a)) {
    EXPECT_EQ(entry.path().string().find(".tmp"), std::string::npos) << entry.path();
  }

  const nlohmann::json truth = nlohmann::json::parse(ReadText(a / "truth.json"));
  const auto& ac = truth["aircraft"];
  const double ix = ac["ix_kg_m2"], iz = ac["iz_kg_m2"], ixz = ac["ixz_kg_m2"];
  EXPECT_NEAR(ix, 2.3596 * 1.35581795, 1e-12);
  EXPECT_NEAR(ac["tau_deg"].get<double>(), 0.5 * std::atan2(2 * ixz, iz - ix) / kDeg, 1e-12);
  ASSERT_EQ(truth["traces"].size(), 5u);
  for (const auto& t : truth["traces"]) {
    const double theta = t["true_pitch_deg"].get<double>() * kDeg;
    const double rig = t["inertia_rig_kg_m2"];
    EXPECT_NEAR(rig, 0.25, 1e-15);
    if (t["kind"] == "tare") {
      EXPECT_NEAR(t["inertia_total_kg_m2"].get<double>(), 0.25, 1e-15);
      EXPECT_NEAR(t["mass_kg"].get<double>(), 1.25, 1e-12);
      continue;
    }
    const double expected = iz * std::pow(std::cos(theta), 2) + ix * std::pow(std::sin(theta), 2) +
                            ixz * std::sin(2 * theta);
    EXPECT_NEAR(t["inertia_aircraft_kg_m2"].get<double>(), expected, 1e-12);
    EXPECT_NEAR(t["inertia_total_kg_m2"].get<double>(), expected + rig, 1e-12);
    EXPECT_NEAR(t["mass_kg"].get<double>(), 6.75, 1e-12);
    // The CSV rows and the truth agree; the release lies inside the log.
    const std::string csv = ReadText(a / t["file"].get<std::string>());
    const long rows = std::count(csv.begin(), csv.end(), '\n') - 1;
    EXPECT_EQ(rows, t["samples"].get<long>());
    EXPECT_GT(t["t_release_s"].get<double>(), t["t_twist_s"].get<double>());
    EXPECT_TRUE(t["t_stop_s"].is_null() || t["t_stop_s"].get<double>() > t["t_release_s"].get<double>());
    EXPECT_EQ(csv.find("nan"), std::string::npos);
  }
  fs::remove_all(a);
  fs::remove_all(b);
  fs::remove_all(c);
}

TEST(SimulateCampaign, ErrorWritesNothing) {
  // The rig table lacks 60 deg: found while simulating, before any file is written.
  std::string yaml = kSmallSpec;
  yaml.replace(yaml.find("inertia_kg_m2: 0.25"), std::string("inertia_kg_m2: 0.25").size(),
               "inertia_by_pitch_kg_m2: {-30: 0.25, 0: 0.25}");
  const fs::path dir = TempDir("err");
  try {
    RunSimulateCampaign(ParseSimulateSpec(yaml, "table.yaml"), dir.string());
    FAIL() << "expected an error";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("no entry for pitch 60"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir));
}

int RunCli(const std::string& args) {
  const std::string command = std::string(BIFILAR_BINARY) + " " + args + " >/dev/null 2>&1";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(SimulateCli, EndToEnd) {
  const fs::path dir = TempDir("cli");
  fs::create_directories(dir);
  const fs::path spec = dir / "spec.yaml";
  std::ofstream(spec) << kSmallSpec;
  EXPECT_EQ(RunCli("simulate " + spec.string() + " --out " + (dir / "out").string() + " --seed 3"), 0);
  EXPECT_TRUE(fs::exists(dir / "out/pitch_60/trial_2.csv"));
  EXPECT_TRUE(fs::exists(dir / "out/tare/tare_1.csv"));
  EXPECT_TRUE(fs::exists(dir / "out/truth.json"));
  EXPECT_EQ(nlohmann::json::parse(ReadText(dir / "out/truth.json"))["seed"].get<int>(), 3);

  const std::string trace = (dir / "one.csv").string();
  EXPECT_EQ(RunCli("simulate --trace " + trace + " --inertia-kg-m2 4.1 --mass-kg 6.75 -L 2 -D 1.8 "
                   "--amplitude-deg 15 --duration-s 10 --seed 9"), 0);
  EXPECT_TRUE(fs::exists(trace));
  const nlohmann::json truth = nlohmann::json::parse(ReadText(dir / "one.truth.json"));
  EXPECT_NEAR(truth["traces"][0]["amplitude_deg"].get<double>(), 15.0, 1e-12);
  EXPECT_NEAR(truth["traces"][0]["inertia_total_kg_m2"].get<double>(), 4.1, 1e-15);

  // Bad input: exit code 2 and nothing written.
  const std::string bad = (dir / "bad.csv").string();
  const std::string good = " --inertia-kg-m2 4.1 --mass-kg 6.75 ";
  EXPECT_EQ(RunCli("simulate --trace " + bad + good + "-L 1.5 -D 1.8"), 2);    // L <= D
  EXPECT_EQ(RunCli("simulate --trace " + bad + good + "-L 0 -D 1.8"), 2);      // L <= 0
  EXPECT_EQ(RunCli("simulate --trace " + bad + " --mass-kg 6.75 -L 2 -D 1.8"), 2);  // no inertia
  EXPECT_EQ(RunCli("simulate --trace " + bad + good + "-L 2 -D 1.8 --duration-s 0"), 2);
  EXPECT_EQ(RunCli("simulate --trace " + bad + good + "-L 2 -D 1.8 --sample-rate-hz 0"), 2);
  EXPECT_EQ(RunCli("simulate --trace " + bad + good + "-L 2 -D 1.8 --model exact"), 2);
  EXPECT_FALSE(fs::exists(bad));
  std::ofstream(dir / "typo.yaml") << std::string(kSmallSpec) + "sensr: {}\n";
  EXPECT_EQ(RunCli("simulate " + (dir / "typo.yaml").string() + " --out " + (dir / "typo").string()), 2);
  EXPECT_FALSE(fs::exists(dir / "typo"));
  EXPECT_EQ(RunCli("simulate " + spec.string() + " --out " + trace), 2);  // --out is a file
  EXPECT_EQ(RunCli("simulate"), 2);                                       // nothing to do
  fs::remove_all(dir);
}

}  // namespace
}  // namespace bifilar
