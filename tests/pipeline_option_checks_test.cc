// Issue 24 item 6, as a user meets it: a bad value given on the command line reaches the options
// struct's Check and comes back as one line naming the field, the value and the bound, in the
// one format of base/option_check.h ("<field> = <value>; must be <allowed>").
#include <algorithm>
#include <string>

#include <gtest/gtest.h>

#include "pipeline/commands/rig_plan.h"
#include "test_support.h"

namespace bifilar {
namespace {

using test_support::Bifilar;
using test_support::CliRun;
using test_support::TempDir;

// Runs `args`, expects exit code 2 and one error line that holds `expect`.
void ExpectOneLineError(const TempDir& dir, const std::string& args, const std::string& expect) {
  SCOPED_TRACE(args);
  const CliRun r = Bifilar(dir, args);
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find(expect), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

// SimulationOptions and TraceSetup through `bifilar simulate --trace`.
TEST(OptionChecks, SimulateNamesFieldValueAndBound) {
  TempDir dir("bifilar_option_checks");
  const std::string trace =
      "simulate --trace " + dir.path + "/t.csv --inertia-kg-m2 1 --mass-kg 6 ";
  ExpectOneLineError(dir, trace + "-L 2 -D 0.9 --amplitude-deg 95",
                     "simulate: amplitude_deg = 95; must be 0 < |amplitude_deg| < 89");
  ExpectOneLineError(dir, trace + "-L 2 -D 0.9 --pitch-deg 120",
                     "simulate: pitch_deg = 120; must be in [-90, 90]");
  // A cross-field bound names both fields and both values.
  ExpectOneLineError(dir, trace + "-L 2 -D 2.5",
                     "simulate: filar_separation_m (D) = 2.5; must be < filar_length_m (L) = 2");
  // A spec: SensorOptions' cross-field bound, at the key's line.
  const std::string spec =
      test_support::WriteFile(dir.path + "/s.yaml",
                              "geometry: {filar_length_m: 2, filar_separation_m: 0.9}\n"
                              "trace: {inertia_kg_m2: 1, mass_kg: 6}\n"
                              "sensor: {sample_rate_hz: 100, rocking_frequency_hz: 40}\n");
  ExpectOneLineError(dir, "simulate " + spec + " --out " + dir.path + "/o",
                     "s.yaml:3:53: sensor.rocking_frequency_hz = 40; must be in [0, 25]");
}

// RigPlanOptions through `bifilar plan --rig`: one bound, a cross-field bound, an interval.
TEST(OptionChecks, PlanRigNamesFieldValueAndBound) {
  TempDir dir("bifilar_option_checks");
  const std::string base = "plan --rig --inertia 1e-5 --target-percent 1 ";
  ExpectOneLineError(dir, base + "--mass -1 --max-length 0.5 --max-separation 0.03",
                     "plan --rig: --mass = -1; must be finite and > 0");
  ExpectOneLineError(dir, base + "--mass 1 --max-length 0.5 --max-separation 0.6",
                     "plan --rig: --max-separation = 0.6; must be < --max-length = 0.5");
  ExpectOneLineError(dir, base + "--mass 1 --max-length 0.5 --max-separation 0.03 --gravity 200",
                     "plan --rig: --gravity = 200; must be in (0, 100]");
  // The same struct built in code.
  RigPlanOptions o;
  o.mass_kg = 1;
  o.inertia_kg_m2 = 1e-5;
  o.max_length_m = 0.5;
  o.max_separation_m = 0.03;
  o.target_percent = 1;
  std::string why;
  EXPECT_TRUE(o.Check(&why)) << why;
  o.imu_rate_hz = 2;
  EXPECT_FALSE(o.Check(&why));
  EXPECT_EQ(why, "plan --rig: --imu-rate = 2; must be in [5, 10000]");
  o.imu_rate_hz = 100;
  o.radius_of_gyration_m = 0.1;
  EXPECT_FALSE(o.Check(&why));
  EXPECT_EQ(why, "plan --rig: --inertia and --radius-of-gyration (given) = 2; must be exactly one");
}

// TensorPlanOptions through `bifilar plan --tensor`.
TEST(OptionChecks, PlanTensorNamesFieldValueAndBound) {
  TempDir dir("bifilar_option_checks");
  ExpectOneLineError(dir, "plan --tensor --pitch=-95:0 --sigma 0.1",
                     "plan --tensor: --pitch: pitch_min_deg = -95; must be in [-90, 90]");
  ExpectOneLineError(dir, "plan --tensor --roll=-45:45 --sigma 1e200",
                     "plan --tensor: --sigma: sigma_kg_m2 = 1e+200; must be in [0, 1e+100]");
  // A guess that is no tensor: the flags that set it, the derived value to 6 digits.
  ExpectOneLineError(dir, "plan --tensor --sigma 0.1 --ixx 1 --iyy 1 --izz 1 --ixy 5",
                     "plan --tensor: --ixx ... --iyz: smallest principal moment of guess_kg_m2 = "
                     "-4; must be > 0 (check the products' signs and sizes)");
}

// Issue 33 item 5: `plan --rig --repeat-scatter 1e308` printed "inf %"; a scatter between
// repeats beyond 50 % of I is refused, naming the flag and the interval.
TEST(OptionChecks, PlanRigRefusesAnOutOfRangeRepeatScatter) {
  TempDir dir("bifilar_option_checks");
  ExpectOneLineError(dir,
                     "plan --rig --inertia 1e-5 --target-percent 1 --mass 1 --max-length 0.5 "
                     "--max-separation 0.03 --repeat-scatter 1e308",
                     "plan --rig: --repeat-scatter = 1e+308; must be in [0, 50]");
}

}  // namespace
}  // namespace bifilar
