// `bifilar fit` against hostile input (issue 23 item 6), end to end with the real binary on the
// sample campaign's logs: identical data given to --repeats is one repeat (the copies named and
// dropped), --plot names are unique and one per log, and fit.windows is read as `process` reads
// it (matched however the log's path is written; an entry naming no log is an error).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <string>

#include "pipeline/trace/repeats.h"
#include "test_support.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test_support::ReadFile;
using test_support::TempDir;
using test_support::WriteFile;

const std::string kSource = BIFILAR_SOURCE_DIR;
const std::string kLogs = kSource + "/sample_runs/prandtl_d/logs";

// The sample campaign's config with runs.root absolute, plus `extra_fit` lines under `fit:`.
std::string WriteConfig(const TempDir& dir, const std::string& extra_fit = "") {
  std::string text = ReadFile(kSource + "/configs/prandtl_d.yaml");
  for (size_t at = text.find("../sample_runs"); at != std::string::npos;
       at = text.find("../sample_runs", at)) {
    text.replace(at, 2, kSource);
  }
  const std::string fit = "  max_amplitude_deg: 30\n";
  const size_t at = text.find(fit);
  EXPECT_NE(at, std::string::npos);
  text.insert(at + fit.size(), extra_fit);
  return WriteFile(dir.path + "/c.yaml", text);
}

// `bifilar ARGS` run in `cwd`, output in dir.
test_support::CliRun RunIn(const TempDir& dir, const std::string& cwd, const std::string& args) {
  const std::string out = dir.path + "/stdout.txt", err = dir.path + "/stderr.txt";
  const int status = std::system(
      ("cd '" + cwd + "' && " + std::string(BIFILAR_BINARY) + " " + args + " >" + out + " 2>" + err)
          .c_str());
  test_support::CliRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = ReadFile(out);
  r.err = ReadFile(err);
  return r;
}

void CopyLog(const std::string& from, const std::string& to) {
  fs::create_directories(fs::path(to).parent_path());
  fs::copy_file(from, to, fs::copy_options::overwrite_existing);
}

TEST(FitCli, IdenticalLogsAreOneRepeatAndTheCopiesAreNamed) {
  TempDir dir("bifilar_fit_cli");
  const std::string config = WriteConfig(dir);
  // One swing three times: the same file twice and a byte-identical copy under another name.
  CopyLog(kLogs + "/pitch_0/trial_1.csv.gz", dir.path + "/r/swing-1.csv.gz");
  CopyLog(kLogs + "/pitch_0/trial_1.csv.gz", dir.path + "/r/swing-2.csv.gz");
  CopyLog(kLogs + "/pitch_0/trial_2.csv.gz", dir.path + "/r/swing-3.csv.gz");
  const test_support::CliRun same = RunIn(
      dir, dir.path, "fit c.yaml r/swing-1.csv.gz r/swing-1.csv.gz r/swing-2.csv.gz --repeats");
  ASSERT_EQ(same.exit_code, 0) << same.err;
  EXPECT_NE(same.out.find("warning: r/swing-1.csv.gz: given again: one swing is one repeat"),
            std::string::npos)
      << same.out;
  EXPECT_NE(same.out.find("warning: r/swing-2.csv.gz: the same bytes as r/swing-1.csv.gz"),
            std::string::npos)
      << same.out;
  // Never "mean of 3, Q = 0.0": one usable repeat, nothing combined.
  EXPECT_EQ(same.out.find("mean of"), std::string::npos) << same.out;
  EXPECT_NE(same.out.find("1 usable repeat(s) of 1: nothing to combine"), std::string::npos)
      << same.out;

  // With a genuine second swing: two repeats are combined, the copy is listed in the JSON.
  const test_support::CliRun json_run =
      RunIn(dir, dir.path,
            "fit c.yaml r/swing-1.csv.gz r/swing-2.csv.gz r/swing-3.csv.gz --repeats --json");
  ASSERT_EQ(json_run.exit_code, 0) << json_run.err;
  const json j = json::parse(json_run.out);
  ASSERT_EQ(j["traces"].size(), 2u);
  ASSERT_EQ(j["repeats"].size(), 1u);
  EXPECT_EQ(j["repeats"][0]["n_used"], 2);
  ASSERT_EQ(j["identical_logs_dropped"].size(), 1u);
  EXPECT_EQ(j["identical_logs_dropped"][0]["file"], "r/swing-2.csv.gz");
  EXPECT_EQ(j["identical_logs_dropped"][0]["same_as"], "r/swing-1.csv.gz");
}

TEST(FitCli, DropIdenticalLogsComparesBytesNotNames) {
  TempDir dir("bifilar_fit_cli");
  const std::string a = WriteFile(dir.path + "/a-1.csv", "t,w\n0,1\n");
  const std::string b = WriteFile(dir.path + "/a-2.csv", "t,w\n0,1\n");  // same bytes
  const std::string c = WriteFile(dir.path + "/a-3.csv", "t,w\n0,2\n");  // same size, differs
  const std::string d = WriteFile(dir.path + "/a-4.csv", "t,w\n0,1\n\n");
  const std::string dot = dir.path + "/./a-1.csv";  // the same file written otherwise
  const std::string missing = dir.path + "/a-5.csv";
  // Not logs of this format (no gx column): compared by their bytes.
  const ImuFormat format;
  const std::vector<IdenticalLog> same =
      FindIdenticalLogs({a, b, c, d, dot, missing, missing}, format, ImuLogOptions());
  std::vector<int> first;
  for (const IdenticalLog& s : same) first.push_back(s.first);
  EXPECT_EQ(first, (std::vector<int>{-1, 0, -1, -1, 0, -1, -1}));
  const DistinctLogs distinct = DropIdenticalLogs({a, b, c, dot}, format, ImuLogOptions());
  EXPECT_EQ(distinct.kept, (std::vector<std::string>{a, c}));
  ASSERT_EQ(distinct.warnings.size(), 2u);
  EXPECT_NE(distinct.warnings[0].find("the same bytes as " + a), std::string::npos);
  EXPECT_NE(distinct.warnings[1].find("the same file as " + a), std::string::npos);
}

// issue 33 item 5: the same swing saved with CRLF line ends, an extra newline or a comment line
// above the header is the same repeat (judged on the samples), named as such; a log whose
// samples differ in one digit is not.
TEST(FitCli, DropIdenticalLogsComparesSamplesNotBytes) {
  TempDir dir("bifilar_fit_cli");
  const std::string body = "0,0.1,0.2,0.3\n0.01,0.11,0.21,0.31\n0.02,0.12,0.22,0.32\n";
  const std::string a = WriteFile(dir.path + "/s-1.csv", "t,gx,gy,gz\n" + body);
  std::string crlf = "t,gx,gy,gz\r\n" + body;
  for (size_t at = crlf.find("\n", crlf.find("\r\n") + 2); at != std::string::npos;
       at = crlf.find("\n", at + 2)) {
    crlf.replace(at, 1, "\r\n");
  }
  const std::string b = WriteFile(dir.path + "/s-2.csv", crlf);
  const std::string c = WriteFile(dir.path + "/s-3.csv", "t,gx,gy,gz\n" + body + "\n");
  const std::string d = WriteFile(dir.path + "/s-4.csv", "# saved again\nt,gx,gy,gz\n" + body);
  const std::string e =
      WriteFile(dir.path + "/s-5.csv",
                "t,gx,gy,gz\n0,0.1,0.2,0.3\n0.01,0.11,0.21,0.31\n0.02,0.12,0.22,0.33\n");
  ImuFormat format;
  format.accel_columns = {"", "", ""};
  const DistinctLogs distinct = DropIdenticalLogs({a, b, c, d, e}, format, ImuLogOptions());
  EXPECT_EQ(distinct.kept, (std::vector<std::string>{a, e}));
  ASSERT_EQ(distinct.warnings.size(), 3u);
  for (const std::string& w : distinct.warnings) {
    EXPECT_NE(w.find(": the same samples as " + a +
                     " (the files differ only in what the reader "
                     "skips"),
              std::string::npos)
        << w;
  }
  EXPECT_EQ(distinct.warnings[0].rfind(b + ": ", 0), 0u) << distinct.warnings[0];
}

// The figure files a run's "figures:" lines name, one set per log line.
std::vector<std::string> FigureLines(const std::string& out) {
  std::vector<std::string> lines;
  const std::regex figures("\n    figures: ([^\n]*)");
  for (auto it = std::sregex_iterator(out.begin(), out.end(), figures);
       it != std::sregex_iterator(); ++it) {
    lines.push_back((*it)[1]);
  }
  return lines;
}

TEST(FitCli, PlotNamesAreUniqueAndOnePerLog) {
  TempDir dir("bifilar_fit_cli");
  WriteConfig(dir);
  // x/t, y/t and x_t: "x_t" was both x/t's name (folder in front) and x_t's own.
  CopyLog(kLogs + "/pitch_0/trial_1.csv.gz", dir.path + "/x/t.csv.gz");
  CopyLog(kLogs + "/pitch_10/trial_1.csv.gz", dir.path + "/y/t.csv.gz");
  CopyLog(kLogs + "/pitch_20/trial_1.csv.gz", dir.path + "/x_t.csv.gz");
  CopyLog(kLogs + "/pitch_30/trial_1.csv.gz", dir.path + "/a.csv.gz");
  CopyLog(kLogs + "/pitch_-10/trial_1.csv.gz", dir.path + "/a_sweep.csv.gz");  // a's sweep name
  const test_support::CliRun r = RunIn(
      dir, dir.path,
      "fit c.yaml x/t.csv.gz y/t.csv.gz x_t.csv.gz ./x/t.csv.gz a.csv.gz a_sweep.csv.gz --plot p");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<std::string> lines = FigureLines(r.out);
  ASSERT_EQ(lines.size(), 6u) << r.out;
  EXPECT_EQ(lines[0], lines[3]);  // x/t.csv.gz and ./x/t.csv.gz: one log, one name
  std::set<std::string> files;
  for (size_t i : {0, 1, 2, 4, 5}) {
    std::istringstream names(lines[i]);
    std::string name;
    while (names >> name) {
      EXPECT_TRUE(files.insert(name).second) << name << " is named twice:\n" << r.out;
      EXPECT_TRUE(fs::exists(dir.path + "/" + name)) << name;
    }
  }
  EXPECT_EQ(files.size(), 5u * 4u);  // fit and sweep, svg and png, for five distinct logs
  // A name unique in the run stays readable: y/t is y_t.
  EXPECT_EQ(lines[1], "p/y_t.svg p/y_t.png p/y_t_sweep.svg p/y_t_sweep.png");
  // Each figure shows its own log: the measured samples of x/t and x_t differ.
  const std::string xt = lines[0].substr(0, lines[0].find(' '));
  const std::string x_t = lines[2].substr(0, lines[2].find(' '));
  EXPECT_NE(ReadFile(dir.path + "/" + xt), ReadFile(dir.path + "/" + x_t));
}

TEST(FitCli, FitWindowsAreReadAsProcessReadsThem) {
  TempDir dir("bifilar_fit_cli");
  WriteConfig(dir, "  windows:\n    pitch_0/trial_1.csv.gz: [5, 20]\n");
  // The log given relative to the working folder, to the logs folder, and absolute: the entry
  // (relative to runs.root) applies every time.
  const struct {
    std::string cwd, log;
  } runs[] = {{kSource, "sample_runs/prandtl_d/logs/pitch_0/trial_1.csv.gz"},
              {kLogs, "./pitch_0/trial_1.csv.gz"},
              {dir.path, kLogs + "/pitch_0/../pitch_0/trial_1.csv.gz"}};
  for (const auto& run : runs) {
    SCOPED_TRACE(run.log);
    const test_support::CliRun r =
        RunIn(dir, run.cwd, "fit " + dir.path + "/c.yaml " + run.log + " --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const json j = json::parse(r.out);
    EXPECT_DOUBLE_EQ(j[0]["window_s"][0].get<double>(), 5.0) << r.out;
    EXPECT_DOUBLE_EQ(j[0]["window_s"][1].get<double>(), 20.0) << r.out;
  }
  // Another log: no entry, the detected window.
  const test_support::CliRun other =
      RunIn(dir, kLogs, "fit " + dir.path + "/c.yaml pitch_0/trial_2.csv.gz --json");
  ASSERT_EQ(other.exit_code, 0) << other.err;
  EXPECT_NE(json::parse(other.out)[0]["window_s"][0].get<double>(), 5.0);

  // An entry naming no log: an error before any fit, as `process` says.
  WriteConfig(dir, "  windows:\n    pitch_0/nothere.csv: [5, 20]\n");
  const test_support::CliRun bad =
      RunIn(dir, kLogs, "fit " + dir.path + "/c.yaml pitch_0/trial_1.csv.gz");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("'fit.windows.pitch_0/nothere.csv' names no log that exists"),
            std::string::npos)
      << bad.err;
  EXPECT_TRUE(bad.out.empty()) << bad.out;
}

}  // namespace
}  // namespace bifilar
