// Issue 23, through the real `bifilar` binary: no command writes over a file it did not create
// without --force (simulate --trace/--truth/--out, init, export --out), export never writes over
// its input or the campaign's files, no symbolic link is replaced (a link to /proc/self/fd/1 in a
// private folder: the real /dev/stdout is never touched), a simulated log says so in inspect and
// the report, export writes no non-physical tensor to a simulator file, init writes only configs
// `fit` accepts and no log name can add a key to them.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/units.h"
#include "base/user_error.h"
#include "pipeline/config/config.h"
#include "pipeline/config/config_template.h"
#include "pipeline/logs/simulated_log.h"
#include "test_support.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;
using test_support::Bifilar;
using test_support::CliRun;
using test_support::ReadFile;
using test_support::TempDir;
using test_support::WriteFile;

// A one-line shell word: `text` in single quotes (a quote inside closed, escaped and reopened).
std::string Shell(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

const std::string kTrace =
    " --inertia-kg-m2 1.6e-5 --mass-kg 0.0343 -L 0.594 -D 0.030 --duration-s 20 --seed 3";

const char* kSmallCampaign = R"(
seed: 5
geometry: {filar_length_m: 2.0, filar_separation_m: 1.8}
aircraft: {mass_kg: 5.5, ix_slug_ft2: 2.3596, iz_slug_ft2: 2.8477, ixz_slug_ft2: 0.0178}
rig: {mass_kg: 1.2, imu_mass_kg: 0.05, inertia_kg_m2: 0.25, tare_logs: 1}
campaign: {pitch_deg: [0, 45, 90], trials_per_pitch: 1}
timeline: {free_s: 6, rest_before_s: [1, 2]}
)";

TEST(Overwrite, SimulateTraceAndTruthRefuseAnExistingFileWithoutForce) {
  TempDir dir("bifilar_overwrite");
  const std::string real = WriteFile(dir.path + "/real_log.csv", "t,gx,gy,gz\n0,0,0,0\n");
  CliRun r = Bifilar(dir, "simulate --trace " + real + kTrace);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("simulate --trace: " + real + " exists"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--force"), std::string::npos) << r.err;
  EXPECT_EQ(ReadFile(real), "t,gx,gy,gz\n0,0,0,0\n");
  EXPECT_FALSE(fs::exists(dir.path + "/real_log.truth.json"));

  const std::string notes = WriteFile(dir.path + "/notes.json", "{\"mine\": 1}\n");
  r = Bifilar(dir, "simulate --trace " + dir.path + "/new.csv --truth " + notes + kTrace);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("simulate --truth: " + notes + " exists"), std::string::npos) << r.err;
  EXPECT_EQ(ReadFile(notes), "{\"mine\": 1}\n");
  EXPECT_FALSE(fs::exists(dir.path + "/new.csv"));

  // Told to: replaced, and marked as simulated.
  r = Bifilar(dir, "simulate --trace " + real + kTrace + " --force");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(ReadFile(real).rfind(SimulatedCsvMarkerLine(SimulatedLogOrigin(3)) + "\n", 0), 0u);
}

TEST(Overwrite, SimulateCampaignRefusesAFolderHoldingItsFilesAndWritesItsOwnOnlyWithForce) {
  TempDir dir("bifilar_overwrite");
  const std::string spec = WriteFile(dir.path + "/spec.yaml", kSmallCampaign);
  const std::string out = dir.path + "/out";
  const std::string real = WriteFile(out + "/pitch_0/trial_1.csv", "my real log\n");
  CliRun r = Bifilar(dir, "simulate " + spec + " --out " + out);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(real + " exists"), std::string::npos) << r.err;
  EXPECT_EQ(ReadFile(real), "my real log\n");
  EXPECT_FALSE(fs::exists(out + "/truth.json"));
  EXPECT_FALSE(fs::exists(out + "/tare/tare_1.csv"));
  // An existing truth.json is refused before any simulation.
  const std::string other = dir.path + "/other";
  WriteFile(other + "/truth.json", "{}");
  r = Bifilar(dir, "simulate " + spec + " --out " + other);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(other + "/truth.json exists"), std::string::npos) << r.err;
  EXPECT_EQ(ReadFile(other + "/truth.json"), "{}");
  // A fresh folder: written; the same again needs --force.
  const std::string fresh = dir.path + "/fresh";
  ASSERT_EQ(Bifilar(dir, "simulate " + spec + " --out " + fresh).exit_code, 0);
  r = Bifilar(dir, "simulate " + spec + " --out " + fresh);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("exists"), std::string::npos) << r.err;
  r = Bifilar(dir, "simulate " + spec + " --out " + fresh + " --force");
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

TEST(Overwrite, ASimulatedLogSaysSoInInspectCsvAndUlog) {
  TempDir dir("bifilar_overwrite");
  for (const std::string name : {"s.csv", "s.csv.gz", "s.ulg"}) {
    const std::string log = dir.path + "/" + name;
    ASSERT_EQ(Bifilar(dir, "simulate --trace " + log + kTrace).exit_code, 0) << name;
    const CliRun r = Bifilar(dir, "inspect " + log);
    EXPECT_NE(r.out.find("warning: " + SimulatedLogWarning(SimulatedLogOrigin(3))),
              std::string::npos)
        << name << "\n"
        << r.out << r.err;
    // The mark is not counted with other comment lines, and the log reads as before.
    EXPECT_EQ(r.out.find("comment line"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("samples"), std::string::npos) << r.out;
  }
  // A real log (no mark) says nothing of the kind.
  const std::string plain = ReadFile(dir.path + "/s.csv");
  WriteFile(dir.path + "/real.csv", plain.substr(plain.find('\n') + 1));
  const CliRun r = Bifilar(dir, "inspect " + dir.path + "/real.csv");
  EXPECT_EQ(r.out.find("simulated"), std::string::npos) << r.out;
}

TEST(Overwrite, TheReportOfASimulatedCampaignSaysSo) {
  TempDir dir("bifilar_overwrite");
  const std::string spec = WriteFile(dir.path + "/spec.yaml", kSmallCampaign);
  ASSERT_EQ(Bifilar(dir, "simulate " + spec + " --out " + dir.path + "/logs").exit_code, 0);
  const std::string config = WriteFile(dir.path + "/c.yaml", R"(
rig:
  filar_length_m: 2.0
  filar_separation_m: 1.8
  mass_kg: 1.25
  inertia: {tare: {logs: logs/tare/*.csv}}
aircraft: {mass_kg: 5.5}
imu: {time: {column: t, unit: s}, gyro: {columns: [gx, gy, gz], unit: rad/s}}
runs: {root: logs, pattern: "pitch_{pitch_deg}/*.csv"}
)");
  const CliRun r = Bifilar(dir, "process " + config + " --out " + dir.path + "/out");
  const std::string html = ReadFile(dir.path + "/out/report.html");
  ASSERT_FALSE(html.empty()) << r.err;
  EXPECT_NE(
      html.find("Simulated data: 4 of the 4 logs were written by <code>bifilar simulate</code>"),
      std::string::npos);
  EXPECT_NE(html.find("simulated by bifilar"), std::string::npos);
}

// The campaign output folder of a process run, with its manifest (copied from the sample).
std::string CopySampleOutput(const TempDir& dir) {
  const std::string out = dir.path + "/OUT";
  fs::copy(std::string(BIFILAR_SOURCE_DIR) + "/sample_runs/prandtl_d/out", out,
           fs::copy_options::recursive);
  return out;
}

TEST(Overwrite, ExportRefusesItsInputAndTheCampaignFilesHoweverSpelled) {
  TempDir dir("bifilar_overwrite");
  const std::string out = CopySampleOutput(dir);
  const std::string results = ReadFile(out + "/results.json");
  fs::create_symlink(out + "/results.json", dir.path + "/results_link.json");
  fs::create_hard_link(out + "/angles.csv", dir.path + "/angles_hard.csv");
  const std::vector<std::string> refused = {
      out + "/results.json",           out + "/../OUT/traces.csv", out + "/./report.html",
      out + "/.bifilar-manifest.json", out + "/cache/x.json",      out + "/figures/a.svg",
      dir.path + "/results_link.json",
  };
  for (const std::string& target : refused) {
    for (const std::string format : {"csv", "jsbsim --symmetric --set Iyy=3.5"}) {
      const CliRun r =
          Bifilar(dir, "export " + out + " --format " + format + " --out " + target + " --force");
      EXPECT_EQ(r.exit_code, 2) << target << "\n" << r.err;
      EXPECT_NE(r.err.find("export: --out " + target), std::string::npos) << r.err;
    }
  }
  // Hard link to the input: the same file.
  CliRun r = Bifilar(dir, "export " + out + "/angles.csv --format csv --out " + dir.path +
                              "/angles_hard.csv --force");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(ReadFile(out + "/results.json"), results);
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir.path + "/results_link.json")));
  EXPECT_FALSE(fs::exists(out + "/figures/a.svg"));
  // export still reads the input.
  r = Bifilar(dir, "export " + out + " --format csv");
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

TEST(Overwrite, ExportReplacesItsOwnOutputButNoOtherFileWithoutForce) {
  TempDir dir("bifilar_overwrite");
  const std::string out = CopySampleOutput(dir);
  const std::string csv = dir.path + "/inertia.csv";
  ASSERT_EQ(Bifilar(dir, "export " + out + " --format csv --out " + csv).exit_code, 0);
  ASSERT_EQ(Bifilar(dir, "export " + out + " --format csv --out " + csv).exit_code, 0);
  const std::string mine = WriteFile(dir.path + "/mine.urdf", "<robot/>\n");
  CliRun r =
      Bifilar(dir, "export " + out + " --format urdf --symmetric --set Iyy=3.5 --out " + mine);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("export --out: " + mine + " exists"), std::string::npos) << r.err;
  EXPECT_EQ(ReadFile(mine), "<robot/>\n");
  r = Bifilar(
      dir, "export " + out + " --format urdf --symmetric --set Iyy=3.5 --out " + mine + " --force");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(ReadFile(mine).rfind("<!-- bifilar export of", 0), 0u);
}

// Issue 23 item 3: in a private folder, a link to /proc/self/fd/1 (what /dev/stdout is) given
// to export --out, init PATH and simulate --trace stays a link, with or without --force.
TEST(Overwrite, ALinkToADescriptorIsNeverReplaced) {
  TempDir dir("bifilar_overwrite");
  const std::string out = CopySampleOutput(dir);
  const std::string link = dir.path + "/stdout_link";
  fs::create_symlink("/proc/self/fd/1", link);
  const std::vector<std::string> commands = {
      "export " + out + " --format csv --out " + link,
      "export " + out + " --format csv --out " + link + " --force",
      "init " + link + " --rig 0.594,0.030,0.0343",
      "init " + link + " --rig 0.594,0.030,0.0343 --force",
      "simulate --trace " + link + kTrace,
      "simulate --trace " + link + kTrace + " --force",
  };
  for (const std::string& command : commands) {
    const CliRun r = Bifilar(dir, command);
    EXPECT_EQ(r.exit_code, 2) << command << "\n" << r.err;
    EXPECT_TRUE(fs::is_symlink(fs::symlink_status(link))) << command;
    EXPECT_EQ(fs::read_symlink(link), "/proc/self/fd/1") << command;
  }
}

// results.json with a tensor section (kg m^2, products positive) and the config's mass.
std::string TensorResults(const std::vector<double>& v, const std::string& mass = "1.25") {
  nlohmann::json t;
  const char* names[6] = {"Ixx", "Iyy", "Izz", "Ixy", "Ixz", "Iyz"};
  for (int k = 0; k < 6; ++k) {
    t[std::string(names[k]) + "_kg_m2"] = v[k];
    t[std::string(names[k]) + "_kg_m2_std"] = 0.001;
  }
  nlohmann::json j = {
      {"program", "bifilar"}, {"tensor", t}, {"config", "aircraft:\n  mass_kg: " + mass + "\n"}};
  return j.dump();
}

TEST(Overwrite, ExportWritesNoNonPhysicalTensorToASimulatorFile) {
  TempDir dir("bifilar_overwrite");
  const struct {
    std::vector<double> v;
    std::string condition;
  } cases[] = {
      {{0, 2, 2.5, 0, 0, 0}, "the moment Ixx = 0 kg m^2 is not positive"},
      {{1, -2, 2.5, 0, 0, 0}, "the moment Iyy = -2 kg m^2 is not positive"},
      {{1, 1, 3, 0, 0, 0}, "break the triangle inequality"},
      {{1, 1, 1, 2, 0, 0}, "not positive definite"},
      {{1e308, 1, 1, 0, 0, 0}, "is beyond any aircraft"},
  };
  for (const auto& c : cases) {
    const std::string results = WriteFile(dir.path + "/r.json", TensorResults(c.v));
    for (const std::string format : {"urdf", "sdf", "jsbsim"}) {
      const std::string file = dir.path + "/out." + format;
      fs::remove(file);
      CliRun r = Bifilar(dir, "export " + results + " --format " + format + " --out " + file);
      EXPECT_EQ(r.exit_code, 1) << format << " " << c.condition << "\n" << r.err;
      EXPECT_NE(r.err.find(c.condition), std::string::npos) << r.err;
      EXPECT_NE(r.err.find("not written"), std::string::npos) << r.err;
      EXPECT_FALSE(fs::exists(file)) << format;
      r = Bifilar(dir, "export " + results + " --format " + format + " --out " + file + " --force");
      EXPECT_EQ(r.exit_code, 0) << r.err;
      EXPECT_NE(r.err.find("warning: " + results + ": "), std::string::npos) << r.err;
      EXPECT_NE(r.err.find(c.condition), std::string::npos) << r.err;
      EXPECT_TRUE(fs::exists(file));
    }
    // CSV: written, with the warning.
    const CliRun r = Bifilar(dir, "export " + results + " --format csv");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find(c.condition), std::string::npos) << r.err;
  }
  // A partial result (pitch campaign: Ixx, Izz, Ixz) is checked too: Ixz^2 >= Ixx Izz.
  const std::string partial = WriteFile(
      dir.path + "/p.json",
      R"({"program": "bifilar", "ellipse": {"Ix_kg_m2": 1, "Iz_kg_m2": 2, "Ixz_kg_m2": 1.5}})");
  const CliRun r = Bifilar(dir, "export " + partial + " --format csv");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("the product Ixz = 1.5 kg m^2 is too large"), std::string::npos) << r.err;
  // A physical one passes without a word.
  const std::string good = WriteFile(dir.path + "/g.json", TensorResults({1, 2, 2.5, 0.1, 0.2, 0}));
  const CliRun ok = Bifilar(dir, "export " + good + " --format urdf");
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_EQ(ok.err.find("warning"), std::string::npos) << ok.err;
}

TEST(Overwrite, ExportNamesANegativeMassAsSuch) {
  TempDir dir("bifilar_overwrite");
  const std::string results =
      WriteFile(dir.path + "/r.json", TensorResults({1, 2, 2.5, 0, 0, 0}, "-5"));
  const CliRun r = Bifilar(dir, "export " + results + " --format urdf");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("aircraft.mass_kg = -5 in the config stored in this result is not a "
                       "positive mass; give it with --mass-kg"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("has no aircraft.mass_kg"), std::string::npos) << r.err;
}

TEST(Overwrite, InitWritesOnlyConfigsFitAccepts) {
  TempDir dir("bifilar_overwrite");
  const std::string config = dir.path + "/c.yaml";
  const struct {
    std::string args, says;
  } refused[] = {
      {"--rig 594,30,34.3",
       "rig.filar_length_m = 594; must be in [0.05, 20] (m), a lab rig's range"},
      {"--rig 0.594,0.030,0.0343 --gravity 9.7",
       "init: --gravity: gravity_mps2 = 9.7; must be in [9.76, 9.84]"},
      {"--rig 0.594,0.030,0.0343 --gravity 9.9",
       "init: --gravity: gravity_mps2 = 9.9; must be in [9.76, 9.84]"},
      {"--rig 0.594,0.030,0.0343 --gravity nan", "--gravity: 'nan' is not a finite number"},
  };
  for (const auto& c : refused) {
    const CliRun r = Bifilar(dir, "init " + config + " " + c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_EQ(r.err.find("--rig '"), std::string::npos) << "blamed on --rig: " << r.err;
    EXPECT_FALSE(fs::exists(config)) << c.args;
  }
  // The edges of the config's range are fine, and a 255-byte name is written.
  const std::string longest = dir.path + "/" + std::string(250, 'n') + ".yaml";
  CliRun r = Bifilar(dir, "init " + longest + " --rig 0.594,0.030,0.0343 --gravity 9.76");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NO_THROW(test_support::LoadFitConfig(longest));
  r = Bifilar(dir, "init " + dir.path + "/" + std::string(256, 'n') + " --rig 0.594,0.030,0.0343");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("the file name is 256 bytes long"), std::string::npos) << r.err;
}

// Issue 23 item 6: the log named "swing<newline>aircraft: {mass_kg: 0.5}<newline>#.csv" added
// a key to the config. Every hostile name gives a config that reads back the rig as given.
TEST(Overwrite, InitQuotesHostileLogNames) {
  TempDir dir("bifilar_overwrite");
  ASSERT_EQ(Bifilar(dir, "simulate --trace " + dir.path + "/plain.csv" + kTrace).exit_code, 0);
  const std::string log = ReadFile(dir.path + "/plain.csv");
  const std::vector<std::string> names = {
      "swing\naircraft: {mass_kg: 0.5}\n#.csv",
      "a: b.csv",
      "quote\"d'.csv",
      "#hash.csv",
      "- leading dash.csv",
      "back\\slash\\n.csv",
      "tab\there\rcr.csv",
      "unicode \xc3\xa9\xe2\x80\xa8ls\xc2\x85nel.csv",
  };
  for (size_t i = 0; i < names.size(); ++i) {
    const std::string path = dir.path + "/" + names[i];
    WriteFile(path, log);
    const std::string config = dir.path + "/c" + std::to_string(i) + ".yaml";
    const CliRun r =
        Bifilar(dir, "init " + config + " --rig 0.594,0.030,0.0343 --log " + Shell(path));
    ASSERT_EQ(r.exit_code, 0) << names[i] << "\n" << r.err;
    const CampaignConfig c = test_support::LoadFitConfig(config);
    EXPECT_EQ(c.rig_mass_kg, 0.0343) << names[i];
    EXPECT_EQ(c.aircraft_mass_kg, 0.0) << names[i];
    EXPECT_EQ(c.imu.format.gyro_columns[0], "gx") << names[i];
  }
}

// The quoting helper with hostile column names, read back by the config loader.
TEST(Overwrite, StartingConfigKeepsHostileColumnNames) {
  StartingConfigOptions o;
  o.filar_length_m = 0.594;
  o.filar_separation_m = 0.030;
  o.mass_kg = 0.0343;
  ImuFormat f;
  f.time_column = "t\n rig: {mass_kg: 9}";
  f.gyro_columns = {"g: x", "\"gy\" # y", "- gz\x01"};
  f.accel_columns = {"a\\x", "ay\xe2\x80\xa9", "\xc3\xa9z"};
  o.format = f;
  o.format_source = "x\nfit: {model: linear}\n";
  const CampaignConfig c =
      LoadCampaignConfigText(CheckedStartingConfigText(o, "c.yaml"), "c.yaml", [] {
        ConfigLoadOptions l;
        l.require_runs = false;
        return l;
      }());
  EXPECT_EQ(c.imu.format.time_column, f.time_column);
  EXPECT_EQ(c.imu.format.gyro_columns, f.gyro_columns);
  EXPECT_EQ(c.imu.format.accel_columns, f.accel_columns);
  EXPECT_EQ(c.rig_mass_kg, 0.0343);
}

// Issue 33 item 1: `ellipse --plot DIR` and `fit --plot DIR` replace only the figures they wrote
// there (recorded in DIR/.bifilar-plots.json); a file of the user's under a figure's name is
// refused before anything is written unless --force; a link is never replaced.
TEST(Overwrite, EllipsePlotReplacesOnlyItsOwnFigures) {
  TempDir dir("bifilar_overwrite");
  std::string table = "pitch_deg,inertia\n";
  for (int d = -80; d <= 90; d += 10) {
    const double t = d * kRadPerDeg;
    table += std::to_string(d) + "," +
             std::to_string(2.85 * std::cos(t) * std::cos(t) + 2.36 * std::sin(t) * std::sin(t) +
                            0.002 * ((d / 10) % 3 - 1)) +
             "\n";
  }
  const std::string csv = WriteFile(dir.path + "/table.csv", table);
  const std::string plots = dir.path + "/plots";
  const std::string mine = WriteFile(plots + "/ellipse_polar.png", "my picture");
  const std::string run = "ellipse " + csv + " --bootstrap 0 --plot " + plots;
  CliRun r = Bifilar(dir, run);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(mine), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--force"), std::string::npos) << r.err;
  EXPECT_EQ(ReadFile(mine), "my picture");
  EXPECT_FALSE(fs::exists(plots + "/ellipse_moments.png"));  // nothing written
  // Its own figures, from an earlier run, are replaced; the user's only with --force.
  r = Bifilar(dir, run + " --force");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(ReadFile(mine), "my picture");
  r = Bifilar(dir, run);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  // A link under a figure's name: never replaced, not with --force either.
  const std::string other = WriteFile(dir.path + "/photo.png", "my photo");
  fs::remove(plots + "/ellipse_moments.svg");
  fs::create_symlink(other, plots + "/ellipse_moments.svg");
  for (const std::string force : {"", " --force"}) {
    r = Bifilar(dir, run + force);
    EXPECT_EQ(r.exit_code, 2) << force;
    EXPECT_TRUE(fs::is_symlink(fs::symlink_status(plots + "/ellipse_moments.svg")));
    EXPECT_EQ(ReadFile(other), "my photo");
  }
  // An empty folder name writes nothing: refused, not silently skipped (fit --plot the same).
  r = Bifilar(dir, "ellipse " + csv + " --bootstrap 0 --plot ''");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("empty"), std::string::npos) << r.err;
}

TEST(Overwrite, FitPlotReplacesOnlyItsOwnFigures) {
  TempDir dir("bifilar_overwrite");
  // The sample campaign's config (runs.root made absolute) and one of its logs.
  const std::string source = BIFILAR_SOURCE_DIR;
  std::string text = ReadFile(source + "/configs/prandtl_d.yaml");
  for (size_t at = text.find("../sample_runs"); at != std::string::npos;
       at = text.find("../sample_runs", at)) {
    text.replace(at, 2, source);
  }
  const std::string config = WriteFile(dir.path + "/c.yaml", text);
  const std::string log = dir.path + "/swing.csv.gz";
  fs::copy_file(source + "/sample_runs/prandtl_d/logs/pitch_0/trial_1.csv.gz", log);
  const std::string plots = dir.path + "/plots";
  const std::string mine = WriteFile(plots + "/swing.png", "my picture");
  const std::string run = "fit " + config + " " + log + " --plot " + plots;
  CliRun r = Bifilar(dir, run);
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.err.find(mine), std::string::npos) << r.err;
  EXPECT_EQ(ReadFile(mine), "my picture");
  EXPECT_FALSE(fs::exists(plots + "/swing.svg"));  // refused before any fit
  r = Bifilar(dir, run + " --force");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(ReadFile(mine), "my picture");
  EXPECT_EQ(Bifilar(dir, run).exit_code, 0);  // its own, from the earlier run
}

}  // namespace
}  // namespace bifilar
