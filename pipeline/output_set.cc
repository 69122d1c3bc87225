#include "pipeline/output_set.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <filesystem>

#include "pipeline/bounded_read.h"
#include "pipeline/cache.h"
#include "pipeline/atomic_file.h"
#include "pipeline/json_error.h"
#include "pipeline/user_error.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;

constexpr const char* kLockName = ".bifilar.lock";
constexpr const char* kOwnedFolders[] = {"cache", "figures"};
constexpr const char* kResultFiles[] = {"results.json", "traces.csv", "angles.csv", "report.html"};
constexpr const char* kReportStamp = "<!-- bifilar results.json fnv1a64: ";

// The file's bytes, "" when it cannot be read (pipeline/bounded_read.h: not a regular file, or
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

bool IsBifilarResults(const std::string& path) {
  try {
    const nlohmann::json j = nlohmann::json::parse(ReadAll(path));
    return j.is_object() && j.contains("traces") && j.contains("version");
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace

OutputFolderLock::OutputFolderLock(const std::string& out_dir) {
  const std::string path = (fs::path(out_dir) / kLockName).string();
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    throw UserError(path + ": cannot open the output folder's lock file: " + std::strerror(errno));
  }
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int error = errno;
    std::string holder;
    char buffer[256] = {};
    const ssize_t n = ::pread(fd_, buffer, sizeof(buffer) - 1, 0);
    if (n > 0) holder = std::string(buffer, static_cast<size_t>(n));
    while (!holder.empty() && (holder.back() == '\n' || holder.back() == '\0')) holder.pop_back();
    ::close(fd_);
    fd_ = -1;
    if (error == EWOULDBLOCK) {
      throw UserError(out_dir + ": output folder is in use by another bifilar run (" +
                      (holder.empty() ? std::string("holder unknown") : holder) +
                      "); wait for it to finish or choose another --out");
    }
    throw UserError(path + ": cannot lock the output folder: " + std::strerror(error));
  }
  char stamp[64];
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  std::strftime(stamp, sizeof(stamp), "%Y-%m-%d %H:%M:%S UTC", &utc);
  const std::string text = "pid " + std::to_string(::getpid()) + ", started " + stamp + "\n";
  if (::ftruncate(fd_, 0) == 0) {
    [[maybe_unused]] const ssize_t written = ::pwrite(fd_, text.data(), text.size(), 0);
  }
}

OutputFolderLock::~OutputFolderLock() {
  if (fd_ >= 0) {
    [[maybe_unused]] const int ignored = ::ftruncate(fd_, 0);
    ::close(fd_);  // releases the flock
  }
}

OutputManifest::OutputManifest(std::string out_dir) : out_dir_(std::move(out_dir)) {
  const std::string path = (fs::path(out_dir_) / kFileName).string();
  std::error_code ec;
  // Temporary copies of the manifest itself left by a killed run (the name is bifilar's own).
  const std::string stale_prefix = std::string(kFileName) + ".tmp.";
  for (fs::directory_iterator it(out_dir_, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->path().filename().string().rfind(stale_prefix, 0) == 0) {
      std::error_code ignored;
      fs::remove(it->path(), ignored);
    }
  }
  if (!fs::exists(path, ec)) {
    AdoptLegacy();
    return;
  }
  try {
    const nlohmann::json j = nlohmann::json::parse(ReadAll(path, ManifestCap()));
    if (!j.is_object() || !j.contains("files") || !j["files"].is_array()) {
      throw UserError("no list 'files'");
    }
    for (const auto& name : j.at("files")) files_.insert(name.get<std::string>());
  } catch (const std::exception& e) {
    throw UserError(path + ": damaged manifest of the files bifilar wrote (" + DescribeJsonError(e) +
                    "); move the output folder away or choose another --out");
  }
}

void OutputManifest::AdoptLegacy() {
  // A folder written before the manifest existed: the files its results.json names (the cache
  // entries and figures of that run, and the result files) are bifilar's; nothing else is.
  const std::string results_path = (fs::path(out_dir_) / "results.json").string();
  if (!IsBifilarResults(results_path)) return;
  const nlohmann::json results = nlohmann::json::parse(ReadAll(results_path));
  for (const char* name : kResultFiles) files_.insert(name);
  auto adopt = [&](const std::string& folder, const nlohmann::json& name, const char* suffix) {
    if (name.is_string() && !name.get<std::string>().empty() &&
        name.get<std::string>().find('/') == std::string::npos) {
      files_.insert(folder + "/" + name.get<std::string>() + suffix);
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
    for (const std::string& n : WithTemporaries(name)) files_.insert(n);
  }
  if (files_.size() != before) Save();
}

void OutputManifest::Prune(const std::set<std::string>& keep) {
  std::error_code ec;
  for (auto it = files_.begin(); it != files_.end();) {
    const fs::path path = fs::path(out_dir_) / *it;
    if (!keep.count(*it) && fs::is_regular_file(path, ec)) fs::remove(path, ec);
    if (!fs::exists(path, ec)) {
      it = files_.erase(it);
    } else {
      ++it;
    }
  }
  Save();
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
    WriteFileAtomically((out / "report.html").string(),
                        StampReport(report_html_builder(results, out_dir),
                                    HashToHex(Fnv1a64(results_text))));
  } else {
    std::error_code ec;
    fs::remove(out / "report.html", ec);  // a report of an earlier run would not match
  }
  WriteFileAtomically((out / "results.json").string(), results_text);
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
    const std::string path = (out / name).string();
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
    const fs::path path = out / "figures" / name.get<std::string>();
    if (!fs::exists(path, ec)) {
      problems.push_back(path.string() + " (named in results.json) is missing");
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
