// Repeats of one set-up (pipeline/repeats.h): grouping by the last number of the file name,
// DerSimonian-Laird between-repeat std, and on the real quadrotor logs (../shared/data/crazyflie,
// skipped when absent) the 4 repeats of each set-up within 2.5 sigma of their 4-log mean.
#include "pipeline/repeats.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pipeline/config.h"
#include "tests/test_support.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;
const std::string kSource = BIFILAR_SOURCE_DIR;
const std::string kCrazyflie = kSource + "/../shared/data/crazyflie";

TraceRecord Record(double inertia, double std) {
  TraceRecord r;
  r.status = TraceStatus::kOk;
  r.inertia_total_kg_m2 = inertia;
  r.inertia_total_std_kg_m2 = std;
  r.amplitude_deg = {20.0, 15.0};
  return r;
}

TEST(Repeats, GroupsByTheLastNumberOfTheFileName) {
  const std::vector<RepeatGroup> g =
      GroupRepeats({"logs/A_Log-1.csv", "logs/B_Log-1.csv", "logs/A_Log-2.csv",
                    "pitch_10/trial_3.csv", "pitch_10/trial_12.csv", "pitch_20/trial_1.csv",
                    "single.csv"});
  ASSERT_EQ(g.size(), 5u);
  EXPECT_EQ(g[0].name, "logs/A_Log-*.csv");
  EXPECT_EQ(g[0].members, (std::vector<int>{0, 2}));
  EXPECT_EQ(g[1].name, "logs/B_Log-*.csv");
  EXPECT_EQ(g[2].name, "pitch_10/trial_*.csv");  // the folder's number is not the repeat number
  EXPECT_EQ(g[2].members, (std::vector<int>{3, 4}));
  EXPECT_EQ(g[3].name, "pitch_20/trial_*.csv");
  EXPECT_EQ(g[4].name, "single.csv");
}

TEST(Repeats, ConsistentRepeatsAddNothing) {
  std::vector<TraceRecord> r = {Record(1.000, 0.01), Record(1.005, 0.01), Record(0.995, 0.01),
                                Record(1.002, 0.01)};
  std::vector<RepeatGroup> g = GroupRepeats({"a1", "a2", "a3", "a4"});
  CombineRepeats(&g, &r);
  ASSERT_EQ(g.size(), 1u);
  EXPECT_EQ(g[0].n_used, 4);
  EXPECT_EQ(g[0].tau_kg_m2, 0.0);
  for (const TraceRecord& x : r) {
    EXPECT_DOUBLE_EQ(x.inertia_total_std_kg_m2, 0.01);
    EXPECT_TRUE(x.warnings.empty());
  }
  EXPECT_NEAR(g[0].mean_kg_m2, 1.0005, 1e-12);
  EXPECT_NEAR(g[0].mean_std_kg_m2, 0.005, 1e-12);
}

// Repeats drawn with a known between-repeat std tau = 5 sigma: the DerSimonian-Laird estimate
// recovers it on average, and with it added the repeats cover their mean.
TEST(Repeats, RecoversAKnownBetweenRepeatStd) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double sigma = 0.001, tau = 0.005;
  double tau_sum = 0.0;
  int within = 0, n = 0;
  const int sets = 400;
  for (int s = 0; s < sets; ++s) {
    std::vector<TraceRecord> r;
    for (int k = 0; k < 6; ++k) r.push_back(Record(1.0 + tau * normal(rng) + sigma * normal(rng), sigma));
    std::vector<RepeatGroup> g = GroupRepeats({"l1", "l2", "l3", "l4", "l5", "l6"});
    CombineRepeats(&g, &r);
    tau_sum += g[0].tau_kg_m2;
    for (const TraceRecord& x : r) {
      ++n;
      if (std::abs(x.inertia_total_kg_m2 - 1.0) <= 1.96 * x.inertia_total_std_kg_m2) ++within;
    }
  }
  EXPECT_NEAR(tau_sum / sets, tau, 0.15 * tau);  // E[tau_hat] a little below tau for k = 6
  EXPECT_GT(static_cast<double>(within) / n, 0.88);
}

TEST(Repeats, UnusableMembersAreLeftAlone) {
  std::vector<TraceRecord> r = {Record(1.0, 0.01), Record(2.0, 0.01), Record(1.0, 0.01)};
  r[1].status = TraceStatus::kRejected;
  std::vector<RepeatGroup> g = GroupRepeats({"x_1", "x_2", "x_3"});
  CombineRepeats(&g, &r);
  EXPECT_EQ(g[0].n_used, 2);
  EXPECT_TRUE(std::isnan(r[1].repeat_scatter_std_kg_m2));
  std::vector<TraceRecord> one = {Record(1.0, 0.01)};
  std::vector<RepeatGroup> g1 = GroupRepeats({"y_1"});
  CombineRepeats(&g1, &one);
  EXPECT_FALSE(g1[0].note.empty());
  EXPECT_FALSE(std::isfinite(g1[0].mean_kg_m2));
}

// `bifilar fit --repeats --json` on the simulated quadrotor (two set-ups x 4 repeats): an object
// with the traces and one group per set-up. The preset hangs each trial by hand (pitch error
// 1 deg), so the trials' true I differ by ~0.03 %: the between-repeat std sees that.
TEST(Repeats, FitCommandCombinesSimulatedQuadrotorRepeats) {
  char dir_template[] = "/tmp/bifilar_repeats_cli_XXXXXX";
  const std::string dir = mkdtemp(dir_template);
  const std::string simulate = std::string(BIFILAR_BINARY) + " simulate " + kSource +
                               "/configs/simulate_quadrotor.yaml --out " + dir + "/logs > /dev/null";
  ASSERT_EQ(std::system(simulate.c_str()), 0);
  std::ofstream(dir + "/fit.yaml") << test_support::QuadrotorFitConfig();
  const std::string fit = std::string(BIFILAR_BINARY) + " fit " + dir + "/fit.yaml " + dir +
                          "/logs/pitch_0/trial_*.csv " + dir + "/logs/pitch_90/trial_*.csv" +
                          " --repeats --json > " + dir + "/out.json";
  ASSERT_EQ(std::system(fit.c_str()), 0);
  std::ifstream in(dir + "/out.json");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\"traces\""), std::string::npos);
  EXPECT_NE(text.find("pitch_0/trial_*.csv"), std::string::npos);
  EXPECT_NE(text.find("pitch_90/trial_*.csv"), std::string::npos);
  const size_t z = text.find("\"max_abs_z\": ");
  ASSERT_NE(z, std::string::npos);
  EXPECT_LE(std::atof(text.c_str() + z + 13), 3.5);
  EXPECT_NE(text.find("\"tau_kg_m2\": "), std::string::npos);
  fs::remove_all(dir);
}

// Issue 8: the 4 repeats of each quadrotor set-up are consistent with their reported std.
TEST(Repeats, QuadrotorRepeatsAreWithinTheirStd) {
  if (!fs::is_directory(kCrazyflie)) GTEST_SKIP() << kCrazyflie << " absent";
  char dir_template[] = "/tmp/bifilar_repeats_XXXXXX";
  const std::string dir = mkdtemp(dir_template);
  int logs = 0, beyond = 0, beyond_before = 0;
  for (const char* airframe : {"BaseModel", "NarrowMedium"}) {
    const double mass = std::string(airframe) == "BaseModel" ? 0.0343 : 0.0381;
    const std::string config_path = dir + "/" + airframe + ".yaml";
    std::ofstream(config_path) << test_support::QuadrotorFitConfig(mass);
    ConfigLoadOptions load;
    load.require_runs = false;
    const CampaignConfig config = LoadCampaignConfig(config_path, load);
    for (const char* axis : {"Ixx", "Iyy", "Izz"}) {
      std::vector<std::string> paths;
      std::vector<TraceRecord> records;
      for (int k = 1; k <= 4; ++k) {
        paths.push_back(kCrazyflie + "/" + airframe + "_" + axis + "_Log-" + std::to_string(k) + ".csv");
        records.push_back(ProcessTrace(config, paths.back(), {}));
        ASSERT_TRUE(records.back().ok()) << paths.back() << ": " << records.back().message;
      }
      double mean = 0.0;
      for (const TraceRecord& r : records) mean += r.inertia_total_kg_m2 / 4.0;
      for (const TraceRecord& r : records) {
        if (std::abs(r.inertia_total_kg_m2 - mean) > 2.5 * r.inertia_total_std_kg_m2) ++beyond_before;
      }
      std::vector<RepeatGroup> groups = GroupRepeats(paths);
      CombineRepeats(&groups, &records);
      ASSERT_EQ(groups.size(), 1u);
      EXPECT_EQ(groups[0].n_used, 4);
      for (const TraceRecord& r : records) {
        ++logs;
        const double z = (r.inertia_total_kg_m2 - mean) / r.inertia_total_std_kg_m2;
        if (std::abs(z) > 2.5) ++beyond;
        EXPECT_LE(std::abs(z), 2.5) << r.file;
      }
      std::printf("  %s %s: %s\n", airframe, axis, RepeatGroupLine(groups[0]).c_str());
    }
  }
  std::printf("  %d logs: %d beyond 2.5 sigma of their set-up's mean with the per-log std alone, "
              "%d with the repeats combined\n", logs, beyond_before, beyond);
  EXPECT_EQ(logs, 24);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace bifilar
