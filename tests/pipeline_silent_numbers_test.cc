// Issue 15 items 3, 8 and 10: a blank is never a number, no silent wrong number (gravity, seeds,
// NaN flags, a non-physical ellipse, a swing axis that overflows, a window past the log, merged
// angles, tables with a BOM or a log listed twice) and messages that name the cause (a missing
// tare log said once and first, an empty runs table, a tiny std in an ellipse table).
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/units.h"
#include "base/user_error.h"
#include "fit/ellipse.h"
#include "pipeline/campaign/campaign.h"
#include "pipeline/campaign/campaign_summary.h"
#include "pipeline/campaign/run_discovery.h"
#include "pipeline/commands/ellipse_command.h"
#include "pipeline/config/config.h"
#include "test_support.h"

namespace bifilar {
namespace {

using test_support::Contains;
using test_support::ReadFile;
using test_support::TempDir;
using test_support::WriteFile;

std::string ErrorOf(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}

// Runs bifilar; returns the exit code, *output gets stdout and stderr.
int Cli(const TempDir& dir, const std::string& args, std::string* output) {
  const std::string log = dir.path + "/cli.txt";
  const int status =
      std::system((std::string(BIFILAR_BINARY) + " " + args + " > " + log + " 2>&1").c_str());
  *output = ReadFile(log);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// A campaign config in block style, with `rig_inertia` and `extra` lines spliced in.
std::string Config(const std::string& rig_inertia = "    inertia_kg_m2: 0.5\n",
                   const std::string& extra = "") {
  return "rig:\n  filar_length_m: 2.0\n  filar_separation_m: 1.0\n  mass_kg: 2.0\n"
         "  inertia:\n" +
         rig_inertia +
         "aircraft:\n  mass_kg: 10\n"
         "imu:\n  time: {column: t, unit: s}\n  gyro: {columns: [gx, gy, gz], unit: rad/s}\n"
         "  accel: null\n"
         "runs:\n  root: logs\n  pattern: \"pitch_{pitch_deg}/*.csv\"\n" +
         extra;
}

std::string LoadError(const TempDir& dir, const std::string& yaml) {
  const std::string path = WriteFile(dir.path + "/c.yaml", yaml);
  return ErrorOf([&] { LoadCampaignConfig(path); });
}

// ---- Item 3: a blank value is not zero ---------------------------------------------------------

TEST(SilentNumbers, BlankOrNullNumberIsAnErrorNamingTheKey) {
  TempDir dir;
  // The case: rig inertia blank or ~ ran with 0 and exit 0.
  for (const char* blank : {"", " ~", " null"}) {
    const std::string why =
        LoadError(dir, Config(std::string("    inertia_kg_m2:") + blank + "\n"));
    EXPECT_TRUE(Contains(why, "c.yaml:6:5:")) << why;  // the key's own line
    EXPECT_TRUE(Contains(why, "'rig.inertia.inertia_kg_m2' is blank")) << why;
  }
  // Every other kind of numeric key: required, optional with a default, int, bool, std.
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"gravity_mps2:\n", "'gravity_mps2' is blank"},
      {"fit:\n  max_amplitude_deg: ~\n", "'fit.max_amplitude_deg' is blank"},
      {"fit:\n  quality:\n    min_periods:\n", "'fit.quality.min_periods' is blank"},
      {"fit:\n  glitch:\n    enabled:\n", "'fit.glitch.enabled' is blank"},
      {"ellipse:\n  bootstrap: ~\n", "'ellipse.bootstrap' is blank"},
      {"ellipse:\n  seed:\n", "'ellipse.seed' is blank"},
  };
  for (const auto& [extra, expected] : cases) {
    const std::string why = LoadError(dir, Config("    inertia_kg_m2: 0.5\n", extra));
    EXPECT_TRUE(Contains(why, expected)) << extra << " -> " << why;
    EXPECT_FALSE(Contains(why, "missing")) << why;
  }
  EXPECT_TRUE(Contains(LoadError(dir, Config("    inertia_kg_m2: 0.5\n    inertia_std_kg_m2:\n")),
                       "'rig.inertia.inertia_std_kg_m2' is blank"));
  // A required key left blank is "blank", not "missing".
  std::string yaml = Config();
  yaml.replace(yaml.find("mass_kg: 2.0"), 12, "mass_kg:");
  EXPECT_TRUE(Contains(LoadError(dir, yaml), "'rig.mass_kg' is blank")) << LoadError(dir, yaml);
  // The same in a simulation spec.
  const std::string spec = WriteFile(dir.path + "/s.yaml", "geometry:\n  gravity_mps2:\n");
  std::string out;
  EXPECT_EQ(Cli(dir,
                "simulate " + spec + " --trace " + dir.path +
                    "/t.csv --inertia-kg-m2 1 "
                    "--mass-kg 1",
                &out),
            2)
      << out;
  EXPECT_TRUE(Contains(out, "'geometry.gravity_mps2' is blank")) << out;
  EXPECT_FALSE(std::filesystem::exists(dir.path + "/t.csv"));
}

// ---- Item 8: silent numbers --------------------------------------------------------------------

TEST(SilentNumbers, GravityIsBoundedToEarthUnlessOverridden) {
  TempDir dir;
  const std::string why =
      LoadError(dir, Config("    inertia_kg_m2: 0.5\n", "gravity_mps2: 98.0665\n"));
  EXPECT_TRUE(
      Contains(why, "gravity_mps2 = 98.0665; must be in [9.76, 9.84], a gravity found on Earth"))
      << why;
  EXPECT_TRUE(Contains(why, "[9.76, 9.84]")) << why;
  EXPECT_TRUE(Contains(why, "gravity_off_earth: true")) << why;
  EXPECT_TRUE(Contains(LoadError(dir, Config("    inertia_kg_m2: 0.5\n", "gravity_mps2: 9.7\n")),
                       "gravity_mps2 = 9.7; must be in [9.76, 9.84], a gravity found on Earth"));
  // Earth's extremes pass; Mars with the override passes; 0 and 1000 never.
  for (const char* ok : {"gravity_mps2: 9.7639\n", "gravity_mps2: 9.8337\n",
                         "gravity_mps2: 3.71\ngravity_off_earth: true\n"}) {
    const std::string path =
        WriteFile(dir.path + "/ok.yaml", Config("    inertia_kg_m2: 0.5\n", ok));
    EXPECT_NO_THROW(LoadCampaignConfig(path)) << ok;
  }
  EXPECT_DOUBLE_EQ(LoadCampaignConfig(dir.path + "/ok.yaml").gravity_mps2, 3.71);
  for (const char* bad : {"gravity_mps2: 0\ngravity_off_earth: true\n",
                          "gravity_mps2: 1000\ngravity_off_earth: true\n"}) {
    EXPECT_TRUE(Contains(LoadError(dir, Config("    inertia_kg_m2: 0.5\n", bad)),
                         "must be in (0, 100] (gravity_off_earth: true)"))
        << bad;
  }
}

TEST(SilentNumbers, SwingAxisAndEllipseSeedAreCheckedInTheConfig) {
  TempDir dir;
  auto with_axis = [&](const std::string& axis) {
    std::string yaml = Config();
    yaml.insert(yaml.find("runs:"), "  swing_axis: " + axis + "\n");
    return LoadError(dir, yaml);
  };
  for (const char* bad : {"[1e300, 0, 0]", "[0, 0, 1e-9]", "[0, 0, 0]", "[2000, 0, 0]"}) {
    const std::string why = with_axis(bad);
    EXPECT_TRUE(Contains(why, "'imu.swing_axis' must be auto or a direction"))
        << bad << ": " << why;
    EXPECT_TRUE(Contains(why, "[0.001, 1000]")) << why;
  }
  EXPECT_EQ(with_axis("[0, 0, 2]"), "");
  EXPECT_EQ(with_axis("auto"), "");
  // ellipse.seed beyond its range says the range (it said "must be an integer").
  for (const char* seed : {"9223372036854775808", "-1", "4294967296", "1.5"}) {
    const std::string why = LoadError(
        dir, Config("    inertia_kg_m2: 0.5\n", std::string("ellipse: {seed: ") + seed + "}\n"));
    EXPECT_TRUE(Contains(why, "'ellipse.seed' must be an integer in [0, 4294967295]")) << why;
  }
  const std::string path = WriteFile(
      dir.path + "/ok.yaml", Config("    inertia_kg_m2: 0.5\n", "ellipse: {seed: 4294967295}\n"));
  EXPECT_EQ(LoadCampaignConfig(path).ellipse.seed, 4294967295u);
}

TEST(SilentNumbers, SeedsAndNumericFlagsAreCheckedOnTheCommandLine) {
  TempDir dir;
  const std::string table =
      WriteFile(dir.path + "/t.csv", "pitch_deg,inertia\n0,3\n30,2.8\n60,2.3\n90,2\n-30,3.1\n");
  std::string out;
  for (const char* seed : {"-1", "18446744073709551616", "1e23", "1.5", "x"}) {
    EXPECT_EQ(Cli(dir, std::string("ellipse ") + table + " --seed " + seed, &out), 2) << out;
    EXPECT_TRUE(Contains(out, "--seed")) << out;
    EXPECT_TRUE(Contains(out, "[0, 18446744073709551615]")) << out;
    EXPECT_EQ(Cli(dir,
                  std::string("simulate --trace ") + dir.path +
                      "/s.csv --inertia-kg-m2 1 "
                      "--mass-kg 1 -L 2 -D 1 --seed " +
                      seed,
                  &out),
              2)
        << out;
    EXPECT_TRUE(Contains(out, "[0, 18446744073709551615]")) << out;
  }
  EXPECT_EQ(Cli(dir, "ellipse " + table + " --seed 18446744073709551615 --bootstrap 0", &out), 0)
      << out;
  // NaN (and inf) in a numeric flag is refused, naming the flag.
  const std::string config = WriteFile(dir.path + "/fit.yaml", test_support::QuadrotorFitConfig());
  const std::vector<std::string> commands = {"fit " + config + " " + table + " --max-amplitude nan",
                                             "ellipse " + table + " --outlier-threshold nan",
                                             "plan --angles 0,45,90 --sigma nan",
                                             "plan --angles 0,45,90 --sigma 0.01 --ix inf --iz 1",
                                             "simulate --trace " + dir.path +
                                                 "/s.csv --inertia-kg-m2 1 --mass-kg 1 -L 2 -D 1 "
                                                 "--amplitude-deg nan",
                                             "simulate --trace " + dir.path +
                                                 "/s.csv --inertia-kg-m2 1 --mass-kg 1 -L 2 -D 1 "
                                                 "--pitch-deg nan"};
  for (const std::string& command : commands) {
    EXPECT_EQ(Cli(dir, command, &out), 2) << command << "\n" << out;
    EXPECT_TRUE(Contains(out, "finite number") || Contains(out, "not a number")) << command << "\n"
                                                                                 << out;
  }
  EXPECT_FALSE(std::filesystem::exists(dir.path + "/s.csv"));
}

// The case: one outlier (1000) among moments of a body; the fit's I_x went negative.
TEST(SilentNumbers, NonPhysicalEllipseIsAWarningAndExitOne) {
  TempDir dir;
  std::string text = "pitch_deg,inertia\n";
  for (int p = -80; p <= 90; p += 10) {
    const double t = p * kRadPerDeg;
    char row[64];
    std::snprintf(
        row, sizeof(row), "%d,%.6f\n", p,
        p == 30 ? 1000.0 : 3.0 * std::cos(t) * std::cos(t) + 2.0 * std::sin(t) * std::sin(t));
    text += row;
  }
  const std::string table = WriteFile(dir.path + "/outlier.csv", text);
  std::ostringstream out;
  EllipseCommandOptions options;
  options.table_path = table;
  options.fit.bootstrap_replicates = 0;
  const EllipseCommandResult outlier = RunEllipse(options);
  PrintEllipseCommand(options, outlier, out);
  EXPECT_EQ(EllipseExitCode(outlier), 1) << out.str();
  EXPECT_FALSE(outlier.fit.physical);
  EXPECT_TRUE(Contains(out.str(), "warning: non-physical result")) << out.str();
  EXPECT_TRUE(Contains(out.str(), "point 12 at pitch 30 deg")) << out.str();
  std::string cli;
  EXPECT_EQ(Cli(dir, "ellipse " + table + " --bootstrap 0", &cli), 1) << cli;
  // The same moments without the outlier: physical, exit 0.
  text.replace(text.find("30,1000.000000"), 14, "30,2.750000");
  WriteFile(table, text);
  std::ostringstream clean;
  const EllipseCommandResult fixed = RunEllipse(options);
  PrintEllipseCommand(options, fixed, clean);
  EXPECT_EQ(EllipseExitCode(fixed), 0) << clean.str();
  EXPECT_FALSE(Contains(clean.str(), "non-physical")) << clean.str();
}

TEST(SilentNumbers, TinyStdIsNamedAndMergedAnglesAreSaid) {
  TempDir dir;
  std::string out;
  const std::string table = WriteFile(
      dir.path + "/std.csv",
      "pitch_deg,inertia,std\n0,3,0.01\n30,2.75,0.01\n60,2.25,1e-99\n90,2,0.01\n-30,2.75,0.01\n");
  EXPECT_EQ(Cli(dir, "ellipse " + table, &out), 2) << out;
  EXPECT_TRUE(Contains(out, "point 3 (pitch 60 deg) has std 1e-99 kg m^2")) << out;
  EXPECT_TRUE(Contains(out, "check that std")) << out;
  // A noise-free dense table: the points 0.25 deg apart are one angle group; the warning names
  // them (Table 1's "raw data sigma" then holds the curve's change, not noise).
  std::vector<EllipsePoint> points;
  for (double p : {0.0, 0.25, 30.0, 30.25, 60.0, 90.0, -30.0}) {
    const double t = p * kRadPerDeg;
    points.push_back({p, 3.0 * std::cos(t) * std::cos(t) + 2.0 * std::sin(t) * std::sin(t), 0.0});
  }
  EllipseOptions options;
  options.bootstrap_replicates = 0;
  EllipseResult result;
  std::string why;
  ASSERT_TRUE(FitEllipse(points, options, &result, &why)) << why;
  bool said = false;
  for (const std::string& w : result.warnings) {
    said = said || (Contains(w, "2 angle groups merge different pitches within 0.5 deg") &&
                    Contains(w, "0 to 0.25 deg; 30 to 30.25 deg"));
  }
  EXPECT_TRUE(said) << result.BriefReport();
  // Identical nominal angles (the campaign's, the sample's) are no merge: no warning.
  points = {{0, 3, 0}, {0, 3.01, 0}, {30, 2.75, 0}, {60, 2.25, 0}, {90, 2, 0}, {90, 2.01, 0}};
  ASSERT_TRUE(FitEllipse(points, options, &result, &why)) << why;
  for (const std::string& w : result.warnings) EXPECT_FALSE(Contains(w, "merge")) << w;
}

// ---- runs.table: BOM, a log listed twice, empty --------------------------------------------

TEST(SilentNumbers, RunsTableBomDuplicatesAndEmpty) {
  TempDir dir;
  for (const char* name : {"a.csv", "b.csv", "c.csv"}) WriteFile(dir.path + "/logs/" + name, "x");
  const std::string config_path =
      WriteFile(dir.path + "/c.yaml",
                "rig: {filar_length_m: 2.0, filar_separation_m: 1.0, mass_kg: 2.0, "
                "inertia: {inertia_kg_m2: 0.5}}\naircraft: {mass_kg: 10}\n"
                "runs: {root: logs, table: runs.csv}\n");
  const CampaignConfig config = LoadCampaignConfig(config_path);
  // A UTF-8 BOM before the header (spreadsheet export) is accepted.
  WriteFile(dir.path + "/runs.csv", "\xEF\xBB\xBFpath,pitch_deg\na.csv,0\nb.csv,30\n");
  std::vector<RunFile> runs = DiscoverRuns(config);
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(runs[0].error, "");
  EXPECT_EQ(*runs[1].pitch_nominal_deg, 30.0);
  // A log listed twice with two pitches: an error row naming both lines; the same pitch twice is
  // one run.
  WriteFile(dir.path + "/runs.csv",
            "path,pitch_deg\na.csv,0\nb.csv,30\n./a.csv,10\nc.csv,60\nc.csv,60\n");
  runs = DiscoverRuns(config);
  ASSERT_EQ(runs.size(), 3u);
  EXPECT_TRUE(Contains(runs[0].error, "a.csv: listed twice in")) << runs[0].error;
  EXPECT_TRUE(Contains(runs[0].error, "lines 2 and 4 give pitch 0 and 10 deg")) << runs[0].error;
  EXPECT_EQ(runs[1].error, "");
  EXPECT_EQ(runs[2].error, "");
  // Empty, blank or header-only: the table is empty (not "every file is inside the output").
  for (const char* text : {"", "\n\n", "\xEF\xBB\xBF", "path,pitch_deg\n"}) {
    WriteFile(dir.path + "/runs.csv", text);
    const std::string why = ErrorOf([&] { DiscoverRuns(config); });
    EXPECT_TRUE(Contains(why, "runs.csv: runs table")) << why;
    EXPECT_TRUE(Contains(why, "empty") || Contains(why, "no rows")) << why;
    EXPECT_FALSE(Contains(why, "output folder")) << why;
  }
}

// ---- Item 10: a missing tare log is said once, first -------------------------------------------

TEST(SilentNumbers, MissingTareLogIsSaidOnceAndFirst) {
  TempDir dir;
  for (int p : {0, 30, 60, 90}) {
    for (int k = 1; k <= 2; ++k) {
      WriteFile(
          dir.path + "/logs/pitch_" + std::to_string(p) + "/trial_" + std::to_string(k) + ".csv",
          "I=" + std::to_string(3.0 + 0.001 * k + p * 0.001));
    }
  }
  const std::string path =
      WriteFile(dir.path + "/c.yaml", Config("    tare: {logs: tare/rig.csv}\n"));
  CampaignOptions options;
  options.out_dir = dir.path + "/out";
  options.jobs = 1;
  options.fit_function = [](const CampaignConfig&, const std::string& log,
                            const TraceProcessOptions& o) {
    TraceRecord r;
    r.file = o.display_name;
    r.status = TraceStatus::kOk;
    r.inertia_total_kg_m2 = std::stod(ReadFile(log).substr(2));
    r.inertia_total_std_kg_m2 = 1e-4;
    return r;
  };
  const CampaignConfig config = LoadCampaignConfig(path);
  const CampaignResult result = RunCampaign(config, options);
  EXPECT_EQ(result.summary.exit_code, 1);
  EXPECT_TRUE(Contains(result.rig_problem, "tare/rig.csv: tare log not found"))
      << result.rig_problem;
  std::ostringstream console;
  PrintCampaignSummary(config, result, console);
  const std::string text = console.str();
  EXPECT_EQ(text.rfind("Error: no usable tare log, so the rig inertia is unknown: tare/rig.csv: "
                       "tare log not found",
                       0),
            0u)
      << text;
  // The 8 aircraft traces are one line, not 8 (the console showed the same reason 10 times).
  EXPECT_TRUE(Contains(text, "error: 8 aircraft traces: rig inertia unknown")) << text;
  size_t count = 0;
  for (size_t at = text.find("no usable tare log"); at != std::string::npos;
       at = text.find("no usable tare log", at + 1)) {
    ++count;
  }
  EXPECT_EQ(count, 2u) << text;  // the first line, and the count line's pointer to it
}

}  // namespace
}  // namespace bifilar
