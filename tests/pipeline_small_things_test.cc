// Issue 18 item 8, the small things a new user trips over: `fit --repeats` says the between-repeat
// (Q) warning once, the help texts name ULog, command-line errors carry the `bifilar: error:`
// prefix like every other error, a junk `.ulg` is called what it is, and the committed sample
// outputs (sample_runs/prandtl_d/out, which scripts/run_sample.sh no longer overwrites) still
// hold the numbers the code gives.
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "base/user_error.h"
#include "pipeline/campaign/campaign.h"
#include "pipeline/config/config.h"
#include "pipeline/logs/imu_format.h"
#include "pipeline/logs/imu_log.h"
#include "test_support.h"

namespace bifilar {
namespace {

using test_support::ReadFile;
using test_support::TempDir;
using test_support::WriteFile;

const std::string kSource = BIFILAR_SOURCE_DIR;

// Runs bifilar with `args`; returns the exit code, *output gets stdout and stderr together.
int Cli(const TempDir& dir, const std::string& args, std::string* output) {
  const std::string log = dir.path + "/cli_output.txt";
  const int status =
      std::system((std::string(BIFILAR_BINARY) + " " + args + " > " + log + " 2>&1").c_str());
  *output = ReadFile(log);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

int Count(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// Four simulated swings of one set-up whose true inertias differ by up to 2 % (0.500, 0.505,
// 0.495, 0.510 kg m^2): their stat stds are ~0.01 %, so Cochran's Q is far above its 3 dof and
// the between-repeat warning must appear. It is the same for the four logs: printed once.
TEST(SmallThings, RepeatsPrintTheScatterWarningOnce) {
  TempDir dir("bifilar_small_things");
  const double inertia[] = {0.500, 0.505, 0.495, 0.510};
  std::string out;
  std::string logs;
  for (int i = 0; i < 4; ++i) {
    const std::string log = dir.path + "/run_" + std::to_string(i + 1) + ".csv";
    char args[512];
    std::snprintf(args, sizeof(args),
                  "simulate --trace %s --inertia-kg-m2 %.3f --mass-kg 5 -L 2 -D 1.5 "
                  "--duration-s 30 --sample-rate-hz 50 --seed %d",
                  log.c_str(), inertia[i], i + 1);
    ASSERT_EQ(Cli(dir, args, &out), 0) << out;
    logs += " " + log;
  }
  const std::string config = dir.path + "/bifilar.yaml";
  ASSERT_EQ(Cli(dir, "init " + config + " --rig 2,1.5,5 --log " + dir.path + "/run_1.csv", &out), 0)
      << out;
  ASSERT_EQ(Cli(dir, "fit " + config + logs + " --repeats", &out), 0) << out;
  EXPECT_EQ(Count(out, "scatter beyond their own stds"), 1) << out;
  EXPECT_EQ(Count(out, "is added to each log's std"), 1) << out;
  EXPECT_EQ(Count(out, "this log's std"), 0) << out;
  // The group line follows the four log lines, and the warning follows the group line.
  const size_t group = out.find("repeats " + dir.path + "/run_*.csv: I = ");
  ASSERT_NE(group, std::string::npos) << out;
  EXPECT_GT(out.find("scatter beyond their own stds"), group) << out;
  // JSON records keep the warning on each member (a record stands alone there).
  ASSERT_EQ(Cli(dir, "fit " + config + logs + " --repeats --json", &out), 0) << out;
  EXPECT_EQ(Count(out, "scatter beyond their own stds"), 4) << out;
}

// `fit --plot DIR` names the figures DIR/<log>.{svg,png} after the log's own name (issue 18),
// and puts the folder in front only for logs that share a name ("pitch_10_trial_2").
TEST(SmallThings, PlotFiguresAreNamedAfterTheLog) {
  TempDir dir;
  const std::string logs = kSource + "/sample_runs/prandtl_d/logs";
  WriteFile(dir.path + "/my_swing.csv.gz", ReadFile(logs + "/pitch_30/trial_1.csv.gz"));
  std::string out;
  ASSERT_EQ(Cli(dir,
                "fit " + kSource + "/configs/prandtl_d.yaml " + logs + "/pitch_10/trial_2.csv.gz " +
                    logs + "/pitch_20/trial_2.csv.gz " + dir.path + "/my_swing.csv.gz --plot " +
                    dir.path + "/plots",
                &out),
            0)
      << out;
  for (const char* name : {"pitch_10_trial_2", "pitch_20_trial_2", "my_swing"}) {
    for (const char* suffix : {".svg", ".png", "_sweep.svg"}) {
      EXPECT_TRUE(std::filesystem::exists(dir.path + "/plots/" + name + suffix)) << name << suffix;
    }
  }
}

// A text cell that would read as a number stays text: a tare log listed as `nan` (the long
// stress run's config mutation) is written "nan", quoted, in traces.csv, never a bare nan.
TEST(SmallThings, TextCellsThatReadAsNaNAreQuoted) {
  TempDir dir;
  std::string config = ReadFile(kSource + "/configs/prandtl_d.yaml");
  const std::string tare = "../sample_runs/prandtl_d/logs/tare/*.csv.gz";
  const std::string root = "../sample_runs/prandtl_d/logs";
  ASSERT_NE(config.find(tare), std::string::npos);
  config.replace(config.find(tare), tare.size(), "nan");
  config.replace(config.find(root), root.size(), kSource + "/sample_runs/prandtl_d/logs");
  WriteFile(dir.path + "/c.yaml", config);
  std::string out;
  Cli(dir, "process " + dir.path + "/c.yaml --out " + dir.path + "/out --jobs 2", &out);
  const std::string csv = ReadFile(dir.path + "/out/traces.csv");
  EXPECT_NE(csv.find("\n\"nan\",tare,error"), std::string::npos) << out;
  EXPECT_EQ(csv.find("\nnan,"), std::string::npos);
}

TEST(SmallThings, HelpNamesUlog) {
  TempDir dir("bifilar_small_things");
  std::string out;
  ASSERT_EQ(Cli(dir, "fit --help", &out), 0) << out;
  EXPECT_EQ(out.find("IMU CSV logs"), std::string::npos) << out;
  EXPECT_NE(out.find("PX4 ULog (.ulg)"), std::string::npos) << out;
  ASSERT_EQ(Cli(dir, "simulate --help", &out), 0) << out;
  EXPECT_NE(out.find("ULog"), std::string::npos) << out;
  EXPECT_NE(out.find(".ulg"), std::string::npos) << out;
}

// Errors found by the command-line parser look like every other error: one `bifilar: error:`
// line, then the pointer to --help, exit 2. --help and --version still exit 0 with no prefix.
TEST(SmallThings, CommandLineErrorsHaveThePrefix) {
  TempDir dir("bifilar_small_things");
  std::string out;
  for (const std::string args :
       {"fit", "nosuchcommand", "fit a.yaml b.csv --model nonsense", "process --jobs", ""}) {
    EXPECT_EQ(Cli(dir, args, &out), 2) << args << ": " << out;
    EXPECT_EQ(out.rfind("bifilar: error: ", 0), 0u) << args << ": " << out;
    EXPECT_NE(out.find("Run with --help for more information."), std::string::npos) << out;
  }
  Cli(dir, "fitt a.yaml b.csv", &out);  // a typo names the commands
  EXPECT_NE(out.find("unknown command 'fitt'; the commands are process, report, fit"),
            std::string::npos)
      << out;
  ASSERT_EQ(Cli(dir, "--help", &out), 0) << out;
  EXPECT_EQ(out.find("bifilar: error:"), std::string::npos) << out;
  ASSERT_EQ(Cli(dir, "--version", &out), 0) << out;
  EXPECT_EQ(out.rfind("bifilar ", 0), 0u) << out;
}

// A `.ulg` without the ULog magic: text junk, binary junk, an empty file. Each says it is not a
// valid ULog file (with its first bytes) and not a CSV log either; a CSV that happens to be
// named .ulg is still read as CSV.
TEST(SmallThings, JunkUlogIsCalledWhatItIs) {
  TempDir dir("bifilar_small_things");
  ImuFormat format;  // t, gx, gy, gz (s, rad/s), as the simulator writes
  format.accel_columns = {"", "", ""};
  const std::string text = WriteFile(dir.path + "/text.ulg", "hello, world\nthis is no log\n");
  const std::string binary =
      WriteFile(dir.path + "/binary.ulg", std::string("\x01\x02\x00\x7f\xff junk", 10));
  const std::string empty = WriteFile(dir.path + "/empty.ulg", "");
  for (const std::string& path : {text, binary, empty}) {
    try {
      ReadImuLog(path, format);
      ADD_FAILURE() << path << " was read";
    } catch (const UserError& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.rfind(path + ": not a valid ULog file", 0), 0u) << message;
      EXPECT_NE(message.find("not a CSV log either"), std::string::npos) << message;
    }
  }
  try {
    ReadImuLog(text, format);
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("this one starts with \"hello, w\""), std::string::npos)
        << e.what();
  }
  try {
    ReadImuLog(binary, format);
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("the bytes 01 02 00 7f ff 20 6a 75"), std::string::npos)
        << e.what();
  }
  // A CSV named .ulg: read as CSV (the name alone decides nothing).
  std::string csv = "t,gx,gy,gz\n";
  for (int i = 0; i < 50; ++i) {
    csv += std::to_string(0.01 * i) + ",0," + std::to_string(std::sin(0.1 * i)) + ",0\n";
  }
  const ImuData data = ReadImuLog(WriteFile(dir.path + "/csv_named.ulg", csv), format);
  EXPECT_EQ(data.t_s.size(), 50u);
  // Through the command line: the one-line error names the file and says what it is not.
  const std::string config =
      WriteFile(dir.path + "/c.yaml",
                "rig: {filar_length_m: 2, filar_separation_m: 1.5, mass_kg: 5}\n"
                "imu:\n  time: {column: t, unit: s}\n  gyro: {columns: [gx, gy, gz], unit: rad/s}\n"
                "  accel: null\n");
  std::string out;
  EXPECT_EQ(Cli(dir, "fit " + config + " " + text, &out), 1) << out;
  EXPECT_NE(out.find("not a valid ULog file"), std::string::npos) << out;
}

// scripts/run_sample.sh writes into out/prandtl_d/ (ignored by git), so running it leaves the
// checkout unmodified; the committed outputs in sample_runs/prandtl_d/out stay for reading
// without a build. This checks they still hold what the code computes: each trace's I and std
// and the ellipse's I_x, I_z, I_xz, tau agree to 1 % of their own std (a refit on another
// machine may differ in the last digits; anything larger means the committed sample is stale
// and must be regenerated: bifilar process configs/prandtl_d.yaml --out sample_runs/prandtl_d/out).
TEST(SmallThings, CommittedSampleOutputsHoldTheCodesNumbers) {
  constexpr double kFractionOfStd = 0.01;
  const nlohmann::json committed =
      nlohmann::json::parse(ReadFile(kSource + "/sample_runs/prandtl_d/out/results.json"));
  TempDir dir("bifilar_small_things");
  CampaignConfig config = LoadCampaignConfig(kSource + "/configs/prandtl_d.yaml");
  CampaignOptions options;
  options.out_dir = dir.path + "/out";
  options.jobs = 2;
  options.figures = false;
  options.write_report = false;
  const CampaignResult result = RunCampaign(config, options);
  ASSERT_EQ(result.traces.size(), committed["traces"].size());
  std::map<std::string, nlohmann::json> by_file;
  for (const nlohmann::json& t : committed["traces"]) by_file[t["file"].get<std::string>()] = t;
  for (const TraceRecord& r : result.traces) {
    ASSERT_EQ(by_file.count(r.file), 1u) << r.file;
    const nlohmann::json& c = by_file[r.file];
    const double std = c["inertia_total_std_kg_m2"].get<double>();
    EXPECT_NEAR(r.inertia_total_kg_m2, c["inertia_total_kg_m2"].get<double>(), kFractionOfStd * std)
        << r.file;
    EXPECT_NEAR(r.inertia_total_std_kg_m2, std, kFractionOfStd * std) << r.file;
  }
  ASSERT_TRUE(result.ellipse_fit.has_value());
  const nlohmann::json& e = committed["ellipse"];
  const auto& fit = *result.ellipse_fit;
  EXPECT_NEAR(fit.ix.value, e["Ix_kg_m2"].get<double>(),
              kFractionOfStd * e["Ix_kg_m2_std"].get<double>());
  EXPECT_NEAR(fit.iz.value, e["Iz_kg_m2"].get<double>(),
              kFractionOfStd * e["Iz_kg_m2_std"].get<double>());
  EXPECT_NEAR(fit.ixz.value, e["Ixz_kg_m2"].get<double>(),
              kFractionOfStd * e["Ixz_kg_m2_std"].get<double>());
  EXPECT_NEAR(fit.tau_deg.value, e["tau_deg"].get<double>(),
              kFractionOfStd * e["tau_deg_std"].get<double>());
  // The script writes outside sample_runs/ (the path above is what it must not touch).
  const std::string script = ReadFile(kSource + "/scripts/run_sample.sh");
  EXPECT_NE(script.find("--out \"$out\""), std::string::npos) << script;
  EXPECT_NE(script.find("out=\"$here/out/prandtl_d\""), std::string::npos) << script;
}

}  // namespace
}  // namespace bifilar
