// Issue 32 end to end: a three-axis campaign whose level swings were made on another rig
// (configs/simulate_three_axes_other_rig.yaml) is marked not physical in results.json, the
// console, the report's result box and the exit code, with roll 0, pitch 0 named; the healthy one
// (configs/simulate_three_axes.yaml) is not. The survey behind the numbers:
// scripts/physical_survey.sh.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <tuple>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "pipeline/campaign/campaign.h"
#include "pipeline/campaign/campaign_summary.h"
#include "pipeline/commands/simulate_spec.h"
#include "pipeline/config/config.h"
#include "pipeline/report/export.h"
#include "test_support.h"

namespace bifilar {
namespace {

using test_support::ReadFile;
using test_support::TempDir;

CampaignResult SimulateAndProcess(const TempDir& dir, const std::string& spec,
                                  CampaignConfig* config) {
  const std::string source = BIFILAR_SOURCE_DIR;
  RunSimulateCampaign(ReadSimulateSpec(source + "/configs/" + spec), dir.path + "/logs");
  ConfigLoadOptions load;
  load.runs_root = dir.path + "/logs";
  CampaignOptions options;
  options.out_dir = dir.path + "/out";
  options.jobs = 2;
  options.figures = false;
  *config = LoadCampaignConfig(source + "/configs/tensor_uav.yaml", load);
  return RunCampaign(*config, options);
}

TEST(PhysicalCampaign, OtherRigForOneAttitudeIsNotPhysical) {
  TempDir dir("physical_other_rig");
  CampaignConfig config;
  const CampaignResult result =
      SimulateAndProcess(dir, "simulate_three_axes_other_rig.yaml", &config);
  ASSERT_TRUE(result.physical);
  EXPECT_EQ(result.physical->status, PhysicalStatus::kNotPhysical) << result.physical->message;
  EXPECT_EQ(result.physical->attitude, "roll 0, pitch 0 deg");
  EXPECT_EQ(result.summary.exit_code, 1);
  const nlohmann::json j = nlohmann::json::parse(ReadFile(dir.path + "/out/results.json"));
  EXPECT_EQ(j["physical"]["status"], "not_physical");
  EXPECT_EQ(j["physical"]["worst"]["inequality"], "I_xx + I_yy - I_zz");
  EXPECT_LT(j["physical"]["worst"]["z"].get<double>(), j["physical"]["threshold_z"].get<double>());
  std::ostringstream console;
  PrintCampaignSummary(config, result, console);
  EXPECT_EQ(console.str().rfind("Error: NOT PHYSICAL", 0), 0u) << console.str();
  std::istringstream lines(console.str());
  for (std::string line; std::getline(lines, line);) {
    if (line.find("PHYSICAL") != std::string::npos ||
        line.find("Likely causes") != std::string::npos) {
      EXPECT_LE(line.size(), 160u) << line;
    }
  }
  const std::string html = ReadFile(dir.path + "/out/report.html");
  EXPECT_NE(html.find("<b>Not physical</b>: I_xx + I_yy - I_zz"), std::string::npos);
  // Every simulator format refuses it with the one message (and writes nothing); --force writes.
  std::string first_message;
  for (ExportFormat format : {ExportFormat::kUrdf, ExportFormat::kSdf, ExportFormat::kJsbsim,
                              ExportFormat::kMjcf, ExportFormat::kArdupilot}) {
    ExportOptions o;
    o.results_path = dir.path + "/out/results.json";
    o.format = format;
    o.symmetric = true;            // a three-axis campaign holds no products:
    o.set_kg_m2 = {{"Ixz", 0.0}};  // Ixy, Iyz by symmetry, Ixz given
    std::ostringstream out, err;
    EXPECT_NE(RunExport(o, out, err), 0) << ExportFormatName(format);
    EXPECT_EQ(out.str(), "") << ExportFormatName(format);
    const std::string message = err.str();
    EXPECT_NE(message.find("physical check says not physical"), std::string::npos) << message;
    const std::string reason = message.substr(0, message.find("; not written"));
    if (first_message.empty()) first_message = reason;
    EXPECT_EQ(reason, first_message) << ExportFormatName(format);
    o.force = true;
    std::ostringstream forced_out, forced_err;
    EXPECT_EQ(RunExport(o, forced_out, forced_err), 0) << forced_err.str();
    EXPECT_FALSE(forced_out.str().empty());
  }
}

TEST(PhysicalCampaign, HealthyThreeAxesArePhysical) {
  TempDir dir("physical_healthy");
  CampaignConfig config;
  const CampaignResult result = SimulateAndProcess(dir, "simulate_three_axes.yaml", &config);
  ASSERT_TRUE(result.physical);
  EXPECT_EQ(result.physical->status, PhysicalStatus::kPhysical) << result.physical->message;
  EXPECT_EQ(result.summary.exit_code, 0);
  const std::string html = ReadFile(dir.path + "/out/report.html");
  EXPECT_EQ(html.find("Not physical"), std::string::npos);
}

}  // namespace
}  // namespace bifilar

namespace bifilar {
namespace {

// configs/simulate_three_axes_two_setups.yaml simulated once; `table` (rows of
// path,roll_deg,pitch_deg[,group]) replaces runs.pattern when not empty.
CampaignResult ProcessTwoSetups(const TempDir& dir, const std::string& table,
                                std::string* console) {
  const std::string source = BIFILAR_SOURCE_DIR;
  if (!std::filesystem::exists(dir.path + "/logs")) {
    RunSimulateCampaign(ReadSimulateSpec(source + "/configs/simulate_three_axes_two_setups.yaml"),
                        dir.path + "/logs");
  }
  std::string config_text = ReadFile(source + "/configs/tensor_uav.yaml");
  if (!table.empty()) {
    const std::string pattern = "pattern: \"roll_{roll_deg}_pitch_{pitch_deg}/*.csv.gz\"";
    const size_t at = config_text.find(pattern);
    EXPECT_NE(at, std::string::npos);
    config_text.replace(at, pattern.size(), "table: runs.csv");
    std::ofstream(dir.path + "/runs.csv") << table;
  }
  std::ofstream(dir.path + "/config.yaml") << config_text;
  ConfigLoadOptions load;
  load.runs_root = dir.path + "/logs";
  CampaignOptions options;
  options.out_dir = dir.path + "/out";
  options.jobs = 2;
  options.figures = false;
  options.write_report = false;
  const CampaignConfig config = LoadCampaignConfig(dir.path + "/config.yaml", load);
  const CampaignResult result = RunCampaign(config, options);
  std::ostringstream out;
  PrintCampaignSummary(config, result, out);
  *console = out.str();
  return result;
}

std::string Rows(bool comment_other_rig, bool groups) {
  std::string t = std::string("path,roll_deg,pitch_deg") + (groups ? ",group" : "") + "\n";
  for (const auto& [folder, roll, pitch] :
       {std::make_tuple("roll_0_pitch_0", 0, 0), std::make_tuple("roll_0_pitch_-90", 0, -90),
        std::make_tuple("roll_90_pitch_0", 90, 0)}) {
    for (int trial = 1; trial <= 4; ++trial) {
      const bool other = roll == 90 && trial >= 3;
      t += std::string(comment_other_rig && other ? "#" : "") + folder + "/trial_" +
           std::to_string(trial) + ".csv.gz," + std::to_string(roll) + "," + std::to_string(pitch) +
           (groups ? (other ? ",long wires" : ",rig A") : "") + "\n";
    }
  }
  return t;
}

// Found by the test: I_yy withheld, both set-ups named with their logs; the advice (comment out
// the other set-up's rows) gives I_yy = 0.300 (truth) and nothing withheld.
TEST(PhysicalCampaign, TwoSetupsFoundAreWithheldUntilOneIsKept) {
  TempDir dir("physical_two_setups");
  std::string console;
  CampaignResult r = ProcessTwoSetups(dir, "", &console);
  ASSERT_EQ(r.setup_warnings.size(), 1u) << console;
  const std::string& w = r.setup_warnings[0];
  EXPECT_NE(w.find("result withheld at roll 90, pitch 0 deg"), std::string::npos) << w;
  EXPECT_NE(w.find("set-up 1 ("), std::string::npos) << w;
  EXPECT_NE(w.find("set-up 2 ("), std::string::npos) << w;
  EXPECT_NE(w.find("comment out"), std::string::npos) << w;
  ASSERT_TRUE(r.tensor_fit);
  EXPECT_FALSE(r.tensor_fit->components[kIyy].observable);  // not averaged into a number
  r = ProcessTwoSetups(dir, Rows(true, false), &console);
  EXPECT_TRUE(r.setup_warnings.empty()) << console;
  ASSERT_TRUE(r.tensor_fit);
  const TensorEstimate& iyy = r.tensor_fit->components[kIyy];
  ASSERT_TRUE(iyy.observable);
  // Truth 0.300; tolerance: 4 stds and the 0.25 % systematic the rig's uncertainties allow.
  EXPECT_NEAR(iyy.value, 0.300, 4 * iyy.std + 0.0025 * 0.3) << console;
  EXPECT_EQ(r.summary.exit_code, 0) << console;
}

// Named by the user (group column): withheld, both groups named; keeping one gives the truth.
TEST(PhysicalCampaign, TwoSetupsNamedInTheGroupColumnAreWithheldUntilOneIsKept) {
  TempDir dir("physical_named_setups");
  std::string console;
  CampaignResult r = ProcessTwoSetups(dir, Rows(false, true), &console);
  ASSERT_EQ(r.setup_warnings.size(), 1u) << console;
  EXPECT_NE(r.setup_warnings[0].find("group 'long wires' ("), std::string::npos);
  EXPECT_NE(r.setup_warnings[0].find("group 'rig A' ("), std::string::npos);
  ASSERT_TRUE(r.tensor_fit);
  EXPECT_FALSE(r.tensor_fit->components[kIyy].observable);
  EXPECT_EQ(r.summary.exit_code, 1);
  r = ProcessTwoSetups(dir, Rows(true, true), &console);
  EXPECT_TRUE(r.setup_warnings.empty()) << console;
  const TensorEstimate& iyy = r.tensor_fit->components[kIyy];
  ASSERT_TRUE(iyy.observable);
  EXPECT_NEAR(iyy.value, 0.300, 4 * iyy.std + 0.0025 * 0.3) << console;
}

}  // namespace
}  // namespace bifilar
