// issue 25 items 5 and 6 through the real binary: `bifilar fit` prints one result line of at most
// ~160 characters per log (beyond the folder of the path), detail lines, then one line per
// warning (no warning squeezed into the result line, none hidden behind "+N more"), in the
// record's order; `inspect` labels its small-angle number as a whole-log estimate.
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "pipeline/records/total_uncertainty.h"
#include "pipeline/records/trace_record.h"
#include "test_support.h"

namespace bifilar {
namespace {

using test_support::Bifilar;
using test_support::QuadrotorFitConfig;
using test_support::SimulateQuadrotor;
using test_support::TempDir;
using test_support::WriteFile;

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

TEST(Console, FitPrintsOneShortResultLineThenOneLinePerWarning) {
  TempDir dir("bifilar_console");
  const std::string logs = SimulateQuadrotor(dir, 1, 5.0);  // a glitch, a footer, sway
  const std::string config = WriteFile(dir.path + "/fit.yaml", QuadrotorFitConfig());
  const std::string args =
      config + " " + logs + "/pitch_0/trial_1.csv " + logs + "/pitch_0/trial_2.csv";
  const test_support::CliRun text = Bifilar(dir, "fit " + args);
  ASSERT_EQ(text.exit_code, 0) << text.out << text.err;
  const test_support::CliRun json = Bifilar(dir, "fit --json " + args);
  ASSERT_EQ(json.exit_code, 0) << json.err;
  const nlohmann::json records = nlohmann::json::parse(json.out);
  ASSERT_EQ(records.size(), 2u);

  EXPECT_EQ(text.out.find("more warnings"), std::string::npos) << text.out;
  const std::vector<std::string> lines = Lines(text.out);
  size_t at = 0;
  for (const nlohmann::json& record : records) {
    const std::string file = record["file"].get<std::string>();
    // The result line: the record's file, then at most 160 characters after its folder.
    while (at < lines.size() && lines[at].rfind(file + ": ", 0) != 0) ++at;
    ASSERT_LT(at, lines.size()) << file << "\n" << text.out;
    const std::string& result = lines[at];
    const size_t folder = file.rfind('/') + 1;
    EXPECT_LE(result.size() - folder, 160u) << result;
    EXPECT_EQ(result.find("warning"), std::string::npos) << result;
    EXPECT_EQ(result.find("  ("), std::string::npos) << result;  // nothing squeezed in
    // Its warning lines, in the record's order, each the warning's summary.
    std::vector<std::string> expected;
    for (const auto& w : record["warnings"]) {
      if (!IsAssumedInputsWarning(w.get<std::string>()))
        expected.push_back("    warning: " + LineOfWarning(w.get<std::string>()).Text());
    }
    EXPECT_GE(expected.size(), 2u) << "the simulated log has a footer and a glitch";
    std::vector<std::string> shown;
    for (size_t k = at + 1; k < lines.size() && lines[k].rfind("    ", 0) == 0; ++k) {
      if (lines[k].rfind("    warning: ", 0) == 0) shown.push_back(lines[k]);
      EXPECT_LE(lines[k].size(), 4u + 160u + 20u) << lines[k];
    }
    EXPECT_EQ(shown, expected) << text.out;
    ++at;
  }
}

TEST(Console, InspectCallsItsSmallAngleInertiaAWholeLogEstimate) {
  TempDir dir("bifilar_console");
  const std::string logs = SimulateQuadrotor(dir, 1, 5.0);
  const std::string config = WriteFile(dir.path + "/fit.yaml", QuadrotorFitConfig());
  const test_support::CliRun r =
      Bifilar(dir, "inspect --config " + config + " " + logs + "/pitch_0/trial_1.csv");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("small-angle inertia"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("a whole-log estimate"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("corrects it"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace bifilar
