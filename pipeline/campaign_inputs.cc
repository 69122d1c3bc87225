#include "pipeline/campaign_inputs.h"

#include <algorithm>
#include <filesystem>
#include <map>

#include "pipeline/user_error.h"

namespace bifilar {

namespace fs = std::filesystem;

int DropOutputFolder(const std::string& out_dir, std::vector<RunFile>* runs) {
  std::error_code ec;
  fs::path out = fs::weakly_canonical(fs::absolute(out_dir), ec);
  if (ec) out = fs::absolute(out_dir).lexically_normal();
  const auto inside = [&](const RunFile& run) {
    std::error_code ec2;
    fs::path path = fs::weakly_canonical(run.path, ec2);
    if (ec2) path = fs::path(run.path).lexically_normal();
    const std::string rel = path.lexically_relative(out).string();
    return !rel.empty() && rel != "." && rel.rfind("..", 0) != 0;
  };
  const size_t before = runs->size();
  runs->erase(std::remove_if(runs->begin(), runs->end(), inside), runs->end());
  return static_cast<int>(before - runs->size());
}

std::vector<std::optional<std::array<double, 2>>> WindowsForRuns(
    const CampaignConfig& config, const std::vector<RunFile>& runs) {
  // Each entry resolved the two ways ConfigWindowFor does: against runs.root, then the config
  // folder.
  std::map<std::string, std::string> key_of;  // resolved path -> entry
  for (const auto& [key, window] : config.fit.windows_s) {
    if (!config.runs.root.empty()) key_of.emplace(ResolvePath(config.runs.root, key), key);
    key_of.emplace(ResolvePath(config.folder, key), key);
  }
  std::vector<std::optional<std::array<double, 2>>> windows(runs.size());
  std::map<std::string, bool> used;
  for (size_t i = 0; i < runs.size(); ++i) {
    const std::string target = fs::path(runs[i].path).lexically_normal().string();
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

}  // namespace bifilar
