// The campaign pipeline with a fake trace fit (the fit reads the total inertia written in the
// "log"), so discovery, tare, grouping, ellipse, cache and bad-input handling are tested exactly,
// independently of the trace fit: the truth is known to the last digit.
#include "base/units.h"
#include "pipeline/campaign/campaign.h"

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "base/user_error.h"
#include "pipeline/campaign/rig_inertia.h"
#include "pipeline/commands/simulate_spec.h"
#include "test_support.h"

namespace bifilar {
namespace {

using test_support::ReadFile;
using test_support::WriteFile;

namespace fs = std::filesystem;

// Aircraft truth (kg m^2) and the rig.
constexpr double kIx = 2.0, kIz = 3.0, kIxz = 0.1, kRig = 0.5;
// Trials at one angle are truth +- kTrialOffset, so the per-angle means are exact and the ellipse
// fit must return the truth to rounding.
constexpr double kTrialOffset = 0.001;
const std::vector<double> kPitches = {-60, -30, 0, 30, 60, 90};

double Truth(double pitch_deg) {
  const double t = pitch_deg * kRadPerDeg;
  return kIz * std::cos(t) * std::cos(t) + kIx * std::sin(t) * std::sin(t) + kIxz * std::sin(2 * t);
}

std::string TempDir() {
  char tmpl[] = "/tmp/bifilar_campaign_test_XXXXXX";
  return mkdtemp(tmpl);
}

// A fake campaign: logs whose content is "I=<total inertia>".
struct FakeCampaign {
  std::string dir;
  std::atomic<int> calls{0};

  explicit FakeCampaign(
      const std::string& rig_inertia_yaml = "{inertia_kg_m2: 0.5, inertia_std_kg_m2: 0.0}",
      const std::string& extra_yaml = "") {
    dir = TempDir();
    for (double p : kPitches) {
      for (int k = 1; k <= 2; ++k) {
        std::ostringstream text;
        text.precision(17);
        text << "I=" << Truth(p) + kRig + (k == 1 ? kTrialOffset : -kTrialOffset) << "\n";
        std::ostringstream name;
        name << dir << "/logs/pitch_" << p << "/trial_" << k << ".csv";
        WriteFile(name.str(), text.str());
      }
    }
    WriteConfig(rig_inertia_yaml, extra_yaml);
  }

  ~FakeCampaign() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }

  void WriteConfig(const std::string& rig_inertia_yaml, const std::string& extra_yaml,
                   double filar_length_m = 2.0) {
    std::ostringstream yaml;
    yaml << "rig:\n  filar_length_m: " << filar_length_m
         << "\n  filar_separation_m: 1.0\n  mass_kg: 2.0\n  inertia: " << rig_inertia_yaml
         << "\naircraft: {mass_kg: 10}\nruns: {root: logs, pattern: \"pitch_{pitch_deg}/*.csv\"}\n"
         << extra_yaml;
    WriteFile(dir + "/campaign.yaml", yaml.str());
  }

  CampaignOptions Options() {
    CampaignOptions o;
    o.out_dir = dir + "/out";
    o.jobs = 2;
    o.fit_function = [this](const CampaignConfig&, const std::string& path,
                            const TraceProcessOptions& options) {
      ++calls;
      TraceRecord r;
      r.file = options.display_name;
      const std::string text = ReadFile(path);
      if (text.rfind("I=", 0) != 0) throw UserError(path + ": not a CSV log");
      r.status = TraceStatus::kOk;
      r.inertia_total_kg_m2 = std::stod(text.substr(2));
      r.inertia_total_std_kg_m2 = 1e-4;
      r.model = "full";
      return r;
    };
    return o;
  }

  CampaignResult Run() {
    return RunCampaign(LoadCampaignConfig(dir + "/campaign.yaml"), Options());
  }
};

const TraceRecord* Find(const CampaignResult& result, const std::string& needle) {
  for (const TraceRecord& r : result.traces) {
    if (r.file.find(needle) != std::string::npos) return &r;
  }
  return nullptr;
}

TEST(Campaign, RecoversTheEllipseAndWritesEveryOutput) {
  FakeCampaign c;
  const CampaignResult result = c.Run();
  EXPECT_EQ(result.summary.exit_code, 0);
  EXPECT_EQ(result.summary.n_ok, 12);
  EXPECT_EQ(result.summary.n_fitted, 12);
  ASSERT_EQ(result.angles.size(), kPitches.size());
  for (size_t i = 0; i < kPitches.size(); ++i) {
    EXPECT_DOUBLE_EQ(result.angles[i].pitch_deg, kPitches[i]);
    EXPECT_NEAR(result.angles[i].inertia_mean_kg_m2, Truth(kPitches[i]), 1e-12);
    // Two trials at +-d: sample std = d sqrt(2).
    EXPECT_NEAR(result.angles[i].inertia_std_kg_m2, kTrialOffset * std::sqrt(2.0), 1e-12);
  }
  ASSERT_TRUE(result.ellipse_fit.has_value());
  // Exact data: the closed-form fit returns the truth to rounding.
  EXPECT_NEAR(result.ellipse_fit->ix.value, kIx, 1e-9);
  EXPECT_NEAR(result.ellipse_fit->iz.value, kIz, 1e-9);
  EXPECT_NEAR(result.ellipse_fit->ixz.value, kIxz, 1e-9);
  for (const TraceRecord& r : result.traces) {
    EXPECT_NEAR(r.inertia_kg_m2, r.inertia_total_kg_m2 - kRig, 1e-15);
    EXPECT_DOUBLE_EQ(r.pitch_used_deg, *r.pitch_nominal_deg);
  }
  // Outputs.
  const std::string out = c.dir + "/out";
  const nlohmann::json json = nlohmann::json::parse(ReadFile(out + "/results.json"));
  EXPECT_EQ(json["traces"].size(), 12u);
  EXPECT_EQ(json["angles"].size(), kPitches.size());
  EXPECT_NEAR(json["ellipse"]["Ix_kg_m2"].get<double>(), kIx, 1e-9);
  EXPECT_FALSE(json["version"].get<std::string>().empty());
  EXPECT_NE(json["config"].get<std::string>().find("filar_length_m"), std::string::npos);
  for (const char* key : {"file",
                          "status",
                          "message",
                          "inertia_total_kg_m2",
                          "inertia_total_std_kg_m2",
                          "drag_coeff_kg_m2",
                          "viscous_coeff_kg_m2_per_s",
                          "window_s",
                          "amplitude_deg",
                          "bias_rad_per_s",
                          "residual_rms_rad_per_s",
                          "pitch_measured_deg",
                          "model",
                          "iterations",
                          "fit_seconds",
                          "pitch_nominal_deg",
                          "pitch_used_deg",
                          "inertia_kg_m2",
                          "budget",
                          "flags"}) {
    EXPECT_TRUE(json["traces"][0].contains(key)) << key;
  }
  const std::string traces_csv = ReadFile(out + "/traces.csv");
  EXPECT_EQ(std::count(traces_csv.begin(), traces_csv.end(), '\n'), 13);
  const std::string angles_csv = ReadFile(out + "/angles.csv");
  EXPECT_EQ(std::count(angles_csv.begin(), angles_csv.end(), '\n'), 7);
  const std::string html = ReadFile(out + "/report.html");
  EXPECT_NE(html.find("Table 2"), std::string::npos);
  EXPECT_NE(html.find("data:image/png;base64,"), std::string::npos);  // Fig. 3/4 embedded
  // No temporary file left behind.
  for (const auto& entry : fs::directory_iterator(out)) {
    EXPECT_EQ(entry.path().string().find(".tmp"), std::string::npos) << entry.path();
  }
}

TEST(Campaign, CacheRefitsOnlyWhatChanged) {
  FakeCampaign c;
  c.Run();
  EXPECT_EQ(c.calls, 12);
  // Nothing changed: nothing refitted.
  CampaignResult again = c.Run();
  EXPECT_EQ(c.calls, 12);
  EXPECT_EQ(again.summary.n_reused, 12);
  EXPECT_EQ(again.summary.n_fitted, 0);
  EXPECT_NEAR(again.ellipse_fit->ix.value, kIx, 1e-9);
  // Rig inertia and ellipse options are not fit inputs.
  c.WriteConfig("{inertia_kg_m2: 0.4}", "ellipse: {bootstrap: 500, seed: 3}\nunits: imperial\n");
  again = c.Run();
  EXPECT_EQ(c.calls, 12);
  EXPECT_NEAR(again.traces[0].inertia_kg_m2, again.traces[0].inertia_total_kg_m2 - 0.4, 1e-15);
  // One log edited: one refit.
  WriteFile(c.dir + "/logs/pitch_0/trial_1.csv", "I=3.5011\n");
  again = c.Run();
  EXPECT_EQ(c.calls, 13);
  EXPECT_EQ(again.summary.n_fitted, 1);
  // L changes every fit.
  c.WriteConfig("{inertia_kg_m2: 0.4}", "", 2.1);
  again = c.Run();
  EXPECT_EQ(c.calls, 25);
  // The model too.
  c.WriteConfig("{inertia_kg_m2: 0.4}", "fit: {model: jardin}\n", 2.1);
  again = c.Run();
  EXPECT_EQ(c.calls, 37);
  // --force refits everything.
  CampaignOptions force = c.Options();
  force.force = true;
  again = RunCampaign(LoadCampaignConfig(c.dir + "/campaign.yaml"), force);
  EXPECT_EQ(again.summary.n_fitted, 12);
  // Stale cache entries are pruned: one per log.
  int entries = 0;
  for (const auto& e : fs::directory_iterator(c.dir + "/out/cache")) entries += e.is_regular_file();
  EXPECT_EQ(entries, 12);
}

TEST(Campaign, BadLogsAreRowsAndTheRestIsProcessed) {
  FakeCampaign c;
  // Pitch not readable from the path.
  WriteFile(c.dir + "/logs/pitch_abc/trial_1.csv", "I=3\n");
  // The same log twice.
  fs::copy_file(c.dir + "/logs/pitch_0/trial_1.csv", c.dir + "/logs/pitch_0/trial_3.csv");
  // Not a log at all.
  WriteFile(c.dir + "/logs/pitch_30/trial_3.csv", "\x89PNG garbage");
  // Unreadable: a dangling link (chmod does not stop root).
  fs::create_symlink(c.dir + "/nowhere.csv", c.dir + "/logs/pitch_60/trial_3.csv");
  const CampaignResult result = c.Run();
  EXPECT_EQ(result.summary.exit_code, 1);
  EXPECT_EQ(result.summary.n_ok, 12);
  EXPECT_EQ(result.summary.n_error, 4);
  const TraceRecord* abc = Find(result, "pitch_abc");
  ASSERT_NE(abc, nullptr);
  EXPECT_EQ(abc->status, TraceStatus::kError);
  EXPECT_NE(abc->message.find("cannot read the pitch"), std::string::npos) << abc->message;
  const TraceRecord* dup = Find(result, "pitch_0/trial_3");
  ASSERT_NE(dup, nullptr);
  EXPECT_NE(dup->message.find("same content as pitch_0/trial_1.csv"), std::string::npos)
      << dup->message;
  const TraceRecord* png = Find(result, "pitch_30/trial_3");
  ASSERT_NE(png, nullptr);
  EXPECT_EQ(png->status, TraceStatus::kError);
  EXPECT_NE(png->message.find("not a CSV log"), std::string::npos) << png->message;
  const TraceRecord* link = Find(result, "pitch_60/trial_3");
  ASSERT_NE(link, nullptr);
  EXPECT_NE(link->message.find("pitch_60/trial_3.csv: cannot open"), std::string::npos)
      << link->message;
  // The good logs still give the ellipse.
  ASSERT_TRUE(result.ellipse_fit.has_value());
  EXPECT_NEAR(result.ellipse_fit->ix.value, kIx, 1e-9);
  // The report lists the failures with their reasons.
  const std::string html = ReadFile(c.dir + "/out/report.html");
  EXPECT_NE(html.find("cannot read the pitch"), std::string::npos);
}

TEST(Campaign, UsageErrorsThrow) {
  FakeCampaign c;
  CampaignOptions options = c.Options();
  WriteFile(c.dir + "/afile", "x");
  options.out_dir = c.dir + "/afile";
  const CampaignConfig config = LoadCampaignConfig(c.dir + "/campaign.yaml");
  try {
    RunCampaign(config, options);
    FAIL();
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("is not a folder"), std::string::npos) << e.what();
  }
  fs::rename(c.dir + "/logs", c.dir + "/logs_moved");
  try {
    c.Run();
    FAIL();
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("runs.root: folder"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
  }
}

TEST(Campaign, RigHeavierThanTotalIsAClearErrorRow) {
  FakeCampaign c("{inertia_kg_m2: 2.9}");
  const CampaignResult result = c.Run();
  EXPECT_EQ(result.summary.exit_code, 1);
  // I(theta) + 0.5 is below 2.9 near 90 deg (I_x = 2): those rows fail, the rest fit.
  const TraceRecord* r = Find(result, "pitch_90/trial_1");
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->status, TraceStatus::kError);
  EXPECT_NE(r->message.find("rig inertia 2.9 kg m^2 is not below the measured total"),
            std::string::npos)
      << r->message;
  EXPECT_GT(result.summary.n_ok, 0);
  EXPECT_FALSE(std::isnan(result.traces[0].inertia_total_kg_m2));
}

TEST(Campaign, TareLogsGiveTheRigInertia) {
  FakeCampaign c("{tare: {logs: \"logs/tare/*.csv\"}}");
  // Two tare logs at 0.5 +- 0.002: mean 0.5, std of the mean 0.002 sqrt(2) / sqrt(2) = 0.002
  // (above the fits' own 1e-4 / sqrt(2)).
  WriteFile(c.dir + "/logs/tare/tare_1.csv", "I=0.502\n");
  WriteFile(c.dir + "/logs/tare/tare_2.csv", "I=0.498\n");
  // The tare folder also matches the aircraft pattern? No: "tare" has no pitch_ prefix.
  const CampaignResult result = c.Run();
  EXPECT_EQ(result.summary.exit_code, 0);
  EXPECT_EQ(result.rig_tare_n, 2);
  EXPECT_NEAR(result.rig_inertia_kg_m2, 0.5, 1e-12);
  EXPECT_NEAR(result.rig_inertia_std_kg_m2, 0.002, 1e-12);
  ASSERT_TRUE(result.ellipse_fit.has_value());
  EXPECT_NEAR(result.ellipse_fit->iz.value, kIz, 1e-9);
  const TraceRecord* tare = Find(result, "tare_1");
  ASSERT_NE(tare, nullptr);
  EXPECT_EQ(tare->role, TraceRole::kTare);
  // A missing tare folder is a config error.
  c.WriteConfig("{tare: {logs: \"nowhere/*.csv\"}}", "");
  EXPECT_THROW(c.Run(), UserError);
}

TEST(Campaign, RigInertiaTableIsInterpolated) {
  FakeCampaign c("{table: {-90: 0.5, 90: 0.5}}");
  const CampaignResult result = c.Run();
  EXPECT_EQ(result.summary.exit_code, 0);
  EXPECT_NEAR(result.ellipse_fit->ixz.value, kIxz, 1e-9);
  CampaignConfig config = LoadCampaignConfig(c.dir + "/campaign.yaml");
  config.rig_inertia.table_kg_m2 = {{0.0, 1.0}, {10.0, 2.0}};
  double value = 0, std = 0;
  std::string why;
  ASSERT_TRUE(RigInertiaAt(config, NAN, NAN, 2.5, &value, &std, &why));
  EXPECT_DOUBLE_EQ(value, 1.25);
  EXPECT_FALSE(RigInertiaAt(config, NAN, NAN, 20.0, &value, &std, &why));
  EXPECT_NE(why.find("outside the rig inertia table"), std::string::npos) << why;
}

TEST(Campaign, RunsTableAndTooFewAngles) {
  FakeCampaign c;
  WriteFile(c.dir + "/runs.csv",
            "path,pitch_deg\npitch_0/trial_1.csv,0\npitch_90/trial_1.csv,90\n"
            "missing.csv,30\npitch_30/trial_1.csv,abc\n");
  WriteFile(
      c.dir + "/campaign.yaml",
      "rig: {filar_length_m: 2, filar_separation_m: 1, mass_kg: 2, inertia: {inertia_kg_m2: 0.5}}\n"
      "aircraft: {mass_kg: 10}\nruns: {root: logs, table: runs.csv}\n");
  const CampaignResult result = c.Run();
  ASSERT_EQ(result.traces.size(), 4u);
  EXPECT_EQ(result.summary.n_ok, 2);
  EXPECT_NE(Find(result, "missing.csv")->message.find("not found"), std::string::npos);
  EXPECT_NE(Find(result, "pitch_30")->message.find("not a number"), std::string::npos);
  // Two angles: no ellipse, said so, exit 1.
  EXPECT_FALSE(result.summary.ellipse_fitted);
  EXPECT_NE(result.summary.ellipse_message.find("at least 3 needed"), std::string::npos);
  EXPECT_EQ(result.summary.exit_code, 1);
}

// ---- With the real trace fit, on logs from the simulator ----

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  if (at == std::string::npos)
    ADD_FAILURE() << "sample spec changed: '" << from << "' not found";
  else
    text.replace(at, from.size(), to);
  return text;
}

// A small campaign simulated from the sample spec (5 angles, 2 trials, 2 tare logs, 20-25 s).
struct SimulatedCampaign {
  std::string dir;
  nlohmann::json truth;
  SimulatedCampaign() {
    dir = TempDir();
    std::string spec =
        ReadFile(std::string(BIFILAR_SOURCE_DIR) + "/configs/simulate_prandtl_d.yaml");
    spec = Replace(spec,
                   "pitch_deg: [-80, -70, -60, -50, -40, -30, -20, -10, 0, 10, 20, 30, 40, 50, 60, "
                   "70, 80, 90]",
                   "pitch_deg: [-60, -20, 0, 45, 90]");
    spec = Replace(spec, "trials_per_pitch: 3", "trials_per_pitch: 2");
    spec = Replace(spec, "tare_logs: 3", "tare_logs: 2");
    spec = Replace(spec, "free_s: [35, 45]", "free_s: [20, 25]");
    spec = Replace(spec, "gzip: true", "gzip: false");  // plain .csv: tests edit logs as text
    RunSimulateCampaign(ParseSimulateSpec(spec, "small_spec.yaml"), dir + "/logs");
    truth = nlohmann::json::parse(ReadFile(dir + "/logs/truth.json"));
    WriteConfig("{tare: {logs: logs/tare/*.csv}}", "nominal");
  }
  ~SimulatedCampaign() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  void WriteConfig(const std::string& rig_inertia, const std::string& pitch_source) {
    WriteFile(dir + "/campaign.yaml",
              "rig:\n  filar_length_m: 2.0\n  filar_separation_m: 1.8\n  mass_kg: 1.25\n"
              "  inertia: " +
                  rig_inertia +
                  "\n"
                  "aircraft: {mass_kg: 5.5}\n"
                  "runs: {root: logs, pattern: \"pitch_{pitch_deg}/*.csv\", pitch_source: " +
                  pitch_source + "}\n");
  }
  CampaignResult Run() {
    CampaignOptions options;
    options.out_dir = dir + "/out";
    options.jobs = 2;
    return RunCampaign(LoadCampaignConfig(dir + "/campaign.yaml"), options);
  }
};

TEST(CampaignRealFit, RecoversTheSimulatedAircraft) {
  SimulatedCampaign c;
  // A log that is not CSV at all, in the middle of the campaign.
  WriteFile(c.dir + "/logs/pitch_0/trial_9.csv", std::string("\x89PNG\r\n\x1a\n\0\0binary", 16));
  const CampaignResult result = c.Run();
  EXPECT_EQ(result.summary.n_ok, 12);  // 10 aircraft + 2 tare
  EXPECT_EQ(result.summary.n_error, 1);
  const TraceRecord* bad = Find(result, "pitch_0/trial_9.csv");
  ASSERT_NE(bad, nullptr);
  EXPECT_EQ(bad->status, TraceStatus::kError);
  EXPECT_EQ(bad->message.rfind("pitch_0/trial_9.csv", 0), 0u) << bad->message;
  // Rig from the tare logs: the simulated 0.25 kg m^2 within 5 std of the mean.
  EXPECT_NEAR(result.rig_inertia_kg_m2, 0.25, 5 * result.rig_inertia_std_kg_m2 + 1e-4);
  // Every trace within 5 of its own sigma of the simulated total, plus 0.02 % (below the trace
  // fit's 0.05 % maximum-error target) for what the statistical sigma does not cover (gyro
  // scale error, rocking, jitter).
  for (const auto& t : c.truth["traces"]) {
    const TraceRecord* r = Find(result, t["file"].get<std::string>());
    ASSERT_NE(r, nullptr) << t["file"];
    ASSERT_TRUE(r->ok()) << r->message;
    EXPECT_NEAR(r->inertia_total_kg_m2, t["inertia_total_kg_m2"].get<double>(),
                5 * r->inertia_total_std_kg_m2 + 2e-4 * t["inertia_total_kg_m2"].get<double>())
        << r->file;
    ASSERT_TRUE(r->pitch_measured_deg.has_value());
    // Accelerometer pitch: noise 0.02 m/s^2 and bias 0.05 m/s^2 (1 sigma) give ~0.3 deg.
    if (t["kind"] == "aircraft") {
      EXPECT_NEAR(*r->pitch_measured_deg, t["true_pitch_deg"].get<double>(), 1.5) << r->file;
    }
  }
  // The ellipse: within 5 reported std of the truth (nominal pitch, 0.5 deg setting errors).
  ASSERT_TRUE(result.ellipse_fit.has_value()) << result.summary.ellipse_message;
  const auto& aircraft = c.truth["aircraft"];
  EXPECT_NEAR(result.ellipse_fit->ix.value, aircraft["ix_kg_m2"].get<double>(),
              5 * result.ellipse_fit->ix.std);
  EXPECT_NEAR(result.ellipse_fit->iz.value, aircraft["iz_kg_m2"].get<double>(),
              5 * result.ellipse_fit->iz.std);
  EXPECT_NEAR(result.ellipse_fit->ixz.value, aircraft["ixz_kg_m2"].get<double>(),
              5 * result.ellipse_fit->ixz.std);
}

TEST(CampaignRealFit, RigLargerThanTotalAndMeasuredPitch) {
  SimulatedCampaign c;
  c.WriteConfig("{inertia_kg_m2: 50}", "measured");
  CampaignResult result = c.Run();
  EXPECT_EQ(result.summary.exit_code, 1);
  EXPECT_EQ(result.summary.n_ok, 0);
  const TraceRecord* r = Find(result, "pitch_0/trial_1.csv");
  ASSERT_NE(r, nullptr);
  EXPECT_NE(r->message.find("rig inertia 50 kg m^2 is not below the measured total"),
            std::string::npos)
      << r->message;
  EXPECT_FALSE(result.summary.ellipse_fitted);
  // Same logs, rig fixed: no trace refitted (the rig is not a fit input); measured pitch used.
  c.WriteConfig("{inertia_kg_m2: 0.25}", "measured");
  result = c.Run();
  EXPECT_EQ(result.summary.n_fitted, 0);
  EXPECT_EQ(result.summary.n_ok, 10);
  for (const TraceRecord& t : result.traces) {
    EXPECT_DOUBLE_EQ(t.pitch_used_deg, *t.pitch_measured_deg);
  }
  ASSERT_TRUE(result.ellipse_fit.has_value());
}

// The command line: exit codes 0 / 1 / 2 and one clear line for config errors.
int RunCli(const std::string& args, const std::string& output) {
  const std::string command = std::string(BIFILAR_BINARY) + " " + args + " > " + output + " 2>&1";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(CampaignCli, ExitCodesAndMessages) {
  SimulatedCampaign c;
  const std::string log = c.dir + "/cli.txt";
  const std::string config = c.dir + "/campaign.yaml";
  EXPECT_EQ(RunCli("process " + config + " --out " + c.dir + "/out --jobs 2", log), 0)
      << ReadFile(log);
  EXPECT_NE(ReadFile(log).find("Table 2"), std::string::npos) << ReadFile(log);
  EXPECT_NE(ReadFile(log).find("reused from cache 0"), std::string::npos) << ReadFile(log);
  EXPECT_EQ(RunCli("process " + config + " --out " + c.dir + "/out", log), 0);
  EXPECT_NE(ReadFile(log).find("fits run 0, reused from cache 12"), std::string::npos)
      << ReadFile(log);
  EXPECT_EQ(RunCli("report " + c.dir + "/out", log), 0) << ReadFile(log);
  // Output path that is a file.
  WriteFile(c.dir + "/afile", "x");
  EXPECT_EQ(RunCli("process " + config + " --out " + c.dir + "/afile", log), 2);
  EXPECT_NE(ReadFile(log).find("is not a folder"), std::string::npos) << ReadFile(log);
  // A typo in a key: file, line and key.
  WriteFile(config, ReadFile(config) + "fit: {modl: full}\n");
  EXPECT_EQ(RunCli("process " + config, log), 2);
  EXPECT_NE(ReadFile(log).find("campaign.yaml:8:7: unknown key 'fit.modl'"), std::string::npos)
      << ReadFile(log);
  // A bad log: exit 1, the rest processed.
  c.WriteConfig("{tare: {logs: logs/tare/*.csv}}", "nominal");
  WriteFile(c.dir + "/logs/pitch_0/trial_9.csv", "t,gx\n");
  EXPECT_EQ(RunCli("process " + config + " --out " + c.dir + "/out", log), 1);
  EXPECT_NE(ReadFile(log).find("pitch_0/trial_9.csv"), std::string::npos) << ReadFile(log);
  EXPECT_NE(ReadFile(log).find("12 ok, 0 rejected, 1 error"), std::string::npos) << ReadFile(log);
  // `fit` on one log, JSON.
  EXPECT_EQ(RunCli("fit " + config + " " + c.dir + "/logs/pitch_45/trial_1.csv --json", log), 0)
      << ReadFile(log);
  const nlohmann::json records = nlohmann::json::parse(ReadFile(log));
  ASSERT_EQ(records.size(), 1u);
  EXPECT_EQ(records[0]["status"], "ok");
}

}  // namespace
}  // namespace bifilar

namespace bifilar {
namespace {

// issue 9 item 9: `rig.inertia.inertia_std_kg_m2: 0.05` made the std of I_x shrink and moved
// I_xz: it was used as a relative weight. A constant rig offset moves I_x and I_z together and
// leaves I_xz alone: its std adds in quadrature to theirs, and I_xz (value and std) is unchanged.
TEST(Campaign, RigInertiaStdEntersIxAndIzNotIxz) {
  FakeCampaign without("{inertia_kg_m2: 0.5, inertia_std_kg_m2: 0.0}", "ellipse: {bootstrap: 0}\n");
  FakeCampaign with("{inertia_kg_m2: 0.5, inertia_std_kg_m2: 0.05}", "ellipse: {bootstrap: 0}\n");
  const CampaignResult a = without.Run(), b = with.Run();
  ASSERT_TRUE(a.ellipse_fit && b.ellipse_fit);
  const EllipseResult &ea = *a.ellipse_fit, &eb = *b.ellipse_fit;
  EXPECT_NEAR(eb.ix.std, std::hypot(ea.ix.std, 0.05), 1e-12);
  EXPECT_NEAR(eb.iz.std, std::hypot(ea.iz.std, 0.05), 1e-12);
  EXPECT_DOUBLE_EQ(eb.ixz.value, ea.ixz.value);
  EXPECT_DOUBLE_EQ(eb.ixz.std, ea.ixz.std);
  EXPECT_DOUBLE_EQ(eb.ix.value, ea.ix.value);
}

}  // namespace
}  // namespace bifilar
