// The output folder (pipeline/store/output_set.h): the user's files are never removed, one run at a
// time, a mixed set is detected. A fake trace fit (the "log" holds its total inertia) keeps the
// runs instant.
#include "base/units.h"
#include "pipeline/store/output_set.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "base/user_error.h"
#include "pipeline/campaign/campaign.h"
#include "pipeline/report/report.h"
#include "test_support.h"

namespace bifilar {
namespace {

using test_support::ReadFile;
using test_support::WriteFile;

namespace fs = std::filesystem;

// Six angles, two trials each, of I(theta) = 3 cos^2 + 2 sin^2 + 0.1 sin 2theta plus a 0.5 rig.
struct Campaign {
  std::string dir;
  std::string out;

  Campaign() {
    char tmpl[] = "/tmp/bifilar_output_set_test_XXXXXX";
    dir = mkdtemp(tmpl);
    out = dir + "/out";
    for (int pitch : {-60, -30, 0, 30, 60, 90}) {
      for (int k = 1; k <= 2; ++k) SetLog(pitch, k, 0.0);
    }
    WriteFile(dir + "/campaign.yaml",
              "rig: {filar_length_m: 2.0, filar_separation_m: 1.0, mass_kg: 2.0,\n"
              "      inertia: {inertia_kg_m2: 0.5}}\n"
              "aircraft: {mass_kg: 10}\n"
              "runs: {root: logs, pattern: \"pitch_{pitch_deg}/*.csv\"}\n");
  }
  ~Campaign() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }

  void SetLog(int pitch, int trial, double offset) {
    const double t = pitch * kRadPerDeg;
    std::ostringstream text;
    text.precision(17);
    text << "I="
         << 3 * std::cos(t) * std::cos(t) + 2 * std::sin(t) * std::sin(t) + 0.1 * std::sin(2 * t) +
                0.5 + (trial == 1 ? 1e-3 : -1e-3) + offset
         << "\n";
    WriteFile(
        dir + "/logs/pitch_" + std::to_string(pitch) + "/trial_" + std::to_string(trial) + ".csv",
        text.str());
  }

  std::atomic<int> calls{0};

  CampaignResult Run() {
    CampaignOptions o;
    o.out_dir = out;
    o.jobs = 2;
    o.figures = false;
    o.fit_function = [this](const CampaignConfig&, const std::string& path,
                            const TraceProcessOptions& options) {
      ++calls;  // atomic: the fits run on two threads
      TraceRecord r;
      r.file = options.display_name;
      r.status = TraceStatus::kOk;
      r.inertia_total_kg_m2 = std::stod(ReadFile(path).substr(2));
      r.inertia_total_std_kg_m2 = 1e-4;
      r.model = "full";
      return r;
    };
    return RunCampaign(LoadCampaignConfig(dir + "/campaign.yaml"), o);
  }

  void AppendConfig(const std::string& yaml) {
    WriteFile(dir + "/campaign.yaml", ReadFile(dir + "/campaign.yaml") + yaml);
  }

  size_t CacheFiles() const {
    size_t n = 0;
    for (const auto& entry : fs::directory_iterator(out + "/cache")) n += entry.is_regular_file();
    return n;
  }
};

// issue 9 item 1: `process` removed every unused file in OUT/figures/ and OUT/cache/.
TEST(OutputSet, UserFilesAreNeverRemovedAndTheFolderIsRefused) {
  Campaign c;
  WriteFile(c.out + "/figures/my_plot.png", "mine");
  try {
    c.Run();
    ADD_FAILURE() << "a folder holding the user's file was used";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("figures/my_plot.png"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("did not write"), std::string::npos) << e.what();
  }
  EXPECT_EQ(ReadFile(c.out + "/figures/my_plot.png"), "mine");

  // A folder of bifilar's own: its stale entries are removed, a file added later is refused.
  fs::remove(c.out + "/figures/my_plot.png");
  c.Run();
  EXPECT_EQ(c.CacheFiles(), 12u);
  c.SetLog(0, 1, 0.01);  // one log changed: its old cache entry is stale and removed
  c.Run();
  EXPECT_EQ(c.CacheFiles(), 12u);
  WriteFile(c.out + "/cache/notes.txt", "mine too");
  EXPECT_THROW(c.Run(), UserError);
  EXPECT_EQ(ReadFile(c.out + "/cache/notes.txt"), "mine too");
}

// A folder written before the manifest existed is adopted through its results.json.
TEST(OutputSet, FolderFromBeforeTheManifestIsAdopted) {
  Campaign c;
  c.Run();
  fs::remove(c.out + "/" + OutputManifest::kFileName);
  const CampaignResult again = c.Run();
  EXPECT_EQ(again.summary.n_reused, 12);
}

// issue 9 item 2: two runs on one OUT interleaved and left cache/ and figures/ empty.
TEST(OutputSet, SecondRunOnTheSameFolderFailsNamingTheHolder) {
  Campaign c;
  fs::create_directories(c.out);
  // Another process's lock, as `bifilar` takes it: flock on OUT/.bifilar.lock.
  const std::string lock_path = c.out + "/.bifilar.lock";
  const int fd = ::open(lock_path.c_str(), O_RDWR | O_CREAT, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
  const std::string holder = "pid 4242, started 2026-01-01 00:00:00 UTC\n";
  ASSERT_EQ(::write(fd, holder.data(), holder.size()), static_cast<ssize_t>(holder.size()));
  try {
    c.Run();
    ADD_FAILURE() << "ran while another run held the folder";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("in use by another bifilar run (pid 4242, started "
                                         "2026-01-01 00:00:00 UTC)"),
              std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(c.out + "/results.json"));
  EXPECT_THROW(RunReport(c.out), UserError);
  ::close(fd);  // released: the next run works
  EXPECT_EQ(c.Run().summary.n_ok, 12);
}

// issue 9 item 5: a kill -9 between renames left a new traces.csv beside an old results.json.
TEST(OutputSet, MixedSetIsDetectedByReportAndRewrittenByProcess) {
  Campaign c;
  c.Run();
  EXPECT_TRUE(CheckOutputSet(c.out, true).empty());
  RunReport(c.out);  // consistent: rebuilt and still consistent
  EXPECT_TRUE(CheckOutputSet(c.out, true).empty());
  const std::string old_results = ReadFile(c.out + "/results.json");
  c.SetLog(30, 2, 0.05);
  c.Run();
  // What a kill between the traces.csv and results.json renames leaves behind.
  WriteFile(c.out + "/results.json", old_results);
  const std::vector<std::string> problems = CheckOutputSet(c.out, true);
  ASSERT_FALSE(problems.empty());
  EXPECT_NE(problems.front().find(".csv does not belong to"), std::string::npos)
      << problems.front();
  try {
    RunReport(c.out);
    ADD_FAILURE() << "report built from a mixed set";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("mixed set"), std::string::npos) << e.what();
  }
  // The next process rewrites the whole set.
  c.Run();
  EXPECT_TRUE(CheckOutputSet(c.out, true).empty());
  // A report from another results.json is found too.
  WriteFile(c.out + "/report.html", "<!DOCTYPE html>\n<html></html>\n");
  EXPECT_FALSE(CheckOutputSet(c.out, true).empty());
  EXPECT_TRUE(CheckOutputSet(c.out, false).empty());
}

// issue 9 item 6: a cached inertia scaled by 0.9 was used (I_xz moved, exit 0).
TEST(OutputSet, TamperedCacheEntryIsRefittedNotUsed) {
  Campaign c;
  const CampaignResult first = c.Run();
  ASSERT_TRUE(first.ellipse_fit.has_value());
  int tampered = 0;
  for (const auto& entry : fs::directory_iterator(c.out + "/cache")) {
    std::string text = ReadFile(entry.path().string());
    const size_t at = text.find("\"inertia_total_kg_m2\": ");
    ASSERT_NE(at, std::string::npos);
    const size_t begin = at + 23, end = text.find_first_of(",\n", begin);
    const double value = std::stod(text.substr(begin, end - begin));
    std::ostringstream scaled;
    scaled.precision(17);
    scaled << 0.9 * value;
    text.replace(begin, end - begin, scaled.str());
    WriteFile(entry.path().string(), text);
    if (++tampered == 3) break;
  }
  const CampaignResult again = c.Run();
  EXPECT_EQ(again.summary.n_cache_refused, 3);
  EXPECT_EQ(again.summary.n_fitted, 3);
  EXPECT_EQ(again.summary.n_reused, 9);
  ASSERT_TRUE(again.ellipse_fit.has_value());
  EXPECT_DOUBLE_EQ(again.ellipse_fit->ixz.value, first.ellipse_fit->ixz.value);
  // The refitted entries are good again.
  EXPECT_EQ(c.Run().summary.n_cache_refused, 0);
}

// issue 9 item 11: an output folder inside runs.root made the rerun read its own outputs as logs.
TEST(OutputSet, OutputFolderInsideTheLogsIsNotReadAsLogs) {
  Campaign c;
  c.out = c.dir + "/logs/pitch_out";  // matches runs.pattern pitch_{pitch_deg}/*.csv
  EXPECT_EQ(c.Run().summary.n_traces, 12);
  const CampaignResult again = c.Run();  // traces.csv and angles.csv now exist in it
  EXPECT_EQ(again.summary.n_traces, 12);
  EXPECT_EQ(again.summary.exit_code, 0);
}

// ---- Issue 15: nothing outside the output folder is ever touched ----------------------------

// A user's file beside the campaign that no bifilar run may change ("thesis.txt").
struct Precious {
  std::string path, text = "four years of work\n";
  explicit Precious(const Campaign& c) : path(c.dir + "/precious/thesis.txt") {
    WriteFile(path, text);
  }
  bool Intact() const {
    return fs::is_regular_file(fs::symlink_status(path)) && ReadFile(path) == text;
  }
};

std::string ManifestPath(const Campaign& c) { return c.out + "/" + OutputManifest::kFileName; }

// Appends `entry` to OUT's manifest "files".
void AppendManifestEntry(const Campaign& c, const std::string& entry) {
  nlohmann::json j = nlohmann::json::parse(ReadFile(ManifestPath(c)));
  j["files"].push_back(entry);
  WriteFile(ManifestPath(c), j.dump(1));
}

// The message of the UserError `f` throws ("" and a failure when it throws none).
template <typename F>
std::string UserErrorOf(F f) {
  try {
    f();
  } catch (const UserError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no UserError";
  return "";
}

// issue 15 item 1: "../precious/thesis.txt" or an absolute path appended to the manifest's
// "files" was deleted by the next `process`, exit 0, no message.
TEST(OutputSet, ManifestEntryOutsideTheFolderIsRefusedAndNothingIsRemoved) {
  Campaign c;
  Precious thesis(c);
  c.Run();
  const std::string manifest = ReadFile(ManifestPath(c));
  const std::string log = c.dir + "/logs/pitch_0/trial_1.csv";
  const std::string log_text = ReadFile(log);
  for (const std::string& entry :
       {std::string("../precious/thesis.txt"), thesis.path,
        std::string("cache/../../precious/thesis.txt"),
        std::string("figures/../../logs/pitch_0/trial_1.csv"), log, std::string("cache/sub/x.json"),
        std::string("notes.txt"), std::string("cache/thesis.txt"), std::string("figures/.."),
        std::string("")}) {
    SCOPED_TRACE(entry);
    AppendManifestEntry(c, entry);
    // A stale entry among them, so a run that used the manifest would prune.
    c.SetLog(60, 2, 0.02);
    const std::string message = UserErrorOf([&] { c.Run(); });
    EXPECT_NE(message.find("damaged manifest"), std::string::npos) << message;
    EXPECT_NE(message.find(nlohmann::json(entry).dump() + " refused"), std::string::npos)
        << message;
    EXPECT_NE(message.find("nothing was removed"), std::string::npos) << message;
    EXPECT_TRUE(thesis.Intact());
    EXPECT_EQ(ReadFile(log), log_text);
    c.SetLog(60, 2, 0.0);
    WriteFile(ManifestPath(c), manifest);
  }
  EXPECT_EQ(c.Run().summary.n_ok, 12);  // the repaired manifest is used again
}

// Issue 15 item 1, symbolic links: a recorded name that is now a link to a file outside OUT,
// or cache/ replaced by a link to another folder, is refused; the target is never removed.
TEST(OutputSet, RecordedNameBehindASymbolicLinkIsRefused) {
  Campaign c;
  Precious thesis(c);
  c.Run();
  std::string entry;
  for (const auto& e : fs::directory_iterator(c.out + "/cache")) entry = e.path().string();
  ASSERT_FALSE(entry.empty());
  const std::string entry_text = ReadFile(entry);
  fs::remove(entry);
  fs::create_symlink(thesis.path, entry);
  c.SetLog(0, 1, 0.02);  // the linked entry, if it is trial 1 at 0 deg, would be stale
  std::string message = UserErrorOf([&] { c.Run(); });
  EXPECT_NE(message.find("damaged manifest"), std::string::npos) << message;
  EXPECT_NE(message.find("is a symbolic link"), std::string::npos) << message;
  EXPECT_TRUE(thesis.Intact());
  fs::remove(entry);
  WriteFile(entry, entry_text);

  // cache/ itself a link to a folder outside OUT holding a file under a recorded name.
  const std::string elsewhere = c.dir + "/precious/cache_copy";
  fs::rename(c.out + "/cache", elsewhere);
  fs::create_symlink(elsewhere, c.out + "/cache");
  message = UserErrorOf([&] { c.Run(); });
  EXPECT_NE(message.find("is a symbolic link"), std::string::npos) << message;
  EXPECT_TRUE(fs::exists(elsewhere + "/" + fs::path(entry).filename().string()));
  fs::remove(c.out + "/cache");
  fs::rename(elsewhere, c.out + "/cache");
  c.SetLog(0, 1, 0.0);
  EXPECT_EQ(c.Run().summary.n_ok, 12);
}

// The last line of defence: a link planted under a recorded name after the manifest was read
// (during the run) is left alone by Prune, with a warning, and forgotten.
TEST(OutputSet, PruneNeverFollowsALinkPlantedDuringTheRun) {
  Campaign c;
  Precious thesis(c);
  c.Run();
  OutputManifest manifest(c.out);
  std::string name;
  for (const auto& e : fs::directory_iterator(c.out + "/cache")) {
    name = "cache/" + e.path().filename().string();
  }
  ASSERT_TRUE(manifest.Contains(name));
  fs::remove(c.out + "/" + name);
  fs::create_symlink(thesis.path, c.out + "/" + name);
  const std::vector<std::string> warnings = manifest.Prune({});
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find(name + ": not removed (is a symbolic link)"), std::string::npos)
      << warnings[0];
  EXPECT_TRUE(thesis.Intact());
  EXPECT_TRUE(fs::is_symlink(c.out + "/" + name));
  EXPECT_FALSE(manifest.Contains(name));
  EXPECT_FALSE(fs::exists(c.out + "/results.json"));  // every regular recorded file was removed
}

// issue 15 item 2: `ln -s ~/thesis.txt OUT/.bifilar.lock` then `process` left thesis.txt empty.
TEST(OutputSet, LockThatIsNotARegularFileOfItsOwnIsRefusedAndNeverWritten) {
  Campaign c;
  Precious thesis(c);
  fs::create_directories(c.out);
  const std::string lock = c.out + "/.bifilar.lock";
  struct Case {
    std::string what, expected;
    std::function<void()> make;
  };
  const std::vector<Case> cases = {
      {"symbolic link", "is a symbolic link", [&] { fs::create_symlink(thesis.path, lock); }},
      {"dangling link", "is a symbolic link",
       [&] { fs::create_symlink(c.dir + "/precious/new.txt", lock); }},
      {"hard link", "has other names", [&] { fs::create_hard_link(thesis.path, lock); }},
      {"FIFO", "not a regular file", [&] { ASSERT_EQ(::mkfifo(lock.c_str(), 0644), 0); }},
      {"folder", "", [&] { fs::create_directories(lock); }},
      {"user's file", "not bifilar's lock file", [&] { WriteFile(lock, "my own text\n"); }},
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(k.what);
    k.make();
    for (bool report : {false, true}) {
      const std::string message = UserErrorOf([&] {
        if (report) {
          RunReport(c.out);
        } else {
          c.Run();
        }
      });
      EXPECT_NE(message.find(lock), std::string::npos) << message;
      EXPECT_NE(message.find(k.expected), std::string::npos) << message;
    }
    EXPECT_TRUE(thesis.Intact());
    EXPECT_FALSE(fs::exists(c.dir + "/precious/new.txt"));
    if (k.what == "user's file") {
      EXPECT_EQ(ReadFile(lock), "my own text\n");
    }
    EXPECT_FALSE(fs::exists(c.out + "/results.json"));
    fs::remove_all(lock);
  }
  // A lock of bifilar's own, even a long holder line left by a killed run, is used and
  // overwritten in place (never truncated, never grown).
  WriteFile(lock, "pid 4242, started 2026-01-01 00:00:00 UTC\n");
  EXPECT_EQ(c.Run().summary.n_ok, 12);
  EXPECT_EQ(fs::file_size(lock), 64u);
  EXPECT_EQ(ReadFile(lock).rfind("pid ", 0), 0u);
  EXPECT_EQ(c.Run().summary.n_ok, 12);
  EXPECT_EQ(fs::file_size(lock), 64u);
}

// Everything under `dir` with its content: what a refused run must leave as it was.
std::map<std::string, std::string> TreeOf(const std::string& dir) {
  std::map<std::string, std::string> tree;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    tree[e.path().string()] = e.is_regular_file() ? ReadFile(e.path().string()) : "(folder)";
  }
  return tree;
}

// issue 15 item 4: `process cfg --out LOGS/pitch_0` dropped that folder's logs, exit 0.
TEST(OutputSet, OutputFolderHoldingLogsIsRefusedBeforeAnythingIsWritten) {
  Campaign c;
  const std::map<std::string, std::string> before = TreeOf(c.dir);
  for (const std::string& out : {c.dir + "/logs/pitch_0", c.dir + "/logs/pitch_0/", c.dir + "/logs",
                                 c.dir, c.dir + "/logs/../logs/pitch_30"}) {
    SCOPED_TRACE(out);
    c.out = out;
    const std::string message = UserErrorOf([&] { c.Run(); });
    EXPECT_NE(message.find("the output folder holds"), std::string::npos) << message;
    EXPECT_NE(message.find("log(s) of this campaign"), std::string::npos) << message;
    EXPECT_NE(message.find("trial_1.csv"), std::string::npos) << message;
    EXPECT_EQ(TreeOf(c.dir), before);  // no lock, manifest, cache/ or figures/ created
  }
  EXPECT_EQ(c.calls, 0);
  // A link to a log folder is the log folder.
  fs::create_symlink(c.dir + "/logs/pitch_90", c.dir + "/link_out");
  c.out = c.dir + "/link_out";
  const std::string linked = UserErrorOf([&] { c.Run(); });
  EXPECT_NE(linked.find("2 log(s) of this campaign (pitch_90/trial_1.csv, "
                        "pitch_90/trial_2.csv)"),
            std::string::npos)
      << linked;
  // The tare folder too.
  fs::remove(c.dir + "/link_out");
  WriteFile(c.dir + "/tare/tare_1.csv", "I=0.5\n");
  WriteFile(c.dir + "/campaign.yaml",
            "rig: {filar_length_m: 2.0, filar_separation_m: 1.0, mass_kg: 2.0,\n"
            "      inertia: {tare: {logs: tare/*.csv}}}\n"
            "aircraft: {mass_kg: 10}\n"
            "runs: {root: logs, pattern: \"pitch_{pitch_deg}/*.csv\"}\n");
  c.out = c.dir + "/tare";
  const std::string message = UserErrorOf([&] { c.Run(); });
  EXPECT_NE(message.find("1 log(s) of this campaign (tare/tare_1.csv)"), std::string::npos)
      << message;
  c.out = c.dir + "/out";
  EXPECT_EQ(c.Run().summary.n_traces, 13);
}

// issue 9 item 11: a fit.windows entry for a file that does not exist was ignored silently.
TEST(OutputSet, WindowForAMissingFileIsAnErrorBeforeAnyFit) {
  Campaign c;
  c.AppendConfig(
      "fit:\n  windows:\n    pitch_0/trial_1.csv: [1, 20]\n    pitch_0/trial_9.csv: [1, 20]\n");
  try {
    c.Run();
    ADD_FAILURE() << "a window for a missing file was accepted";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("'fit.windows.pitch_0/trial_9.csv' names no log"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(c.calls, 0);
}

}  // namespace
}  // namespace bifilar
