// Grouping logs into set-ups (pipeline/trace/repeats.h, RepeatGroupingOptions).
//
// --group-by is a user's regular expression, matched with RE2, not std::regex: RE2 compiles and
// matches without recursion (a pattern of 20,000 nested groups or a 16 kB path cannot overflow
// the stack, as std::regex's recursive compiler and backtracking matcher did) and in time linear
// in the text for any pattern (`(a+)+$` has no exponential case), within a memory budget. The
// pattern itself is capped at kMaxGroupByBytes.
#include <algorithm>
#include <cctype>
#include <cstdint>
#include <map>
#include <memory>

#include <re2/re2.h>

#include "base/user_error.h"
#include "pipeline/trace/repeats.h"

namespace bifilar {
namespace {

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string FileName(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

// "logs/BaseModel_Ixx_Log-3.csv" -> "logs/BaseModel_Ixx_Log-*.csv": the last run of digits in
// the file name (not the folders) becomes '*'.
std::string RepeatKey(const std::string& path) {
  const size_t name_start = path.size() - FileName(path).size();
  size_t end = path.size();
  while (end > name_start && !std::isdigit(static_cast<unsigned char>(path[end - 1]))) --end;
  if (end == name_start) return path;
  size_t begin = end;
  while (begin > name_start && std::isdigit(static_cast<unsigned char>(path[begin - 1]))) --begin;
  return path.substr(0, begin) + "*" + path.substr(end);
}

// Edit distance (insertions, deletions, substitutions), case ignored.
size_t Distance(const std::string& a_in, const std::string& b_in) {
  const std::string a = Lower(a_in), b = Lower(b_in);
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1] ? 1 : 0)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// Each path's key (what names its set-up; "" when it names none) and, for a key-less path, why.
struct Keys {
  std::vector<std::string> key, why_none;
};

// The longest --group-by pattern accepted (bytes): a set-up name needs a few dozen; 4 kB leaves
// room for any list of alternatives and bounds the compiled program (with kGroupByMemBytes).
constexpr size_t kMaxGroupByBytes = 4096;
// RE2's memory budget for the compiled pattern and its DFA cache (bytes); a pattern whose
// program exceeds it is refused at compile time, and a DFA that fills it falls back to RE2's
// NFA, still linear in the text.
constexpr int64_t kGroupByMemBytes = 8 << 20;

// A pattern as messages quote it: whole up to 80 bytes, else its start and its size.
std::string Quoted(const std::string& pattern) {
  return pattern.size() <= 80
             ? "'" + pattern + "'"
             : "'" + pattern.substr(0, 60) + "...' (" + std::to_string(pattern.size()) + " bytes)";
}

// The compiled --group-by (case ignored), or a UserError naming the pattern and what is wrong.
std::unique_ptr<RE2> CompileGroupBy(const std::string& pattern) {
  const std::string shown = Quoted(pattern);
  if (pattern.size() > kMaxGroupByBytes) {
    throw UserError("--group-by " + shown + ": longer than " + std::to_string(kMaxGroupByBytes) +
                    " bytes; a pattern naming the set-up in a file name needs far less");
  }
  RE2::Options options;
  options.set_case_sensitive(false);
  options.set_log_errors(false);
  options.set_max_mem(kGroupByMemBytes);
  auto re = std::make_unique<RE2>(pattern, options);
  if (!re->ok()) {
    throw UserError("--group-by " + shown + ": not a regular expression RE2 accepts (" +
                    re->error() + "; RE2 syntax: no backreferences or lookaround)");
  }
  return re;
}

Keys KeysOf(const std::vector<std::string>& paths, const RepeatGroupingOptions& o) {
  Keys k;
  std::unique_ptr<RE2> re;
  if (o.named.empty() && !o.group_by.empty()) re = CompileGroupBy(o.group_by);
  for (size_t i = 0; i < paths.size(); ++i) {
    std::string key, why;
    if (!o.named.empty()) {
      key = i < o.named.size() ? o.named[i] : "";
      if (key.empty()) why = "not in " + o.named_source;
    } else if (re != nullptr) {
      const std::string target =
          o.group_by.find('/') != std::string::npos ? paths[i] : FileName(paths[i]);
      // The whole match and the first capture group (when the pattern has one).
      re2::StringPiece match[2];
      const int n = std::min(2, re->NumberOfCapturingGroups() + 1);
      if (re->Match(target, 0, target.size(), RE2::UNANCHORED, match, n)) {
        key = n > 1 && match[1].data() != nullptr ? std::string(match[1]) : std::string(match[0]);
      }
      if (key.empty()) why = "its name does not match --group-by " + Quoted(o.group_by);
    } else {
      key = RepeatKey(paths[i]);
    }
    k.key.push_back(key);
    k.why_none.push_back(why);
  }
  return k;
}

// Why a group of one is alone, and the nearest name that almost matched: another log's key, or
// (a log a table does not name) the table's nearest row.
// The work (characters compared) the nearest-name search of every group of one may do in one
// GroupRepeats: edit distances cost len(a) x len(b), and comparing each of a thousand lone logs
// with every other would be quadratic. Past it the nearest name is not searched, and the text says
// so; the groups themselves never depend on it.
constexpr uint64_t kNearestNameWork = 20000000;

std::string AloneText(const std::vector<std::string>& paths, const Keys& k, size_t i,
                      const RepeatGroupingOptions& o, uint64_t* work) {
  std::string why = k.why_none[i];
  if (why.empty()) {
    if (!o.named.empty()) {
      why = "the only log of group '" + k.key[i] + "' in " + o.named_source;
    } else if (!o.group_by.empty()) {
      why = "no other log's name gives '" + k.key[i] + "' for --group-by " + Quoted(o.group_by);
    } else if (k.key[i] == paths[i]) {
      why = "its file name holds no number to count repeats by";
    } else {
      why = "no other log's name differs from it only in its last number (case ignored)";
    }
  }
  std::string nearest;
  size_t best = std::string::npos;
  bool out_of_work = false;
  // Edit distance within the work budget; false when the budget is spent.
  const auto distance = [&](const std::string& a, const std::string& b, size_t* d) {
    const uint64_t cost = static_cast<uint64_t>(a.size() + 1) * (b.size() + 1);
    if (*work + cost > kNearestNameWork) {
      out_of_work = true;
      return false;
    }
    *work += cost;
    *d = Distance(a, b);
    return true;
  };
  if (!o.named.empty() && k.key[i].empty()) {
    for (const std::string& row : o.named_rows) {
      size_t d = 0;
      if (!distance(FileName(row), FileName(paths[i]), &d)) break;
      if (d < best) {
        best = d;
        nearest = row + " (a row of the table, " + std::to_string(d) + " character(s) apart)";
      }
    }
  } else {
    for (size_t j = 0; j < paths.size(); ++j) {
      if (j == i) continue;
      const bool by_key = !k.key[i].empty() && !k.key[j].empty();
      size_t d = 0;
      if (!(by_key ? distance(FileName(k.key[i]), FileName(k.key[j]), &d)
                   : distance(FileName(paths[i]), FileName(paths[j]), &d)))
        break;
      if (d < best) {
        best = d;
        nearest = paths[j] + " (" +
                  (!o.named.empty()                           ? "group '" + k.key[j] + "', "
                   : !o.group_by.empty() && !k.key[j].empty() ? "'" + k.key[j] + "', "
                                                              : std::string()) +
                  std::to_string(d) + " character(s) apart" +
                  (o.named.empty() && o.group_by.empty() && by_key ? " besides the number" : "") +
                  ")";
      }
    }
  }
  if (out_of_work) {
    return why + (nearest.empty() ? "; nearest name not searched (too many names to compare)"
                                  : "; nearest of those compared: " + nearest);
  }
  return why + (nearest.empty() ? "; the only log given" : "; nearest: " + nearest);
}

std::string Rule(const RepeatGroupingOptions& o) {
  if (!o.named.empty()) return "as " + o.named_source + " names them";
  if (!o.group_by.empty()) {
    return "by --group-by " + Quoted(o.group_by) +
           " (the part of each name it matches; case ignored)";
  }
  return "by file name (names that differ only in their last number; case ignored)";
}

}  // namespace

std::vector<RepeatGroup> GroupRepeats(const std::vector<std::string>& paths,
                                      const RepeatGroupingOptions& options) {
  const Keys k = KeysOf(paths, options);
  std::vector<RepeatGroup> groups;
  std::map<std::string, size_t> index;
  for (size_t i = 0; i < paths.size(); ++i) {
    // A log without a key is a group of its own, named by its path.
    const std::string lookup = k.key[i].empty() ? "\n" + std::to_string(i) : Lower(k.key[i]);
    auto [it, inserted] = index.emplace(lookup, groups.size());
    if (inserted) {
      groups.emplace_back();
      groups.back().name = k.key[i].empty() ? paths[i] : k.key[i];
    }
    groups[it->second].members.push_back(static_cast<int>(i));
  }
  uint64_t work = 0;
  for (RepeatGroup& g : groups) {
    if (g.members.size() == 1) g.alone = AloneText(paths, k, g.members[0], options, &work);
  }
  return groups;
}

std::vector<RepeatGroup> GroupRepeats(const std::vector<std::string>& paths) {
  return GroupRepeats(paths, RepeatGroupingOptions());
}

std::string RepeatGroupsText(const std::vector<RepeatGroup>& groups,
                             const std::vector<std::string>& paths,
                             const RepeatGroupingOptions& options) {
  std::string text = "repeats: " + std::to_string(paths.size()) + " log(s) in " +
                     std::to_string(groups.size()) + " group(s), " + Rule(options) + ":";
  for (const RepeatGroup& g : groups) {
    text += "\n  " + g.name + ": ";
    if (!g.alone.empty()) {
      text += FileName(paths[g.members[0]]) + " alone: " + g.alone;
      continue;
    }
    for (size_t k = 0; k < g.members.size(); ++k) {
      text += (k ? ", " : "") + FileName(paths[g.members[k]]);
    }
  }
  return text;
}

}  // namespace bifilar
