// Run discovery (pipeline/campaign/run_discovery.h): the pattern rules of configs/README.md
// (`runs`) — `*` and `?` within one component, `{pitch_deg}` capturing the pitch, '[' and '\'
// literal, names starting with '.' matched, folders never matched as logs, results in path order.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>

#include "base/user_error.h"
#include "pipeline/campaign/run_discovery.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;

struct Tree {
  Tree() {
    root = fs::temp_directory_path() / ("bifilar_discovery_" + std::to_string(::getpid()));
    fs::remove_all(root);
    fs::create_directories(root);
  }
  ~Tree() { fs::remove_all(root); }
  void Add(const std::string& relative) {
    fs::create_directories((root / relative).parent_path());
    std::ofstream(root / relative) << relative;
  }
  // DiscoverRuns with runs.pattern = `pattern` under the tree, rig inertia a constant.
  std::vector<RunFile> Discover(const std::string& pattern) const {
    CampaignConfig config;
    config.file = (root / "c.yaml").string();
    config.folder = root.string();
    config.runs.root = root.string();
    config.runs.pattern = pattern;
    config.rig_inertia.kind = RigInertiaSpec::Kind::kValue;
    return DiscoverRuns(config);
  }
  fs::path root;
};

std::vector<std::string> Displays(const std::vector<RunFile>& runs) {
  std::vector<std::string> names;
  for (const RunFile& run : runs) names.push_back(run.display);
  return names;
}

TEST(RunDiscovery, StarAndQuestionMarkStayWithinOneComponent) {
  Tree t;
  for (const char* f : {"pitch_10/trial_1.csv", "pitch_10/trial_2.csv", "pitch_10/deep/trial_3.csv",
                        "pitch_-5/trial_1.csv", "pitch_10/notes.txt"}) {
    t.Add(f);
  }
  const std::vector<RunFile> runs = t.Discover("pitch_{pitch_deg}/trial_?.csv");
  EXPECT_EQ(Displays(runs),
            (std::vector<std::string>{"pitch_-5/trial_1.csv", "pitch_10/trial_1.csv",
                                      "pitch_10/trial_2.csv"}));
  ASSERT_EQ(runs.size(), 3u);
  EXPECT_EQ(*runs[0].pitch_nominal_deg, -5.0);
  EXPECT_EQ(*runs[2].pitch_nominal_deg, 10.0);
  // `**` is two stars in one component, not "any depth".
  EXPECT_EQ(t.Discover("pitch_{pitch_deg}/**.csv").size(), 3u);
}

TEST(RunDiscovery, PitchSpellingsAndUnreadablePitches) {
  Tree t;
  for (const char* f : {"m80.csv", "p10.csv", "+5.csv", "12.5.csv", "abc.csv", "200.csv"}) t.Add(f);
  std::map<std::string, RunFile> by_name;
  for (const RunFile& run : t.Discover("{pitch_deg}.csv")) by_name[run.display] = run;
  EXPECT_EQ(*by_name["m80.csv"].pitch_nominal_deg, -80.0);
  EXPECT_EQ(*by_name["p10.csv"].pitch_nominal_deg, 10.0);
  EXPECT_EQ(*by_name["+5.csv"].pitch_nominal_deg, 5.0);
  EXPECT_EQ(*by_name["12.5.csv"].pitch_nominal_deg, 12.5);
  for (const char* bad : {"abc.csv", "200.csv"}) {
    EXPECT_FALSE(by_name[bad].pitch_nominal_deg) << bad;
    EXPECT_NE(by_name[bad].error.find("cannot read the pitch from the path"), std::string::npos)
        << by_name[bad].error;
  }
}

TEST(RunDiscovery, CaptureIsTheShortestTextBeforeTheRest) {
  Tree t;
  t.Add("p10_a.csv");
  t.Add("p20_trial.csv");
  const std::vector<RunFile> runs = t.Discover("p{pitch_deg}_*.csv");
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(*runs[0].pitch_nominal_deg, 10.0);
  EXPECT_EQ(*runs[1].pitch_nominal_deg, 20.0);
}

TEST(RunDiscovery, BracketsAndBackslashesAreLiteralDotFilesMatchFoldersDoNot) {
  Tree t;
  t.Add("p0/[1].csv");
  t.Add("p0/1.csv");
  t.Add("p0/.hidden.csv");
  fs::create_directories(t.root / "p0" / "folder.csv");
  EXPECT_EQ(Displays(t.Discover("p{pitch_deg}/[1]*.csv")),
            (std::vector<std::string>{"p0/[1].csv"}));
  EXPECT_EQ(Displays(t.Discover("p{pitch_deg}/*.csv")),
            (std::vector<std::string>{"p0/.hidden.csv", "p0/1.csv", "p0/[1].csv"}));
}

TEST(RunDiscovery, BadPlaceholdersAndNoMatchAreConfigErrors) {
  Tree t;
  t.Add("p0/a.csv");
  auto error_of = [&](const std::string& pattern) {
    try {
      t.Discover(pattern);
    } catch (const UserError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error_of("p{pitch}/*.csv").find("unknown placeholder"), std::string::npos);
  EXPECT_NE(error_of("{pitch_deg}{pitch_deg}/*.csv").find("only once"), std::string::npos);
  EXPECT_NE(error_of("q*/*.csv").find("no file matches"), std::string::npos);
}

}  // namespace
}  // namespace bifilar
