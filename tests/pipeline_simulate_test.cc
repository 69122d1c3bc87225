// `bifilar simulate` end to end: the spec reader (strict keys, ranges, units), the CSV writer
// (units, round trip), byte-identical reruns, truth.json consistency, the CLI's exit codes.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "base/units.h"
#include "base/user_error.h"
#include "pipeline/commands/simulate_spec.h"
#include "pipeline/logs/imu_log_writer.h"
#include "pipeline/logs/simulated_log.h"
#include "test_support.h"

namespace bifilar {
namespace {

using test_support::ReadFile;

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("bifilar_sim_test_" + name + "_" + std::to_string(::getpid()));
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
  EXPECT_NEAR(spec.campaign.aircraft.ix_kg_m2, 2.3596 * kKgM2PerSlugFt2, 1e-12);
  EXPECT_NEAR(spec.campaign.aircraft.ixz_kg_m2, 0.0178 * kKgM2PerSlugFt2, 1e-12);
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
      {base + "sensor: {sample_rat_hz: 100}\n",
       "spec.yaml:2:10: unknown key 'sensor.sample_rat_hz'"},
      {base + "bogus: 1\n", "unknown key 'bogus'"},
      {"geometry: {filar_length_m: 1.5, filar_separation_m: 1.8}\n",
       "'geometry.filar_separation_m': filar_separation_m (D) = 1.8; must be < filar_length_m (L) "
       "= 1.5"},
      {"geometry: {filar_length_m: -1, filar_separation_m: 1.8}\n",
       "spec.yaml:1:28: geometry.filar_length_m = -1; must be in (0, 1000]"},
      {base + "sensor: {sample_rate_hz: 0}\n", "sensor.sample_rate_hz = 0; must be in (0, 100000]"},
      {base + "timeline: {free_s: 0}\n",
       "timeline.free_s = [0, 0]; must be min <= max, both in (0, 86400]"},
      {base + "timeline: {free_s: [50, 40]}\n",
       "timeline.free_s = [50, 40]; must be min <= max, both in (0, 86400]"},
      {base + "format: {time_unit: min}\n",
       "unknown unit 'min' for 'format.time_unit'; allowed s, ms or us"},
      {base + "format: {gyro_unit: rpm}\n", "unknown unit 'rpm' for 'format.gyro_unit'"},
      {base + "format: {accel_unit: ft/s^2}\n", "unknown unit 'ft/s^2' for 'format.accel_unit'"},
      {base + "model: exact\n", "unknown model 'exact'"},
      {base + "trace: {inertia_kg_m2: 0}\n", "trace.inertia_kg_m2 = 0; must be in (0, 1000000000]"},
      {base + "trace: {mass_kg: -3}\n", "trace.mass_kg = -3; must be in (0, 1000000]"},
      {base + "aircraft: {mass_kg: 5, ix_kg_m2: 1, iz_kg_m2: 1, ixz_kg_m2: 0}\n",
       "missing required key 'rig'"},
      {base + "aircraft: {mass_kg: 0, ix_kg_m2: 1, iz_kg_m2: 1, ixz_kg_m2: 0}\n",
       "aircraft.mass_kg = 0; must be in (0, 1000000]"},
      {base + "aircraft: {mass_kg: 5, iz_kg_m2: 1, ixz_kg_m2: 0}\n",
       "missing required key 'aircraft.ix_kg_m2' (or 'aircraft.ix_slug_ft2')"},
      {base + "aircraft: {mass_kg: 5, ix_kg_m2: 1, iz_kg_m2: 1, ixz_kg_m2: 0}\n"
              "rig: {mass_kg: 1, inertia_kg_m2: -0.2}\ncampaign: {pitch_deg: [0]}\n",
       "rig.inertia_kg_m2 = -0.2; must be in (0, 1000000000]"},
      {base + "aircraft: {mass_kg: 5, ix_kg_m2: 1, iz_kg_m2: 1, ixz_kg_m2: 0}\n"
              "rig: {mass_kg: 1, inertia_kg_m2: 0.2}\ncampaign: {pitch_deg: [0, 100]}\n",
       "'campaign.pitch_deg' has 100; allowed [-90, 90]"},
      {"geometry: [1, 2]\n", "'geometry' must be a mapping"},
  };
  for (const Case& c : cases) {
    const std::string message = ErrorOf(c.yaml);
    EXPECT_NE(message.find(c.expect), std::string::npos)
        << "yaml:\n"
        << c.yaml << "message: " << message << "\nexpected: " << c.expect;
  }
}

TEST(SimulateWriter, UnitsAndRoundTrip) {
  ImuData data;
  data.t_s = {0.0, 0.0101, 0.0199};
  data.gyro_in_imu = {Eigen::Vector3d(0.1, -0.2, 0.3), Eigen::Vector3d(0, 0, 1),
                      Eigen::Vector3d(1e-4, 2, -3)};
  data.accel_in_imu = {Eigen::Vector3d(0, 0, -kStandardGravityMps2), Eigen::Vector3d(1, 2, 3),
                       Eigen::Vector3d(-1, 0.5, kStandardGravityMps2)};
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
      EXPECT_NEAR(v[1 + i] * kRadPerDeg, data.gyro_in_imu[k][i],
                  1e-8 * std::abs(data.gyro_in_imu[k][i]) + 1e-15);
      EXPECT_NEAR(v[4 + i] * kStandardGravityMps2, data.accel_in_imu[k][i],
                  1e-8 * std::abs(data.accel_in_imu[k][i]) + 1e-15);
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
                                          "pitch_60/trial_1.csv",  "pitch_60/trial_2.csv",
                                          "tare/tare_1.csv",       "truth.json"};
  for (const auto& f : files) {
    ASSERT_TRUE(fs::exists(a / f)) << f;
    EXPECT_EQ(ReadFile(a / f), ReadFile(b / f)) << f;
    EXPECT_NE(ReadFile(a / f), ReadFile(c / f)) << f;
  }
  // The mark of a simulated log with its seed (pipeline/logs/simulated_log.h), then the header in
  // the spec's format; no temporary files left behind.
  const std::string head =
      SimulatedCsvMarkerLine(SimulatedLogOrigin(spec.seed)) + "\nt,wx,wy,wz,ax,ay,az\n";
  EXPECT_EQ(ReadFile(a / files[0]).substr(0, head.size()), head);
  for (const auto& entry : fs::recursive_directory_iterator(a)) {
    EXPECT_EQ(entry.path().string().find(".tmp"), std::string::npos) << entry.path();
  }

  const nlohmann::json truth = nlohmann::json::parse(ReadFile(a / "truth.json"));
  const auto& ac = truth["aircraft"];
  const double ix = ac["ix_kg_m2"], iz = ac["iz_kg_m2"], ixz = ac["ixz_kg_m2"];
  EXPECT_NEAR(ix, 2.3596 * kKgM2PerSlugFt2, 1e-12);
  EXPECT_NEAR(ac["tau_deg"].get<double>(), 0.5 * std::atan2(2 * ixz, iz - ix) / kRadPerDeg, 1e-12);
  ASSERT_EQ(truth["traces"].size(), 5u);
  for (const auto& t : truth["traces"]) {
    const double theta = t["true_pitch_deg"].get<double>() * kRadPerDeg;
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
    const std::string csv = ReadFile(a / t["file"].get<std::string>());
    const long rows = std::count(csv.begin(), csv.end(), '\n') - 2;  // the mark and the header
    EXPECT_EQ(rows, t["samples"].get<long>());
    EXPECT_GT(t["t_release_s"].get<double>(), t["t_twist_s"].get<double>());
    EXPECT_TRUE(t["t_stop_s"].is_null() ||
                t["t_stop_s"].get<double>() > t["t_release_s"].get<double>());
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
    EXPECT_NE(
        std::string(e.what()).find("pitch_deg = 60; must be a pitch of rig.inertia_by_pitch_kg_m2"),
        std::string::npos)
        << e.what();
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
  EXPECT_EQ(RunCli("simulate " + spec.string() + " --out " + (dir / "out").string() + " --seed 3"),
            0);
  EXPECT_TRUE(fs::exists(dir / "out/pitch_60/trial_2.csv"));
  EXPECT_TRUE(fs::exists(dir / "out/tare/tare_1.csv"));
  EXPECT_TRUE(fs::exists(dir / "out/truth.json"));
  EXPECT_EQ(nlohmann::json::parse(ReadFile(dir / "out/truth.json"))["seed"].get<int>(), 3);

  const std::string trace = (dir / "one.csv").string();
  EXPECT_EQ(RunCli("simulate --trace " + trace +
                   " --inertia-kg-m2 4.1 --mass-kg 6.75 -L 2 -D 1.8 "
                   "--amplitude-deg 15 --duration-s 10 --seed 9"),
            0);
  EXPECT_TRUE(fs::exists(trace));
  const nlohmann::json truth = nlohmann::json::parse(ReadFile(dir / "one.truth.json"));
  EXPECT_NEAR(truth["traces"][0]["amplitude_deg"].get<double>(), 15.0, 1e-12);
  EXPECT_NEAR(truth["traces"][0]["inertia_total_kg_m2"].get<double>(), 4.1, 1e-15);

  // Bad input: exit code 2 and nothing written.
  const std::string bad = (dir / "bad.csv").string();
  const std::string good = " --inertia-kg-m2 4.1 --mass-kg 6.75 ";
  EXPECT_EQ(RunCli("simulate --trace " + bad + good + "-L 1.5 -D 1.8"), 2);         // L <= D
  EXPECT_EQ(RunCli("simulate --trace " + bad + good + "-L 0 -D 1.8"), 2);           // L <= 0
  EXPECT_EQ(RunCli("simulate --trace " + bad + " --mass-kg 6.75 -L 2 -D 1.8"), 2);  // no inertia
  EXPECT_EQ(RunCli("simulate --trace " + bad + good + "-L 2 -D 1.8 --duration-s 0"), 2);
  EXPECT_EQ(RunCli("simulate --trace " + bad + good + "-L 2 -D 1.8 --sample-rate-hz 0"), 2);
  EXPECT_EQ(RunCli("simulate --trace " + bad + good + "-L 2 -D 1.8 --model exact"), 2);
  EXPECT_FALSE(fs::exists(bad));
  std::ofstream(dir / "typo.yaml") << std::string(kSmallSpec) + "sensr: {}\n";
  EXPECT_EQ(
      RunCli("simulate " + (dir / "typo.yaml").string() + " --out " + (dir / "typo").string()), 2);
  EXPECT_FALSE(fs::exists(dir / "typo"));
  EXPECT_EQ(RunCli("simulate " + spec.string() + " --out " + trace), 2);  // --out is a file
  EXPECT_EQ(RunCli("simulate"), 2);                                       // nothing to do
  fs::remove_all(dir);
}

// ---- Realism keys, footer, presets (issue 8) and output targets (issue 9) -------------------

// Runs the CLI with stderr captured; returns the exit code, *err the message.
int RunCliCapture(const std::string& args, const fs::path& dir, std::string* err) {
  const fs::path err_file = dir / "stderr.txt";
  const std::string command =
      std::string(BIFILAR_BINARY) + " " + args + " >/dev/null 2>" + err_file.string();
  const int status = std::system(command.c_str());
  *err = ReadFile(err_file);
  fs::remove(err_file);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(SimulateSpec, RealismKeysParseAndBadValuesNameTheKey) {
  const std::string base = "geometry: {filar_length_m: 2.0, filar_separation_m: 1.8}\n";
  const SimulateSpec spec = ParseSimulateSpec(
      base +
          "sensor: {sample_steps: lognormal, step_log_sigma: 0.5, step_range_s: [0.01, 0.1],\n"
          "  gyro_noise_ar1_phi: 0.7, gyro_bias_walk_deg_per_s_per_sqrt_s: 0.02,\n"
          "  spike_count: 5, spike_rate_rad_per_s: 50, accelerometer: gravity_removed,\n"
          "  gravity_removal_error_deg: [4, 15]}\n"
          "swing: {softening_percent_at_30deg: 2.8, softening_exponent: 1}\n"
          "format: {footer: true}\n",
      "spec.yaml");
  const SensorOptions& s = spec.options.sensor;
  EXPECT_EQ(s.sample_steps, SampleSteps::kLogNormal);
  EXPECT_EQ(s.step_log_sigma, 0.5);
  EXPECT_EQ(s.step_range_s.min, 0.01);
  EXPECT_EQ(s.step_range_s.max, 0.1);
  EXPECT_EQ(s.gyro_noise_ar1_phi, 0.7);
  EXPECT_EQ(s.gyro_bias_walk_deg_per_s_per_sqrt_s, 0.02);
  EXPECT_EQ(s.spike_count, 5);
  EXPECT_EQ(s.spike_rate_rad_per_s, 50);
  EXPECT_TRUE(s.accelerometer);
  EXPECT_TRUE(s.accel_gravity_removed);
  EXPECT_EQ(s.gravity_removal_error_deg.max, 15);
  EXPECT_NEAR(spec.options.softening_at_30deg, 0.028, 1e-15);
  EXPECT_EQ(spec.options.softening_exponent, 1);
  EXPECT_TRUE(spec.footer);
  // Absent keys: everything off, as before the keys existed.
  const SimulateSpec plain = ParseSimulateSpec(base, "plain.yaml");
  EXPECT_EQ(plain.options.sensor.sample_steps, SampleSteps::kRegular);
  EXPECT_EQ(plain.options.sensor.gyro_noise_ar1_phi, 0.0);
  EXPECT_EQ(plain.options.sensor.spike_count, 0);
  EXPECT_FALSE(plain.options.sensor.accel_gravity_removed);
  EXPECT_EQ(plain.options.softening_at_30deg, 0.0);
  EXPECT_FALSE(plain.footer);

  const std::vector<std::pair<std::string, std::string>> bad = {
      {"sensor: {gyro_noise_ar1_phi: 1.0}\n",
       "spec.yaml:2:30: sensor.gyro_noise_ar1_phi = 1; must be in [0, 0.99]"},
      {"sensor: {sample_steps: poisson}\n",
       "unknown value 'poisson' for 'sensor.sample_steps'; allowed regular or lognormal"},
      {"sensor: {step_range_s: [0.2, 0.1]}\n",
       "sensor.step_range_s = [0.2, 0.1]; must be min <= max, both in (0, 3600]"},
      {"sensor: {spike_count: 2.5}\n", "'sensor.spike_count' must be a whole number"},
      {"sensor: {spike_count: 5000}\n", "sensor.spike_count = 5000; must be in [0, 1000]"},
      {"sensor: {spike_rate_rad_per_s: 0}\n",
       "sensor.spike_rate_rad_per_s = 0; must be in (0, 10000]"},
      {"sensor: {accelerometer: gravity}\n",
       "'sensor.accelerometer' must be true, false or gravity_removed"},
      {"sensor: {gravity_removal_error_deg: 40}\n",
       "sensor.gravity_removal_error_deg = [40, 40]; must be min <= max, both in [0, 30]"},
      {"sensor: {gyro_bias_walk_deg_per_s_per_sqrt_s: -1}\n",
       "sensor.gyro_bias_walk_deg_per_s_per_sqrt_s = -1; must be in [0, 10]"},
      {"swing: {softening_percent_at_30deg: 80}\n",
       "swing.softening_percent_at_30deg = 80; must be in [0, 50]"},
      {"swing: {softening_exponent: 6}\n", "swing.softening_exponent = 6; must be in [1, 4]"},
      {"format: {footer: maybe}\n", "'format.footer' must be true or false"},
      {"sensor: {sample_rate_hz: 2000, time_jitter_sigma_s: 0.001}\n",
       "'sensor.time_jitter_sigma_s' = 0.001 s is more than one sample period"},
  };
  for (const auto& c : bad) {
    const std::string message = ErrorOf(base + c.first);
    EXPECT_NE(message.find(c.second), std::string::npos)
        << "yaml:\n"
        << c.first << "message: " << message << "\nexpected: " << c.second;
  }
}

TEST(SimulateTrace, FooterFollowsUnchangedData) {
  const std::string yaml =
      "seed: 4\ngeometry: {filar_length_m: 2.0, filar_separation_m: 1.8}\n"
      "trace: {inertia_kg_m2: 4.1, mass_kg: 6.75}\ntimeline: {free_s: 5}\n"
      "format: {time_unit: ms, delimiter: ';'}\n";
  const fs::path dir = TempDir("footer");
  SimulateSpec spec = ParseSimulateSpec(yaml, "f.yaml");
  RunSimulateTrace(spec, (dir / "plain.csv").string());
  spec.footer = true;
  RunSimulateTrace(spec, (dir / "footer.csv").string());
  const std::string plain = ReadFile(dir / "plain.csv"), footer = ReadFile(dir / "footer.csv");
  ASSERT_GT(footer.size(), plain.size());
  EXPECT_EQ(footer.substr(0, plain.size()), plain);  // the data before the footer is unchanged
  const std::string tail = footer.substr(plain.size());
  // A blank line, then 3 rows of 7 cells: time numeric again and smaller than the last time, text
  // in the last column.
  ASSERT_EQ(tail[0], '\n');
  std::istringstream rows(tail.substr(1));
  std::string row;
  std::vector<std::vector<std::string>> cells;
  while (std::getline(rows, row)) {
    std::vector<std::string> v;
    std::stringstream ss(row);
    std::string cell;
    while (std::getline(ss, cell, ';')) v.push_back(cell);
    if (!row.empty() && row.back() == ';') v.push_back("");
    cells.push_back(v);
  }
  ASSERT_EQ(cells.size(), 3u);
  const size_t last_row = plain.rfind('\n', plain.size() - 2);
  const double last_time_ms = std::stod(plain.substr(last_row + 1));
  for (size_t r = 0; r < 3; ++r) ASSERT_EQ(cells[r].size(), 7u) << "footer row " << r;
  EXPECT_EQ(cells[0][0], "");
  EXPECT_EQ(cells[1][6], "Flip Data");
  EXPECT_EQ(cells[2][6], "Impact Data");
  const nlohmann::json truth = nlohmann::json::parse(ReadFile(dir / "footer.truth.json"));
  const auto& t = truth["traces"][0];
  EXPECT_NEAR(std::stod(cells[1][0]),
              1e3 * (t["t_release_s"].get<double>() - t["start_time_s"].get<double>()), 1e-2);
  EXPECT_LT(std::stod(cells[1][0]), last_time_ms);
  EXPECT_EQ(std::stod(cells[2][0]), 0.0);
  EXPECT_EQ(t["footer_rows"].get<int>(), 4);
  EXPECT_TRUE(truth["options"]["format"]["footer"].get<bool>());
  EXPECT_FALSE(
      nlohmann::json::parse(ReadFile(dir / "plain.truth.json"))["options"]["format"].contains(
          "footer"));
  fs::remove_all(dir);
}

TEST(SimulateCli, RefusesTargetsThatAreNotRegularFilesOrTheSameFile) {
  const fs::path dir = TempDir("targets");
  fs::create_directories(dir / "sub");
  const std::string good = " --inertia-kg-m2 4.1 --mass-kg 6.75 -L 2 -D 1.8 --duration-s 3";
  const fs::path fifo = dir / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  fs::create_symlink("/dev/null", dir / "null_link");  // a rename would replace the link only
  std::string err;
  struct Case {
    std::string args, expect;
  };
  const std::string d = dir.string() + "/";
  const std::vector<Case> cases = {
      {"--trace " + d + "fifo", "--trace " + d + "fifo: exists and is not a regular file"},
      {"--trace " + d + "a.csv --truth " + d + "fifo",
       "--truth " + d + "fifo: exists and is not a regular file"},
      {"--trace " + d + "null_link", "null_link: exists and is not a regular file"},
      {"--trace " + d + "sub", "--trace " + d + "sub: is a folder"},
      {"--trace " + d + "b.csv --truth " + d + "b.csv", "are the same file"},
      {"--trace " + d + "b.csv --truth " + d + "./b.csv", "are the same file"},
      {"--trace " + d + "b.csv --truth " + d + "sub/../b.csv", "are the same file"},
      {"--trace " + d + "b.csv --truth " + d + "nosuch/../b.csv", "are the same file"},
      {"--trace " + d + "fifo/x.csv", "fifo exists and is not a folder"},
  };
  for (const Case& c : cases) {
    EXPECT_EQ(RunCliCapture("simulate " + c.args + good, dir, &err), 2) << c.args;
    EXPECT_NE(err.find(c.expect), std::string::npos) << c.args << "\n" << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << "one line: " << err;
  }
  // A hard link to the CSV is the same file too (with --force, which lets an existing file be
  // replaced); a symbolic link is refused as a link (base/atomic_file.h), and without
  // --force an existing file is refused as such (issue 23).
  std::ofstream(dir / "c.csv") << "mine\n";
  fs::create_symlink(dir / "c.csv", dir / "c_link.json");
  fs::create_hard_link(dir / "c.csv", dir / "c_hard.json");
  const struct {
    std::string args, expect;
  } links[] = {
      {"--truth " + d + "c_hard.json --force", "are the same file"},
      {"--truth " + d + "c_link.json --force", "c_link.json: is a symbolic link"},
      {"--truth " + d + "c_hard.json", "simulate --trace: " + d + "c.csv exists"},
  };
  for (const auto& c : links) {
    EXPECT_EQ(RunCliCapture("simulate --trace " + d + "c.csv " + c.args + good, dir, &err), 2);
    EXPECT_NE(err.find(c.expect), std::string::npos) << c.args << "\n" << err;
  }
  // Nothing was written: the FIFO is still a FIFO, the link still a link, no new files.
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(fifo)));
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir / "null_link")));
  EXPECT_EQ(ReadFile(dir / "c.csv"), "mine\n");
  for (const char* name : {"a.csv", "b.csv", "a.truth.json", "b.truth.json", "nosuch"}) {
    EXPECT_FALSE(fs::exists(dir / name)) << name;
  }
  // A campaign whose truth.json or one of whose logs is a FIFO: refused before any log is written.
  const fs::path spec = dir / "spec.yaml";
  std::ofstream(spec) << kSmallSpec;
  fs::create_directories(dir / "out1");
  ASSERT_EQ(::mkfifo((dir / "out1/truth.json").c_str(), 0600), 0);
  EXPECT_EQ(RunCliCapture("simulate " + spec.string() + " --out " + d + "out1", dir, &err), 2);
  EXPECT_NE(err.find("truth.json: exists and is not a regular file"), std::string::npos) << err;
  fs::create_directories(dir / "out2/pitch_60");
  ASSERT_EQ(::mkfifo((dir / "out2/pitch_60/trial_2.csv").c_str(), 0600), 0);
  EXPECT_EQ(RunCliCapture("simulate " + spec.string() + " --out " + d + "out2", dir, &err), 2);
  EXPECT_NE(err.find("trial_2.csv: exists and is not a regular file"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir / "out2/pitch_-30"));
  EXPECT_FALSE(fs::exists(dir / "out2/truth.json"));
  // The same file given as a campaign folder: refused as before.
  EXPECT_EQ(RunCliCapture("simulate " + spec.string() + " --out " + d + "fifo", dir, &err), 2);
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(fifo)));
  fs::remove_all(dir);
}

TEST(SimulateCli, SampleRateFlagNamesWhatTheUserSet) {
  const fs::path dir = TempDir("rate");
  fs::create_directories(dir);
  const std::string good = " --inertia-kg-m2 4.1 --mass-kg 6.75 -L 2 -D 1.8 --duration-s 2";
  std::string err;
  // Issue 9: --sample-rate-hz 2000 failed on sensor.time_jitter_sigma_s, a key the user never
  // set. The default jitter now follows the rate (at most 10 % of a sample period).
  EXPECT_EQ(RunCliCapture(
                "simulate --trace " + (dir / "fast.csv").string() + good + " --sample-rate-hz 2000",
                dir, &err),
            0)
      << err;
  const nlohmann::json truth = nlohmann::json::parse(ReadFile(dir / "fast.truth.json"));
  EXPECT_EQ(truth["options"]["sensor"]["sample_rate_hz"].get<double>(), 2000);
  EXPECT_NEAR(truth["options"]["sensor"]["time_jitter_sigma_s"].get<double>(), 0.1 / 2000, 1e-18);
  // At 100 Hz and below the default stays 1 ms (the same bytes as before).
  EXPECT_EQ(DefaultTimeJitterSigmaS(100), 0.001);
  EXPECT_EQ(DefaultTimeJitterSigmaS(50), 0.001);
  // A jitter the spec did set, too large for the new rate: the message names both and what to do.
  std::ofstream(dir / "jitter.yaml") << "sensor: {time_jitter_sigma_s: 0.001}\n";
  EXPECT_EQ(RunCliCapture("simulate " + (dir / "jitter.yaml").string() + " --trace " +
                              (dir / "bad.csv").string() + good + " --sample-rate-hz 2000",
                          dir, &err),
            2);
  EXPECT_NE(err.find("--sample-rate-hz 2000: 'sensor.time_jitter_sigma_s' = 0.001 s in " +
                     (dir / "jitter.yaml").string() + " is more than one sample period"),
            std::string::npos)
      << err;
  EXPECT_NE(err.find("lower it in the spec"), std::string::npos) << err;
  std::ofstream(dir / "rocking.yaml") << "sensor: {rocking_frequency_hz: 2}\n";
  EXPECT_EQ(RunCliCapture("simulate " + (dir / "rocking.yaml").string() + " --trace " +
                              (dir / "bad.csv").string() + good + " --sample-rate-hz 4",
                          dir, &err),
            2);
  EXPECT_NE(err.find("'sensor.rocking_frequency_hz' = 2 Hz"), std::string::npos) << err;
  EXPECT_NE(err.find("raise --sample-rate-hz to at least 8"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir / "bad.csv"));
  // The same rule in a spec: sample_rate_hz 2000 without a jitter key works.
  const SimulateSpec spec = ParseSimulateSpec("sensor: {sample_rate_hz: 2000}\n", "fast.yaml");
  EXPECT_EQ(spec.options.sensor.time_jitter_sigma_s, 0.1 / 2000);
  fs::remove_all(dir);
}

// The `t` column of a Crazyflie log up to its first break (blank line, text, time going back).
std::vector<double> CrazyflieTimes(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  std::stringstream header(line);
  std::string cell;
  int column = -1;
  for (int i = 0; std::getline(header, cell, ','); ++i) {
    if (cell == "t") column = i;
  }
  std::vector<double> t;
  while (column >= 0 && std::getline(in, line) && !line.empty()) {
    std::stringstream row(line);
    for (int i = 0; i <= column; ++i) std::getline(row, cell, ',');
    char* end = nullptr;
    const double value = std::strtod(cell.c_str(), &end);
    if (cell.empty() || *end != '\0' || (!t.empty() && value <= t.back())) break;
    t.push_back(value);
  }
  return t;
}

struct StepStats {
  double median = 0, mean = 0, p95 = 0, min = 0;
  size_t count = 0;
};

StepStats Steps(const std::vector<std::vector<double>>& logs) {
  std::vector<double> steps;
  for (const auto& t : logs) {
    for (size_t k = 1; k < t.size(); ++k) steps.push_back(t[k] - t[k - 1]);
  }
  std::sort(steps.begin(), steps.end());
  StepStats s;
  s.count = steps.size();
  if (steps.empty()) return s;
  for (double v : steps) s.mean += v / steps.size();
  s.median = steps[steps.size() / 2];
  s.p95 = steps[steps.size() * 95 / 100];
  s.min = steps.front();
  return s;
}

TEST(SimulatePresets, QuadrotorLooksLikeTheCrazyflieLogs) {
  const SimulateSpec spec =
      ReadSimulateSpec(std::string(BIFILAR_SOURCE_DIR) + "/configs/simulate_quadrotor.yaml");
  const fs::path dir = TempDir("quadrotor");
  const SimulateRunSummary summary = RunSimulateCampaign(spec, dir.string());
  EXPECT_EQ(summary.files_written, 8);
  const nlohmann::json truth = nlohmann::json::parse(ReadFile(dir / "truth.json"));
  std::vector<std::vector<double>> simulated;
  for (const auto& t : truth["traces"]) {
    const double inertia = t["inertia_total_kg_m2"];
    const double expected = t["nominal_pitch_deg"].get<double>() == 0 ? 32e-6 : 16e-6;
    EXPECT_NEAR(inertia, expected, 0.002 * expected);  // 1 deg pitch error: < 0.1 %
    EXPECT_NEAR(t["mass_kg"].get<double>(), 0.0343, 1e-12);
    const double amplitude = std::abs(t["amplitude_deg"].get<double>());
    EXPECT_GE(amplitude, 10.0);
    EXPECT_LE(amplitude, 25.0);
    ASSERT_EQ(t["spikes"].size(), 1u);
    EXPECT_EQ(std::abs(t["spikes"][0]["rate_rad_per_s"].get<double>()), 5.0);
    EXPECT_GE(t["spikes"][0]["t_s"].get<double>(), t["t_release_s"].get<double>());
    std::string csv = ReadFile(dir / t["file"].get<std::string>());
    ASSERT_EQ(csv.rfind("# simulated by bifilar ", 0), 0u);  // the mark, then the real log's form
    csv.erase(0, csv.find('\n') + 1);
    EXPECT_EQ(csv.substr(0, 11), "t,wx,wy,wz\n");                        // no accelerometer
    EXPECT_NE(csv.find("\n\n,,,Rollout Completed"), std::string::npos);  // the footer
    std::ofstream(dir / "one.csv") << csv;
    simulated.push_back(CrazyflieTimes(dir / "one.csv"));
    EXPECT_EQ(simulated.back().size(), t["samples"].get<size_t>());  // the data stops at the footer
  }
  EXPECT_EQ(truth["options"]["sensor"]["gyro_noise_ar1_phi"].get<double>(), 0.5);
  // Steps: 8-160 ms around a 31 ms median, like the real logs.
  const StepStats sim = Steps(simulated);
  EXPECT_GE(sim.min, 0.008 - 1e-9);
  EXPECT_NEAR(sim.median, 0.031, 0.003);
  // The real logs (crazyflie/ of the data folder; without one named the test ends here).
  fs::remove_all(dir);
  BIFILAR_REAL_DATA(real_dir, "crazyflie");
  std::vector<std::vector<double>> real;
  for (const auto& entry : fs::directory_iterator(real_dir)) {
    if (entry.path().extension() == ".csv") real.push_back(CrazyflieTimes(entry.path()));
  }
  const StepStats measured = Steps(real);
  ASSERT_GT(measured.count, 10000u);
  // Median 31.1 ms, mean 40.9 ms, 95th percentile 103 ms on the 24 real logs; the preset within
  // 10 % (~6 000 simulated steps: the sampling error of each statistic is 1-3 %).
  EXPECT_NEAR(sim.median / measured.median, 1.0, 0.10);
  EXPECT_NEAR(sim.mean / measured.mean, 1.0, 0.10);
  EXPECT_NEAR(sim.p95 / measured.p95, 1.0, 0.10);
}

TEST(SimulatePresets, NonidealRigRecordsItsSoftening) {
  const SimulateSpec spec =
      ReadSimulateSpec(std::string(BIFILAR_SOURCE_DIR) + "/configs/simulate_nonideal_rig.yaml");
  EXPECT_NEAR(spec.options.softening_at_30deg, 0.12, 1e-15);
  const fs::path a = TempDir("nonideal_a"), b = TempDir("nonideal_b");
  RunSimulateCampaign(spec, a.string());
  RunSimulateCampaign(spec, b.string());
  const nlohmann::json truth = nlohmann::json::parse(ReadFile(a / "truth.json"));
  EXPECT_EQ(truth["options"]["softening_percent_at_30deg"].get<double>(), 12);
  ASSERT_EQ(truth["traces"].size(), 8u);
  for (const auto& t : truth["traces"]) {
    const std::string file = t["file"];
    EXPECT_EQ(ReadFile(a / file), ReadFile(b / file)) << file;  // same spec and seed, same bytes
    const double inertia = t["inertia_total_kg_m2"];
    const double expected = t["nominal_pitch_deg"].get<double>() == 0 ? 0.050 : 0.027;
    EXPECT_NEAR(inertia, expected, 1e-4 * expected);  // the TRUE inertia, softening or not
    EXPECT_NEAR(t["mass_kg"].get<double>(), 3.34, 1e-12);
    // Harmonic balance at the release amplitude: x = x30 (A/30)^2, excess x / (1 - x), as the
    // header says, with 1 / (1 - x30) = 1.12.
    const double x30 = 0.12 / 1.12, x = x30 * std::pow(t["amplitude_deg"].get<double>() / 30, 2);
    EXPECT_NEAR(t["apparent_inertia_excess_at_release"].get<double>(), x / (1 - x), 1e-12);
    EXPECT_NEAR(t["apparent_inertia_at_release_kg_m2"].get<double>(), inertia * (1 + x / (1 - x)),
                1e-15);
    EXPECT_LT(t["amplitude_at_end_deg"].get<double>(), 8.0);  // the sweep reaches small amplitudes
    const double error = t["gravity_removal_error_deg"];
    EXPECT_GE(error, 4.0);
    EXPECT_LE(error, 15.0);
    // Gravity removed: the mean accelerometer reading is 0.07-0.26 g, not 1 g.
    std::istringstream csv(ReadFile(a / file));
    std::string line;
    std::getline(csv, line);
    EXPECT_EQ(line.rfind("# simulated by bifilar ", 0), 0u) << line;
    std::getline(csv, line);
    EXPECT_EQ(line, "t,gx,gy,gz,ax,ay,az");
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    long rows = 0;
    while (std::getline(csv, line)) {
      double v[7];
      ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf,%lf", &v[0], &v[1], &v[2], &v[3],
                            &v[4], &v[5], &v[6]),
                7);
      mean += Eigen::Vector3d(v[4], v[5], v[6]);
      ++rows;
    }
    // |mean| = 2 sin(error/2) g, plus the lever-arm and bias terms (< 0.02 g).
    EXPECT_NEAR(mean.norm() / rows, 2 * std::sin(error / 2 * kRadPerDeg), 0.02) << file;
  }
  fs::remove_all(a);
  fs::remove_all(b);
}

}  // namespace
}  // namespace bifilar
