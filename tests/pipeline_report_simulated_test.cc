// report.html of simulated campaigns with the real fit (issue 25 item 3 and "Numbers to reach"):
// three separate axes (configs/simulate_three_axes.yaml) and a full tensor
// (configs/simulate_tensor.yaml), both processed with configs/tensor_uav.yaml. The three-axis page
// has no "not fitted" text and no empty figure section; the tensor page shows its ellipsoid; every
// thumbnail's caption gives the record's std, labelled; the page loads in headless Chromium.
#include <filesystem>
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

namespace fs = std::filesystem;
using test_support::ReadFile;
using test_support::TempDir;

int Count(const std::string& html, const std::string& needle) {
  int n = 0;
  for (size_t at = html.find(needle); at != std::string::npos; at = html.find(needle, at + 1)) ++n;
  return n;
}

// Simulates `spec` and processes it; returns the report.
std::string SimulateAndReport(const TempDir& dir, const std::string& spec, CampaignResult* result) {
  const std::string source = BIFILAR_SOURCE_DIR;
  RunSimulateCampaign(ReadSimulateSpec(source + "/configs/" + spec), dir.path + "/logs");
  ConfigLoadOptions load;
  load.runs_root = dir.path + "/logs";
  CampaignOptions options;
  options.out_dir = dir.path + "/out";
  options.jobs = 2;
  *result = RunCampaign(LoadCampaignConfig(source + "/configs/tensor_uav.yaml", load), options);
  return ReadFile(dir.path + "/out/report.html");
}

// What both pages share: no error colour, no empty figure, the record's stds on each thumbnail.
void ExpectCleanPage(const std::string& html, int traces) {
  const std::string page = html.substr(0, html.find("<h2>Config used</h2>"));
  EXPECT_EQ(page.find("not fitted"), std::string::npos);
  EXPECT_EQ(page.find("(no figure)"), std::string::npos);
  EXPECT_EQ(page.find("missing)"), std::string::npos);
  EXPECT_EQ(page.find("class=\"bad\""), std::string::npos);
  EXPECT_EQ(Count(page, "<svg class=\"trace\""), traces);
  // Each thumbnail's caption (the result box and the tables give them too: counted after them).
  const std::string thumbnails = page.substr(page.find("<h2>Fit and residual of every trace</h2>"));
  EXPECT_EQ(Count(thumbnails, " (stat) &plusmn; "), traces);
  EXPECT_EQ(Count(thumbnails, " (total) "), traces);
  for (const char* absent : {"Table 2", "Figure 3", "Figure 4", "NACA"}) {
    EXPECT_EQ(page.find(absent), std::string::npos) << absent;
  }
}

TEST(ReportSimulated, ThreeSeparateAxes) {
  TempDir dir("bifilar_report_sim");
  CampaignResult result;
  const std::string html = SimulateAndReport(dir, "simulate_three_axes.yaml", &result);
  ASSERT_EQ(result.summary.n_ok, 6);
  ASSERT_TRUE(result.tensor_fit.has_value()) << result.summary.tensor_message;
  EXPECT_FALSE(result.tensor_fit->full);
  ExpectCleanPage(html, 6);
  EXPECT_NE(html.find("campaign: separate axes"), std::string::npos);
  EXPECT_EQ(html.find("Ellipsoid of inertia"), std::string::npos);  // needs a full tensor
  // Truth (configs/simulate_three_axes.yaml): I_yy = 0.300 kg m^2; the headline gives it.
  EXPECT_NE(html.find("I<sub>yy</sub> = 0.300"), std::string::npos);
}

TEST(ReportSimulated, FullTensorShowsItsEllipsoid) {
  TempDir dir("bifilar_report_sim");
  CampaignResult result;
  const std::string html = SimulateAndReport(dir, "simulate_tensor.yaml", &result);
  ASSERT_EQ(result.summary.n_ok, 24);
  ASSERT_TRUE(result.tensor_fit.has_value() && result.tensor_fit->full);
  ExpectCleanPage(html, 24);
  EXPECT_NE(html.find("campaign: full inertia tensor"), std::string::npos);
  EXPECT_NE(html.find("alt=\"ellipsoid of inertia"), std::string::npos);
  // The 0.5 deg hanging errors scatter the moments beyond their logs' stds: the logs are named
  // in the report as on the console.
  const nlohmann::json results = nlohmann::json::parse(ReadFile(dir.path + "/out/results.json"));
  const nlohmann::json& logs = results["tensor"]["scatter_logs"];
  ASSERT_FALSE(logs.empty());
  EXPECT_NE(html.find("the logs behind the scatter, residual over their own std: " +
                      logs[0]["file"].get<std::string>()),
            std::string::npos);
  std::ostringstream console;
  PrintCampaignSummary(
      LoadCampaignConfig(std::string(BIFILAR_SOURCE_DIR) + "/configs/tensor_uav.yaml",
                         [&] {
                           ConfigLoadOptions o;
                           o.runs_root = dir.path + "/logs";
                           return o;
                         }()),
      result, console);
  EXPECT_NE(console.str().find("the logs behind the scatter, residual over their own std: " +
                               logs[0]["file"].get<std::string>()),
            std::string::npos)
      << console.str();
}

}  // namespace
}  // namespace bifilar
