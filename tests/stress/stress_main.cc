// The stress test of issue 9 ("a test that stays"): `bifilar` driven as a careful, hostile user
// would, from a fixed seed and a fixed number of cases, on a small copy of the sample campaign
// (sample_runs/prandtl_d: 6 angles x 2 trials + 3 tare logs, plain CSV) in a temporary folder.
//
// Case kinds: random mutations of the logs (byte flips, truncation, duplicated and shuffled rows,
// huge, NaN and empty values, BOM, CRLF) and of the config (hostile values, duplicated lines,
// byte flips, truncation); cache tampering; kill -9 at a random time of `process` followed by a
// rerun; two concurrent runs on one output folder; a user's file in a folder bifilar owns; and,
// when ../shared/data/crazyflie is beside the repository, mutations of real logs through
// `bifilar fit`. Every tenth case (issue 15 item 11) aims a run outside the output folder: a
// manifest entry with "../", an absolute path or a symbolic link out of OUT; the lock replaced
// by a link, hard link or FIFO; `--out` inside the logs.
// Then, once each, hostile inputs that must stop quickly with a clear message
// (issue 15; issue 26: ArduPilot DataFlash logs that are not DataFlash, empty, without IMU, with a
// bad FMT, and damaged copies): a FIFO and a symlink to /dev/urandom among the logs, /dev/zero as
// the config, a multi-member gzip log (the baseline's ellipse), a gzip bomb, a FIFO as results.json
// and as a cache entry (process and report), a YAML alias bomb; (issue 23) simulate, init and
// export aimed at a user's file, a log, the campaign's results or a link to /proc/self/fd/1.
//
// Asserted for every run: no crash (signal), no hang (each run is bounded by --run-timeout-s,
// default 60 s, far above the ~0.3 s a run takes), exit code 0, 1 or 2, no NaN or inf written
// (results.json, traces.csv, angles.csv, `fit --json`), no file outside OUT changed, added or
// removed (the workspace beside OUT, with the logs, the config and a fake thesis, hashed
// before and after every run), the user's files untouched, a consistent
// output set (pipeline/store/output_set.h CheckOutputSet) after every run that finished; after
// cache tampering, a kill or concurrent runs on the pristine campaign, the ellipse equals the
// baseline.
//
//   bifilar_stress --binary build/bifilar --source . [--seed 1] [--cases 150] [--keep]
// CTest runs `stress/short` (500 cases, 40-60 s on 2 cores); the long mode is --cases 3000
// (or more, and other seeds: --seed N).
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/gzip.h"
#include "base/units.h"
#include "pipeline/live/mavlink.h"  // issue 34 block at the end
#include "pipeline/live/mavlink_writer.h"
#include "pipeline/logs/dataflash_writer.h"
#include "pipeline/store/cache.h"
#include "pipeline/store/output_set.h"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct Args {
  std::string binary;
  std::string source;
  uint64_t seed = 1;
  int cases = 150;
  double run_timeout_s = 60.0;
  bool keep = false;
};

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void WriteFile(const std::string& path, const std::string& text) {
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
}

// ---- The files outside OUT (issue 15 item 11) ----

// The workspace outside the output folder: every entry under `root` except the `skip` folders
// (OUT, and the harness's own folder of run outputs).
struct Sentinel {
  std::string root;
  std::vector<std::string> skip;
};
const Sentinel* g_sentinel = nullptr;  // set once the workspace exists

// path -> what it is: a file's size and FNV-1a 64, a link's target, "folder", another type.
using TreeState = std::map<std::string, std::string>;

TreeState SnapshotOutside(const Sentinel& sentinel) {
  TreeState state;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(sentinel.root, ec), end; !ec && it != end;
       it.increment(ec)) {
    const std::string path = it->path().string();
    if (std::find(sentinel.skip.begin(), sentinel.skip.end(), path) != sentinel.skip.end()) {
      it.disable_recursion_pending();
      continue;
    }
    const fs::file_status status = it->symlink_status(ec);
    if (fs::is_symlink(status)) {
      state[path] = "link -> " + fs::read_symlink(it->path(), ec).string();
    } else if (fs::is_regular_file(status)) {
      const std::string bytes = ReadFile(path);
      state[path] = "file " + std::to_string(bytes.size()) + " " +
                    bifilar::HashToHex(bifilar::Fnv1a64(bytes));
    } else if (fs::is_directory(status)) {
      state[path] = "folder";
    } else {
      state[path] = "type " + std::to_string(static_cast<int>(status.type()));
    }
  }
  return state;
}

// The first few differences between two states, "" when equal.
std::string DescribeChanges(const TreeState& before, const TreeState& after) {
  std::vector<std::string> changes;
  for (const auto& [path, what] : before) {
    const auto it = after.find(path);
    if (it == after.end()) {
      changes.push_back(path + " removed");
    } else if (it->second != what) {
      changes.push_back(path + " changed (" + what + " -> " + it->second + ")");
    }
  }
  for (const auto& [path, what] : after) {
    if (!before.count(path)) changes.push_back(path + " added (" + what + ")");
  }
  std::string text;
  for (size_t i = 0; i < changes.size() && i < 5; ++i) text += (i ? "; " : "") + changes[i];
  if (changes.size() > 5) text += "; and " + std::to_string(changes.size() - 5) + " more";
  return text;
}

// ---- Running bifilar ----

struct Process {
  pid_t pid = -1;
  std::string out_path, err_path;
  Clock::time_point start;
  TreeState outside_before;  // the workspace outside OUT when the run started
};

struct Outcome {
  bool timed_out = false;
  bool killed = false;  // by us, on purpose
  int signal = 0;       // terminated by a signal we did not send
  int exit_code = -1;
  std::string out, err;
  double seconds = 0.0;
  std::string outside_changed;  // what changed outside OUT during the run, "" when nothing
};

Process Start(const std::vector<std::string>& argv, const std::string& log_prefix) {
  Process p;
  p.out_path = log_prefix + ".stdout";
  p.err_path = log_prefix + ".stderr";
  if (g_sentinel) p.outside_before = SnapshotOutside(*g_sentinel);
  p.start = Clock::now();
  p.pid = fork();
  if (p.pid == 0) {
    const int out = open(p.out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = open(p.err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(out, 1);
    dup2(err, 2);
    std::vector<char*> c_argv;
    for (const std::string& a : argv) c_argv.push_back(const_cast<char*>(a.c_str()));
    c_argv.push_back(nullptr);
    execv(c_argv[0], c_argv.data());
    _exit(127);
  }
  return p;
}

// Waits for p; kills it with SIGKILL after kill_after_s (>= 0) or, as a hang, after timeout_s.
Outcome Wait(const Process& p, double timeout_s, double kill_after_s = -1.0) {
  Outcome o;
  int status = 0;
  for (;;) {
    const pid_t r = waitpid(p.pid, &status, WNOHANG);
    if (r == p.pid) break;
    const double elapsed = std::chrono::duration<double>(Clock::now() - p.start).count();
    if (kill_after_s >= 0.0 && elapsed >= kill_after_s) {
      kill(p.pid, SIGKILL);
      waitpid(p.pid, &status, 0);
      o.killed = true;
      break;
    }
    if (elapsed > timeout_s) {
      kill(p.pid, SIGKILL);
      waitpid(p.pid, &status, 0);
      o.timed_out = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  o.seconds = std::chrono::duration<double>(Clock::now() - p.start).count();
  if (g_sentinel)
    o.outside_changed = DescribeChanges(p.outside_before, SnapshotOutside(*g_sentinel));
  if (!o.killed && !o.timed_out) {
    if (WIFSIGNALED(status)) o.signal = WTERMSIG(status);
    if (WIFEXITED(status)) o.exit_code = WEXITSTATUS(status);
  }
  o.out = ReadFile(p.out_path);
  o.err = ReadFile(p.err_path);
  return o;
}

// ---- Checks ----

bool IsNonFiniteToken(std::string cell) {
  while (!cell.empty() && (cell.front() == ' ' || cell.front() == '"')) cell.erase(cell.begin());
  while (!cell.empty() && (cell.back() == ' ' || cell.back() == '"' || cell.back() == '\r')) {
    cell.pop_back();
  }
  std::transform(cell.begin(), cell.end(), cell.begin(), ::tolower);
  if (!cell.empty() && (cell[0] == '-' || cell[0] == '+')) cell.erase(cell.begin());
  return cell == "nan" || cell == "inf" || cell == "infinity";
}

// A NaN or inf written as a number: a bare JSON token, or an unquoted CSV cell.
std::string NonFiniteIn(const std::string& text, bool csv) {
  if (!csv) {
    try {
      const nlohmann::json parsed = nlohmann::json::parse(text);  // NaN, inf: not JSON
      (void)parsed;
    } catch (const std::exception& e) {
      return std::string("not valid JSON: ") + e.what();
    }
    return "";
  }
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    std::string cell;
    bool quoted = false;
    for (size_t i = 0; i <= line.size(); ++i) {
      const char c = i < line.size() ? line[i] : ',';
      if (c == '"') quoted = !quoted;
      if (c == ',' && !quoted) {
        if (cell.find('"') == std::string::npos && IsNonFiniteToken(cell)) {
          return "line " + std::to_string(line_no) + ": '" + cell + "'";
        }
        cell.clear();
      } else {
        cell += c;
      }
    }
  }
  return "";
}

struct Failures {
  int count = 0;
  void Add(int case_no, const std::string& kind, const std::string& what) {
    ++count;
    std::cerr << "FAIL case " << case_no << " (" << kind << "): " << what << "\n";
  }
};

// Issue 15: a run of bifilar never touches a file outside its output folder.
void CheckOutside(const Outcome& o, int case_no, const std::string& kind, Failures* failures) {
  if (!o.outside_changed.empty()) {
    failures->Add(case_no, kind, "a file outside the output folder changed: " + o.outside_changed);
  }
}

// ---- Mutations ----

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) lines.push_back(line);
  return lines;
}

std::string Join(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& l : lines) out += l + "\n";
  return out;
}

template <typename T>
const T& Pick(const std::vector<T>& v, std::mt19937_64& rng) {
  return v[std::uniform_int_distribution<size_t>(0, v.size() - 1)(rng)];
}

int Uniform(std::mt19937_64& rng, int lo, int hi) {
  return std::uniform_int_distribution<int>(lo, hi)(rng);
}

// One random mutation of a CSV log; `what` says which.
std::string MutateLog(const std::string& text, std::mt19937_64& rng, std::string* what) {
  std::vector<std::string> lines = Lines(text);
  const int n = static_cast<int>(lines.size());
  auto data_line = [&] { return Uniform(rng, 1, std::max(1, n - 1)); };
  switch (Uniform(rng, 0, 10)) {
    case 0: {
      std::string t = text;
      const int k = Uniform(rng, 1, 40);
      for (int i = 0; i < k && !t.empty(); ++i) {
        t[Uniform(rng, 0, static_cast<int>(t.size()) - 1)] =
            static_cast<char>(Uniform(rng, 0, 255));
      }
      *what = "byte flips x" + std::to_string(k);
      return t;
    }
    case 1: {
      const int at = Uniform(rng, 0, static_cast<int>(text.size()));
      *what = "truncated at byte " + std::to_string(at);
      return text.substr(0, at);
    }
    case 2: {
      const int k = Uniform(rng, 1, 200);
      for (int i = 0; i < k && n > 1; ++i) {
        const int at = data_line();
        lines.insert(lines.begin() + at, lines[at]);
      }
      *what = "duplicated rows x" + std::to_string(k);
      return Join(lines);
    }
    case 3: {
      if (n > 2) std::shuffle(lines.begin() + 1, lines.end(), rng);
      *what = "all rows shuffled";
      return Join(lines);
    }
    case 4: {
      const int k = Uniform(rng, 1, 50);
      for (int i = 0; i < k && n > 2; ++i) std::swap(lines[data_line()], lines[data_line()]);
      *what = "rows swapped x" + std::to_string(k);
      return Join(lines);
    }
    case 5:
    case 6: {
      static const std::vector<std::string> huge = {
          "1e308", "-1e308", "1e300", "3e38", "1e-320", "-0", "99999999999999999999"};
      static const std::vector<std::string> bad = {"nan", "NaN", "inf", "-inf", "", "x", "1e999"};
      const std::vector<std::string>& values = Uniform(rng, 0, 1) ? huge : bad;
      const int k = Uniform(rng, 1, 30);
      for (int i = 0; i < k && n > 1; ++i) {
        std::string& line = lines[data_line()];
        std::vector<size_t> commas = {0};
        for (size_t j = 0; j < line.size(); ++j) {
          if (line[j] == ',') commas.push_back(j + 1);
        }
        const size_t begin = Pick(commas, rng);
        const size_t end = std::min(line.find(',', begin), line.size());
        line.replace(begin, end - begin, Pick(values, rng));
      }
      *what = std::string(&values == &huge ? "huge" : "NaN/inf/empty") + " values x" +
              std::to_string(k);
      return Join(lines);
    }
    case 7:
      *what = "header removed";
      if (n > 0) lines.erase(lines.begin());
      return Join(lines);
    case 8:
      *what = Uniform(rng, 0, 1) ? "only the header" : "empty file";
      return *what == "empty file" || n == 0 ? "" : lines[0] + "\n";
    case 9: {
      *what = "BOM and CRLF";
      std::string t = "\xEF\xBB\xBF";
      for (const std::string& l : lines) t += l + "\r\n";
      return t;
    }
    default: {
      *what = "a log of a few rows";
      lines.resize(std::min(n, Uniform(rng, 1, 12)));
      return Join(lines);
    }
  }
}

std::string MutateConfig(const std::string& text, std::mt19937_64& rng, std::string* what) {
  std::vector<std::string> lines = Lines(text);
  static const std::vector<std::string> values = {
      "0",   "-1",         "1e308",       "-1e308", ".nan",
      "nan", "2147483647", "-2147483648", "1e-320", "\"\"",
      "[]",  "{}",         "~",           "abc",    "99999999999999999999",
      "/",   "../../..",   "[1, 2, 3]",   "0.5"};
  switch (Uniform(rng, 0, 4)) {
    case 0:
    case 1: {
      std::vector<int> with_value;
      for (int i = 0; i < static_cast<int>(lines.size()); ++i) {
        const size_t colon = lines[i].find(": ");
        if (colon != std::string::npos && lines[i].find('#') != 0) with_value.push_back(i);
      }
      const int i = Pick(with_value, rng);
      std::string& line = lines[i];
      const size_t colon = line.find(": ");
      const size_t comment = line.find(" #", colon);
      const std::string value = Pick(values, rng);
      line = line.substr(0, colon + 2) + value +
             (comment == std::string::npos ? "" : line.substr(comment));
      *what = "line " + std::to_string(i + 1) + " value -> " + value;
      return Join(lines);
    }
    case 2: {
      const int i = Uniform(rng, 0, static_cast<int>(lines.size()) - 1);
      lines.insert(lines.begin() + i, lines[i]);
      *what = "line " + std::to_string(i + 1) + " duplicated";
      return Join(lines);
    }
    case 3: {
      std::string t = text;
      const int k = Uniform(rng, 1, 5);
      for (int j = 0; j < k; ++j) {
        t[Uniform(rng, 0, static_cast<int>(t.size()) - 1)] =
            static_cast<char>(Uniform(rng, 32, 126));
      }
      *what = "byte flips x" + std::to_string(k);
      return t;
    }
    default: {
      const int at = Uniform(rng, 0, static_cast<int>(text.size()));
      *what = "truncated at byte " + std::to_string(at);
      return text.substr(0, at);
    }
  }
}

// ---- The campaign ----

struct Workspace {
  std::string dir, logs, out, config_path, config_text;
  std::string harness;  // the runs' stdout and stderr (outside the sentinel tree)
  std::string thesis;   // a user's file beside the campaign: never to be touched
  std::map<std::string, std::string> pristine;    // path -> content of every log
  std::map<std::string, std::string> user_files;  // path -> content, must never change
  double ixz_kg_m2 = NAN, ix_kg_m2 = NAN;         // baseline ellipse

  void RestoreLogs() const {
    for (const auto& [path, text] : pristine) {
      if (ReadFile(path) != text) WriteFile(path, text);
    }
    // Files a mutation may have added.
    for (const auto& entry : fs::recursive_directory_iterator(logs)) {
      if (entry.is_regular_file() && !pristine.count(entry.path().string()))
        fs::remove(entry.path());
    }
  }
  void RestoreConfig() const { WriteFile(config_path, config_text); }
};

bool Replace(std::string* text, const std::string& from, const std::string& to) {
  const size_t at = text->find(from);
  if (at == std::string::npos) return false;
  text->replace(at, from.size(), to);
  return true;
}

Workspace MakeWorkspace(const Args& args) {
  Workspace w;
  char tmpl[] = "/tmp/bifilar_stress_XXXXXX";
  w.dir = mkdtemp(tmpl);
  w.logs = w.dir + "/logs";
  w.out = w.dir + "/out";
  w.harness = w.dir + "/harness";
  w.thesis = w.dir + "/precious/thesis.txt";
  fs::create_directories(w.harness);
  w.config_path = w.dir + "/campaign.yaml";
  const std::string sample = args.source + "/sample_runs/prandtl_d/logs";
  std::vector<std::string> names;
  for (int pitch : {-60, -30, 0, 30, 60, 90}) {
    for (int k = 1; k <= 2; ++k) {
      names.push_back("pitch_" + std::to_string(pitch) + "/trial_" + std::to_string(k));
    }
  }
  for (int k = 1; k <= 3; ++k) names.push_back("tare/tare_" + std::to_string(k));
  for (const std::string& name : names) {
    std::string text, why;
    if (!bifilar::GzipDecompress(ReadFile(sample + "/" + name + ".csv.gz"), &text, &why,
                                 bifilar::LogCap(1'000'000'000))) {
      throw std::runtime_error(sample + "/" + name + ".csv.gz: " + why);
    }
    w.pristine[w.logs + "/" + name + ".csv"] = text;
  }
  std::string config = ReadFile(args.source + "/configs/prandtl_d.yaml");
  if (!Replace(&config, "../sample_runs/prandtl_d/logs/tare/*.csv.gz", "logs/tare/*.csv") ||
      !Replace(&config, "../sample_runs/prandtl_d/logs", "logs") ||
      !Replace(&config, "*.csv.gz", "*.csv") ||
      !Replace(&config, "bootstrap: 2000", "bootstrap: 200")) {
    throw std::runtime_error("configs/prandtl_d.yaml changed: update MakeWorkspace in " __FILE__);
  }
  w.config_text = config;
  w.RestoreLogs();
  w.RestoreConfig();
  // The user's own files beside and above the outputs: never to be touched.
  w.user_files[w.out + "/my_notes.txt"] = "my notes\n";
  w.user_files[w.dir + "/results_backup.json"] = "{}\n";
  w.user_files[w.thesis] = "four years of work\n";
  for (const auto& [path, text] : w.user_files) WriteFile(path, text);
  fs::create_symlink(w.thesis, w.dir + "/precious/thesis_link.txt");
  return w;
}

std::vector<std::string> ProcessArgv(const Args& args, const Workspace& w, bool force) {
  std::vector<std::string> argv = {args.binary, "process", w.config_path, "--out", w.out,
                                   "--jobs",    "2"};
  if (force) argv.push_back("--force");
  return argv;
}

// The ellipse in results.json, NaN when none.
void ReadEllipse(const std::string& out, double* ix, double* ixz) {
  *ix = *ixz = NAN;
  try {
    const nlohmann::json j = nlohmann::json::parse(ReadFile(out + "/results.json"));
    if (j.contains("ellipse") && j["ellipse"].is_object()) {
      *ix = j["ellipse"]["Ix_kg_m2"].get<double>();
      *ixz = j["ellipse"]["Ixz_kg_m2"].get<double>();
    }
  } catch (const std::exception&) {
  }
}

// Checks common to every finished `process`: exit code, no NaN, consistent set, user files.
void CheckRun(const Outcome& o, const Workspace& w, int case_no, const std::string& kind,
              Failures* failures) {
  if (o.timed_out) failures->Add(case_no, kind, "no answer within the bound: a hang");
  if (o.signal)
    failures->Add(case_no, kind, "crashed with signal " + std::to_string(o.signal) + "\n" + o.err);
  CheckOutside(o, case_no, kind, failures);
  if (!o.killed && !o.timed_out && !o.signal && (o.exit_code < 0 || o.exit_code > 2)) {
    failures->Add(case_no, kind, "exit code " + std::to_string(o.exit_code) + "\n" + o.err);
  }
  if (o.exit_code == 2 && o.err.find("error") == std::string::npos) {
    failures->Add(case_no, kind, "exit 2 without an error message");
  }
  for (const auto& [path, text] : w.user_files) {
    if (ReadFile(path) != text)
      failures->Add(case_no, kind, "user file changed or removed: " + path);
  }
  if (o.killed || !(o.exit_code == 0 || o.exit_code == 1)) return;
  for (const char* name : {"results.json", "traces.csv", "angles.csv"}) {
    const std::string path = w.out + "/" + name;
    if (!fs::exists(path)) {
      failures->Add(case_no, kind,
                    std::string(name) + " missing after exit " + std::to_string(o.exit_code));
      continue;
    }
    const std::string bad = NonFiniteIn(ReadFile(path), std::string(name) != "results.json");
    if (!bad.empty())
      failures->Add(case_no, kind, std::string(name) + ": non-finite number, " + bad);
  }
  for (const std::string& problem : bifilar::CheckOutputSet(w.out, true)) {
    failures->Add(case_no, kind, "inconsistent output set: " + problem);
  }
}

void CheckBaseline(const Workspace& w, int case_no, const std::string& kind, Failures* failures) {
  double ix = NAN, ixz = NAN;
  ReadEllipse(w.out, &ix, &ixz);
  if (!(std::fabs(ixz - w.ixz_kg_m2) <= 1e-12 && std::fabs(ix - w.ix_kg_m2) <= 1e-12)) {
    char buffer[200];
    std::snprintf(buffer, sizeof(buffer),
                  "ellipse differs from the baseline: I_x %.9g (%.9g), I_xz %.9g (%.9g)", ix,
                  w.ix_kg_m2, ixz, w.ixz_kg_m2);
    failures->Add(case_no, kind, buffer);
  }
}

// One random tampering of a cache entry.
std::string TamperCache(const Workspace& w, std::mt19937_64& rng) {
  std::vector<std::string> entries;
  if (fs::is_directory(w.out + "/cache")) {
    for (const auto& e : fs::directory_iterator(w.out + "/cache"))
      entries.push_back(e.path().string());
  }
  std::sort(entries.begin(), entries.end());
  if (entries.empty()) return "no cache entry";
  const std::string path = Pick(entries, rng);
  std::string text = ReadFile(path);
  const size_t at = text.find("\"inertia_total_kg_m2\": ");
  switch (Uniform(rng, 0, 4)) {
    case 0:
      if (at != std::string::npos) {
        const size_t b = at + 23, e = text.find_first_of(",\n", b);
        const double v = std::atof(text.substr(b, e - b).c_str());
        char buffer[40];
        std::snprintf(buffer, sizeof(buffer), "%.17g", 0.9 * v);
        text.replace(b, e - b, buffer);
      }
      WriteFile(path, text);
      return "inertia scaled by 0.9 in " + path;
    case 1:
      WriteFile(path, ReadFile(Pick(entries, rng)));
      return "another entry copied over " + path;
    case 2:
      if (at != std::string::npos) {
        const size_t b = at + 23, e = text.find_first_of(",\n", b);
        text.replace(b, e - b, Uniform(rng, 0, 1) ? "NaN" : "-5");
      }
      WriteFile(path, text);
      return "NaN or -5 written in " + path;
    case 3:
      text[Uniform(rng, 0, static_cast<int>(text.size()) - 1)] ^= 0x20;
      WriteFile(path, text);
      return "one bit flipped in " + path;
    default:
      WriteFile(path, text.substr(0, Uniform(rng, 0, static_cast<int>(text.size()))));
      return "truncated " + path;
  }
}

// The first time series of a Crazyflie log: up to the first row whose `t` is empty (the footer).
std::string CrazyflieSeries(const std::string& text) {
  std::vector<std::string> lines = Lines(text);
  std::vector<std::string> kept;
  int t_col = -1;
  for (const std::string& line : lines) {
    std::vector<std::string> cells;
    std::stringstream in(line);
    std::string cell;
    while (std::getline(in, cell, ',')) cells.push_back(cell);
    if (t_col < 0) {
      for (size_t i = 0; i < cells.size(); ++i) {
        if (cells[i] == "t") t_col = static_cast<int>(i);
      }
    } else if (static_cast<int>(cells.size()) <= t_col || cells[t_col].empty()) {
      break;
    }
    kept.push_back(line);
  }
  return Join(kept);
}

// ---- Runs aimed outside the output folder (issue 15 items 1, 2, 4) ----

// A regular file in `folder`, picked by `rng` from the sorted list, "" when none.
std::string SomeFileIn(const std::string& folder, std::mt19937_64& rng) {
  std::vector<std::string> files;
  std::error_code ec;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->is_regular_file(ec) && !it->is_symlink(ec)) files.push_back(it->path().string());
  }
  std::sort(files.begin(), files.end());
  return files.empty() ? "" : Pick(files, rng);
}

// A manifest entry reaching outside OUT: "../", an absolute path, a recorded name that is now a
// symbolic link out of OUT, or cache/ or figures/ replaced by a link to a folder outside.
// `process` must refuse the manifest (exit 2, naming the entry) and remove nothing.
void ManifestTraversalCase(const Args& args, const Workspace& w, int c, std::mt19937_64& rng,
                           Failures* failures) {
  const std::string manifest_path = w.out + "/" + bifilar::OutputManifest::kFileName;
  const std::string manifest = ReadFile(manifest_path);
  const std::string log = w.logs + "/pitch_0/trial_1.csv";
  std::string kind = "manifest traversal", expected = "damaged manifest";
  std::function<void()> restore = [] {};
  const int variant = Uniform(rng, 0, 6);
  if (variant <= 4) {
    static const char* kWhat[] = {"relative ../", "absolute thesis", "cache/../../ to a log",
                                  "absolute log", "figures/../../ to the config"};
    const std::vector<std::string> entries = {"../precious/thesis.txt", w.thesis,
                                              "cache/../../logs/pitch_0/trial_1.csv", log,
                                              "figures/../../campaign.yaml"};
    kind += std::string(" (") + kWhat[variant] + ")";
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(manifest);
    } catch (const std::exception&) {
      failures->Add(c, kind, "no readable manifest in OUT before the case");
      return;
    }
    j["files"].push_back(entries[variant]);
    WriteFile(manifest_path, j.dump(1));
    restore = [&] { WriteFile(manifest_path, manifest); };
  } else if (variant == 5) {
    kind += " (recorded cache entry is a link to the thesis)";
    expected = "is a symbolic link";
    const std::string entry = SomeFileIn(w.out + "/cache", rng);
    if (entry.empty()) {
      failures->Add(c, kind, "no cache entry in OUT before the case");
      return;
    }
    const std::string text = ReadFile(entry);
    fs::remove(entry);
    fs::create_symlink(w.thesis, entry);
    restore = [entry, text] {
      std::error_code ignored;
      fs::remove(entry, ignored);
      WriteFile(entry, text);
    };
  } else {
    const std::string folder = Uniform(rng, 0, 1) ? "cache" : "figures";
    kind += " (" + folder + "/ is a link to a folder outside OUT)";
    expected = "symbolic link";
    const std::string outside = w.dir + "/precious/" + folder;
    std::error_code ec;
    fs::rename(w.out + "/" + folder, outside, ec);
    if (ec) {
      failures->Add(c, kind, "no " + folder + "/ in OUT before the case: " + ec.message());
      return;
    }
    fs::create_symlink(outside, w.out + "/" + folder);
    restore = [&w, folder, outside] {
      std::error_code ignored;
      fs::remove(w.out + "/" + folder, ignored);
      fs::rename(outside, w.out + "/" + folder, ignored);
    };
  }
  const Outcome o =
      Wait(Start(ProcessArgv(args, w, Uniform(rng, 0, 1)), w.harness + "/run"), args.run_timeout_s);
  CheckRun(o, w, c, kind, failures);
  if (o.exit_code != 2 || o.err.find(expected) == std::string::npos) {
    failures->Add(
        c, kind,
        "not refused with '" + expected + "': exit " + std::to_string(o.exit_code) + "\n" + o.err);
  }
  restore();
}

// OUT/.bifilar.lock replaced by a link to the thesis, a dangling link, a hard link to the thesis,
// a FIFO or a file of the user's: `process` and `report` refuse it (exit 2, naming it) and
// write nothing through it.
void LockCase(const Args& args, const Workspace& w, int c, std::mt19937_64& rng,
              Failures* failures) {
  const std::string lock = w.out + "/.bifilar.lock";
  std::error_code ignored;
  fs::remove(lock, ignored);
  std::string kind = "lock: ";
  const int variant = Uniform(rng, 0, 4);
  std::error_code ec;
  if (variant == 0) {
    kind += "link to the thesis";
    fs::create_symlink(w.thesis, lock, ec);
  } else if (variant == 1) {
    kind += "dangling link";
    fs::create_symlink(w.dir + "/precious/new_file.txt", lock, ec);
  } else if (variant == 2) {
    kind += "hard link to the thesis";
    fs::create_hard_link(w.thesis, lock, ec);
  } else if (variant == 3) {
    kind += "FIFO";
    if (mkfifo(lock.c_str(), 0644) != 0) ec = std::error_code(errno, std::generic_category());
  } else {
    kind += "a file of the user's";
    WriteFile(lock, "my lock notes\n");
  }
  if (ec) {  // e.g. the thesis is gone: an earlier failure, already counted
    failures->Add(c, kind, "cannot plant the lock: " + ec.message());
    return;
  }
  const bool report = Uniform(rng, 0, 1) == 1;
  kind += report ? ", report" : ", process";
  const Outcome o = Wait(Start(report ? std::vector<std::string>{args.binary, "report", w.out}
                                      : ProcessArgv(args, w, false),
                               w.harness + "/run"),
                         args.run_timeout_s);
  CheckRun(o, w, c, kind, failures);
  if (o.exit_code != 2 || o.err.find(".bifilar.lock") == std::string::npos) {
    failures->Add(c, kind,
                  "a lock that is not bifilar's own file was used: exit " +
                      std::to_string(o.exit_code) + "\n" + o.err);
  }
  if (variant == 4 && ReadFile(lock) != "my lock notes\n") {
    failures->Add(c, kind, "the user's file in place of the lock was changed");
  }
  fs::remove(lock, ignored);
}

// `--out` inside the logs (a pitch folder, runs.root, the tare folder, the folder holding the
// logs): refused before anything is written (exit 2, naming the logs), never a silent drop.
void OutInsideLogsCase(const Args& args, const Workspace& w, int c, std::mt19937_64& rng,
                       Failures* failures) {
  const std::vector<std::string> outs = {w.logs + "/pitch_0", w.logs + "/pitch_30/", w.logs,
                                         w.logs + "/tare", w.dir};
  const std::string out = Pick(outs, rng);
  const std::string kind = "--out inside the logs (" + out + ")";
  std::vector<std::string> argv = ProcessArgv(args, w, Uniform(rng, 0, 1));
  argv[4] = out;  // process CONFIG --out OUT
  const Outcome o = Wait(Start(argv, w.harness + "/run"), args.run_timeout_s);
  CheckRun(o, w, c, kind, failures);
  if (o.exit_code != 2 || o.err.find("log(s) of this campaign") == std::string::npos) {
    failures->Add(c, kind,
                  "an output folder holding logs was used: exit " + std::to_string(o.exit_code) +
                      "\n" + o.err);
  }
}

// One of the three, chosen by `rng`; returns the kind for the counts.
std::string OutsideOutCase(const Args& args, const Workspace& w, int c, std::mt19937_64& rng,
                           Failures* failures) {
  switch (Uniform(rng, 0, 2)) {
    case 0:
      ManifestTraversalCase(args, w, c, rng, failures);
      return "manifest traversal";
    case 1:
      LockCase(args, w, c, rng, failures);
      return "lock not a file of its own";
    default:
      OutInsideLogsCase(args, w, c, rng, failures);
      return "--out inside the logs";
  }
}

// ---- Hostile inputs that must stop quickly (issue 15, items 5 and 6) ----------------------------
//
// Each case runs once, after the random ones, bounded like every run by --run-timeout-s, and
// restores the workspace. Asserted: no hang, no signal, the expected exit codes, and the clear
// message (on stderr, or in the error row of results.json for a bad log in a campaign).

// Checks a run that must end with one of `codes` and show `message` in `where`. A hang or a
// crash is reported here unless CheckRun, which reports them too, has seen the run.
void ExpectStop(const Outcome& o, int case_no, const std::string& kind,
                const std::vector<int>& codes, const std::string& where, const std::string& message,
                Failures* failures, bool after_check_run = false) {
  if (o.timed_out || o.signal) {
    if (after_check_run) return;
    failures->Add(case_no, kind,
                  o.timed_out ? "no answer within the bound: a hang"
                              : "crashed with signal " + std::to_string(o.signal));
    return;
  }
  if (std::find(codes.begin(), codes.end(), o.exit_code) == codes.end()) {
    failures->Add(case_no, kind, "exit code " + std::to_string(o.exit_code) + "\n" + o.err);
  }
  if (where.find(message) == std::string::npos) {
    failures->Add(case_no, kind, "no message '" + message + "' in:\n" + where.substr(0, 2000));
  }
}

// The results.json text of OUT ("" when it is not a regular file: never read a FIFO).
std::string ResultsText(const Workspace& w) {
  const std::string path = w.out + "/results.json";
  return fs::is_regular_file(fs::symlink_status(path)) ? ReadFile(path) : "";
}

// A log that is not a regular file among the logs: a FIFO, or a symlink to /dev/urandom. An error
// row naming it; the campaign goes on.
void CaseSpecialFileAmongLogs(const Args& args, const Workspace& w, int case_no, bool fifo,
                              Failures* failures) {
  const std::string kind = fifo ? "FIFO among the logs" : "log symlinked to /dev/urandom";
  const std::string path = w.logs + "/pitch_30/trial_9.csv";
  std::error_code ec;
  if (fifo && mkfifo(path.c_str(), 0644) != 0) ec = std::error_code(errno, std::generic_category());
  if (!fifo) fs::create_symlink("/dev/urandom", path, ec);
  if (ec) {
    failures->Add(case_no, kind, "cannot create " + path + ": " + ec.message());
    return;
  }
  const Outcome o =
      Wait(Start(ProcessArgv(args, w, false), w.harness + "/hostile"), args.run_timeout_s);
  CheckRun(o, w, case_no, kind, failures);
  ExpectStop(o, case_no, kind, {0, 1}, ResultsText(w),
             fifo ? "trial_9.csv: is a FIFO (named pipe), not a regular file"
                  : "trial_9.csv: is a character device, not a regular file",
             failures, /*after_check_run=*/true);
  fs::remove(path);
}

// `fit` and `process` with /dev/zero as the config: refused before reading.
void CaseDevZeroConfig(const Args& args, const Workspace& w, int case_no, Failures* failures) {
  const std::string log = w.logs + "/pitch_0/trial_1.csv";
  for (const std::vector<std::string>& argv :
       {std::vector<std::string>{args.binary, "fit", "/dev/zero", log},
        std::vector<std::string>{args.binary, "process", "/dev/zero", "--out", w.out}}) {
    const Outcome o = Wait(Start(argv, w.harness + "/hostile"), args.run_timeout_s);
    ExpectStop(o, case_no, "/dev/zero as the config (" + argv[1] + ")", {2}, o.err,
               "/dev/zero: is a character device, not a regular file", failures);
  }
}

// `cat a.gz b.gz > log`: one log in two gzip members gives the baseline's ellipse.
void CaseMultiMemberGzip(const Args& args, Workspace& w, int case_no, Failures* failures) {
  const std::string kind = "multi-member gzip log";
  const std::string path = w.logs + "/pitch_0/trial_1.csv";
  const std::string& text = w.pristine.at(path);
  const size_t half = text.find('\n', text.size() / 2) + 1;
  WriteFile(path,
            bifilar::GzipCompress(text.substr(0, half)) + bifilar::GzipCompress(text.substr(half)));
  const Outcome o =
      Wait(Start(ProcessArgv(args, w, false), w.harness + "/hostile"), args.run_timeout_s);
  CheckRun(o, w, case_no, kind, failures);
  ExpectStop(o, case_no, kind, {0}, o.out + o.err, "Traces:", failures, /*after_check_run=*/true);
  if (o.exit_code == 0) CheckBaseline(w, case_no, kind, failures);
  w.RestoreLogs();
}

// A gzip bomb: 110 members of 10 MB of zeros each (~1 MB on disk, 1.1 GB inflated), above the
// default decompressed-log cap (1000 MB): an error row, inflation stopped at the cap.
void CaseGzipBomb(const Args& args, const Workspace& w, int case_no, Failures* failures) {
  const std::string kind = "gzip bomb";
  const std::string path = w.logs + "/pitch_60/trial_9.csv";
  const std::string member = bifilar::GzipCompress(std::string(10'000'000, '0'));
  std::string bomb;
  for (int i = 0; i < 110; ++i) bomb += member;
  WriteFile(path, bomb);
  const Outcome o =
      Wait(Start(ProcessArgv(args, w, false), w.harness + "/hostile"), args.run_timeout_s);
  CheckRun(o, w, case_no, kind + " (" + std::to_string(bomb.size()) + " bytes)", failures);
  ExpectStop(o, case_no, kind, {0, 1}, ResultsText(w),
             "too large for a log once decompressed: more than the cap of 1000000000 bytes; "
             "raise limits.max_decompressed_log_mb",
             failures, /*after_check_run=*/true);
  fs::remove(path);
}

// A FIFO in place of OUT/results.json or of a cache entry: `process` refuses before any fit and
// `report` refuses to read it; both name it.
void CaseFifoInOutput(const Args& args, const Workspace& w, int case_no, bool cache_entry,
                      Failures* failures) {
  const std::string kind = cache_entry ? "FIFO as a cache entry" : "FIFO as results.json";
  std::string path = w.out + "/results.json";
  if (cache_entry) {
    std::vector<std::string> entries;
    for (const auto& e : fs::directory_iterator(w.out + "/cache"))
      entries.push_back(e.path().string());
    std::sort(entries.begin(), entries.end());
    if (entries.empty()) {
      failures->Add(case_no, kind, "no cache entry to replace");
      return;
    }
    path = entries.front();
  }
  const std::string saved = ReadFile(path);
  fs::remove(path);
  if (mkfifo(path.c_str(), 0644) != 0) {
    failures->Add(case_no, kind, "cannot create " + path);
    WriteFile(path, saved);
    return;
  }
  const std::string message = path + ": is a FIFO (named pipe), not a regular file";
  const Outcome o =
      Wait(Start(ProcessArgv(args, w, false), w.harness + "/hostile"), args.run_timeout_s);
  // `process` checks the manifest first: a recorded file that is no longer a regular file makes
  // it refuse the manifest, naming the entry (pipeline/store/output_set.h); either refusal will do.
  const std::string entry = path.substr(w.out.size() + 1);
  const std::string refused = "entry \"" + entry + "\" refused: is not a regular file";
  ExpectStop(o, case_no, kind + " (process)", {2}, o.err,
             o.err.find(refused) != std::string::npos ? refused : message, failures);
  const Outcome r =
      Wait(Start({args.binary, "report", w.out}, w.harness + "/hostile"), args.run_timeout_s);
  if (cache_entry) {  // report reads no cache entry: it only has to end
    ExpectStop(r, case_no, kind + " (report)", {0, 2}, "", "", failures);
  } else {
    ExpectStop(r, case_no, kind + " (report)", {2}, r.err, message, failures);
  }
  fs::remove(path);
  WriteFile(path, saved);
}

// "Billion laughs" in the config: 10 levels of 9 aliases (~0.5 kB). Refused at the first alias.
void CaseAliasBomb(const Args& args, const Workspace& w, int case_no, Failures* failures) {
  const std::string kind = "YAML alias bomb in the config";
  std::string bomb = "laughs:\n  a0: &a0 [lol, lol, lol, lol, lol, lol, lol, lol, lol]\n";
  for (int level = 1; level <= 10; ++level) {
    bomb += "  a" + std::to_string(level) + ": &a" + std::to_string(level) + " [";
    for (int k = 0; k < 9; ++k) bomb += (k ? ", *a" : "*a") + std::to_string(level - 1);
    bomb += "]\n";
  }
  WriteFile(w.config_path, w.config_text + bomb);
  const Outcome o =
      Wait(Start(ProcessArgv(args, w, false), w.harness + "/hostile"), args.run_timeout_s);
  CheckRun(o, w, case_no, kind, failures);
  ExpectStop(o, case_no, kind, {2}, o.err, "YAML alias '*a0'", failures, /*after_check_run=*/true);
  w.RestoreConfig();
}

// Issue 23: commands that would write over a user's file, the campaign's input or outputs, or a
// link to a descriptor, refuse (exit 2, the file named); the sentinel and CheckRun assert that
// nothing outside OUT changed. The link to /proc/self/fd/1 lives in the harness folder.
void CaseNoOverwrite(const Args& args, const Workspace& w, int case_no, Failures* failures) {
  const std::string log = w.logs + "/pitch_0/trial_1.csv";
  const std::string link = w.harness + "/stdout_link";
  std::error_code ec;
  fs::remove(link, ec);
  fs::create_symlink("/proc/self/fd/1", link, ec);
  const std::vector<std::string> trace = {
      "--inertia-kg-m2", "0.4", "--mass-kg", "6", "-L", "2", "-D", "1", "--duration-s", "10"};
  struct Run {
    std::vector<std::string> argv;
    std::string message;
  };
  std::vector<Run> runs = {
      {{args.binary, "simulate", "--trace", log}, "simulate --trace: " + log + " exists"},
      {{args.binary, "simulate", "--trace", w.harness + "/sim.csv", "--truth", w.thesis},
       "simulate --truth: " + w.thesis + " exists"},
      {{args.binary, "simulate", "--trace", link, "--force"}, link + ": is a symbolic link"},
      {{args.binary, "init", w.thesis, "--rig", "2,1,6"}, "init: " + w.thesis + " exists"},
      {{args.binary, "init", link, "--rig", "2,1,6", "--force"}, link + ": is a symbolic link"},
      {{args.binary, "init", w.harness + "/i.yaml", "--rig", "2000,1000,6"}, "if this is in mm"},
      {{args.binary, "export", w.out, "--format", "csv", "--out", w.out + "/results.json",
        "--force"},
       "is the input"},
      {{args.binary, "export", w.out, "--format", "csv", "--out",
        w.out + "/../" + fs::path(w.out).filename().string() + "/traces.csv", "--force"},
       "of the output folder"},
      {{args.binary, "export", w.out, "--format", "csv", "--out", w.thesis}, "exists"},
      {{args.binary, "export", w.out, "--format", "csv", "--out", link, "--force"},
       "is a symbolic link"},
  };
  for (Run& run : runs) {
    if (run.argv[1] == "simulate") run.argv.insert(run.argv.end(), trace.begin(), trace.end());
    const std::string kind =
        "no overwrite: bifilar " + run.argv[1] + " " + run.argv[2] + " " + run.argv[3];
    const Outcome o = Wait(Start(run.argv, w.harness + "/hostile"), args.run_timeout_s);
    CheckRun(o, w, case_no, kind, failures);
    ExpectStop(o, case_no, kind, {2}, o.err, run.message, failures, /*after_check_run=*/true);
    if (!fs::is_symlink(fs::symlink_status(link, ec))) {
      failures->Add(case_no, kind, link + " (a link to /proc/self/fd/1) was replaced");
      fs::remove(link, ec);
      fs::create_symlink("/proc/self/fd/1", link, ec);
    }
  }
  w.RestoreLogs();
}

// Issue 26: ArduPilot DataFlash logs (.bin) that are not what they claim: not DataFlash, empty,
// no IMU message, an FMT that makes the IMU longer than its messages or too short for its format.
// `fit` ends (exit 1) with an error naming the file and what was found; then `inspect` over 40
// randomly damaged copies of a simulated .bin (cut, bytes flipped, garbage inserted, the FMTs
// damaged) only has to end without a crash or hang.
void CaseDataflash(const Args& args, const Workspace& w, int case_no, std::mt19937_64& rng,
                   Failures* failures) {
  using bifilar::DataflashPayload;
  using bifilar::DataflashWriter;
  const std::string dir = w.harness + "/dataflash";
  fs::create_directories(dir);
  const char* imu_format = "QBffffffIIfBBHH";
  const char* imu_labels = "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ,EG,EA,T,GH,AH,GHz,AHz";
  auto imu_log = [&](int length) {
    DataflashWriter d;
    d.Format(48, "IMU", imu_format, imu_labels, length);
    for (int k = 0; k < 50; ++k) {
      DataflashPayload p;
      p.U64(10000 * k).U8(0).F32(0.1f).F32(0).F32(0).F32(0).F32(0).F32(-9.8f);
      p.U32(0).U32(0).F32(25.0f).U8(1).U8(1).U16(1000).U16(1000);
      d.Message(48, p.str());
    }
    return d.bytes();
  };
  std::string noise(5000, '\0');
  for (char& c : noise) c = static_cast<char>(rng() % 160);  // never a3 95: no message
  DataflashWriter no_imu;
  no_imu.Format(91, "MSG", "QZ", "TimeUS,Message");
  no_imu.Message(91, DataflashPayload().U64(1).Text("ArduPlane V4.5.0", 64).str());
  struct Bad {
    std::string file, bytes, message;
  };
  const std::vector<Bad> bad = {
      {"noise.bin", noise, "noise.bin: error: not an ArduPilot DataFlash log: no message found"},
      {"empty.bin", "",
       "empty.bin: error: the file is empty (expected an ArduPilot DataFlash log)"},
      {"no_imu.bin", no_imu.bytes(), "no_imu.bin: error: an ArduPilot DataFlash log without IMU"},
      {"long_fmt.bin", imu_log(120),
       "long_fmt.bin: error: the FMT of IMU (type 48, byte 89) cannot be read: it defines the "
       "message as 120 bytes"},
      {"short_fmt.bin", imu_log(20),
       "short_fmt.bin: error: the FMT of IMU (type 48, byte 89) cannot be read: its length 20 is "
       "too short for its format"},
  };
  for (const Bad& b : bad) {
    WriteFile(dir + "/" + b.file, b.bytes);
    const Outcome o =
        Wait(Start({args.binary, "fit", w.config_path, dir + "/" + b.file}, w.harness + "/hostile"),
             args.run_timeout_s);
    ExpectStop(o, case_no, "DataFlash " + b.file, {1}, o.out + o.err, b.message, failures);
  }
  const std::string sim = dir + "/sim.bin";
  fs::remove(sim);
  const Outcome made =
      Wait(Start({args.binary, "simulate", "--trace", sim, "--inertia-kg-m2", "0.4", "--mass-kg",
                  "6", "-L", "2", "-D", "1", "--duration-s", "20", "--seed", "26"},
                 w.harness + "/hostile"),
           args.run_timeout_s);
  ExpectStop(made, case_no, "DataFlash simulate", {0}, made.out, "wrote", failures);
  const std::string clean = ReadFile(sim);
  if (clean.empty()) return;
  std::vector<std::string> argv = {args.binary, "inspect"};
  for (int k = 0; k < 40; ++k) {
    std::string bytes = clean;
    switch (k % 4) {
      case 0:
        bytes.resize(rng() % bytes.size());
        break;
      case 1:
        for (int i = 0; i < 30; ++i) bytes[rng() % bytes.size()] = static_cast<char>(rng());
        break;
      case 2:
        bytes.insert(rng() % bytes.size(), std::string(1 + rng() % 500, static_cast<char>(rng())));
        break;
      default:
        for (int i = 0; i < 3; ++i) bytes[rng() % 900] = static_cast<char>(rng());
        break;
    }
    const std::string path = dir + "/damaged_" + std::to_string(k) + ".bin";
    WriteFile(path, bytes);
    argv.push_back(path);
  }
  const Outcome o = Wait(Start(argv, w.harness + "/hostile"), args.run_timeout_s);
  ExpectStop(o, case_no, "DataFlash damaged copies (inspect)", {0, 1}, o.out, "dataflash",
             failures);
}

// ---- Issue 33 items 5 and 7 (helper `logs`): what `inspect` and `init` make of a log. ----
// A flipped bit in one DataFlash gyro float is a glitch, named; CSV header names are echoed
// without terminal controls; `init` writes no config `fit` rejects (names that collide once
// trimmed, an unreadable .bin, a 300-byte name) and takes an exact-case column as named.
void CaseLogGuessAndDamage(const Args& args, const Workspace& w, int case_no, std::mt19937_64& rng,
                           Failures* failures) {
  const std::string dir = w.harness + "/log_guess";
  fs::create_directories(dir);
  const std::string sim = dir + "/sim.bin";
  fs::remove(sim);
  const Outcome made =
      Wait(Start({args.binary, "simulate", "--trace", sim, "--inertia-kg-m2", "0.4", "--mass-kg",
                  "6", "-L", "2", "-D", "1", "--duration-s", "20", "--seed", "33"},
                 dir),
           args.run_timeout_s);
  ExpectStop(made, case_no, "log guess: simulate .bin", {0}, made.out, "wrote", failures);
  const std::string clean = ReadFile(sim);
  // Every IMU message (header a3 95 30): GyrZ at byte 20 of it (TimeUS 8, I 1, GyrX, GyrY 4 each).
  std::vector<size_t> imu;
  for (size_t at = clean.find("\xA3\x95\x30"); at != std::string::npos;
       at = clean.find("\xA3\x95\x30", at + 1)) {
    if (at + 24 <= clean.size()) imu.push_back(at);
  }
  for (int k = 0; k < 6 && imu.size() > 100; ++k) {
    std::string bytes = clean;
    const float damage[] = {-9.2e36f, NAN, INFINITY, 3e5f};
    const float value = damage[k % 4];
    std::memcpy(&bytes[imu[imu.size() - 1 - rng() % 50] + 20], &value, 4);  // near the end
    const std::string path = dir + "/flipped_" + std::to_string(k) + ".bin";
    WriteFile(path, bytes);
    const Outcome o = Wait(Start({args.binary, "inspect", path}, dir), args.run_timeout_s);
    ExpectStop(o, case_no, "log guess: damaged DataFlash gyro float", {0}, o.out,
               "dropped as glitches", failures);
  }
  std::string rows;
  for (int i = 0; i < 400; ++i) {
    const double t = 0.01 * i, rate = 0.3 * std::sin(4.19 * t) * (i > 50);  // a 1.5 s swing
    rows += std::to_string(t) + "," + std::to_string(rate * 0.01) + "," +
            std::to_string(rate * 0.02) + "," + std::to_string(rate) + "\n";
  }
  const std::string esc = dir + "/esc.csv";
  WriteFile(esc, "t,g\x1b[2Jx,gy,gz\x1b]0;owned\x07\n" + rows);
  const Outcome shown = Wait(Start({args.binary, "inspect", esc}, dir), args.run_timeout_s);
  if (shown.out.find('\x1b') != std::string::npos || shown.err.find('\x1b') != std::string::npos) {
    failures->Add(case_no, "log guess: escape sequence in a header", "echoed raw");
  }
  struct Refused {
    std::string file, text, message;
  };
  const std::vector<Refused> refused = {
      {"padded.csv", "t, gx,gy,gz,gx \n" + rows, "appears twice"},
      {"noise.bin", std::string(3000, '\x01'), "no config written"},
      {"long.csv", "time" + std::string(300, 'x') + ",gx,gy,gz\n" + rows, "of 304 bytes"},
  };
  for (const Refused& r : refused) {
    const std::string log = dir + "/" + r.file, config = log + ".yaml";
    WriteFile(log, r.text);
    fs::remove(config);
    const Outcome o =
        Wait(Start({args.binary, "init", config, "--log", log, "--rig", "2,1,6"}, dir),
             args.run_timeout_s);
    ExpectStop(o, case_no, "log guess: init refuses " + r.file, {1, 2}, o.err, r.message, failures);
    if (fs::exists(config)) failures->Add(case_no, "log guess: init " + r.file, "wrote a config");
  }
  const std::string cased = dir + "/cased.csv", cased_yaml = dir + "/cased.yaml";
  std::string both = "t,GX,GY,GZ,gx,gy,gz\n";
  for (int i = 0; i < 400; ++i) both += std::to_string(0.01 * i) + ",0,0,0,0,0,0.1\n";
  WriteFile(cased, both);
  fs::remove(cased_yaml);
  const Outcome init = Wait(Start({args.binary, "init", cased_yaml, "--log", cased, "--gyro",
                                   "gx,gy,gz", "--rig", "2,1,6"},
                                  dir),
                            args.run_timeout_s);
  ExpectStop(init, case_no, "log guess: init --gyro gx,gy,gz", {0}, init.out, "wrote", failures);
  if (ReadFile(cased_yaml).find("[\"gx\", \"gy\", \"gz\"]") == std::string::npos) {
    failures->Add(case_no, "log guess: init --gyro gx,gy,gz", "config:\n" + ReadFile(cased_yaml));
  }
}

// Runs the cases above once each; returns how many ran.
// ---- Issue 33 items 1, 4, 5, 7 and issue 32 item 7 (`plan` helper): no user file replaced by
// `plan --rig`, `fit --plot` or `ellipse --plot`, never a link; the figure's folder checked before
// PLplot runs; a 10 kHz IMU on a long-period rig answered within the bound; an unreachable target
// exits 1 naming the floor. The sentinel asserts nothing outside the harness folder changed.
void CasePlanNoReplace(const Args& args, const Workspace& w, int case_no, Failures* failures) {
  const std::string h = w.harness + "/plan";
  std::error_code ec;
  fs::remove_all(h, ec);
  fs::create_directories(h + "/plots", ec);
  WriteFile(h + "/mine.png", "mine");
  WriteFile(h + "/plots/ellipse_polar.png", "mine");
  WriteFile(h + "/file", "mine");
  fs::create_symlink(h + "/mine.png", h + "/link.png", ec);
  std::string table = "pitch_deg,inertia\n";
  for (int d = -80; d <= 90; d += 10) {
    const double s = std::sin(d * bifilar::kRadPerDeg);
    table += std::to_string(d) + "," + std::to_string(2.8 - 0.4 * s * s + 0.001 * (d % 3)) + "\n";
  }
  WriteFile(h + "/table.csv", table);
  const std::vector<std::string> quad = {
      args.binary, "plan",         "--rig", "--mass",           "0.0343", "--inertia",
      "1.6e-5",    "--max-length", "0.594", "--max-separation", "0.030",  "--target-percent"};
  const auto plan = [&](const std::string& target, std::vector<std::string> extra) {
    std::vector<std::string> argv = quad;
    argv.push_back(target);
    argv.insert(argv.end(), extra.begin(), extra.end());
    return argv;
  };
  struct Run {
    std::vector<std::string> argv;
    std::vector<int> codes;
    std::string message;
  };
  const std::vector<Run> runs = {
      {plan("1", {"--write-config", w.thesis}), {2}, "exists"},
      {plan("1", {"--plot", h + "/mine.png"}), {2}, "exists"},
      {plan("1", {"--plot", h + "/link.png", "--force"}), {2}, "is a symbolic link"},
      {plan("1", {"--write-config", h + "/x.svg", "--plot", h + "/./x.svg"}), {2}, "same file"},
      {plan("1", {"--write-config", ""}), {2}, "empty"},
      {plan("1", {"--plot", h + "/file/p.png"}), {2}, "cannot create the folder"},
      {plan("0.01", {}), {1}, "TARGET UNREACHABLE"},
      {{args.binary, "plan", "--rig", "--mass", "2.5", "--inertia", "16", "--max-length", "3",
        "--max-separation", "1", "--target-percent", "0.5", "--imu-rate", "10000"},
       {1},
       "NO RIG FITS THE PERIOD WINDOW"},
      {{args.binary, "ellipse", h + "/table.csv", "--bootstrap", "0", "--plot", h + "/plots"},
       {2},
       "will not replace"},
  };
  for (const Run& run : runs) {
    const std::string kind = "plan/figures: bifilar " + run.argv[1] + " ... " + run.argv.back();
    const Outcome o = Wait(Start(run.argv, w.harness + "/hostile"), args.run_timeout_s);
    CheckOutside(o, case_no, kind, failures);
    ExpectStop(o, case_no, kind, run.codes, run.codes[0] == 1 ? o.out : o.err, run.message,
               failures);
    if (o.err.find("PLPLOT") != std::string::npos ||
        o.err.find("Can't open") != std::string::npos) {
      failures->Add(case_no, kind, "PLplot reached a path it cannot open:\n" + o.err);
    }
    for (const std::string& path : {h + "/mine.png", h + "/plots/ellipse_polar.png"}) {
      if (ReadFile(path) != "mine") {
        failures->Add(case_no, kind, path + ": a user's file was replaced");
      }
    }
    if (!fs::is_symlink(fs::symlink_status(h + "/link.png", ec))) {
      failures->Add(case_no, kind, h + "/link.png: a link was replaced");
    }
  }
  fs::remove_all(h, ec);
}

int RunHostileInputCases(const Args& args, Workspace& w, int first_case_no, Failures* failures) {
  int c = first_case_no;
  CaseSpecialFileAmongLogs(args, w, c++, /*fifo=*/true, failures);
  CaseSpecialFileAmongLogs(args, w, c++, /*fifo=*/false, failures);
  CaseDevZeroConfig(args, w, c++, failures);
  CaseMultiMemberGzip(args, w, c++, failures);
  CaseGzipBomb(args, w, c++, failures);
  CaseFifoInOutput(args, w, c++, /*cache_entry=*/false, failures);
  CaseFifoInOutput(args, w, c++, /*cache_entry=*/true, failures);
  CaseAliasBomb(args, w, c++, failures);
  CaseNoOverwrite(args, w, c++, failures);
  std::mt19937_64 rng(26);
  CaseDataflash(args, w, c++, rng, failures);
  CaseLogGuessAndDamage(args, w, c++, rng, failures);
  CasePlanNoReplace(args, w, c++, failures);  // `plan` helper, issue 33
  return c - first_case_no;
}

// ---- Issue 33: the fourth hostile-input sweep (report paths, regexes, repeats, runs tables)
// ------
//
// Once each, after the hostile inputs above. Asserted as everywhere: no hang, no crash, the
// expected exit code and message, nothing outside OUT changed (the sentinel).

// Runs `argv` once as a hostile case: bounded, checked for the files outside OUT, the exit code
// and the message.
Outcome RunSweep4(const Args& args, const Workspace& w, int case_no, const std::string& kind,
                  const std::vector<std::string>& argv, const std::vector<int>& codes,
                  const std::string& message, Failures* failures) {
  const Outcome o = Wait(Start(argv, w.harness + "/sweep4"), args.run_timeout_s);
  CheckOutside(o, case_no, kind, failures);
  ExpectStop(o, case_no, kind, codes, o.out + o.err, message, failures);
  return o;
}

// Item 2: a results.json naming figures outside OUT (`../`, an absolute path, a link out of OUT):
// `report` refuses naming the key and the value; the files outside stay as they were.
void CaseReportFiguresOutside(const Args& args, const Workspace& w, int case_no,
                              Failures* failures) {
  const std::string kind = "report: figure outside OUT";
  const Outcome fresh =
      Wait(Start(ProcessArgv(args, w, true), w.harness + "/sweep4"), args.run_timeout_s);
  CheckRun(fresh, w, case_no, kind + " (process first)", failures);
  const std::string results_path = w.out + "/results.json";
  const std::string text = ResultsText(w);
  nlohmann::json results = nlohmann::json::parse(text, nullptr, false);
  if (results.is_discarded() || !results.contains("traces") || results["traces"].empty()) {
    failures->Add(case_no, kind, "no results.json to start from");
    return;
  }
  const std::string drawing = w.dir + "/precious/drawing.svg";
  WriteFile(drawing,
            "<?xml version=\"1.0\"?>\n<!-- mine -->\n<svg width=\"1\" height=\"1\"></svg>\n");
  const std::string link = w.out + "/figures/leaving.svg";
  std::error_code ec;
  fs::create_symlink(drawing, link, ec);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"figures.moments", "../../precious/drawing.svg"},
      {"figures.polar", w.thesis},
      {"traces[0].figure", "leaving.svg"},
      {"traces[0].sweep_figure", "../../precious/thesis.txt"}};
  for (const auto& [key, value] : cases) {
    nlohmann::json hostile = results;
    if (key == "figures.moments") hostile["figures"]["moments"] = value;
    if (key == "figures.polar") hostile["figures"]["polar"] = value;
    if (key == "traces[0].figure") hostile["traces"][0]["figure"] = value;
    if (key == "traces[0].sweep_figure") hostile["traces"][0]["sweep_figure"] = value;
    WriteFile(results_path, hostile.dump(1));
    RunSweep4(args, w, case_no, kind + " " + key, {args.binary, "report", w.out}, {2},
              key + " = \"" + value + "\"", failures);
    if (!fs::is_symlink(fs::symlink_status(link, ec))) {
      failures->Add(case_no, kind + " " + key, link + " (a link) was replaced");
    }
  }
  WriteFile(results_path, text);
  fs::remove(link, ec);
  fs::remove(drawing, ec);
}

// Item 3: --group-by patterns that crashed std::regex or ran for minutes: refused or answered.
void CaseGroupByPatterns(const Args& args, const Workspace& w, int case_no, Failures* failures) {
  const std::string l1 = w.logs + "/pitch_0/trial_1.csv", l2 = w.logs + "/pitch_0/trial_2.csv";
  std::string deep = w.harness + "/";
  for (int i = 0; i < 8000; ++i) deep += "a/";
  const std::string a28 = w.harness + "/" + std::string(28, 'a');
  struct Pattern {
    std::string what, pattern;
    std::vector<std::string> logs;
    std::vector<int> codes;
    std::string message;
  };
  const std::vector<Pattern> patterns = {
      {"100 kB", std::string(100000, 'a'), {l1, l2}, {2}, "longer than 4096 bytes"},
      {"20,000 nested groups",
       std::string(20000, '(') + "a" + std::string(20000, ')'),
       {l1, l2},
       {2},
       "longer than 4096 bytes"},
      {"2,000 nested groups",
       std::string(2000, '(') + "trial" + std::string(2000, ')'),
       {l1, l2},
       {0, 1},
       "repeats: 2 log(s) in 1 group(s)"},
      // One group or two: the pattern matches (case ignored) up to the last x of the path, and
      // the workspace's random name may hold one. Either way answered, never a crash.
      {"'/((.|/)*)x' on a 16 kB path",
       "/((.|/)*)x",
       {deep + "s-1.csv", deep + "s-2.csv"},
       {1},
       "repeats: 2 log(s) in "},
      {"'(a+)+$' on 28 a's and a b",
       "(a+)+$",
       {a28 + "b", a28 + "ab"},
       {1},
       "repeats: 2 log(s) in 2 group(s)"},
      {"a backreference", "(a)\\1", {l1, l2}, {2}, "not a regular expression RE2 accepts"}};
  double slowest_s = 0.0;
  for (const Pattern& p : patterns) {
    std::vector<std::string> argv = {args.binary, "fit", w.config_path};
    argv.insert(argv.end(), p.logs.begin(), p.logs.end());
    argv.insert(argv.end(), {"--repeats", "--group-by", p.pattern});
    const Outcome o =
        RunSweep4(args, w, case_no, "--group-by " + p.what, argv, p.codes, p.message, failures);
    slowest_s = std::max(slowest_s, o.seconds);
  }
  std::cout << "bifilar_stress: --group-by patterns of issue 33: slowest run " << slowest_s
            << " s (fits included)\n";
}

// Item 5: the same swing with CRLF line ends, an extra newline and a comment line is one repeat:
// the three copies are dropped, each named.
void CaseRepeatsJudgedOnSamples(const Args& args, const Workspace& w, int case_no,
                                Failures* failures) {
  const std::string kind = "repeats: the same samples";
  const std::string dir = w.harness + "/same_samples";
  fs::create_directories(dir);
  const std::string text = ReadFile(w.logs + "/pitch_0/trial_1.csv");
  std::string crlf;
  for (char c : text) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  const std::vector<std::pair<std::string, std::string>> copies = {
      {dir + "/swing-1.csv", text},
      {dir + "/swing-2.csv", crlf},
      {dir + "/swing-3.csv", text + "\n"},
      {dir + "/swing-4.csv", "# saved again\n" + text}};
  std::vector<std::string> argv = {args.binary, "fit", w.config_path};
  for (const auto& [path, bytes] : copies) {
    WriteFile(path, bytes);
    argv.push_back(path);
  }
  argv.insert(argv.end(), {"--repeats", "--json"});
  const Outcome o =
      RunSweep4(args, w, case_no, kind, argv, {0, 1}, "identical_logs_dropped", failures);
  const nlohmann::json j = nlohmann::json::parse(o.out, nullptr, false);
  if (j.is_discarded() || !j.contains("identical_logs_dropped") ||
      j["identical_logs_dropped"].size() != 3) {
    failures->Add(case_no, kind, "not 3 copies dropped:\n" + o.out.substr(0, 2000));
  }
}

// Items 4 and 5: a runs table naming roll -0 and 0 makes one group; tables beyond their bounds
// (size, line length) are refused by the bound; 300 same-size files are grouped at once.
void CaseRunsTablesAndManyLogs(const Args& args, const Workspace& w, int case_no,
                               Failures* failures) {
  const std::string dir = w.harness + "/tables";
  fs::create_directories(dir);
  const std::string l1 = w.logs + "/pitch_0/trial_1.csv", l2 = w.logs + "/pitch_0/trial_2.csv";
  WriteFile(dir + "/zero.csv",
            "path,roll_deg,pitch_deg\npitch_0/trial_1.csv,-0,0\n"
            "pitch_0/trial_2.csv,0,-0\n");
  const Outcome zero = RunSweep4(
      args, w, case_no, "runs table: roll -0 and 0",
      {args.binary, "fit", w.config_path, l1, l2, "--repeats", "--runs-table", dir + "/zero.csv"},
      {0, 1}, "repeats: 2 log(s) in 1 group(s)", failures);
  (void)zero;
  WriteFile(dir + "/big.csv", "path,group\n" + std::string(17000000, 'x') + ",A\n");
  RunSweep4(
      args, w, case_no, "runs table: 17 MB",
      {args.binary, "fit", w.config_path, l1, l2, "--repeats", "--runs-table", dir + "/big.csv"},
      {2}, "too large for a runs table", failures);
  WriteFile(dir + "/line.csv", "path,group\n" + std::string(100000, 'x') + ",A\n");
  RunSweep4(
      args, w, case_no, "runs table: a 100 kB line",
      {args.binary, "fit", w.config_path, l1, l2, "--repeats", "--runs-table", dir + "/line.csv"},
      {2}, "line.csv:2: a line of 100002 bytes", failures);
  fs::remove(dir + "/big.csv");
  std::vector<std::string> argv = {args.binary, "fit", w.config_path};
  for (int k = 0; k < 300; ++k) {
    char text[64];
    std::snprintf(text, sizeof(text), "t,gx,gy,gz\n0,0,0,0.%03d\n", k);
    const std::string path = dir + "/same-" + std::to_string(k) + ".csv";
    WriteFile(path, text);
    argv.push_back(path);
  }
  argv.push_back("--repeats");
  RunSweep4(args, w, case_no, "300 same-size files", argv, {1}, "repeats: 300 log(s)", failures);
}

// Item 5 (messages): `plan --rig --repeat-scatter 1e308` is refused, never "inf %".
void CasePlanRepeatScatter(const Args& args, const Workspace& w, int case_no, Failures* failures) {
  const Outcome o = RunSweep4(
      args, w, case_no, "plan --repeat-scatter 1e308",
      {args.binary, "plan", "--rig", "--inertia", "1e-5", "--target-percent", "1", "--mass", "1",
       "--max-length", "0.5", "--max-separation", "0.03", "--repeat-scatter", "1e308"},
      {2}, "--repeat-scatter = 1e+308; must be in [0, 50]", failures);
  if ((o.out + o.err).find("inf %") != std::string::npos) {
    failures->Add(case_no, "plan --repeat-scatter 1e308", "printed inf %:\n" + o.out + o.err);
  }
}

// Runs the cases of issue 33 once each; returns how many ran.
int RunSweep4Cases(const Args& args, const Workspace& w, int first_case_no, Failures* failures) {
  int c = first_case_no;
  CaseReportFiguresOutside(args, w, c++, failures);
  CaseGroupByPatterns(args, w, c++, failures);
  CaseRepeatsJudgedOnSamples(args, w, c++, failures);
  CaseRunsTablesAndManyLogs(args, w, c++, failures);
  CasePlanRepeatScatter(args, w, c++, failures);
  return c - first_case_no;
}

// The command line into *args; false (after a message) when it is wrong.
bool ParseArgs(int argc, char** argv, Args* args) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << a << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--binary")
      args->binary = next();
    else if (a == "--source")
      args->source = next();
    else if (a == "--seed")
      args->seed = std::stoull(next());
    else if (a == "--cases")
      args->cases = std::stoi(next());
    else if (a == "--run-timeout-s")
      args->run_timeout_s = std::stod(next());
    else if (a == "--keep")
      args->keep = true;
    else {
      std::cerr << "usage: bifilar_stress --binary BIFILAR --source REPO [--seed N] [--cases N] "
                   "[--run-timeout-s S] [--keep]\n";
      return false;
    }
  }
  if (args->binary.empty() || args->source.empty()) {
    std::cerr << "bifilar_stress: --binary and --source are required\n";
    return false;
  }
  return true;
}

// Real logs (optional): the Crazyflie logs beside the repository, with their config written.
std::vector<std::string> RealLogs(const Args& args, const Workspace& w) {
  const std::string crazyflie = args.source + "/../shared/data/crazyflie";
  std::vector<std::string> real_logs;
  if (fs::is_directory(crazyflie)) {
    for (const auto& e : fs::directory_iterator(crazyflie)) {
      if (e.path().extension() == ".csv") real_logs.push_back(e.path().string());
    }
    std::sort(real_logs.begin(), real_logs.end());
    WriteFile(w.dir + "/crazyflie.yaml",
              "gravity_mps2: 9.8066\n"
              "rig: {filar_length_m: 0.594, filar_separation_m: 0.030, mass_kg: 0.0343}\n"
              "imu:\n  time: {column: t, unit: s}\n  gyro: {columns: [wx, wy, wz], unit: rad/s}\n"
              "  swing_axis: [0, 0, 1]\n");
  }
  return real_logs;
}

// What every random case gets: the run's settings, the workspace, its case number, the random
// stream and where failures go.
struct CaseContext {
  const Args& args;
  Workspace& w;
  int c;
  std::mt19937_64& rng;
  Failures* failures;
  std::string prefix;  // of the runs' output files
};

// 1-3 logs mutated: a bad log is an error row, never the end of the run.
std::string CaseLogMutation(CaseContext& x) {
  const std::string kind = "log mutation";
  std::string what;
  const int k = Uniform(x.rng, 1, 3);
  std::vector<std::string> paths;
  for (const auto& [path, text] : x.w.pristine) paths.push_back(path);
  for (int i = 0; i < k; ++i) {
    const std::string& path = Pick(paths, x.rng);
    std::string how;
    WriteFile(path, MutateLog(ReadFile(path), x.rng, &how));
    what += fs::path(path).filename().string() + ": " + how + "; ";
  }
  const Outcome o = Wait(Start(ProcessArgv(x.args, x.w, false), x.prefix), x.args.run_timeout_s);
  CheckRun(o, x.w, x.c, kind + " (" + what + ")", x.failures);
  if (o.exit_code == 2) {  // a bad log is an error row, never the end of the run
    x.failures->Add(x.c, kind + " (" + what + ")", "exit 2 for a bad log:\n" + o.err);
  }
  x.w.RestoreLogs();
  return kind;
}

// The config mutated.
std::string CaseConfigMutation(CaseContext& x) {
  const std::string kind = "config mutation";
  std::string what;
  WriteFile(x.w.config_path, MutateConfig(x.w.config_text, x.rng, &what));
  CheckRun(Wait(Start(ProcessArgv(x.args, x.w, false), x.prefix), x.args.run_timeout_s), x.w, x.c,
           kind + " (" + what + ")", x.failures);
  x.w.RestoreConfig();
  return kind;
}

// 1-4 cache entries tampered with: the run refits them and gives the baseline.
std::string CaseCacheTampering(CaseContext& x) {
  const std::string kind = "cache tampering";
  std::string what;
  const int k = Uniform(x.rng, 1, 4);
  for (int i = 0; i < k; ++i) what += TamperCache(x.w, x.rng) + "; ";
  const Outcome o = Wait(Start(ProcessArgv(x.args, x.w, false), x.prefix), x.args.run_timeout_s);
  CheckRun(o, x.w, x.c, kind + " (" + what + ")", x.failures);
  if (o.exit_code == 0) {
    CheckBaseline(x.w, x.c, kind + " (" + what + ")", x.failures);
  } else {
    x.failures->Add(x.c, kind + " (" + what + ")",
                    "exit " + std::to_string(o.exit_code) + "\n" + o.err);
  }
  return kind;
}

// A run killed at a random time (up to 1.2 forced runs), then `report` on what it left, then a
// rerun that must give the baseline.
std::string CaseKill(CaseContext& x, double forced_s) {
  const std::string kind = "kill -9";
  const Args& args = x.args;
  const bool force = Uniform(x.rng, 0, 1) == 1;
  const double at_s = std::uniform_real_distribution<double>(0.0, 1.2 * forced_s)(x.rng);
  const std::string what = (force ? "--force, " : "") + std::to_string(at_s) + " s";
  const Outcome killed =
      Wait(Start(ProcessArgv(args, x.w, force), x.prefix), args.run_timeout_s, at_s);
  CheckRun(killed, x.w, x.c, kind + " (" + what + ")", x.failures);
  // `report` on what the kill left: a page from a consistent set, or a refusal naming it.
  const bool mixed = !bifilar::CheckOutputSet(x.w.out, false).empty();
  const Outcome report =
      Wait(Start({args.binary, "report", x.w.out}, x.prefix), args.run_timeout_s);
  CheckOutside(report, x.c, kind + " then report (" + what + ")", x.failures);
  if (report.signal || report.timed_out || (report.exit_code != 0 && report.exit_code != 2) ||
      (mixed && report.exit_code != 2) ||
      (report.exit_code == 2 && report.err.find("error") == std::string::npos)) {
    x.failures->Add(x.c, kind + " then report (" + what + ")",
                    std::string(mixed ? "mixed set, " : "") + "report exit " +
                        std::to_string(report.exit_code) + "\n" + report.err);
  }
  const Outcome rerun = Wait(Start(ProcessArgv(args, x.w, false), x.prefix), args.run_timeout_s);
  CheckRun(rerun, x.w, x.c, kind + " then rerun (" + what + ")", x.failures);
  if (rerun.exit_code == 0) {
    CheckBaseline(x.w, x.c, kind + " then rerun (" + what + ")", x.failures);
  } else {
    x.failures->Add(x.c, kind + " then rerun (" + what + ")",
                    "rerun exit " + std::to_string(rerun.exit_code) + "\n" + rerun.err);
  }
  return kind;
}

// Two runs at once: one succeeds, the other succeeds too or is refused for the lock.
std::string CaseConcurrentRuns(CaseContext& x) {
  const std::string kind = "two concurrent runs";
  const Args& args = x.args;
  const bool force_a = Uniform(x.rng, 0, 1), force_b = Uniform(x.rng, 0, 1);
  const Process a = Start(ProcessArgv(args, x.w, force_a), x.prefix + "_a");
  const Process b = Start(ProcessArgv(args, x.w, force_b), x.prefix + "_b");
  const Outcome oa = Wait(a, args.run_timeout_s), ob = Wait(b, args.run_timeout_s);
  CheckRun(oa, x.w, x.c, kind + " (first)", x.failures);
  CheckRun(ob, x.w, x.c, kind + " (second)", x.failures);
  int ok = 0;
  for (const Outcome* o : {&oa, &ob}) {
    if (o->exit_code == 0)
      ++ok;
    else if (!(o->exit_code == 2 &&
               o->err.find("in use by another bifilar run") != std::string::npos)) {
      x.failures->Add(x.c, kind,
                      "a run neither succeeded nor was refused for the lock: exit " +
                          std::to_string(o->exit_code) + "\n" + o->err);
    }
  }
  if (ok == 0) x.failures->Add(x.c, kind, "neither run succeeded");
  CheckRun(Wait(Start(ProcessArgv(args, x.w, false), x.prefix), args.run_timeout_s), x.w, x.c,
           kind + " then rerun", x.failures);
  CheckBaseline(x.w, x.c, kind, x.failures);
  return kind;
}

// A user's file in figures/ or cache/: the run refuses the folder and keeps the file.
std::string CaseUserFileInOutput(CaseContext& x) {
  const std::string kind = "user file in figures/";
  const std::string path = x.w.out + "/" + (Uniform(x.rng, 0, 1) ? "figures" : "cache") + "/user_" +
                           std::to_string(x.c) + ".png";
  WriteFile(path, "mine");
  const Outcome o =
      Wait(Start(ProcessArgv(x.args, x.w, Uniform(x.rng, 0, 1)), x.prefix), x.args.run_timeout_s);
  CheckRun(o, x.w, x.c, kind, x.failures);
  if (o.exit_code != 2 || o.err.find("did not write") == std::string::npos) {
    x.failures->Add(x.c, kind,
                    "a folder holding a user's file was used: exit " + std::to_string(o.exit_code));
  }
  if (ReadFile(path) != "mine") x.failures->Add(x.c, kind, "the user's file was removed: " + path);
  fs::remove(path);
  return kind;
}

// A real log mutated, through `fit --json`: no hang, crash or non-finite number.
std::string CaseRealLogMutation(CaseContext& x, const std::vector<std::string>& real_logs) {
  const std::string kind = "real log mutation";
  std::string what;
  const std::string& source = Pick(real_logs, x.rng);
  const std::string path = x.w.dir + "/real/" + fs::path(source).filename().string();
  WriteFile(path, MutateLog(CrazyflieSeries(ReadFile(source)), x.rng, &what));
  const Outcome o =
      Wait(Start({x.args.binary, "fit", x.w.dir + "/crazyflie.yaml", path, "--json"}, x.prefix),
           x.args.run_timeout_s);
  const std::string label = kind + " (" + fs::path(source).filename().string() + ": " + what + ")";
  if (o.timed_out) x.failures->Add(x.c, label, "no answer within the bound: a hang");
  if (o.signal) {
    x.failures->Add(x.c, label, "crashed with signal " + std::to_string(o.signal) + "\n" + o.err);
  }
  CheckOutside(o, x.c, label, x.failures);
  if (!o.timed_out && !o.signal && (o.exit_code < 0 || o.exit_code > 2)) {
    x.failures->Add(x.c, label, "exit code " + std::to_string(o.exit_code));
  }
  if (o.exit_code == 0 || o.exit_code == 1) {
    const std::string bad = NonFiniteIn(o.out, false);
    if (!bad.empty()) x.failures->Add(x.c, label, "fit --json: " + bad);
  }
  fs::remove(path);
  return kind;
}

// One random case, its family drawn from `rng` (25 % log, 15 % config, 15 % cache, 20 % kill,
// 12 % concurrent, 5 % user file, the rest real logs or a plain rerun); returns its kind.
std::string RunRandomCase(CaseContext& x, double forced_s,
                          const std::vector<std::string>& real_logs) {
  const int roll = Uniform(x.rng, 0, 99);
  if (roll < 25) return CaseLogMutation(x);
  if (roll < 40) return CaseConfigMutation(x);
  if (roll < 55) return CaseCacheTampering(x);
  if (roll < 75) return CaseKill(x, forced_s);
  if (roll < 87) return CaseConcurrentRuns(x);
  if (roll < 92) return CaseUserFileInOutput(x);
  if (!real_logs.empty()) return CaseRealLogMutation(x, real_logs);
  const std::string kind = "rerun";
  CheckRun(Wait(Start(ProcessArgv(x.args, x.w, false), x.prefix), x.args.run_timeout_s), x.w, x.c,
           kind, x.failures);
  return kind;
}

// The summary line (cases per kind, failures); the workspace removed unless --keep. The exit
// code: 0 when nothing failed.
int Summarize(const Args& args, const Workspace& w, Clock::time_point start, double forced_s,
              const std::map<std::string, int>& kinds_run, const Failures& failures) {
  const double total_s = std::chrono::duration<double>(Clock::now() - start).count();
  std::cout << "bifilar_stress: seed " << args.seed << ", " << args.cases << " cases in " << total_s
            << " s (one forced run " << forced_s << " s):";
  for (const auto& [kind, n] : kinds_run) std::cout << " " << kind << " " << n << ";";
  std::cout << " failures " << failures.count << "\n";
  if (!args.keep) {
    std::error_code ec;
    fs::remove_all(w.dir, ec);
  } else {
    std::cout << "workspace kept: " << w.dir << "\n";
  }
  return failures.count == 0 ? 0 : 1;
}

// ---- issue 34: `bifilar watch` fed bad input through standard input ----
// A log of the campaign with garbage lines, binary bytes, NaN and infinite values, a clock that
// jumps back, a line cut short, fed to `bifilar watch CONFIG - --json --save FILE` (the saved
// log in the harness folder, outside the campaign). Asserted: no crash or hang, exit 0 or 1 (2
// only with an error message: a header destroyed), every line counted (samples saved + lines
// rejected = the data lines fed), the saved log read by `bifilar fit` without any repaired row
// and giving the watch's final I to 1e-12.
int RunWatchStressCases(const Args& args, const Workspace& w, int case_no, std::mt19937_64& rng,
                        Failures* failures) {
  int runs = 0;
  std::vector<std::string> logs;
  for (const auto& [path, text] : w.pristine) logs.push_back(path);
  for (int k = 0; k < 8 && !logs.empty(); ++k, ++runs) {
    const std::string kind = "watch bad input " + std::to_string(k);
    std::istringstream in(w.pristine.at(logs[Uniform(rng, 0, static_cast<int>(logs.size()) - 1)]));
    std::string fed, line;
    long data_lines = 0;
    bool header = false;
    static const char* kBad[] = {
        "garbage here", "\x01\x02\xfe\xff", "nan,0,0,0,0,0,0", "0,inf,0,0,0,0,0",
        "1,2",          "-5,0,0,0,0,0,0",   "{\"t\": 1}"};
    while (std::getline(in, line)) {
      fed += line + "\n";
      if (line.empty() || line[0] == '#') continue;
      if (!header) {
        header = true;
        continue;
      }
      ++data_lines;
      if (Uniform(rng, 0, 40) == 0) {
        fed += std::string(kBad[Uniform(rng, 0, 6)]) + "\n";
        ++data_lines;
      }
    }
    if (Uniform(rng, 0, 1) == 0) fed += "0.5,0.1,0.";  // cut short at the end (a last line)
    const std::string input = w.harness + "/watch_in.csv", saved = w.harness + "/watch_saved.csv";
    std::error_code ec;
    fs::remove(saved, ec);
    fs::remove(saved + ".rejected.txt", ec);
    WriteFile(input, fed);
    const Outcome o = Wait(Start({"/bin/sh", "-c",
                                  args.binary + " watch " + w.config_path + " - --json --save " +
                                      saved + " < " + input},
                                 w.harness + "/watch"),
                           args.run_timeout_s);
    if (o.timed_out || o.signal || o.exit_code < 0 || o.exit_code > 2 ||
        (o.exit_code == 2 && o.err.find("error") == std::string::npos)) {
      failures->Add(case_no, kind,
                    "exit " + std::to_string(o.exit_code) + ", signal " + std::to_string(o.signal) +
                        (o.timed_out ? ", hung" : "") + "\n" + o.err);
      continue;
    }
    if (o.exit_code == 2) continue;
    const size_t last = o.out.rfind("{\"counters\"");
    const nlohmann::json final = nlohmann::json::parse(
        last == std::string::npos ? std::string("{}")
                                  : o.out.substr(last, o.out.find('\n', last) - last),
        nullptr, false);
    if (final.is_discarded() || !final.contains("logs") || final["logs"].empty()) {
      failures->Add(case_no, kind, "no final result line:\n" + o.out.substr(0, 2000));
      continue;
    }
    const nlohmann::json& log = final["logs"][0];
    const long counted = log["samples"].get<long>() + log["rejected"].get<long>();
    if (counted + (fed.back() == '.' ? -1 : 0) != data_lines && counted != data_lines) {
      failures->Add(
          case_no, kind,
          "lines fed " + std::to_string(data_lines) + ", counted " + std::to_string(counted));
    }
    const Outcome fit =
        Wait(Start({args.binary, "fit", w.config_path, saved, "--json"}, w.harness + "/watch_fit"),
             args.run_timeout_s);
    const nlohmann::json records = nlohmann::json::parse(fit.out, nullptr, false);
    if (records.is_discarded() || !records.is_array() || records.empty()) {
      failures->Add(case_no, kind, "fit on the saved log: " + fit.err);
      continue;
    }
    for (const auto& warning : records[0].value("warnings", nlohmann::json::array())) {
      if (warning.get<std::string>().find("line") != std::string::npos) {
        failures->Add(case_no, kind,
                      "the saved log needed a repair: " + warning.get<std::string>());
      }
    }
    const nlohmann::json& mine = log["record"]["inertia_total_kg_m2"];
    const nlohmann::json& theirs = records[0]["inertia_total_kg_m2"];
    if (mine.is_number() != theirs.is_number() ||
        (mine.is_number() && std::abs(mine.get<double>() - theirs.get<double>()) >
                                 1e-12 * std::abs(theirs.get<double>()))) {
      failures->Add(case_no, kind, "watch's final I " + mine.dump() + " != fit's " + theirs.dump());
    }
  }
  return runs;
}

}  // namespace

namespace {
int RunMavlinkDecoderCases(uint64_t seed, int cases, Failures* failures);  // issue 34, at the end
}  // namespace

// ParseArgs -> the baseline run -> RealLogs -> per case: OutsideOutCase (every tenth) or
// RunRandomCase -> RunHostileInputCases -> Summarize.
int main(int argc, char** argv) {
  Args args;
  if (!ParseArgs(argc, argv, &args)) return 2;
  const Clock::time_point start = Clock::now();
  Workspace w = MakeWorkspace(args);
  const Sentinel sentinel{w.dir, {w.out, w.harness}};
  g_sentinel = &sentinel;
  Failures failures;
  std::mt19937_64 rng(args.seed);
  std::mt19937_64 rng_outside(args.seed + 15);  // the cases aimed outside OUT: their own stream

  // Baseline: the pristine campaign, fitted from scratch; its duration times the kills.
  Outcome base =
      Wait(Start(ProcessArgv(args, w, true), w.harness + "/baseline"), args.run_timeout_s);
  CheckRun(base, w, 0, "baseline", &failures);
  ReadEllipse(w.out, &w.ix_kg_m2, &w.ixz_kg_m2);
  if (base.exit_code != 0 || !std::isfinite(w.ixz_kg_m2)) {
    std::cerr << "bifilar_stress: the pristine campaign did not process (exit " << base.exit_code
              << "):\n"
              << base.err << "\n";
    return 1;
  }
  const double forced_s = base.seconds;
  const std::vector<std::string> real_logs = RealLogs(args, w);

  std::map<std::string, int> kinds_run;
  for (int c = 1; c <= args.cases; ++c) {
    if (c % 10 == 5) {  // every tenth case aims outside OUT (issue 15 item 11)
      ++kinds_run[OutsideOutCase(args, w, c, rng_outside, &failures)];
      continue;
    }
    CaseContext x{args, w, c, rng, &failures, w.harness + "/run"};
    ++kinds_run[RunRandomCase(x, forced_s, real_logs)];
  }
  kinds_run["hostile input (bounded reads)"] =
      RunHostileInputCases(args, w, args.cases + 1, &failures);
  kinds_run["watch bad input"] = RunWatchStressCases(args, w, args.cases + 2, rng, &failures);
  kinds_run["mavlink decoder (in-process)"] =
      RunMavlinkDecoderCases(args.seed, args.cases, &failures);
  kinds_run["hostile input (issue 33)"] = RunSweep4Cases(args, w, args.cases + 101, &failures);
  return Summarize(args, w, start, forced_s, kinds_run, failures);
}

// ---- Issue 34: the MAVLink decoder (pipeline/live/mavlink.h) fed hostile bytes, in-process ----
// Per case, from the seed: a stream of good IMU frames (HIGHRES_IMU, SCALED_IMU, RAW_IMU;
// MAVLink 1 and 2, signed, truncated payloads) mixed with random bytes, frames cut short,
// frames with a flipped bit (both before the signature, which no checksum covers), frames of other
// messages with random lengths and random start bytes, fed in random chunks (1 byte to 4 kB).
// Asserted: every good frame's sample comes out, in order (a sample that is not one is allowed only
// as a checksum collision of a cut frame, counted: about 1 in 2500 cases; more than 3 + cases / 500
// fails); the decoder never holds more than two frames' bytes; every value is finite. Also, once
// per run, 4 MB of pure random bytes.
namespace {

// The samples of good frames, and the bytes; `rng` draws the mix.
std::string MavlinkHostileStream(std::mt19937_64& rng,
                                 std::vector<bifilar::live::MavlinkImuSample>* good) {
  using namespace bifilar::live;
  std::uniform_real_distribution<double> value(-30.0, 30.0);
  std::string stream;
  const int pieces = Uniform(rng, 10, 120);
  for (int k = 0; k < pieces; ++k) {
    MavlinkImuSample s{};
    s.t_s = 1e-3 * k + 1e-6 * Uniform(rng, 0, 999);
    for (int i = 0; i < 3; ++i) {
      s.gyro_rad_per_s[i] = value(rng);
      s.accel_m_per_s2[i] = value(rng);
    }
    MavlinkFrameOptions o;
    o.version = Uniform(rng, 0, 3) == 0 ? 1 : 2;
    o.signed_frame = Uniform(rng, 0, 4) == 0;
    o.seq = Uniform(rng, 0, 255);
    o.sysid = Uniform(rng, 0, 255);
    const int msgid = std::vector<int>{kMavlinkMsgidHighresImu, kMavlinkMsgidScaledImu,
                                       kMavlinkMsgidRawImu}[Uniform(rng, 0, 2)];
    const std::string frame = msgid == kMavlinkMsgidHighresImu ? EncodeHighresImu(s, 0x3F, o)
                              : msgid == kMavlinkMsgidScaledImu
                                  ? EncodeScaledImu(s, o)
                                  : EncodeRawImu(s, MavlinkDecoderOptions(), o);
    // The bytes the checksum covers (a signature is not checked: a cut or a flipped bit
    // there leaves a good sample, and a cut signature takes the next bytes as its own).
    const int checked =
        static_cast<int>(frame.size()) - (o.version == 2 && o.signed_frame ? 13 : 0);
    const int kind = Uniform(rng, 0, 9);
    if (kind <= 4) {  // a good frame
      stream += frame;
      s.msgid = msgid;
      good->push_back(s);
    } else if (kind == 5) {  // random bytes
      for (int i = Uniform(rng, 1, 300); i > 0; --i)
        stream += static_cast<char>(Uniform(rng, 0, 255));
    } else if (kind == 6) {  // a frame cut short
      stream += frame.substr(0, Uniform(rng, 1, checked - 1));
    } else if (kind == 7) {  // a flipped bit
      std::string bad = frame;
      const int bit = Uniform(rng, 8, 8 * checked - 1);
      bad[bit / 8] = static_cast<char>(bad[bit / 8] ^ (1 << (bit % 8)));
      stream += bad;
    } else if (kind == 8) {  // another message, any length
      const int length = Uniform(rng, 0, 255);
      std::string payload;
      for (int i = 0; i < length; ++i) payload += static_cast<char>(Uniform(rng, 0, 255));
      const int other = Uniform(rng, 0, 1) ? Uniform(rng, 0, 25) : Uniform(rng, 200, 255);
      stream += EncodeMavlinkFrame(other, payload, payload.size(), o);
    } else {  // start bytes with nothing behind them
      for (int i = Uniform(rng, 1, 20); i > 0; --i) {
        stream += static_cast<char>(Uniform(rng, 0, 1) ? kMavlink2Magic : kMavlink1Magic);
      }
    }
  }
  stream += std::string(600, '\0');  // resolves what waits at the end
  return stream;
}

// The decoder fed `stream` in random chunks: its samples; a failure for unbounded pending
// bytes or a non-finite value.
std::vector<bifilar::live::MavlinkImuSample> FeedInChunks(const std::string& stream,
                                                          std::mt19937_64& rng,
                                                          std::string* problem) {
  bifilar::live::MavlinkDecoder decoder;
  std::vector<bifilar::live::MavlinkImuSample> out;
  for (std::size_t at = 0; at < stream.size();) {
    const std::size_t n =
        static_cast<std::size_t>(Uniform(rng, 0, 3) == 0 ? 1 : Uniform(rng, 1, 4096));
    for (const auto& s : decoder.Feed(stream.substr(at, n))) {
      for (int i = 0; i < 3; ++i) {
        if (!std::isfinite(s.gyro_rad_per_s[i]) || !std::isfinite(s.accel_m_per_s2[i])) {
          *problem = "a non-finite value decoded";
        }
      }
      out.push_back(s);
    }
    if (decoder.pending_bytes() > 2 * 281) {
      *problem = "the decoder holds " + std::to_string(decoder.pending_bytes()) + " bytes";
    }
    at += n;
  }
  return out;
}

int RunMavlinkDecoderCases(uint64_t seed, int cases, Failures* failures) {
  std::mt19937_64 rng(seed + 34);
  const std::string kind = "mavlink decoder";
  int collisions = 0;
  for (int c = 1; c <= cases; ++c) {
    std::vector<bifilar::live::MavlinkImuSample> good;
    const std::string stream = MavlinkHostileStream(rng, &good);
    std::string problem;
    const auto got = FeedInChunks(stream, rng, &problem);
    if (!problem.empty()) failures->Add(c, kind, problem);
    // The good samples, in order, as a subsequence of what came out (by time and msgid).
    std::size_t next = 0;
    for (const auto& s : got) {
      if (next < good.size() && s.msgid == good[next].msgid &&
          std::abs(s.t_s - good[next].t_s) <= 1e-3 + 1e-9) {  // SCALED_IMU: whole ms
        ++next;
      } else {
        ++collisions;
      }
    }
    if (next != good.size()) {
      failures->Add(c, kind,
                    "good frame " + std::to_string(next) + " of " + std::to_string(good.size()) +
                        " was lost");
    }
  }
  std::string noise;
  for (int i = 0; i < (4 << 20); ++i) noise += static_cast<char>(rng() & 0xFF);
  std::string problem;
  collisions += static_cast<int>(FeedInChunks(noise, rng, &problem).size());
  if (!problem.empty()) failures->Add(cases + 1, kind, problem + " (random bytes)");
  if (collisions > 3 + cases / 500) {  // seeds 1-11, 500 cases each: 2 in all
    failures->Add(
        cases + 1, kind,
        std::to_string(collisions) + " samples from no good frame (checksum collisions?)");
  }
  std::cout << "mavlink decoder: " << cases << " hostile streams and 4 MB of noise, " << collisions
            << " checksum collisions\n";
  return cases + 1;
}

}  // namespace
