// RunFit (pipeline/commands/fit_command.h), the use case behind `bifilar fit`, called as tests and
// Python call it: its records and JSON are what the CLI prints, the run's events arrive in order,
// --repeats names and drops identical logs, bad options fail before any fit, and Ctrl-C is
// reported in the result. Also ApplySimulateOverrides, shared by `bifilar simulate` and Python.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/interrupt.h"
#include "base/user_error.h"
#include "pipeline/commands/fit_command.h"
#include "pipeline/commands/simulate_spec.h"
#include "pipeline/records/results_json.h"
#include "test_support.h"

namespace bifilar {
namespace {

using nlohmann::json;
using test_support::TempDir;

const std::string kSource = BIFILAR_SOURCE_DIR;
const std::string kConfig = kSource + "/configs/prandtl_d.yaml";
const std::string kLogs = kSource + "/sample_runs/prandtl_d/logs";

// The records without their wall-clock time, which differs from run to run.
json WithoutTimes(json j) {
  json& traces = j.is_array() ? j : j["traces"];
  for (json& t : traces) t.erase("fit_seconds");
  return j;
}

TEST(FitCommand, RecordsAndJsonAreWhatTheCliPrints) {
  FitCommandOptions options;
  options.config_path = kConfig;
  options.logs = {kLogs + "/pitch_-10/trial_1.csv.gz", kLogs + "/pitch_10/trial_2.csv.gz"};
  std::vector<std::string> told;
  options.on_record = [&](const TraceRecord& r, const CampaignConfig& config) {
    told.push_back(r.file);
    EXPECT_EQ(config.units, DisplayUnits::kImperial);  // the config's units, for printing
  };
  const FitCommandResult result = RunFit(options);
  ASSERT_EQ(result.records.size(), 2u);
  EXPECT_EQ(told, options.logs);  // each record as soon as its log is fitted, in order
  EXPECT_FALSE(result.interrupted);
  EXPECT_EQ(result.n_failed, 0);
  EXPECT_EQ(result.ExitCode(), 0);
  ASSERT_TRUE(result.json.is_array());
  ASSERT_EQ(result.json.size(), 2u);
  EXPECT_EQ(result.json[1], TraceRecordToJson(result.records[1], false));

  TempDir dir;
  const test_support::CliRun cli = test_support::Bifilar(
      dir, "fit " + kConfig + " " + options.logs[0] + " " + options.logs[1] + " --json");
  ASSERT_EQ(cli.exit_code, 0) << cli.err;
  EXPECT_EQ(WithoutTimes(json::parse(cli.out)), WithoutTimes(result.json));
}

TEST(FitCommand, RepeatsDropIdenticalLogsAndCombine) {
  FitCommandOptions options;
  options.config_path = kConfig;
  options.repeats = true;
  for (int k = 1; k <= 3; ++k) {
    options.logs.push_back(kLogs + "/pitch_-10/trial_" + std::to_string(k) + ".csv.gz");
  }
  options.logs.push_back(options.logs[0]);  // the same swing again: one repeat, dropped
  std::vector<std::string> identical;
  options.on_identical_log = [&](const std::string& w) { identical.push_back(w); };
  const FitCommandResult result = RunFit(options);
  EXPECT_EQ(identical.size(), 1u);
  ASSERT_EQ(result.distinct.dropped.size(), 1u);
  EXPECT_EQ(result.records.size(), 3u);
  ASSERT_EQ(result.groups.size(), 1u);
  EXPECT_EQ(result.groups[0].members.size(), 3u);
  ASSERT_TRUE(result.json.is_object());
  for (const char* key : {"traces", "repeats", "amplitude_correction", "identical_logs_dropped"}) {
    EXPECT_TRUE(result.json.contains(key)) << key;
  }
  EXPECT_EQ(result.json["identical_logs_dropped"][0]["file"], options.logs[3]);
}

TEST(FitCommand, BadOptionsFailBeforeAnyFit) {
  FitCommandOptions options;
  options.config_path = kConfig;
  options.logs = {kLogs + "/pitch_-10/trial_1.csv.gz"};
  int fitted = 0;
  options.on_record = [&](const TraceRecord&, const CampaignConfig&) { ++fitted; };
  options.window = "20:10";
  EXPECT_THROW(RunFit(options), UserError);
  options.window.clear();
  options.max_amplitude_deg = 30;
  options.model = "jardin";
  EXPECT_NO_THROW(RunFit(options));
  EXPECT_EQ(fitted, 1);
}

TEST(FitCommand, InterruptIsReportedInTheResult) {
  FitCommandOptions options;
  options.config_path = kConfig;
  options.logs = {kLogs + "/pitch_-10/trial_1.csv.gz", kLogs + "/pitch_10/trial_2.csv.gz"};
  ProcessInterruptFlag().store(true);  // Ctrl-C before the first log
  const FitCommandResult result = RunFit(options);
  ProcessInterruptFlag().store(false);
  EXPECT_TRUE(result.interrupted);
  EXPECT_TRUE(result.records.empty());
  EXPECT_TRUE(result.json.is_null());
  EXPECT_EQ(result.ExitCode(), kInterruptedExitCode);
}

TEST(SimulateOverrides, GoToTheTraceOrToTheCampaign) {
  SimulateOverrides o;
  o.seed = 7;
  o.length_m = 2.5;
  o.separation_m = 0.5;
  o.gravity_mps2 = 9.8;
  o.inertia_kg_m2 = 0.3;
  o.duration_s = 40;
  o.no_accel = true;
  SimulateSpec trace = ParseSimulateSpec("{}", "<defaults>");
  ApplySimulateOverrides(o, true, &trace);
  EXPECT_EQ(trace.seed, 7u);
  EXPECT_EQ(trace.trace.filar_length_m, 2.5);
  EXPECT_EQ(trace.trace.filar_separation_m, 0.5);
  EXPECT_EQ(trace.trace.gravity_mps2, 9.8);
  EXPECT_EQ(trace.trace.inertia_kg_m2, 0.3);
  EXPECT_FALSE(trace.options.sensor.accelerometer);
  EXPECT_EQ(trace.options.timeline.free_s.min, 40);
  EXPECT_EQ(trace.options.timeline.free_s.max, 40);
  EXPECT_EQ(trace.campaign.filar_length_m, ParseSimulateSpec("{}", "x").campaign.filar_length_m);

  SimulateSpec campaign = ParseSimulateSpec("{}", "<defaults>");
  ApplySimulateOverrides(o, false, &campaign);
  EXPECT_EQ(campaign.campaign.filar_length_m, 2.5);
  EXPECT_EQ(campaign.campaign.filar_separation_m, 0.5);
  EXPECT_EQ(campaign.campaign.gravity_mps2, 9.8);
  EXPECT_FALSE(campaign.trace.inertia_kg_m2.has_value());  // a trace's values stay out
}

}  // namespace
}  // namespace bifilar
