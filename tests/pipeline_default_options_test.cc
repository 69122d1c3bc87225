// Every options struct of the code base passes its own Check at its defaults (issue 36): a default
// outside the struct's own bounds would make every caller that keeps it fail, or show that the
// bound and the default disagree. The structs whose defaults are placeholders for values the
// caller must give (a geometry, a mass, an output folder) are listed apart, and their default
// must fail. The list is complete: every struct in base/, pendulum/, fit/ and pipeline/ headers
// that declares a `bool Check(` is in one of the two lists.
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <regex>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "fit/block_mean.h"
#include "fit/ellipse.h"
#include "fit/glitch.h"
#include "fit/swing_axis.h"
#include "fit/tensor.h"
#include "fit/tensor_plan.h"
#include "fit/trace_fit.h"
#include "fit/trace_options.h"
#include "fit/window.h"
#include "pendulum/integrator.h"
#include "pendulum/model.h"
#include "pendulum/simulate.h"
#include "pipeline/campaign/campaign.h"
#include "pipeline/commands/rig_plan.h"
#include "pipeline/config/config.h"
#include "pipeline/config/config_template.h"
#include "pipeline/live/mavlink.h"
#include "pipeline/logs/imu_format.h"
#include "pipeline/logs/imu_log_options.h"
#include "pipeline/logs/imu_log_writer.h"
#include "pipeline/report/export.h"
#include "pipeline/watch/watch_engine.h"

namespace bifilar {
namespace {

// Check of a default-constructed T: true, or false with *why.
template <class T>
bool DefaultChecks(std::string* why) {
  return T().Check(why);
}
#define BIFILAR_OPTIONS(T) \
  { #T, &DefaultChecks < T> }

using Checker = bool (*)(std::string*);

// Options: every default is a working setting.
const std::map<std::string, Checker> kOptions = {
    BIFILAR_OPTIONS(WindowOptions),
    BIFILAR_OPTIONS(AmplitudeBandOptions),
    BIFILAR_OPTIONS(EllipseOptions),
    BIFILAR_OPTIONS(BlockMeanOptions),
    BIFILAR_OPTIONS(TensorOptions),
    BIFILAR_OPTIONS(SwingAxisOptions),
    BIFILAR_OPTIONS(TraceFitOptions),
    BIFILAR_OPTIONS(TraceQualityOptions),
    BIFILAR_OPTIONS(AmplitudeSweepOptions),
    BIFILAR_OPTIONS(GlitchOptions),
    BIFILAR_OPTIONS(IntegratorOptions),
    BIFILAR_OPTIONS(TimelineOptions),
    BIFILAR_OPTIONS(SensorOptions),
    BIFILAR_OPTIONS(SimulationOptions),
    BIFILAR_OPTIONS(FitConfig),
    BIFILAR_OPTIONS(EllipseConfig),
    BIFILAR_OPTIONS(ImuFormat),
    BIFILAR_OPTIONS(ImuLogWriteOptions),
    BIFILAR_OPTIONS(ImuLogOptions),
    {"MavlinkDecoderOptions", &DefaultChecks<live::MavlinkDecoderOptions>},
    BIFILAR_OPTIONS(WatchEngineOptions),
};

// Values the caller must give: their defaults (zeros, empty) are refused by their Check.
const std::map<std::string, Checker> kRequiredValues = {
    BIFILAR_OPTIONS(RigGeometry),            // L, D, mass: the rig's own
    BIFILAR_OPTIONS(PendulumParams),         // I > 0: a model's, not a setting
    BIFILAR_OPTIONS(TraceSetup),             // a trace's geometry and truth
    BIFILAR_OPTIONS(AircraftTruth),          // a simulated aircraft's moments
    BIFILAR_OPTIONS(RigTruth),               // a simulated rig
    BIFILAR_OPTIONS(CampaignSpec),           // a simulated campaign's rig and aircraft
    BIFILAR_OPTIONS(CampaignConfig),         // the config file's rig
    BIFILAR_OPTIONS(StartingConfigOptions),  // `init --rig L,D,MASS`
    BIFILAR_OPTIONS(TensorPlanOptions),      // `plan`: the per-swing std of the rig
    BIFILAR_OPTIONS(EllipsePlanOptions),     // `plan`: the per-swing std of the rig
    BIFILAR_OPTIONS(RigPlanOptions),         // `plan --rig`: the inertia or radius of gyration
    BIFILAR_OPTIONS(CampaignOptions),        // `process`: the output folder
    BIFILAR_OPTIONS(ExportOptions),          // `export`: the results.json to read
};
#undef BIFILAR_OPTIONS

TEST(DefaultOptions, EveryDefaultOptionsStructPassesItsCheck) {
  for (const auto& [name, check] : kOptions) {
    std::string why;
    EXPECT_TRUE(check(&why)) << name << "(): " << why;
  }
  for (const auto& [name, check] : kRequiredValues) {
    std::string why;
    EXPECT_FALSE(check(&why)) << name << "() passes its Check: move it to kOptions";
    EXPECT_FALSE(why.empty()) << name;
  }
}

// The structs that declare `bool Check(` in the library headers: the last `struct X` or
// `class X` opened before each declaration.
std::set<std::string> StructsWithCheck() {
  std::set<std::string> names;
  const std::regex open(R"(^\s*(struct|class) (\w+)[^;]*$)"), check(R"(^\s*bool Check\()");
  for (const char* folder : {"base", "pendulum", "fit", "pipeline"}) {
    const std::filesystem::path root = std::filesystem::path(BIFILAR_SOURCE_DIR) / folder;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(root)) {
      if (entry.path().extension() != ".h") continue;
      std::ifstream in(entry.path());
      std::string current;
      std::smatch m;
      for (std::string line; std::getline(in, line);) {
        if (std::regex_search(line, m, open)) current = m[2];
        if (std::regex_search(line, check) && !current.empty()) names.insert(current);
      }
    }
  }
  return names;
}

TEST(DefaultOptions, EveryStructWithACheckIsListed) {
  const std::set<std::string> found = StructsWithCheck();
  EXPECT_GE(found.size(), kOptions.size());
  for (const std::string& name : found) {
    EXPECT_TRUE(kOptions.count(name) || kRequiredValues.count(name))
        << name << " declares Check but is in neither list of this test";
  }
}

}  // namespace
}  // namespace bifilar
