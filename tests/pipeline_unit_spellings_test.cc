// The unit facts and enumeration names that help texts, figures and messages spelled out by hand
// now come from their one definition (base/units.h, the enum tables, figures/figure.h), and say
// what they said: the default gravity in the help of simulate, init and plan --rig is
// standard gravity, printed 9.80665; the integrator and model lists are the tables' texts; the
// PLplot inertia unit of every figure is one function of the display units.
#include <string>

#include <gtest/gtest.h>

#include "base/text_format.h"
#include "base/units.h"
#include "base/user_error.h"
#include "pendulum/integrator.h"
#include "pendulum/model.h"
#include "pipeline/commands/simulate_spec.h"
#include "pipeline/figures/ellipse_plot.h"
#include "pipeline/figures/figure.h"
#include "pipeline/figures/sweep_plot.h"
#include "pipeline/figures/tensor_plot.h"
#include "pipeline/figures/trace_plot.h"
#include "tests/test_support.h"

namespace bifilar {
namespace {

using test_support::Bifilar;
using test_support::CliRun;
using test_support::Contains;
using test_support::ErrorOf;
using test_support::TempDir;

TEST(UnitSpellings, InertiaUnitPlotLabelIsThePlplotTextOfTheDisplayUnit) {
  EXPECT_STREQ(InertiaUnitPlotLabel(DisplayUnits::kSi), "kg m#u2#d");
  EXPECT_STREQ(InertiaUnitPlotLabel(DisplayUnits::kImperial), "slug ft#u2#d");
  // Every figure's default is the SI one.
  EXPECT_EQ(EllipsePlotOptions().unit_label, "kg m#u2#d");
  EXPECT_EQ(SweepPlotOptions().unit_label, "kg m#u2#d");
  EXPECT_EQ(TensorPlotOptions().unit_label, "kg m#u2#d");
  EXPECT_EQ(TracePlotOptions().unit_label, "kg m#u2#d");
}

TEST(UnitSpellings, HelpTextsPrintStandardGravityAndTheIntegratorTable) {
  // base_units_test pins kStandardGravityMps2 to its value; printed with %g it reads in full.
  const std::string g0 = Fmt("%g", kStandardGravityMps2);
  ASSERT_EQ(g0.size(), 7u);  // "9.80665": no digit lost
  TempDir dir("bifilar_unit_spellings");
  const CliRun simulate = Bifilar(dir, "simulate --help");
  EXPECT_TRUE(Contains(simulate.out, "local gravity (m/s^2), default " + g0)) << simulate.out;
  const CliRun init = Bifilar(dir, "init --help");
  EXPECT_TRUE(Contains(init.out, "the range a config accepts; default " + g0)) << init.out;
  const CliRun plan = Bifilar(dir, "plan --help");
  EXPECT_TRUE(Contains(plan.out, "with --rig: local g, m/s^2 (" + g0 + ")")) << plan.out;
  const CliRun process = Bifilar(dir, "process --help");
  EXPECT_TRUE(Contains(process.out,
                       "ODE solver of the fits: rk853 or cvodes; overrides "
                       "fit.integrator"))
      << process.out;
  EXPECT_EQ(IntegratorMethodAllowedValues(), "rk853 or cvodes");
}

TEST(UnitSpellings, SimulateNamesTheModelsOfTheTable) {
  SimulateCommandOptions options;
  options.model = "exact";
  const std::string why = ErrorOf([&] { RunSimulate(options); });
  EXPECT_TRUE(Contains(why, "--model: unknown model 'exact'; allowed full, jardin or linear"))
      << why;
  EXPECT_EQ(PendulumModelAllowedValues(), "full, jardin or linear");
}

}  // namespace
}  // namespace bifilar
