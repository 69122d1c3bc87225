// Campaign config: every key read, validated, relative paths resolved; typos and missing keys
// named with file and line.
#include "base/units.h"
#include "pipeline/config/config.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <vector>

#include <gtest/gtest.h>

#include "base/user_error.h"
#include "pipeline/trace/trace_process.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;

// Folders made by the tests, removed at exit.
struct TempDirs {
  std::vector<std::string> dirs;
  ~TempDirs() {
    std::error_code ec;
    for (const std::string& d : dirs) fs::remove_all(d, ec);
  }
};
TempDirs temp_dirs;

std::string TempDir() {
  char tmpl[] = "/tmp/bifilar_config_test_XXXXXX";
  temp_dirs.dirs.push_back(mkdtemp(tmpl));
  return temp_dirs.dirs.back();
}

std::string Write(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string path = dir + "/" + name;
  std::ofstream(path) << text;
  return path;
}

const char* kFull = R"(units: imperial
gravity_mps2: 9.81
rig:
  filar_length_m: 2.4
  filar_separation_m: 1.2
  mass_kg: 3.5
  inertia:
    tare:
      logs: logs/tare/*.csv
  uncertainties:
    filar_length_std_m: 0.002
    filar_separation_std_m: 0.001
    mass_std_kg: 0.01
    gravity_std_mps2: 0.001
aircraft:
  mass_kg: 12.0
  mass_std_kg: 0.02
imu:
  time: {column: time_ms, unit: ms}
  gyro: {columns: [wx, wy, wz], unit: deg/s, scale_std: 0.01}
  accel: {columns: [fx, fy, fz], unit: g}
  swing_axis: [0, 0, 2]
  imu_to_body: {euler_deg: [0, 0, 90]}
runs:
  root: logs
  pattern: "pitch_{pitch_deg}/*.csv"
  pitch_source: measured
fit:
  model: jardin
  windows:
    pitch_10/trial_1.csv: [5.0, 60.0]
  max_amplitude_deg: 30
  min_amplitude_deg: 1
  quality:
    max_rms_over_noise: 2.0
    max_residual_autocorr: 0.3
    whiteness_lags: 5
    max_secondary_motion_ratio: 0.2
    min_periods: 3
ellipse:
  bootstrap: 100
  seed: 7
  confidence: 0.9
  covariance: points
)";

TEST(Config, ReadsEveryKey) {
  const std::string dir = TempDir();
  const CampaignConfig c = LoadCampaignConfig(Write(dir, "c.yaml", kFull));
  EXPECT_EQ(c.units, DisplayUnits::kImperial);
  EXPECT_DOUBLE_EQ(c.gravity_mps2, 9.81);
  EXPECT_DOUBLE_EQ(c.filar_length_m, 2.4);
  EXPECT_DOUBLE_EQ(c.filar_separation_m, 1.2);
  EXPECT_DOUBLE_EQ(c.rig_mass_kg, 3.5);
  EXPECT_EQ(c.rig_inertia.kind, RigInertiaSpec::Kind::kTare);
  ASSERT_EQ(c.rig_inertia.tare_patterns.size(), 1u);
  EXPECT_EQ(c.rig_inertia.tare_patterns[0],
            fs::path(dir + "/logs/tare/*.csv").lexically_normal().string());
  EXPECT_DOUBLE_EQ(c.uncertainties.filar_length_std_m, 0.002);
  EXPECT_DOUBLE_EQ(c.uncertainties.gravity_std_mps2, 0.001);
  EXPECT_DOUBLE_EQ(c.aircraft_mass_kg, 12.0);
  EXPECT_DOUBLE_EQ(c.aircraft_mass_std_kg, 0.02);
  EXPECT_DOUBLE_EQ(c.AircraftGeometry().mass_kg, 15.5);
  EXPECT_DOUBLE_EQ(c.TareGeometry().mass_kg, 3.5);
  EXPECT_EQ(c.imu.format.time_column, "time_ms");
  EXPECT_EQ(c.imu.format.time_unit, TimeUnit::kMilliseconds);
  EXPECT_EQ(c.imu.format.gyro_columns[1], "wy");
  EXPECT_EQ(c.imu.format.gyro_unit, RateUnit::kDegPerS);
  EXPECT_DOUBLE_EQ(c.imu.gyro_scale_std, 0.01);
  EXPECT_EQ(c.imu.format.accel_unit, AccelUnit::kStandardGravity);
  EXPECT_FALSE(c.imu.swing_axis_auto);
  EXPECT_NEAR(c.imu.swing_axis_in_imu.z(), 1.0, 1e-15);  // normalised
  // Yaw 90 deg: IMU x -> body y.
  EXPECT_NEAR((c.imu.imu_to_body * Eigen::Vector3d::UnitX()).y(), 1.0, 1e-12);
  EXPECT_EQ(c.runs.root, fs::path(dir + "/logs").lexically_normal().string());
  EXPECT_EQ(c.runs.pattern, "pitch_{pitch_deg}/*.csv");
  EXPECT_EQ(c.runs.pitch_source, PitchSource::kMeasured);
  EXPECT_EQ(c.fit.model, PendulumModel::kJardin);
  ASSERT_EQ(c.fit.windows_s.count("pitch_10/trial_1.csv"), 1u);
  EXPECT_DOUBLE_EQ(c.fit.windows_s.at("pitch_10/trial_1.csv")[1], 60.0);
  EXPECT_DOUBLE_EQ(*c.fit.max_amplitude_deg, 30.0);
  EXPECT_DOUBLE_EQ(*c.fit.min_amplitude_deg, 1.0);
  EXPECT_DOUBLE_EQ(c.fit.quality.max_rms_over_noise, 2.0);
  EXPECT_EQ(c.fit.quality.whiteness_lags, 5);
  EXPECT_DOUBLE_EQ(c.fit.quality.min_periods, 3.0);
  EXPECT_EQ(c.ellipse.bootstrap, 100);
  EXPECT_EQ(c.ellipse.seed, 7u);
  EXPECT_EQ(c.ellipse.covariance, EllipseCovariance::kPointResiduals);
  EXPECT_NE(c.text.find("filar_length_m: 2.4"), std::string::npos);
  // The window override is found from the absolute log path.
  EXPECT_TRUE(ConfigWindowFor(c, dir + "/logs/pitch_10/trial_1.csv").has_value());
  EXPECT_FALSE(ConfigWindowFor(c, dir + "/logs/pitch_10/trial_2.csv").has_value());
}

const char* kMinimal = R"(rig:
  filar_length_m: 2.0
  filar_separation_m: 0.8
  mass_kg: 2.0
  inertia: {inertia_kg_m2: 0.1, inertia_std_kg_m2: 0.001}
aircraft: {mass_kg: 10}
runs: {root: ., pattern: "p{pitch_deg}.csv"}
)";

TEST(Config, DefaultsAreDocumentedValues) {
  const CampaignConfig c = LoadCampaignConfig(Write(TempDir(), "c.yaml", kMinimal));
  EXPECT_EQ(c.units, DisplayUnits::kSi);
  EXPECT_DOUBLE_EQ(c.gravity_mps2, kStandardGravityMps2);
  EXPECT_EQ(c.rig_inertia.kind, RigInertiaSpec::Kind::kValue);
  EXPECT_DOUBLE_EQ(c.rig_inertia.inertia_kg_m2, 0.1);
  EXPECT_EQ(c.fit.model, PendulumModel::kFull);
  EXPECT_TRUE(c.imu.swing_axis_auto);
  EXPECT_EQ(c.imu.format.time_column, "t");
  EXPECT_TRUE(c.imu.format.has_accel());
  EXPECT_FALSE(c.fit.max_amplitude_deg.has_value());
  EXPECT_EQ(c.runs.pitch_source, PitchSource::kNominal);
  EXPECT_EQ(c.ellipse.bootstrap, 2000);
  EXPECT_TRUE(c.imu.imu_to_body.isIdentity());
}

// Expects LoadCampaignConfig to throw a UserError whose message contains every `parts`.
void ExpectError(const std::string& yaml, std::vector<std::string> parts,
                 ConfigLoadOptions options = ConfigLoadOptions()) {
  const std::string path = Write(TempDir(), "bad.yaml", yaml);
  try {
    LoadCampaignConfig(path, options);
    FAIL() << "no error for:\n" << yaml;
  } catch (const UserError& e) {
    const std::string message = e.what();
    for (const std::string& part : parts) {
      EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
    }
    EXPECT_NE(message.find("bad.yaml"), std::string::npos) << message;
  }
}

TEST(Config, TypoInKeyIsNamedWithLine) {
  std::string yaml = kMinimal;
  yaml.replace(yaml.find("filar_length_m"), 14, "filar_lenght_m");
  // Reported as the missing required key, and (once added back) as an unknown key.
  ExpectError(yaml, {"missing required key 'rig.filar_length_m'"});
  ExpectError(std::string(kMinimal) + "fit: {modle: full}\n", {"unknown key 'fit.modle'", ":8:"});
  ExpectError(std::string(kMinimal) + "unit: si\n", {"unknown key 'unit'", ":8:"});
}

TEST(Config, MissingSectionsAndBadValues) {
  ExpectError(
      "rig: {filar_length_m: 2, filar_separation_m: 1, mass_kg: 1, inertia: {inertia_kg_m2: 0}}\n"
      "aircraft: {mass_kg: 1}\n",
      {"missing required key 'runs'"});
  std::string yaml = kMinimal;
  ExpectError(yaml + "units: metric\n", {"'units' must be si or imperial"});
  ExpectError(yaml + "fit: {model: quadratic}\n", {"'fit.model' must be full, jardin or linear"});
  ExpectError(yaml + "imu: {gyro: {unit: rpm}}\n", {"imu.gyro.unit", "rpm"});
  ExpectError(yaml + "imu: {gyro: {columns: [a, b]}}\n", {"imu.gyro.columns"});
  ExpectError(yaml + "imu: {swing_axis: [0, 0, 0]}\n", {"imu.swing_axis"});
  ExpectError(yaml + "fit: {windows: {a.csv: [5, 1]}}\n", {"fit.windows.a.csv", "t0 < t1"});
  ExpectError(yaml + "fit: {quality: {max_rms_over_noise: 0.5}}\n", {"fit.quality"});
  ExpectError(yaml + "ellipse: {covariance: magic}\n", {"ellipse.covariance"});
  yaml.replace(yaml.find("mass_kg: 2.0"), 12, "mass_kg: -2.0");
  ExpectError(yaml, {"rig.mass_kg = -2; must be > 0", ":4:"});
  ExpectError(
      "rig: {filar_length_m: 2, filar_separation_m: 1, mass_kg: 1,\n"
      "      inertia: {inertia_kg_m2: 0.1, table: {0: 0.1}}}\n"
      "aircraft: {mass_kg: 1}\nruns: {root: ., pattern: '*.csv'}\n",
      {"exactly one of"});
  ExpectError("rig: [1, 2]\n", {"'rig' must be a mapping"});
  ExpectError("rig: {filar_length_m: 2\n", {"invalid YAML"});
  ExpectError(std::string(kMinimal) + "runs2: {}\n", {"unknown key 'runs2'"});
}

TEST(Config, FitOnlyConfigNeedsNoRuns) {
  ConfigLoadOptions fit_only;
  fit_only.require_runs = false;
  const CampaignConfig c =
      LoadCampaignConfig(Write(TempDir(), "fit.yaml",
                               "rig: {filar_length_m: 2, filar_separation_m: 1, mass_kg: 1}\n"
                               "imu: {accel: null}\n"),
                         fit_only);
  EXPECT_TRUE(c.runs.root.empty());
  EXPECT_FALSE(c.imu.format.has_accel());
  EXPECT_DOUBLE_EQ(c.AircraftGeometry().mass_kg, 1.0);
}

TEST(Config, RigInertiaTableAndMatrixMounting) {
  std::string yaml = kMinimal;
  const std::string value_line = "inertia: {inertia_kg_m2: 0.1, inertia_std_kg_m2: 0.001}";
  yaml.replace(yaml.find(value_line), value_line.size(), "inertia: {table: {-10: 0.1, 10: 0.3}}");
  yaml += "imu: {imu_to_body: {matrix: [[0, -1, 0], [1, 0, 0], [0, 0, 1]]}}\n";
  const CampaignConfig c = LoadCampaignConfig(Write(TempDir(), "c.yaml", yaml));
  EXPECT_EQ(c.rig_inertia.kind, RigInertiaSpec::Kind::kTable);
  EXPECT_EQ(c.rig_inertia.table_kg_m2.size(), 2u);
  EXPECT_DOUBLE_EQ(c.imu.imu_to_body(0, 1), -1.0);
  ExpectError(
      std::string(kMinimal) + "imu: {imu_to_body: {matrix: [[1, 1, 0], [0, 1, 0], [0, 0, 1]]}}\n",
      {"must be a rotation"});
}

TEST(Config, MissingFileIsNamed) {
  try {
    LoadCampaignConfig("/nonexistent/campaign.yaml");
    FAIL();
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/campaign.yaml"), std::string::npos);
  }
}

}  // namespace
}  // namespace bifilar

namespace bifilar {
namespace {

// issue 9 items 3 and 11: count-like keys are bounded and every range is checked at load,
// naming the key and line, before any fit (bootstrap 50 and max_amplitude_deg 0 passed).
TEST(Config, CountsAndRangesAreBoundedAtLoad) {
  const std::string yaml = kMinimal;
  ExpectError(yaml + "ellipse:\n  bootstrap: 2147483647\n",
              {"ellipse.bootstrap = 2147483647; must be 0 (off) or in [100, 100000]", ":9:"});
  ExpectError(yaml + "ellipse: {bootstrap: 50}\n",
              {"ellipse.bootstrap = 50; must be 0 (off) or in [100, 100000]"});
  ExpectError(yaml + "ellipse: {min_angles: 100000}\n",
              {"ellipse.min_angles = 100000; must be in [3, 1000]"});
  ExpectError(yaml + "fit: {max_amplitude_deg: 0}\n",
              {"fit.max_amplitude_deg = 0; must be in [1, 90]"});
  ExpectError(yaml + "fit: {max_amplitude_deg: 179.9}\n",
              {"fit.max_amplitude_deg = 179.9; must be in [1, 90]"});
  ExpectError(yaml + "fit: {max_amplitude_deg: 20, min_amplitude_deg: 25}\n",
              {"fit.min_amplitude_deg = 25; must be < max_amplitude_deg = 20"});
  ExpectError(yaml + "fit: {quality: {whiteness_lags: 100000000}}\n",
              {"fit.quality.whiteness_lags = 100000000; must be in [1, 1000]"});
  // Nested keys: the line of the key itself, found through the field -> key table.
  ExpectError(yaml + "fit:\n  amplitude_sweep:\n    max_bands: 50\n",
              {"fit.amplitude_sweep.max_bands = 50; must be in [2, 20]", ":10:"});
  ExpectError(yaml + "fit:\n  quality:\n    reject_residual_fraction: 0\n",
              {"fit.quality.reject_residual_fraction = 0; must be in (0, 1]", ":10:"});
  ExpectError(yaml + "ellipse: {covariance: magic}\n",
              {"'ellipse.covariance' must be auto, points, angle_means or absolute, not 'magic'"});
  // Check() holds the same ranges for a config built in code.
  CampaignConfig config;
  std::string why;
  config.ellipse.bootstrap = 50;
  EXPECT_FALSE(config.ellipse.Check(&why));
  config.ellipse.bootstrap = 0;
  config.fit.max_amplitude_deg = 0.0;
  EXPECT_FALSE(config.fit.Check(&why));
  EXPECT_EQ(why, "fit.max_amplitude_deg = 0; must be in [1, 90]");
}

}  // namespace
}  // namespace bifilar

namespace bifilar {
namespace {

// issue 9 item 10: repeated keys were accepted silently and the first won.
TEST(Config, DuplicateKeysDocumentsAndTablePitchesNameBothLines) {
  // Line 3 repeats line 3's key at line 4 (kMinimal: rig at 1, filar_separation_m at 3).
  std::string yaml = kMinimal;
  yaml.insert(yaml.find("  mass_kg: 2.0"), "  filar_separation_m: 2.5\n");
  ExpectError(yaml, {":4: duplicate key 'rig.filar_separation_m' (first at line 3)"});
  // A second rig block.
  ExpectError(std::string(kMinimal) + "rig: {filar_length_m: 3}\n",
              {":8: duplicate key 'rig' (first at line 1)"});
  // A second YAML document.
  ExpectError(std::string(kMinimal) + "---\nunits: imperial\n",
              {":9:", "second YAML document", "line 1"});
  // Duplicate table pitches, written alike or differently.
  const char* table =
      "rig:\n  filar_length_m: 2\n  filar_separation_m: 1\n  mass_kg: 1\n"
      "  inertia:\n    table:\n      0: 0.1\n      %s: 0.2\n"
      "aircraft: {mass_kg: 1}\nruns: {root: ., pattern: 'p{pitch_deg}.csv'}\n";
  char buffer[400];
  std::snprintf(buffer, sizeof(buffer), table, "0");
  ExpectError(buffer, {":8:", "duplicate key 'rig.inertia.table.0' (first at line 7)"});
  std::snprintf(buffer, sizeof(buffer), table, "0.0");
  ExpectError(buffer, {":8:", "pitch 0.0 deg twice", ":7:"});
}

// The log reader's options as a config sets them: each bad value names the key, its value and the
// bound (the one format of base/option_check.h), and ImuLogOptions::Check does the same for
// options built in code.
TEST(ConfigCheck, LogOptionsNameKeyValueAndBound) {
  const std::string yaml = kMinimal;
  ExpectError(yaml + "limits: {max_log_mb: 0.5}\n",
              {"limits.max_log_mb = 0.5; must be in [1, 1000000] (MB)", ":8:"});
  ExpectError(yaml + "limits: {max_decompressed_log_mb: 2e6}\n",
              {"limits.max_decompressed_log_mb = 2000000; must be in [1, 1000000] (MB)"});
  ExpectError(yaml + "imu: {dataflash: {instance: 300}}\n",
              {"imu.dataflash.instance = 300; must be in [0, 255]"});
  ImuLogOptions options;
  std::string why;
  EXPECT_TRUE(options.Check(&why)) << why;
  options.max_dropped_fraction = 2;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_EQ(why, "max_dropped_fraction = 2; must be in [0, 1]");
  options = ImuLogOptions();
  options.min_rows = 0;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_EQ(why, "min_rows = 0; must be >= 1");
  options = ImuLogOptions();
  options.dataflash_instance = 256;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_EQ(why, "dataflash_instance = 256; must be in [0, 255] (or -1: the lowest in the log)");
}

// Every bound lives in the options struct's Check (a config built in code is checked for the
// quality, sweep and glitch ranges too), reported as field, value and bound; the config layer
// maps the field to its YAML key and line.
TEST(ConfigCheck, FailureNamesFieldValueAndBound) {
  FitConfig fit;
  CheckFailure failure;
  EXPECT_TRUE(fit.Check(&failure));
  fit.sweep.sweep_max_bands = 50;
  ASSERT_FALSE(fit.Check(&failure));
  EXPECT_EQ(failure.field, "amplitude_sweep.max_bands");  // the YAML key below `fit`
  EXPECT_EQ(failure.value, 50);
  EXPECT_EQ(failure.allowed, "in [2, 20]");
  std::string why;
  ASSERT_FALSE(fit.Check(&why));
  EXPECT_EQ(why, "fit.amplitude_sweep.max_bands = 50; must be in [2, 20]");
  fit = FitConfig();
  fit.quality.reject_residual_fraction = 1.5;
  ASSERT_FALSE(fit.Check(&failure));
  EXPECT_EQ(failure.field, "quality.reject_residual_fraction");
  EllipseConfig ellipse;
  ellipse.confidence = 1.0;
  ASSERT_FALSE(ellipse.Check(&failure));
  EXPECT_EQ(failure.field, "confidence");
  ASSERT_FALSE(ellipse.Check(&why));
  EXPECT_EQ(why, "ellipse.confidence = 1; must be in (0, 1)");
}

}  // namespace
}  // namespace bifilar
