#include "pipeline/campaign/run_discovery.h"

#include <fnmatch.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "base/bounded_read.h"
#include "base/csv.h"
#include "base/option_check.h"
#include "base/user_error.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;

// ---- Patterns ---------------------------------------------------------------------------------
// Matching a name is fnmatch(3)'s job. The walk over folders is our own, in a few lines, because
// glob(3) does not fit the rules: without GLOB_PERIOD its `*` skips names starting with '.',
// with it `*` also matches the "." and ".." entries (so `*/x.csv` would look above runs.root),
// and it cannot say what text {pitch_deg} stood for.

bool HasWildcard(const std::string& component) {
  return component.find_first_of("*?{") != std::string::npos;
}

std::vector<std::string> SplitPath(const std::string& pattern) {
  std::vector<std::string> parts;
  std::string part;
  for (char c : pattern) {
    if (c == '/') {
      if (!part.empty()) parts.push_back(part);
      part.clear();
    } else {
      part += c;
    }
  }
  if (!part.empty()) parts.push_back(part);
  return parts;
}

// One wildcard component as fnmatch(3) patterns. '[' and '\' are literal in our rules, so they
// are escaped; {pitch_deg} and {roll_deg} split the component into the literal parts around the
// captures.
struct ComponentPattern {
  std::string whole;               // the component, each placeholder as '*'
  std::vector<std::string> names;  // placeholders in order ("pitch_deg", "roll_deg")
  std::vector<std::string> parts;  // literal parts around them: names.size() + 1 (when any)
  bool captures() const { return !names.empty(); }
};

ComponentPattern ParseComponent(const std::string& component) {
  ComponentPattern p;
  p.parts.emplace_back();
  for (size_t i = 0; i < component.size(); ++i) {
    const char c = component[i];
    if (c == '{') {
      const size_t end = component.find('}', i);
      const std::string name = end == std::string::npos ? "" : component.substr(i + 1, end - i - 1);
      if (name != "pitch_deg" && name != "roll_deg") {
        throw UserError("runs.pattern: unknown placeholder in '" + component +
                        "' (only {pitch_deg} and {roll_deg} are known)");
      }
      for (const std::string& seen : p.names) {
        if (seen == name) throw UserError("runs.pattern: {" + name + "} may appear only once");
      }
      p.names.push_back(name);
      p.parts.emplace_back();
      p.whole += '*';
      i = end;
      continue;
    }
    const std::string literal = c == '[' || c == '\\' ? std::string("\\") + c : std::string(1, c);
    p.whole += literal;
    p.parts.back() += literal;
  }
  if (!p.captures()) p.parts.clear();
  return p;
}

bool FnMatch(const std::string& pattern, const std::string& name) {
  return ::fnmatch(pattern.c_str(), name.c_str(), 0) == 0;
}

// Captures of `name` from literal part `k` on: the longest text matching part k, then the
// shortest capture after which the rest matches (with one placeholder: the shortest text after
// the longest prefix that matches the part before it).
bool MatchFrom(const ComponentPattern& p, size_t k, const std::string& name,
               std::vector<std::string>* captured) {
  if (k + 1 == p.parts.size()) return FnMatch(p.parts[k], name);
  for (size_t i = name.size() + 1; i-- > 0;) {
    if (!FnMatch(p.parts[k], name.substr(0, i))) continue;
    for (size_t j = i; j <= name.size(); ++j) {
      (*captured)[k] = name.substr(i, j - i);
      if (MatchFrom(p, k + 1, name.substr(j), captured)) return true;
    }
  }
  return false;
}

// What the placeholders stood for in a path: {pitch_deg} and {roll_deg}.
struct CapturedText {
  std::optional<std::string> pitch, roll;
};

// Whether `name` matches; its captures go into *text.
bool MatchComponent(const ComponentPattern& p, const std::string& name, CapturedText* text) {
  if (!FnMatch(p.whole, name)) return false;
  if (!p.captures()) return true;
  std::vector<std::string> captured(p.names.size());
  if (!MatchFrom(p, 0, name, &captured)) return false;  // unreachable: `whole` matched
  for (size_t k = 0; k < p.names.size(); ++k) {
    (p.names[k] == "pitch_deg" ? text->pitch : text->roll) = captured[k];
  }
  return true;
}

struct PatternHit {
  std::string path;
  CapturedText text;  // what {pitch_deg} and {roll_deg} stood for
};

// Depth-first from `dir`, entries in name order: files (not folders) matching the last
// component, through folders matching the others. A literal component is looked up directly.
void WalkPattern(const fs::path& dir, const std::vector<std::string>& parts, size_t index,
                 const CapturedText& captured, std::vector<PatternHit>* hits) {
  const bool last = index + 1 == parts.size();
  const std::string& part = parts[index];
  std::error_code ec;
  if (!HasWildcard(part)) {
    const fs::path next = dir / part;
    if (last) {
      if (fs::exists(next, ec)) hits->push_back({next.string(), captured});
    } else if (fs::is_directory(next, ec)) {
      WalkPattern(next, parts, index + 1, captured, hits);
    }
    return;
  }
  const ComponentPattern pattern = ParseComponent(part);
  std::vector<fs::path> entries;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    entries.push_back(it->path());
  }
  std::sort(entries.begin(), entries.end());
  for (const fs::path& entry : entries) {
    CapturedText text = captured;
    if (!MatchComponent(pattern, entry.filename().string(), &text)) continue;
    if (last) {
      if (!fs::is_directory(entry, ec)) hits->push_back({entry.string(), text});
    } else if (fs::is_directory(entry, ec)) {
      WalkPattern(entry, parts, index + 1, text, hits);
    }
  }
}

// ---- Names and pitches ------------------------------------------------------------------------

// A pitch written in a path: "-80", "10", "12.5", "+5", "m80" (minus), "p10" (plus).
bool ParsePitchText(std::string text, double* pitch_deg) {
  double sign = 1.0;
  if (!text.empty() && (text[0] == 'm' || text[0] == 'n')) {
    sign = -1.0;
    text = text.substr(1);
  } else if (!text.empty() && text[0] == 'p') {
    text = text.substr(1);
  }
  double value = 0.0;
  if (!ParseNumber(text, &value)) return false;  // base/csv.h: the whole text, finite
  *pitch_deg = sign * value;
  return *pitch_deg >= -180.0 && *pitch_deg <= 180.0;
}

// How a log is named to the user: relative to runs.root when inside it (pitch_10/trial_1.csv),
// else relative to the config folder, else the absolute path.
std::string Display(const CampaignConfig& config, const std::string& path) {
  for (const std::string& base : {config.runs.root, config.folder}) {
    if (base.empty()) continue;
    const std::string rel = fs::path(path).lexically_relative(base).string();
    if (!rel.empty() && rel.rfind("..", 0) != 0) return rel;
  }
  return path;
}

// The cells of a runs table's line (base/csv.h, RFC 4180: a quoted path may hold a comma, "" is
// a quote), each without surrounding spaces.
std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> cells = SplitCsvRecord(line);
  for (std::string& s : cells) {
    while (!s.empty() && s.front() == ' ') s.erase(s.begin());
    while (!s.empty() && s.back() == ' ') s.pop_back();
  }
  return cells;
}

// ---- The three sources ------------------------------------------------------------------------

// runs.table: one row per log, its pitch in a column.
std::vector<RunFile> DiscoverTable(const CampaignConfig& config) {
  std::istringstream in(
      ReadRegularFileOrThrow(config.runs.table, TableCap("runs table (runs.table)")));
  std::vector<RunFile> runs;
  std::map<std::string, std::pair<size_t, int>> first_row;  // path -> (index in runs, line)
  std::string line;
  int line_no = 0;
  int path_col = -1, pitch_col = -1, roll_col = -1;  // roll_deg is optional (0 when absent)
  int group_col = -1;                                // group is optional
  while (std::getline(in, line)) {
    ++line_no;
    // A UTF-8 byte-order mark (spreadsheet exports) is not part of the first column's name.
    if (line_no == 1 && line.compare(0, 3, "\xEF\xBB\xBF") == 0) line.erase(0, 3);
    const size_t first = line.find_first_not_of(" \r\t");
    if (first == std::string::npos || line[first] == '#') continue;  // blank or a comment
    const std::vector<std::string> cells = SplitCsvLine(line);
    if (path_col < 0) {
      for (size_t i = 0; i < cells.size(); ++i) {
        if (cells[i] == "path" || cells[i] == "file") path_col = static_cast<int>(i);
        if (cells[i] == "pitch_deg") pitch_col = static_cast<int>(i);
        if (cells[i] == "roll_deg") roll_col = static_cast<int>(i);
        if (cells[i] == "group") group_col = static_cast<int>(i);
      }
      if (path_col < 0 || pitch_col < 0) {
        throw UserError(config.runs.table + ":" + std::to_string(line_no) +
                        ": runs table needs a header with columns 'path' and 'pitch_deg'");
      }
      continue;
    }
    RunFile run;
    const std::string rel = static_cast<int>(cells.size()) > path_col ? cells[path_col] : "";
    run.path = ResolvePath(config.runs.root, rel);
    run.display = Display(config, run.path);
    if (group_col >= 0 && static_cast<int>(cells.size()) > group_col) run.group = cells[group_col];
    double pitch = 0.0, roll = 0.0;
    if (rel.empty()) {
      run.display = config.runs.table + ":" + std::to_string(line_no);
      run.error = run.display + ": empty path in runs table";
    } else if (roll_col >= 0 && (static_cast<int>(cells.size()) <= roll_col ||
                                 !ParsePitchText(cells[roll_col], &roll))) {
      run.error = config.runs.table + ":" + std::to_string(line_no) + ": roll of '" + rel +
                  "' is not a number in [-180, 180] (column roll_deg)";
    } else if (static_cast<int>(cells.size()) <= pitch_col ||
               !ParsePitchText(cells[pitch_col], &pitch)) {
      run.error = config.runs.table + ":" + std::to_string(line_no) + ": pitch of '" + rel +
                  "' is not a number in [-180, 180]";
    } else {
      run.pitch_nominal_deg = pitch;
      if (roll_col >= 0) run.roll_nominal_deg = roll;
      std::error_code ec;
      if (!fs::exists(run.path, ec)) {
        run.error = run.display + ": listed in " + config.runs.table + ":" +
                    std::to_string(line_no) + " but not found";
      }
      // A log listed twice: the same pitch is one run; two pitches cannot both be right, so the
      // log becomes an error row naming both lines (its fit would be grouped at a guess).
      auto [it, inserted] = first_row.emplace(run.path, std::make_pair(runs.size(), line_no));
      if (!inserted) {
        RunFile& first = runs[it->second.first];
        if (first.pitch_nominal_deg && *first.pitch_nominal_deg != pitch) {
          char buffer[160];
          std::snprintf(buffer, sizeof(buffer), "lines %d and %d give pitch %g and %g deg",
                        it->second.second, line_no, *first.pitch_nominal_deg, pitch);
          first.error = first.display + ": listed twice in " + config.runs.table + " with " +
                        "different pitches (" + buffer + "); give each log once";
        }
        continue;
      }
    }
    runs.push_back(run);
  }
  if (path_col < 0) {
    throw UserError(config.runs.table +
                    ": runs table is empty (runs.table): expected a header "
                    "'path,pitch_deg' and one row per log");
  }
  if (runs.empty()) {
    throw UserError(config.runs.table +
                    ": runs table has a header but no rows (runs.table): "
                    "add one row 'path,pitch_deg' per log");
  }
  return runs;
}

// runs.pattern under runs.root, the pitch from {pitch_deg}.
std::vector<RunFile> DiscoverPattern(const CampaignConfig& config) {
  const std::vector<std::string> parts = SplitPath(config.runs.pattern);
  if (parts.empty()) throw UserError("runs.pattern is empty");
  std::vector<PatternHit> hits;
  WalkPattern(config.runs.root, parts, 0, CapturedText(), &hits);
  std::vector<RunFile> runs;
  for (const PatternHit& hit : hits) {
    RunFile run;
    run.path = fs::path(hit.path).lexically_normal().string();
    run.display = Display(config, run.path);
    double pitch = 0.0, roll = 0.0;
    if (hit.text.roll) {
      if (ParsePitchText(*hit.text.roll, &roll)) {
        run.roll_nominal_deg = roll;
      } else {
        run.error = run.display + ": cannot read the roll from the path ('" + *hit.text.roll +
                    "' in pattern " + config.runs.pattern + " is not a number in [-180, 180])";
      }
    }
    if (!run.error.empty()) {
      // the roll already failed
    } else if (hit.text.pitch) {
      if (ParsePitchText(*hit.text.pitch, &pitch)) {
        run.pitch_nominal_deg = pitch;
      } else {
        run.error = run.display + ": cannot read the pitch from the path ('" + *hit.text.pitch +
                    "' in pattern " + config.runs.pattern + " is not a number in [-180, 180])";
      }
    } else if (config.runs.pitch_source == PitchSource::kNominal) {
      run.error = run.display + ": runs.pattern has no {pitch_deg} and pitch_source is nominal";
    }
    runs.push_back(run);
  }
  if (runs.empty()) {
    throw UserError("runs: no file matches '" + config.runs.pattern + "' under " +
                    config.runs.root);
  }
  return runs;
}

}  // namespace

// rig.inertia.tare.logs or rig.calibration.logs: plain file names, or patterns whose leading
// literal folders must exist.
std::vector<RunFile> DiscoverListedLogs(const CampaignConfig& config,
                                        const std::vector<std::string>& patterns, TraceRole role) {
  const std::string key =
      role == TraceRole::kCalibration ? "rig.calibration.logs" : "rig.inertia.tare.logs";
  const std::string what = role == TraceRole::kCalibration ? "calibration log" : "tare log";
  std::vector<RunFile> tare;
  for (const std::string& pattern : patterns) {
    const std::vector<std::string> parts = SplitPath(pattern);
    size_t fixed = 0;
    while (fixed < parts.size() && !HasWildcard(parts[fixed])) ++fixed;
    if (fixed == parts.size()) {  // a plain file name
      RunFile run;
      run.path = pattern;
      run.display = Display(config, pattern);
      run.role = role;
      std::error_code ec;
      if (!fs::exists(pattern, ec)) run.error = run.display + ": " + what + " not found";
      tare.push_back(run);
      continue;
    }
    fs::path dir = pattern.rfind('/', 0) == 0 ? fs::path("/") : fs::path(".");
    for (size_t i = 0; i < fixed; ++i) dir /= parts[i];
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) {
      throw UserError(key + ": folder '" + dir.string() + "' does not exist");
    }
    const std::vector<std::string> rest(parts.begin() + fixed, parts.end());
    for (const std::string& part : rest) {
      if (part.find('{') != std::string::npos) {
        throw UserError(key + ": placeholders are not allowed in these patterns");
      }
    }
    std::vector<PatternHit> hits;
    WalkPattern(dir, rest, 0, CapturedText(), &hits);
    if (hits.empty()) {
      throw UserError(key + ": no file matches '" + pattern + "'");
    }
    for (const PatternHit& hit : hits) {
      RunFile run;
      run.path = fs::path(hit.path).lexically_normal().string();
      run.display = Display(config, run.path);
      run.role = role;
      tare.push_back(run);
    }
  }
  return tare;
}

namespace {

// A file matched twice (two tare patterns, a table row repeated) is one log; matched as an
// aircraft run and as a tare log it is an error row, not "the same content as" itself.
std::vector<RunFile> OncePerPath(std::vector<RunFile> runs) {
  std::map<std::string, TraceRole> seen;
  std::vector<RunFile> unique;
  for (RunFile& run : runs) {
    auto [it, inserted] = seen.emplace(run.path, run.role);
    if (inserted) {
      unique.push_back(std::move(run));
    } else if (it->second != run.role && run.error.empty()) {
      run.error = run.display + ": listed both as " +
                  (it->second == TraceRole::kAircraft ? "an " : "a ") + ToString(it->second) +
                  " log and as " + (run.role == TraceRole::kAircraft ? "an " : "a ") +
                  ToString(run.role) + " log";
      unique.push_back(std::move(run));
    }
  }
  return unique;
}

}  // namespace

std::vector<RunFile> DiscoverRuns(const CampaignConfig& config) {
  if (config.runs.root.empty()) throw UserError(config.file + ": no 'runs' section");
  std::error_code ec;
  if (!fs::is_directory(config.runs.root, ec)) {
    throw UserError("runs.root: folder '" + config.runs.root + "' does not exist");
  }
  std::vector<RunFile> runs =
      config.runs.table.empty() ? DiscoverPattern(config) : DiscoverTable(config);
  if (config.rig_inertia.kind == RigInertiaSpec::Kind::kTare) {
    std::vector<RunFile> tare =
        DiscoverListedLogs(config, config.rig_inertia.tare_patterns, TraceRole::kTare);
    runs.insert(runs.end(), tare.begin(), tare.end());
  }
  if (config.calibration.enabled) {
    std::vector<RunFile> reference =
        DiscoverListedLogs(config, config.calibration.log_patterns, TraceRole::kCalibration);
    runs.insert(runs.end(), reference.begin(), reference.end());
  }
  return OncePerPath(std::move(runs));
}

namespace {

// The bounds of a --runs-table (it names the logs of one `fit` command line, so a few thousand
// rows at most): its size, its rows and the length of one line. A table beyond them is refused
// before it is parsed, with what was found and the bound, never read into memory whole at any
// size (issue 33 item 4: a 4-million-row table took 160 s and 885 MB, a 50 MB line 1.16 GB).
constexpr uint64_t kMaxRunsTableGroupsBytes = 16'000'000;
constexpr size_t kMaxRunsTableRows = 100000;
constexpr size_t kMaxRunsTableLineBytes = 65536;

// A set-up named by a number ("-0", "10", "10.0") is the number: -0 and 0 are one set-up, as are
// 10 and 10.0. A cell that is not wholly a finite number stays as written.
std::string NumericKey(const std::string& cell) {
  double value = 0.0;
  if (!ParseNumber(cell, &value)) return cell;  // base/csv.h: the whole cell, finite
  return FormatCheckValue(value + 0.0);         // + 0.0: -0 becomes 0; the shortest exact form
}

}  // namespace

RunsTableGroups ReadRunsTableGroups(const std::string& table) {
  const std::string text =
      ReadRegularFileOrThrow(table, InputCap{kMaxRunsTableGroupsBytes, "runs table (--runs-table)",
                                             "a runs table names one log per row"});
  RunsTableGroups out;
  int line_no = 0, path_col = -1, group_col = -1, pitch_col = -1, roll_col = -1;
  for (size_t at = 0; at < text.size();) {
    const size_t end = std::min(text.find('\n', at), text.size());
    ++line_no;
    if (end - at > kMaxRunsTableLineBytes) {
      throw UserError(table + ":" + std::to_string(line_no) + ": a line of " +
                      std::to_string(end - at) + " bytes, over " +
                      std::to_string(kMaxRunsTableLineBytes) +
                      ": not a runs table (one row per log: path,group)");
    }
    std::string line = text.substr(at, end - at);
    at = end + 1;
    if (line_no == 1 && line.compare(0, 3, "\xEF\xBB\xBF") == 0) line.erase(0, 3);
    const size_t first = line.find_first_not_of(" \r\t");
    if (first == std::string::npos || line[first] == '#') continue;
    const std::vector<std::string> cells = SplitCsvLine(line);
    const auto cell = [&](int col) {
      return col >= 0 && col < static_cast<int>(cells.size()) ? cells[col] : std::string();
    };
    if (path_col < 0) {
      for (size_t i = 0; i < cells.size(); ++i) {
        if (cells[i] == "path" || cells[i] == "file") path_col = static_cast<int>(i);
        if (cells[i] == "group") group_col = static_cast<int>(i);
        if (cells[i] == "pitch_deg") pitch_col = static_cast<int>(i);
        if (cells[i] == "roll_deg") roll_col = static_cast<int>(i);
      }
      if (path_col < 0 || (group_col < 0 && pitch_col < 0)) {
        throw UserError(table + ":" + std::to_string(line_no) +
                        ": a runs table needs a header with a 'path' column and a 'group' column "
                        "(or the attitude: 'pitch_deg', optionally 'roll_deg')");
      }
      out.source =
          table + (group_col >= 0 ? " (its group column)" : " (its roll_deg and pitch_deg)");
      continue;
    }
    if (out.paths.size() >= kMaxRunsTableRows) {
      throw UserError(table + ":" + std::to_string(line_no) + ": more than " +
                      std::to_string(kMaxRunsTableRows) +
                      " rows: a runs table names the logs of one fit, one row per log");
    }
    std::string group = NumericKey(cell(group_col));
    if (group_col < 0) {
      double pitch = 0.0, roll = 0.0;
      if (!ParsePitchText(cell(pitch_col), &pitch) ||
          (roll_col >= 0 && !ParsePitchText(cell(roll_col), &roll))) {
        throw UserError(table + ":" + std::to_string(line_no) + ": the attitude of '" +
                        cell(path_col) + "' is not a number in [-180, 180] (pitch_deg, roll_deg)");
      }
      char attitude[64];  // -0 and 0 are one attitude: + 0.0 turns -0 into 0
      std::snprintf(attitude, sizeof(attitude), "roll %g pitch %g", roll + 0.0, pitch + 0.0);
      group = attitude;
    }
    if (cell(path_col).empty()) {
      throw UserError(table + ":" + std::to_string(line_no) + ": empty path in runs table");
    }
    out.paths.push_back(cell(path_col));
    out.groups.push_back(group);
  }
  if (path_col < 0)
    throw UserError(table + ": runs table is empty: expected a header 'path,group'");
  return out;
}

std::vector<std::string> GroupsOfLogs(const std::vector<std::string>& logs,
                                      const RunsTableGroups& table) {
  // The rows by their file name (their last component): a log is compared only with the rows
  // that end in its file name, so the work is near-linear in logs + rows, not their product.
  std::map<std::string, std::vector<size_t>> rows_of_name;
  std::vector<std::vector<std::string>> rows(table.paths.size());
  for (size_t r = 0; r < table.paths.size(); ++r) {
    rows[r] = SplitPath(fs::path(table.paths[r]).lexically_normal().string());
    if (!rows[r].empty()) rows_of_name[rows[r].back()].push_back(r);
  }
  std::vector<std::string> groups;
  for (const std::string& log : logs) {
    const std::vector<std::string> parts = SplitPath(fs::path(log).lexically_normal().string());
    std::string group;
    size_t longest = 0;
    const auto named = parts.empty() ? rows_of_name.end() : rows_of_name.find(parts.back());
    if (named != rows_of_name.end()) {
      for (size_t r : named->second) {
        const std::vector<std::string>& row = rows[r];
        if (row.size() > parts.size() || row.size() <= longest) continue;
        if (std::equal(row.begin(), row.end(), parts.end() - row.size())) {
          longest = row.size();
          group = table.groups[r];
        }
      }
    }
    groups.push_back(group);
  }
  return groups;
}

}  // namespace bifilar
