#include "pipeline/campaign/campaign_inputs.h"

#include <algorithm>
#include <filesystem>
#include <iterator>
#include <map>

#include "base/user_error.h"
#include "pipeline/trace/trace_process.h"

namespace bifilar {

namespace fs = std::filesystem;

namespace {

// True when `relative` (to OUT) is in a place bifilar writes: cache/, figures/, a result file
// (or its temporary name), or its lock and manifest.
bool IsInOutputPlace(const fs::path& relative) {
  const std::string first = relative.begin()->string();
  if (first == "cache" || first == "figures") return std::next(relative.begin()) != relative.end();
  if (std::next(relative.begin()) != relative.end()) return false;
  if (first.rfind(".bifilar", 0) == 0) return true;
  for (const char* name : {"results.json", "traces.csv", "angles.csv", "report.html"}) {
    if (first.rfind(name, 0) == 0 &&
        (first.size() == std::string(name).size() || first[std::string(name).size()] == '.')) {
      return true;
    }
  }
  return false;
}

}  // namespace

int DropOutputFolder(const std::string& out_dir, std::vector<RunFile>* runs) {
  std::error_code ec;
  fs::path out = fs::weakly_canonical(fs::absolute(out_dir), ec);
  if (ec) out = fs::absolute(out_dir).lexically_normal();
  // The path of a run relative to OUT, empty when it is not inside OUT.
  const auto inside = [&](const RunFile& run) {
    std::error_code ec2;
    fs::path path = fs::weakly_canonical(run.path, ec2);
    if (ec2) path = fs::path(run.path).lexically_normal();
    const fs::path rel = path.lexically_relative(out);
    const std::string text = rel.string();
    return text.empty() || text == "." || text.rfind("..", 0) == 0 ? fs::path() : rel;
  };
  // Issue 15 item 4: a log of the user's inside OUT (`--out LOGS/pitch_0`) was dropped in
  // silence. Only bifilar's own outputs are left out; any other log there stops the run.
  std::vector<std::string> logs_inside;
  for (const RunFile& run : *runs) {
    const fs::path rel = inside(run);
    if (!rel.empty() && !IsInOutputPlace(rel)) logs_inside.push_back(run.display);
  }
  if (!logs_inside.empty()) {
    std::string list;
    for (size_t i = 0; i < logs_inside.size() && i < 3; ++i) {
      list += (i ? ", " : "") + logs_inside[i];
    }
    if (logs_inside.size() > 3) list += " and " + std::to_string(logs_inside.size() - 3) + " more";
    throw UserError(out_dir + ": the output folder holds " + std::to_string(logs_inside.size()) +
                    " log(s) of this campaign (" + list +
                    "); bifilar never reads its output folder as input, so they would be left "
                    "out: choose an --out that is not a log folder and holds no logs");
  }
  const size_t before = runs->size();
  runs->erase(std::remove_if(runs->begin(), runs->end(),
                             [&](const RunFile& run) { return !inside(run).empty(); }),
              runs->end());
  return static_cast<int>(before - runs->size());
}

std::vector<std::optional<std::array<double, 2>>> WindowsForRuns(const CampaignConfig& config,
                                                                 const std::vector<RunFile>& runs) {
  // Each entry resolved the two ways ConfigWindowFor does: against runs.root, then the config
  // folder.
  // Canonical paths on both sides (CanonicalLogPath), as ConfigWindowFor matches for `fit`.
  std::map<std::string, std::string> key_of;  // resolved path -> entry
  for (const auto& [key, window] : config.fit.windows_s) {
    if (!config.runs.root.empty()) {
      key_of.emplace(CanonicalLogPath(ResolvePath(config.runs.root, key)), key);
    }
    key_of.emplace(CanonicalLogPath(ResolvePath(config.folder, key)), key);
  }
  std::vector<std::optional<std::array<double, 2>>> windows(runs.size());
  std::map<std::string, bool> used;
  if (config.fit.windows_s.empty()) return windows;
  for (size_t i = 0; i < runs.size(); ++i) {
    const std::string target = CanonicalLogPath(runs[i].path);
    const auto it = key_of.find(target);
    const std::string key = it == key_of.end() ? std::string() : it->second;
    if (key.empty()) continue;
    windows[i] = config.fit.windows_s.at(key);
    used[key] = true;
  }
  for (const auto& [key, window] : config.fit.windows_s) {
    if (!used.count(key)) {
      throw UserError(config.file + ": 'fit.windows." + key + "' names no log that was found (" +
                      "relative to runs.root " + config.runs.root +
                      " or to the config folder); fix the file name or remove the entry");
    }
  }
  return windows;
}

void CheckWindowEntriesExist(const CampaignConfig& config) {
  for (const auto& [key, window] : config.fit.windows_s) {
    std::error_code ec;
    const bool in_root =
        !config.runs.root.empty() && fs::is_regular_file(ResolvePath(config.runs.root, key), ec);
    if (in_root || fs::is_regular_file(ResolvePath(config.folder, key), ec)) continue;
    throw UserError(config.file + ": 'fit.windows." + key + "' names no log that exists (" +
                    (config.runs.root.empty()
                         ? std::string()
                         : "relative to runs.root " + config.runs.root + " or ") +
                    "relative to the config folder " +
                    (config.folder.empty() ? std::string(".") : config.folder) +
                    "); fix the file name or remove the entry");
  }
}

}  // namespace bifilar
