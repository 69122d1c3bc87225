// Issue 32 end to end: a three-axis campaign whose level swings were made on another rig
// (configs/simulate_three_axes_other_rig.yaml) is marked not physical in results.json, the
// console, the report's result box and the exit code, with roll 0, pitch 0 named; the healthy one
// (configs/simulate_three_axes.yaml) is not. The survey behind the numbers:
// scripts/physical_survey.sh.
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "pipeline/campaign/campaign.h"
#include "pipeline/campaign/campaign_summary.h"
#include "pipeline/commands/simulate_spec.h"
#include "pipeline/config/config.h"
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
    if (line.find("PHYSICAL") != std::string::npos || line.find("Likely causes") != std::string::npos) {
      EXPECT_LE(line.size(), 160u) << line;
    }
  }
  const std::string html = ReadFile(dir.path + "/out/report.html");
  EXPECT_NE(html.find("<b>Not physical</b>: I_xx + I_yy - I_zz"), std::string::npos);
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
