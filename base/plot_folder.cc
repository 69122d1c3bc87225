#include "base/plot_folder.h"

#include <sys/stat.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <system_error>

#include "base/atomic_file.h"
#include "base/bounded_read.h"
#include "base/json_error.h"
#include "base/user_error.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;

// One plain path component: not empty, not "." or "..", no '/' and no NUL.
bool IsPlainName(const std::string& name) {
  return !name.empty() && name != "." && name != ".." &&
         name.find_first_of(std::string("/\0", 2)) == std::string::npos;
}

}  // namespace

PlotFolder::PlotFolder(std::string dir, std::string what, bool force)
    : dir_(std::move(dir)), what_(std::move(what)), force_(force) {
  if (dir_.empty()) throw UserError(what_ + ": the folder name is empty");
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (!fs::is_directory(dir_, ec)) {  // a link to a folder the user named is that folder
    throw UserError(what_ + " " + dir_ + ": cannot create the folder" +
                    (ec ? " (" + ec.message() + ")" : std::string(" (a file has that name)")));
  }
  const std::string manifest = PathOf(kManifestName);
  if (!fs::exists(fs::symlink_status(manifest, ec))) return;
  std::string bytes, why;
  try {
    if (!ReadRegularFile(manifest, ManifestCap(), &bytes, &why)) throw UserError(why);
    const nlohmann::json j = nlohmann::json::parse(bytes);
    if (!j.is_object() || !j.contains("files") || !j["files"].is_array()) {
      throw UserError("no list 'files'");
    }
    for (const auto& name : j.at("files")) {
      // Only plain names: the manifest never reaches outside the folder.
      if (name.is_string() && IsPlainName(name.get<std::string>())) files_.insert(name);
    }
  } catch (const std::exception& e) {
    throw UserError(manifest + ": damaged record of the figures bifilar wrote here (" +
                    DescribeJsonError(e) + "); move it away or choose another " + what_ +
                    " folder");
  }
}

std::string PlotFolder::PathOf(const std::string& name) const {
  return (fs::path(dir_) / name).string();
}

void PlotFolder::Claim(const std::vector<std::string>& names) {
  std::vector<std::string> refused;
  bool others = false;  // a refusal --force would lift
  for (const std::string& name : names) {
    const std::string path = PathOf(name);
    struct stat st {};
    if (!IsPlainName(name)) {
      refused.push_back(path + " (not a plain file name)");
    } else if (::lstat(path.c_str(), &st) != 0) {
      continue;  // absent: nothing replaced
    } else if (S_ISLNK(st.st_mode)) {
      refused.push_back(path + " (a symbolic link: never replaced, not even with --force)");
    } else if (!S_ISREG(st.st_mode)) {
      refused.push_back(path + " (not a regular file: never replaced)");
    } else if (!files_.count(name) && !force_) {
      refused.push_back(path + " (exists; bifilar did not write it)");
      others = true;
    }
  }
  if (!refused.empty()) {
    std::string list;
    for (size_t i = 0; i < refused.size() && i < 3; ++i) list += (i ? ", " : "") + refused[i];
    if (refused.size() > 3) list += " and " + std::to_string(refused.size() - 3) + " more";
    throw UserError(what_ + ": will not replace " + list +
                    "; nothing was written: choose another folder" +
                    (others ? ", or add --force to overwrite files bifilar did not write" : ""));
  }
  const size_t before = files_.size();
  for (const std::string& name : names) {
    files_.insert(name);
    files_.insert(name + ".tmp");  // WriteFigure's temporary name
  }
  if (files_.size() != before) Save();
}

void PlotFolder::Save() const {
  nlohmann::json j;
  j["about"] = "figures bifilar wrote in this folder; only these are replaced without --force";
  j["files"] = files_;
  WriteFileAtomically(PathOf(kManifestName),
                      j.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

}  // namespace bifilar
