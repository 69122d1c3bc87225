#include "pipeline/store/output_set.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cassert>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <filesystem>

#include "base/atomic_file.h"
#include "base/bounded_read.h"
#include "base/hash.h"
#include "base/json_error.h"
#include "base/text_format.h"
#include "base/user_error.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;

constexpr const char* kLockName = ".bifilar.lock";
constexpr const char* kOwnedFolders[] = {"cache", "figures"};
constexpr const char* kResultFiles[] = {"results.json", "traces.csv", "angles.csv", "report.html"};
constexpr const char* kReportStamp = "<!-- bifilar results.json fnv1a64: ";

// The file's bytes, "" when it cannot be read (base/bounded_read.h: not a regular file, or
// larger than the cap).
std::string ReadAll(const std::string& path, const InputCap& cap = OutputFileCap()) {
  std::string bytes, why;
  return ReadRegularFile(path, cap, &bytes, &why) ? bytes : std::string();
}

// The temporary names bifilar's writers use: WriteFileAtomically (".tmp.<pid>") and
// WriteFigure (".tmp").
std::vector<std::string> WithTemporaries(const std::string& relative) {
  return {relative, relative + ".tmp", AtomicTemporaryName(relative)};
}

// One plain path component: not empty, not "." or "..", no '/' and no NUL.
bool IsPlainComponent(const std::string& name) {
  return !name.empty() && name != "." && name != ".." &&
         name.find_first_of(std::string("/\0", 2)) == std::string::npos;
}

// `name` without a writer's temporary suffix (".tmp", or ".tmp.<pid>").
std::string WithoutTemporarySuffix(const std::string& name) {
  const size_t at = name.rfind(".tmp");
  if (at == std::string::npos || at == 0) return name;
  const std::string rest = name.substr(at + 4);
  if (rest.empty()) return name.substr(0, at);
  if (rest.size() >= 2 && rest[0] == '.' &&
      rest.find_first_not_of("0123456789", 1) == std::string::npos) {
    return name.substr(0, at);
  }
  return name;
}

// A name bifilar writes in OUT, relative to it (issue 15 item 1): a result file, a cache entry
// `cache/<name>.json` or a figure `figures/<name>`, each possibly under a writer's temporary
// name. Anything else (an absolute path, "..", a deeper path, another name) is not bifilar's.
bool IsOwnedName(const std::string& relative) {
  const size_t slash = relative.find('/');
  if (slash == std::string::npos) {
    const std::string base = WithoutTemporarySuffix(relative);
    for (const char* name : kResultFiles) {
      if (base == name) return IsPlainComponent(relative);
    }
    return false;
  }
  const std::string folder = relative.substr(0, slash), name = relative.substr(slash + 1);
  if (!IsPlainComponent(name)) return false;
  if (folder == "figures") return true;
  const std::string base = WithoutTemporarySuffix(name);
  return folder == "cache" && base.size() > 5 && base.compare(base.size() - 5, 5, ".json") == 0;
}

// Empty when OUT/<relative> (an owned name) is absent or a regular file reached without a
// symbolic link below OUT; else what it is instead.
std::string RecordedFileProblem(const std::string& out_dir, const std::string& relative) {
  struct stat st {};
  const size_t slash = relative.find('/');
  if (slash != std::string::npos) {
    const std::string folder = (fs::path(out_dir) / relative.substr(0, slash)).string();
    if (::lstat(folder.c_str(), &st) != 0) return "";  // no folder, no file
    if (S_ISLNK(st.st_mode)) return folder + " is a symbolic link";
    if (!S_ISDIR(st.st_mode)) return folder + " is not a folder";
  }
  const std::string path = (fs::path(out_dir) / relative).string();
  if (::lstat(path.c_str(), &st) != 0) return "";
  if (S_ISLNK(st.st_mode)) return "is a symbolic link";
  if (!S_ISREG(st.st_mode)) return "is not a regular file";
  return "";
}

// Removes OUT/<relative> (an owned name) when it is a regular file. The folders below OUT are
// opened without following links and unlinkat(2) never follows the last component, so a link
// planted during the run cannot redirect the removal outside OUT. True when removed or absent;
// false with `why` when something else is there (left alone).
bool RemoveOwnedFile(const std::string& out_dir, const std::string& relative, std::string* why) {
  const int out_fd = ::open(out_dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (out_fd < 0) {
    *why = std::string("cannot open the output folder: ") + std::strerror(errno);
    return false;
  }
  int dir_fd = out_fd;
  std::string name = relative;
  const size_t slash = relative.find('/');
  if (slash != std::string::npos) {
    dir_fd = ::openat(out_fd, relative.substr(0, slash).c_str(),
                      O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    const int error = errno;
    ::close(out_fd);
    if (dir_fd < 0) {
      if (error == ENOENT) return true;
      *why = relative.substr(0, slash) + " is a symbolic link or not a folder";
      return false;
    }
    name = relative.substr(slash + 1);
  }
  bool removed = true;
  struct stat st {};
  if (::fstatat(dir_fd, name.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0) {
    removed = errno == ENOENT;
    if (!removed) *why = std::strerror(errno);
  } else if (!S_ISREG(st.st_mode)) {
    removed = false;
    *why = S_ISLNK(st.st_mode) ? "is a symbolic link" : "is not a regular file";
  } else if (::unlinkat(dir_fd, name.c_str(), 0) != 0 && errno != ENOENT) {
    removed = false;
    *why = std::strerror(errno);
  }
  ::close(dir_fd);
  return removed;
}

bool IsBifilarResults(const std::string& path) {
  try {
    const nlohmann::json j = nlohmann::json::parse(ReadAll(path));
    return j.is_object() && j.contains("traces") && j.contains("version");
  } catch (const std::exception&) {
    return false;
  }
}

// What bifilar writes in its lock: "pid N, started T", padded with spaces to a fixed length so
// that it overwrites the previous holder's line without truncating the file.
constexpr size_t kLockRecordBytes = 64;

// True when `text` is empty or a holder line bifilar wrote (the lock file is bifilar's own).
bool IsLockRecord(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ' || text.back() == '\0')) {
    text.pop_back();
  }
  return text.empty() || (text.size() < kLockRecordBytes && text.rfind("pid ", 0) == 0 &&
                          text.find(", started ") != std::string::npos &&
                          text.find_first_of(std::string("\n\0", 2)) == std::string::npos);
}

}  // namespace

OutputFolderLock::OutputFolderLock(const std::string& out_dir) {
  const std::string path = (fs::path(out_dir) / kLockName).string();
  // Issue 15 item 2: never follow a link planted as the lock (O_NOFOLLOW), never block on a
  // FIFO (O_NONBLOCK), refuse anything but a regular file of bifilar's own, never truncate.
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    const int error = errno;
    if (error == ELOOP) {
      throw UserError(path +
                      ": the output folder's lock is a symbolic link; bifilar never "
                      "writes through a link there: remove the link or choose another --out");
    }
    throw UserError(path + ": cannot open the output folder's lock file: " + std::strerror(error));
  }
  struct stat st {};
  std::string refusal;
  if (::fstat(fd_, &st) != 0) {
    refusal = std::string("cannot examine the output folder's lock file: ") + std::strerror(errno);
  } else if (!S_ISREG(st.st_mode)) {
    refusal =
        "the output folder's lock is not a regular file (a folder, FIFO, device or "
        "socket); move it away or choose another --out";
  } else if (st.st_nlink != 1) {
    refusal =
        "the output folder's lock has other names (a hard link to another file); "
        "bifilar writes its lock only in a file of its own: remove it or choose another "
        "--out";
  }
  if (!refusal.empty()) {
    ::close(fd_);
    fd_ = -1;
    throw UserError(path + ": " + refusal);
  }
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int error = errno;
    std::string holder;
    char buffer[256] = {};
    const ssize_t n = ::pread(fd_, buffer, sizeof(buffer) - 1, 0);
    if (n > 0) holder = std::string(buffer, static_cast<size_t>(n));
    while (!holder.empty() &&
           (holder.back() == '\n' || holder.back() == '\0' || holder.back() == ' ')) {
      holder.pop_back();
    }
    ::close(fd_);
    fd_ = -1;
    if (error == EWOULDBLOCK) {
      throw UserError(out_dir + ": output folder is in use by another bifilar run (" +
                      (holder.empty() ? std::string("holder unknown") : holder) +
                      "); wait for it to finish or choose another --out");
    }
    throw UserError(path + ": cannot lock the output folder: " + std::strerror(error));
  }
  // Held: the file holds nothing but an earlier holder's line, or it is not bifilar's lock.
  char buffer[kLockRecordBytes + 1] = {};
  const ssize_t n = st.st_size > static_cast<off_t>(kLockRecordBytes)
                        ? -1
                        : ::pread(fd_, buffer, kLockRecordBytes, 0);
  if (n < 0 || !IsLockRecord(std::string(buffer, static_cast<size_t>(n)))) {
    ::close(fd_);
    fd_ = -1;
    throw UserError(path +
                    ": is not bifilar's lock file (it holds other data), so bifilar "
                    "will not write to it; move it away or choose another --out");
  }
  char stamp[64];
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  std::strftime(stamp, sizeof(stamp), "%Y-%m-%d %H:%M:%S UTC", &utc);
  std::string text = "pid " + std::to_string(::getpid()) + ", started " + stamp;
  text.resize(kLockRecordBytes - 1, ' ');
  text += '\n';
  [[maybe_unused]] const ssize_t written = ::pwrite(fd_, text.data(), text.size(), 0);
}

OutputFolderLock::~OutputFolderLock() {
  if (fd_ >= 0) ::close(fd_);  // releases the flock; the holder's line stays, harmless
}

OutputManifest::OutputManifest(std::string out_dir) : out_dir_(std::move(out_dir)) {
  const std::string path = (fs::path(out_dir_) / kFileName).string();
  std::error_code ec;
  // Temporary copies of the manifest itself left by a killed run (the name is bifilar's own).
  const std::string stale_prefix = std::string(kFileName) + ".tmp.";
  for (fs::directory_iterator it(out_dir_, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code ignored;
    if (it->path().filename().string().rfind(stale_prefix, 0) == 0 &&
        (it->is_symlink(ignored) || it->is_regular_file(ignored))) {
      fs::remove(it->path(), ignored);  // a link itself, never its target
    }
  }
  if (!fs::exists(fs::symlink_status(path, ec))) {
    AdoptLegacy();
    return;
  }
  const std::string damaged = path + ": damaged manifest of the files bifilar wrote (";
  const std::string advice = "); move the output folder away or choose another --out";
  try {
    const nlohmann::json j = nlohmann::json::parse(ReadAll(path, ManifestCap()));
    if (!j.is_object() || !j.contains("files") || !j["files"].is_array()) {
      throw UserError("no list 'files'");
    }
    for (const auto& name : j.at("files")) files_.insert(name.get<std::string>());
  } catch (const std::exception& e) {
    throw UserError(damaged + DescribeJsonError(e) + advice);
  }
  // Issue 15 item 1: the manifest says what may be removed, so an entry that could reach
  // outside OUT ("../thesis.txt", "/home/me/thesis.txt", a file behind a symbolic link) or
  // name anything bifilar does not write is refused, and with it the whole manifest: nothing
  // is removed and the run stops.
  std::vector<std::string> refused;
  for (const std::string& name : files_) {
    std::string problem;
    if (!IsOwnedName(name)) {
      problem = "not a file bifilar writes inside the output folder";
    } else {
      problem = RecordedFileProblem(out_dir_, name);
    }
    if (!problem.empty()) {
      const std::string quoted =
          nlohmann::json(name).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
      refused.push_back("entry " + quoted + " refused: " + problem);
    }
  }
  if (refused.empty()) return;
  std::string list;
  for (size_t i = 0; i < refused.size() && i < 3; ++i) list += (i ? "; " : "") + refused[i];
  if (refused.size() > 3) list += "; and " + std::to_string(refused.size() - 3) + " more";
  throw UserError(damaged + list + "; nothing was removed" + advice);
}

void OutputManifest::AdoptLegacy() {
  // A folder written before the manifest existed: the files its results.json names (the cache
  // entries and figures of that run, and the result files) are bifilar's; nothing else is.
  const std::string results_path = (fs::path(out_dir_) / "results.json").string();
  if (!IsBifilarResults(results_path)) return;
  const nlohmann::json results = nlohmann::json::parse(ReadAll(results_path));
  for (const char* name : kResultFiles) files_.insert(name);
  auto adopt = [&](const std::string& folder, const nlohmann::json& name, const char* suffix) {
    if (!name.is_string()) return;
    const std::string relative = folder + "/" + name.get<std::string>() + suffix;
    // Only names bifilar writes, and only regular files: never a way out of OUT.
    if (IsOwnedName(relative) && RecordedFileProblem(out_dir_, relative).empty()) {
      files_.insert(relative);
    }
  };
  if (results["traces"].is_array()) {
    for (const auto& trace : results["traces"]) {
      if (!trace.is_object()) continue;
      if (trace.contains("cache_key")) adopt("cache", trace["cache_key"], ".json");
      if (trace.contains("figure")) adopt("figures", trace["figure"], "");
    }
  }
  if (results.contains("figures") && results["figures"].is_object()) {
    for (const auto& [kind, name] : results["figures"].items()) adopt("figures", name, "");
  }
}

void OutputManifest::CheckOwnedPlaces() const {
  std::vector<std::string> foreign;
  std::error_code ec;
  for (const char* folder : kOwnedFolders) {
    const fs::path dir = fs::path(out_dir_) / folder;
    // A link in place of cache/ or figures/ would send bifilar's writes outside OUT.
    if (fs::is_symlink(dir, ec)) {
      foreign.push_back(std::string(folder) + " (a symbolic link)");
      continue;
    }
    if (fs::exists(dir, ec) && !fs::is_directory(dir, ec)) foreign.push_back(folder);
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
      const std::string relative = std::string(folder) + "/" + it->path().filename().string();
      if (!files_.count(relative) || it->is_directory(ec)) foreign.push_back(relative);
    }
  }
  for (const char* name : kResultFiles) {
    if (fs::exists(fs::path(out_dir_) / name, ec) && !files_.count(name)) {
      foreign.push_back(name);
    }
  }
  if (foreign.empty()) return;
  std::string list;
  for (size_t i = 0; i < foreign.size() && i < 3; ++i) {
    list += (i ? ", " : "") + (fs::path(out_dir_) / foreign[i]).string();
  }
  if (foreign.size() > 3) list += " and " + std::to_string(foreign.size() - 3) + " more";
  throw UserError(out_dir_ + ": the output folder holds files bifilar did not write (" + list +
                  "); bifilar owns cache/, figures/ and its result files there and removes stale "
                  "ones, so move your files elsewhere or choose another --out");
}

void OutputManifest::Record(const std::vector<std::string>& relative) {
  size_t before = files_.size();
  for (const std::string& name : relative) {
    assert(IsOwnedName(name) && "bifilar records only names it writes inside OUT");
    for (const std::string& n : WithTemporaries(name)) files_.insert(n);
  }
  if (files_.size() != before) Save();
}

std::vector<std::string> OutputManifest::Prune(const std::set<std::string>& keep) {
  std::vector<std::string> refused;
  std::error_code ec;
  for (auto it = files_.begin(); it != files_.end();) {
    const fs::path path = fs::path(out_dir_) / *it;
    std::string why;
    if (!keep.count(*it) && !RemoveOwnedFile(out_dir_, *it, &why)) {
      refused.push_back(path.string() + ": not removed (" + why +
                        "); bifilar removes only regular files it wrote inside the output folder");
      it = files_.erase(it);  // not bifilar's any more: the next run names it as foreign
    } else if (!fs::exists(fs::symlink_status(path, ec))) {
      it = files_.erase(it);
    } else {
      ++it;
    }
  }
  Save();
  return refused;
}

void OutputManifest::Save() const {
  nlohmann::json j;
  j["about"] = "files bifilar wrote in this folder; only these are ever removed by bifilar";
  j["files"] = files_;
  const std::string text = j.dump(1, ' ', false, nlohmann::json::error_handler_t::replace);
  WriteFileAtomically((fs::path(out_dir_) / kFileName).string(), text + "\n");
}

std::string FileHash(const std::string& path) {
  std::string bytes, why;
  if (!ReadRegularFile(path, OutputFileCap(), &bytes, &why)) return "";
  return HashToHex(Fnv1a64(bytes));
}

std::string StampReport(const std::string& html, const std::string& results_hash) {
  const std::string stamp = kReportStamp + results_hash + " -->\n";
  const size_t eol = html.find('\n');
  if (eol == std::string::npos) return html + "\n" + stamp;
  return html.substr(0, eol + 1) + stamp + html.substr(eol + 1);
}

void WriteOutputSet(const std::string& out_dir, nlohmann::json results,
                    const std::string& traces_csv, const std::string& angles_csv,
                    std::string (*report_html_builder)(const nlohmann::json&, const std::string&)) {
  const fs::path out(out_dir);
  results["outputs"] = {{"traces.csv", HashToHex(Fnv1a64(traces_csv))},
                        {"angles.csv", HashToHex(Fnv1a64(angles_csv))}};
  const std::string results_text =
      results.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  WriteFileAtomically((out / "traces.csv").string(), traces_csv);
  WriteFileAtomically((out / "angles.csv").string(), angles_csv);
  if (report_html_builder) {
    WriteFileAtomically(
        (out / "report.html").string(),
        StampReport(report_html_builder(results, out_dir), HashToHex(Fnv1a64(results_text))));
  } else {
    std::error_code ec;
    fs::remove(out / "report.html", ec);  // a report of an earlier run would not match
  }
  WriteFileAtomically((out / "results.json").string(), results_text);
}

bool ResolveInsideFolder(const std::string& folder, const std::string& sub, const std::string& name,
                         std::string* path, std::string* why) {
  const fs::path relative(name);
  why->clear();
  if (name.empty()) {
    *why = "an empty name";
  } else if (name.find('\0') != std::string::npos) {
    *why = "a name holding a NUL byte";
  } else if (relative.is_absolute() || relative.has_root_name() || relative.has_root_directory()) {
    *why = "an absolute path";
  } else if (std::any_of(relative.begin(), relative.end(),
                         [](const fs::path& part) { return part == ".."; })) {
    *why = "a '..' component";
  }
  if (!why->empty()) return false;
  const fs::path full = fs::path(folder) / sub / relative;
  std::error_code ec_root, ec_target;
  const fs::path root = fs::weakly_canonical(folder, ec_root);
  const fs::path target = fs::weakly_canonical(full, ec_target);
  if (ec_root || ec_target) {
    *why =
        "a name whose links cannot be followed (" + (ec_root ? ec_root : ec_target).message() + ")";
    return false;
  }
  // Component by component: /out2/x is not inside /out.
  const auto [root_end, unused] =
      std::mismatch(root.begin(), root.end(), target.begin(), target.end());
  if (root_end != root.end()) {
    *why = "a link leading out of " + folder;
    return false;
  }
  *path = full.string();
  return true;
}

std::vector<std::string> CheckOutputSet(const std::string& out_dir, bool check_report) {
  std::vector<std::string> problems;
  const fs::path out(out_dir);
  const std::string results_path = (out / "results.json").string();
  std::error_code ec;
  if (!fs::exists(results_path, ec)) return problems;  // nothing written yet
  const std::string results_text = ReadAll(results_path);
  nlohmann::json results;
  try {
    results = nlohmann::json::parse(results_text);
  } catch (const std::exception&) {
    return {results_path + ": missing or not valid JSON"};
  }
  if (!results.is_object() || !results.contains("outputs")) return problems;  // older bifilar
  for (const auto& [name, hash] : results["outputs"].items()) {
    std::string path, why;
    if (!ResolveInsideFolder(out_dir, "", name, &path, &why)) {
      problems.push_back(results_path + ": outputs names \"" + PrintableAscii(name, 200) + "\", " +
                         why + ", not a file of " + out_dir + " (not read)");
      continue;
    }
    if (!fs::exists(path, ec)) {
      problems.push_back(path + " is missing");
    } else if (!hash.is_string() || FileHash(path) != hash.get<std::string>()) {
      problems.push_back(path + " does not belong to " + results_path + " (another run wrote it)");
    }
  }
  const std::string report_path = (out / "report.html").string();
  if (check_report && fs::exists(report_path, ec)) {
    const std::string html = ReadAll(report_path);
    const size_t at = html.find(kReportStamp);
    const std::string expected = HashToHex(Fnv1a64(results_text));
    if (at == std::string::npos ||
        html.compare(at + std::strlen(kReportStamp), expected.size(), expected) != 0) {
      problems.push_back(report_path + " was not built from " + results_path);
    }
  }
  auto check_figure = [&](const nlohmann::json& name) {
    if (!name.is_string() || name.get<std::string>().empty()) return;
    std::string path, why;
    if (!ResolveInsideFolder(out_dir, "figures", name.get<std::string>(), &path, &why)) {
      problems.push_back(results_path + ": a figure named \"" +
                         PrintableAscii(name.get<std::string>(), 200) + "\", " + why +
                         ", not a file of " + out_dir + "/figures (not read)");
    } else if (!fs::exists(path, ec)) {
      problems.push_back(path + " (named in results.json) is missing");
    }
  };
  if (results.contains("traces") && results["traces"].is_array()) {
    for (const auto& trace : results["traces"]) {
      if (trace.is_object() && trace.contains("figure")) check_figure(trace["figure"]);
    }
  }
  if (results.contains("figures") && results["figures"].is_object()) {
    for (const auto& [kind, name] : results["figures"].items()) check_figure(name);
  }
  return problems;
}

void RefuseNonRegularOutputs(const std::string& out_dir) {
  const fs::path out(out_dir);
  std::vector<fs::path> paths = {out / OutputManifest::kFileName};
  for (const char* name : kResultFiles) paths.push_back(out / name);
  std::error_code ec;
  for (const char* folder : kOwnedFolders) {
    for (fs::directory_iterator it(out / folder, ec), end; !ec && it != end; it.increment(ec)) {
      paths.push_back(it->path());
    }
  }
  for (const fs::path& path : paths) {
    const fs::file_status status = fs::status(path, ec);  // follows symlinks
    if (!fs::exists(status) || fs::is_regular_file(status)) continue;
    const char* kind = fs::is_directory(status) ? "a folder"
                       : fs::is_fifo(status)    ? "a FIFO (named pipe)"
                       : fs::is_socket(status)  ? "a socket"
                                                : "a device";
    throw UserError(path.string() + ": is " + kind +
                    ", not a regular file; bifilar reads and writes only regular files in its "
                    "output folder: move it away or choose another --out");
  }
}

}  // namespace bifilar
