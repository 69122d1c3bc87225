// `bifilar plan --tensor` end to end (the real binary): the JSON plan against the library's, the
// human table, a rig that cannot observe some components, units, and bad options. The planning
// itself is tested against a Monte-Carlo in tests/fit_tensor_plan_test.cc.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "base/units.h"
#include "fit/tensor.h"
#include "fit/tensor_plan.h"
#include "test_support.h"

namespace bifilar {
namespace {

using nlohmann::json;
using test_support::ReadFile;
using test_support::TempDir;

using test_support::Bifilar;
using test_support::CliRun;

TEST(TensorPlanCli, JsonMatchesTheLibraryAndUnitsConvert) {
  TempDir dir("bifilar_tensor_plan");
  const CliRun r = Bifilar(dir,
                           "plan --tensor --roll=-45:45 --pitch=-90:90 --trials 2 "
                           "--sigma 0.005 --target 0.002 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  TensorPlanOptions o;
  o.roll_min_deg = -45;
  o.roll_max_deg = 45;
  o.trials_per_orientation = 2;
  o.sigma_kg_m2 = 0.005;
  o.target_std_kg_m2 = 0.002;
  TensorPlan plan;
  std::string why;
  ASSERT_TRUE(PlanTensor(o, &plan, &why)) << why;
  EXPECT_EQ(j["rank"], 6);
  EXPECT_TRUE(j["unobservable"].empty());
  ASSERT_EQ(j["orientations"].size(), 12u);
  for (size_t i = 0; i < 12; ++i) {
    EXPECT_EQ(j["orientations"][i]["roll_deg"].get<double>(), plan.orientations[i].roll_deg);
    EXPECT_EQ(j["orientations"][i]["pitch_deg"].get<double>(), plan.orientations[i].pitch_deg);
  }
  for (int k = 0; k < kTensorComponents; ++k) {
    const json& c = j["components"][TensorComponentName(k)];
    EXPECT_EQ(c["std_kg_m2"].get<double>(), plan.std_kg_m2[k]);
    EXPECT_EQ(c["trials_needed"].get<int>(), plan.trials_needed[k]);
  }
  EXPECT_EQ(j["trials_needed_all"].get<int>(), plan.trials_needed_all);

  // The same plan in slug ft^2: the printed stds are the SI ones divided by 1.35581795.
  char sigma[64];
  std::snprintf(sigma, sizeof sigma, "%.17g", 0.005 / kKgM2PerSlugFt2);
  const CliRun imperial = Bifilar(dir, "plan --tensor --roll=-45:45 --trials 2 --sigma " +
                                           std::string(sigma) + " --units imperial");
  ASSERT_EQ(imperial.exit_code, 0) << imperial.err;
  char izz[64];
  std::snprintf(izz, sizeof izz, "Izz  %-11.4g", plan.std_kg_m2[2] / kKgM2PerSlugFt2);
  EXPECT_NE(imperial.out.find(izz), std::string::npos) << izz << "\n" << imperial.out;
  EXPECT_NE(imperial.out.find("slug ft^2"), std::string::npos);
}

TEST(TensorPlanCli, RollHeldAtZeroNamesTheUnobservableComponents) {
  TempDir dir("bifilar_tensor_plan");
  const CliRun r = Bifilar(dir, "plan --tensor --roll 0 --sigma 0.005");
  ASSERT_EQ(r.exit_code, 0) << r.err;  // not an error: Ixx, Izz, Ixz are still planned
  EXPECT_NE(r.out.find("Iyy  not observable"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Ixy  not observable"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Iyz  not observable"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("cannot observe Iyy, Ixy, Iyz"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("rank 3 of 6"), std::string::npos) << r.out;
}

TEST(TensorPlanCli, BadOptionsAreOneLineErrors) {
  TempDir dir("bifilar_tensor_plan");
  const struct {
    std::string args, expect;
  } cases[] = {
      {"plan --roll 0 --sigma 0.1", "--roll belongs to the tensor plan: add --tensor"},
      {"plan --tensor --angles 0,30 --sigma 0.1", "--angles belongs to the pitch-plane plan"},
      {"plan --tensor --roll=200 --sigma 0.1",
       "plan --tensor: --roll: roll_min_deg = 200; must be in [-180, 180]"},
      {"plan --tensor --roll=30:-30 --sigma 0.1", "MIN must not exceed MAX"},
      {"plan --tensor --roll=a:3 --sigma 0.1", "--roll 'a:3': 'a' is not a number"},
      {"plan --tensor --pitch=-95:0 --sigma 0.1",
       "plan --tensor: --pitch: pitch_min_deg = -95; must be in [-90, 90]"},
      {"plan --tensor --roll 0",
       "sigma_kg_m2 = 0; must be > 0 when sigma_relative = 0 (a per-swing std, absolute or "
       "relative)"},
      {"plan --tensor --sigma-rel 0.01", "--sigma-rel and --attitude-std need a guess"},
      {"plan --tensor --sigma 0.1 --ixx 1 --iyy 1", "give all of --ixx, --iyy, --izz"},
      {"plan --tensor --sigma 0.1 --ixz 0.1", "needs --ixx, --iyy, --izz"},
      {"plan --tensor --sigma 0.1 --target-rel 0.01", "--target-rel is a fraction"},
      {"plan --tensor --sigma 0.1 --ixx 1 --iyy 1 --izz 1 --ixy 2",
       "--ixx ... --iyz: smallest principal moment of guess_kg_m2 = -1; must be > 0"},
      {"plan --angles 0,30,60", "--sigma is required"},
      {"plan --sigma 0.1", "--angles is required"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.args);
    const CliRun r = Bifilar(dir, c.args);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
}

// Issue 23 items 4, 6 and 7: `--sigma 1e-160` ended in "double free or corruption", `--sigma
// 1e200` printed -nan stds (tensor) or stds of 0 (pitch plane) with exit 0, and `--sigma 1e-308`
// was "not a number". Tiny sigmas now plan as any other (stds scaled); huge ones are refused.
TEST(TensorPlanCli, TinySigmasPlanAndHugeOnesAreRefused) {
  TempDir dir("bifilar_tensor_plan");
  for (const std::string sigma : {"--sigma 1e-160", "--sigma 1e-300",
                                  "--sigma-rel 1e-170 "
                                  "--ixx 1 --iyy 2 --izz 2.5"}) {
    SCOPED_TRACE(sigma);
    const CliRun r =
        Bifilar(dir, "plan --tensor --roll=-45:45 --pitch=-90:90 " + sigma + " --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const json j = json::parse(r.out);
    ASSERT_EQ(j["orientations"].size(), 12u);
    for (int k = 0; k < kTensorComponents; ++k) {
      const json& std_json = j["components"][TensorComponentName(k)]["std_kg_m2"];
      ASSERT_TRUE(std_json.is_number()) << std_json;
      EXPECT_GT(std_json.get<double>(), 0.0);
    }
  }
  const CliRun plain = Bifilar(dir, "plan --angles 0:90:10 --sigma 1e-200 --json");
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_GT(json::parse(plain.out)["Ix_kg_m2_std"].get<double>(), 0.0) << plain.out;
  const struct {
    std::string args, expect;
  } refused[] = {
      {"plan --tensor --roll=-45:45 --sigma 1e200",
       "plan --tensor: --sigma: sigma_kg_m2 = 1e+200; must be in [0, 1e+100]"},
      {"plan --tensor --roll=-45:45 --sigma 4.9e-324", "too small to compute with"},
      {"plan --angles 0:90:10 --sigma 1e200",
       "plan: sigma_kg_m2 = 1e+200; must be in [1e-300, 1e+100]"},
      {"plan --angles 0:90:10 --sigma 1e400", "'1e400' is out of range"},
      // A subnormal is a number, named as too small, not "not a number".
      {"plan --angles 0:90:10 --sigma 1e-308", "sigma_kg_m2 = 1e-308; must be in [1e-300, 1e+100]"},
  };
  for (const auto& c : refused) {
    SCOPED_TRACE(c.args);
    const CliRun r = Bifilar(dir, c.args);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << r.err;
    EXPECT_EQ(r.out.find("nan"), std::string::npos) << r.out;
  }
}

}  // namespace
}  // namespace bifilar
