// issue 9 item 13: each bad input gets a message that names the file (and key or line) and says
// what to do; never raw bytes, a bare exception name, a glog preamble or a 300-digit range.
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "base/gzip.h"
#include "base/json_error.h"
#include "base/user_error.h"
#include "pipeline/campaign/campaign.h"
#include "pipeline/commands/ellipse_table.h"
#include "pipeline/config/config.h"
#include "test_support.h"

namespace bifilar {
namespace {

using test_support::ReadFile;
using test_support::WriteFile;

namespace fs = std::filesystem;

struct TempDir {
  std::string path;
  TempDir() {
    char tmpl[] = "/tmp/bifilar_messages_test_XXXXXX";
    path = mkdtemp(tmpl);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

// Runs bifilar; returns the exit code, *output gets stdout and stderr.
int Cli(const TempDir& dir, const std::string& args, std::string* output) {
  const std::string log = dir.path + "/cli.txt";
  const int status =
      std::system((std::string(BIFILAR_BINARY) + " " + args + " > " + log + " 2>&1").c_str());
  *output = ReadFile(log);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string ErrorOf(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}

bool Printable(const std::string& text) {
  for (unsigned char c : text) {
    if ((c < 32 && c != '\n' && c != '\t') || c >= 127) return false;
  }
  return true;
}

const char kTable[] = "pitch_deg,inertia\n0,2.8\n45,2.6\n90,2.3\n-45,2.5\n-20,2.7\n";

TEST(Messages, EllipseTableWithBomGzipOrBinary) {
  TempDir dir;
  // A BOM (spreadsheet export) is not part of 'pitch_deg'.
  WriteFile(dir.path + "/bom.csv", std::string("\xEF\xBB\xBF") + kTable);
  EXPECT_EQ(ReadEllipseTable(dir.path + "/bom.csv", DisplayUnits::kSi).size(), 5u);
  // A .csv.gz table is inflated like a .csv.gz log.
  WriteFile(dir.path + "/t.csv.gz", GzipCompress(kTable));
  EXPECT_EQ(ReadEllipseTable(dir.path + "/t.csv.gz", DisplayUnits::kSi).size(), 5u);
  // Binary: named, no raw bytes in the message.
  std::string binary = "\x01\x02\xff\xfe,\x00\x07\x80";
  binary += std::string(100, '\x9c');
  WriteFile(dir.path + "/b.csv", binary);
  std::string message = ErrorOf([&] { ReadEllipseTable(dir.path + "/b.csv", DisplayUnits::kSi); });
  EXPECT_NE(message.find("b.csv"), std::string::npos) << message;
  EXPECT_TRUE(Printable(message)) << message;
  WriteFile(dir.path + "/c.csv", "p\xc3\xa9tch,\x9c\x9d\n1,2\n");
  message = ErrorOf([&] { ReadEllipseTable(dir.path + "/c.csv", DisplayUnits::kSi); });
  EXPECT_NE(message.find("c.csv:1"), std::string::npos) << message;
  EXPECT_TRUE(Printable(message)) << message;
}

TEST(Messages, ExtremeValuesNameThePointAndNoSolverChatter) {
  TempDir dir;
  WriteFile(dir.path + "/x.csv",
            "pitch_deg,inertia,std\n0,1e300,1e-300\n45,2.6,0.01\n90,2.3,0.01\n"
            "-45,2.5,0.01\n");
  std::string out;
  EXPECT_EQ(Cli(dir, "ellipse " + dir.path + "/x.csv", &out), 2);
  EXPECT_NE(out.find("x.csv"), std::string::npos) << out;
  EXPECT_NE(out.find("check the units"), std::string::npos) << out;
  EXPECT_EQ(out.find("rank-deficient"), std::string::npos) << out;
  EXPECT_EQ(out.find("InitGoogleLogging"), std::string::npos) << out;
  // Large but representable values fit without any solver chatter.
  WriteFile(dir.path + "/y.csv",
            "pitch_deg,inertia\n0,1e90\n45,2e90\n90,3e90\n-45,1.5e90\n10,1.1e90\n");
  Cli(dir, "ellipse " + dir.path + "/y.csv", &out);
  EXPECT_EQ(out.find("InitGoogleLogging"), std::string::npos) << out;
  EXPECT_EQ(out.find("Residual and Jacobian"), std::string::npos) << out;
}

TEST(Messages, HugeStdNamesTheKeyAndJobsRangeIsShort) {
  TempDir dir;
  WriteFile(dir.path + "/c.yaml",
            "rig:\n  filar_length_m: 2\n  filar_separation_m: 1\n  mass_kg: 1\n"
            "  inertia: {inertia_kg_m2: 0.1}\n  uncertainties: {filar_separation_std_m: 1e308}\n"
            "aircraft: {mass_kg: 1}\nruns: {root: ., pattern: 'p{pitch_deg}.csv'}\n");
  const std::string message = ErrorOf([&] { LoadCampaignConfig(dir.path + "/c.yaml"); });
  EXPECT_NE(message.find("c.yaml"), std::string::npos) << message;
  EXPECT_NE(message.find("rig.uncertainties.filar_separation_std_m = 1e+308; must be < 1 (the "
                         "quantity it qualifies)"),
            std::string::npos)
      << message;
  std::string out;
  EXPECT_EQ(Cli(dir, "process " + dir.path + "/c.yaml --jobs -1", &out), 2);
  EXPECT_NE(out.find("--jobs"), std::string::npos) << out;
  EXPECT_LT(out.size(), 200u) << out;
}

TEST(Messages, RunsPatternCannotLeaveTheRoot) {
  TempDir dir;
  WriteFile(
      dir.path + "/c.yaml",
      "rig: {filar_length_m: 2, filar_separation_m: 1, mass_kg: 1, inertia: {inertia_kg_m2: 0.1}}\n"
      "aircraft: {mass_kg: 1}\nruns:\n  root: .\n  pattern: '../../../bin/{pitch_deg}*'\n");
  const std::string message = ErrorOf([&] { LoadCampaignConfig(dir.path + "/c.yaml"); });
  EXPECT_NE(message.find("c.yaml:5"), std::string::npos) << message;
  EXPECT_NE(message.find("must stay inside runs.root"), std::string::npos) << message;
}

TEST(Messages, RunsPatternHoldsThePitchOnce) {
  // It used to be checked per component only: the second one silently won.
  TempDir dir;
  WriteFile(
      dir.path + "/c.yaml",
      "rig: {filar_length_m: 2, filar_separation_m: 1, mass_kg: 1, inertia: {inertia_kg_m2: 0.1}}\n"
      "aircraft: {mass_kg: 1}\nruns:\n  root: .\n  pattern: 'p{pitch_deg}/{pitch_deg}.csv'\n");
  const std::string message = ErrorOf([&] { LoadCampaignConfig(dir.path + "/c.yaml"); });
  EXPECT_NE(message.find("c.yaml:5"), std::string::npos) << message;
  EXPECT_NE(message.find("{pitch_deg} only once"), std::string::npos) << message;
}

TEST(Messages, TareLogListedTwiceIsOneLog) {
  TempDir dir;
  WriteFile(dir.path + "/logs/p0.csv", "x");
  WriteFile(dir.path + "/tare/t1.csv", "t");
  WriteFile(dir.path + "/c.yaml",
            "rig:\n  filar_length_m: 2\n  filar_separation_m: 1\n  mass_kg: 1\n"
            "  inertia: {tare: {logs: [tare/t1.csv, tare/*.csv]}}\n"
            "aircraft: {mass_kg: 1}\nruns: {root: logs, pattern: 'p{pitch_deg}.csv'}\n");
  const std::vector<RunFile> runs = DiscoverRuns(LoadCampaignConfig(dir.path + "/c.yaml"));
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(runs[1].role, TraceRole::kTare);
  EXPECT_TRUE(runs[1].error.empty()) << runs[1].error;
}

TEST(Messages, ReportOfAMalformedResultsFileNamesIt) {
  TempDir dir;
  WriteFile(
      dir.path + "/out/results.json",
      R"({"version": "x", "traces": [{"file": "a", "window_s": ["a", "b"], "status": "ok"}]})");
  std::string out;
  EXPECT_EQ(Cli(dir, "report " + dir.path + "/out", &out), 2);
  EXPECT_NE(out.find("results.json"), std::string::npos) << out;
  // The key, in words; never the library's exception code. The trace's reader
  // (TraceRecordFromJson) names the first key it requires that this record lacks; a mistyped
  // window_s is named in tests/pipeline_report_kinds_test.cc.
  EXPECT_NE(out.find("traces[0] (a): 'message' is missing"), std::string::npos) << out;
  EXPECT_NE(out.find("rerun `bifilar process`"), std::string::npos) << out;
  EXPECT_EQ(out.find("json.exception"), std::string::npos) << out;
  // Not JSON at all: the line and column, and what to do.
  WriteFile(dir.path + "/out/results.json", "{\"traces\": 5");
  EXPECT_EQ(Cli(dir, "report " + dir.path + "/out", &out), 2);
  EXPECT_NE(out.find("results.json: not valid JSON (parse error at line"), std::string::npos)
      << out;
  EXPECT_EQ(out.find("json.exception"), std::string::npos) << out;
}

TEST(Messages, DamagedManifestNamesTheFileAndKey) {
  TempDir dir;
  WriteFile(dir.path + "/logs/p0.csv", "x");
  WriteFile(
      dir.path + "/c.yaml",
      "rig: {filar_length_m: 2, filar_separation_m: 1, mass_kg: 1, inertia: {inertia_kg_m2: 0.1}}\n"
      "aircraft: {mass_kg: 1}\nruns: {root: logs, pattern: 'p{pitch_deg}.csv'}\n");
  const std::string out_dir = dir.path + "/out";
  const std::pair<const char*, const char*> cases[] = {
      {R"({"files": [1, 2]})", "at key /files/0: type must be string"},
      {R"({"files": 5})", "no list 'files'"},
      {"\xff\xfe{", "parse error at line 1, column 1"}};
  for (const auto& [manifest, expected] : cases) {
    WriteFile(out_dir + "/.bifilar-manifest.json", manifest);
    std::string out;
    EXPECT_EQ(Cli(dir, "process " + dir.path + "/c.yaml --out " + out_dir, &out), 2) << out;
    EXPECT_NE(out.find(".bifilar-manifest.json: damaged manifest"), std::string::npos) << out;
    EXPECT_NE(out.find(expected), std::string::npos) << out;
    EXPECT_NE(out.find("choose another --out"), std::string::npos) << out;
    EXPECT_EQ(out.find("json.exception"), std::string::npos) << out;
    EXPECT_TRUE(Printable(out)) << out;
  }
}

TEST(Messages, JsonErrorsInPlainWords) {
  try {
    (void)nlohmann::json::parse(R"({"a": [1, "x"]})")["a"][1].get<double>();
    FAIL() << "no exception";
  } catch (const nlohmann::json::exception& e) {
    EXPECT_EQ(DescribeJsonError(e), "at key /a/1: type must be number, but is string");
  }
  EXPECT_EQ(DescribeJsonError(std::runtime_error("bad \xff byte")), "bad ? byte");
}

TEST(Messages, SpecNameThatIsNotUtf8IsNoJsonError) {
  TempDir dir;
  const std::string spec = dir.path + "/q\xff.yaml";
  WriteFile(spec, ReadFile(std::string(BIFILAR_SOURCE_DIR) + "/configs/simulate_quadrotor.yaml"));
  std::string out;
  EXPECT_EQ(Cli(dir, "simulate '" + spec + "' --out " + dir.path + "/sim", &out), 0) << out;
  EXPECT_EQ(out.find("json.exception"), std::string::npos) << out;
  EXPECT_TRUE(fs::exists(dir.path + "/sim/truth.json"));
}

// An allocation that fails outside any per-file handler names the command and its input, never a
// bare "std::bad_alloc". The address space is capped (ulimit -v) at 120 MB: the program starts in
// ~60 MB, and a 1e6-row ellipse table needs ~250 MB.
TEST(Messages, OutOfMemoryNamesTheInput) {
  TempDir dir;
  std::ostringstream table;
  table << "pitch_deg,inertia\n";
  for (int i = 0; i < 1000000; ++i) table << (i % 181) - 90 << ',' << 2.5 + 1e-7 * i << '\n';
  WriteFile(dir.path + "/big.csv", table.str());
  const std::string log = dir.path + "/oom.txt";
  const int status = std::system(("ulimit -v 120000; " + std::string(BIFILAR_BINARY) + " ellipse " +
                                  dir.path + "/big.csv > " + log + " 2>&1")
                                     .c_str());
  const std::string out = ReadFile(log);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 2) << out;
  EXPECT_NE(out.find("out of memory in `bifilar ellipse on " + dir.path + "/big.csv`"),
            std::string::npos)
      << out;
  EXPECT_EQ(out.find("std::bad_alloc"), std::string::npos) << out;
}

}  // namespace
}  // namespace bifilar
