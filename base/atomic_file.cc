#include "base/atomic_file.h"

#include <fcntl.h>
#include <limits.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <system_error>

#include "base/user_error.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;

// The longest file name (one path component, bytes) the folder's file system allows.
size_t NameMax(const fs::path& folder) {
  const long n = ::pathconf(folder.empty() ? "." : folder.c_str(), _PC_NAME_MAX);
  return n > 0 ? static_cast<size_t>(n) : static_cast<size_t>(NAME_MAX);
}

std::string Fnv1a64Hex(const std::string& text) {
  uint64_t h = 14695981039346656037ull;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ull;
  }
  char hex[17];
  std::snprintf(hex, sizeof(hex), "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

}  // namespace

std::string AtomicTemporaryName(const std::string& path) {
  const std::string suffix = ".tmp." + std::to_string(::getpid());
  const fs::path p(path);
  const std::string name = p.filename().string();
  if (name.size() + suffix.size() <= NameMax(p.parent_path())) return path + suffix;
  // A long name: a short one beside it, the same for the same path within this process.
  return (p.parent_path() / (".bfl-" + Fnv1a64Hex(name) + "." + std::to_string(::getpid())))
      .string();
}

void CheckFileTarget(const std::string& path) {
  const fs::path target(path);
  std::error_code ec;
  // A rename would replace a link (to /proc/self/fd/1, say) by a file, and a folder, device,
  // FIFO or socket likewise (or fail half-way for a folder); refuse before writing anything.
  if (fs::is_symlink(fs::symlink_status(target, ec))) {
    const std::string to = fs::read_symlink(target, ec).string();
    throw UserError(path + ": is a symbolic link" + (to.empty() ? "" : " (to " + to + ")") +
                    "; bifilar neither replaces a link nor writes through one: give the path of "
                    "the file itself");
  }
  const fs::file_status status = fs::status(target, ec);
  if (fs::is_directory(status)) throw UserError(path + ": is a folder, expected a file name");
  if (fs::exists(status) && !fs::is_regular_file(status)) {
    throw UserError(path +
                    ": exists and is not a regular file (a device, FIFO or socket); "
                    "bifilar writes only regular files: move it away or choose another path");
  }
  // An existing folder gives its own limit; a missing one the root's.
  const fs::path folder = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  const size_t name_max = NameMax(fs::is_directory(folder, ec) ? folder : fs::path("/"));
  if (target.filename().string().size() > name_max) {
    throw UserError(path + ": the file name is " +
                    std::to_string(target.filename().string().size()) +
                    " bytes long, more than this file system allows (" + std::to_string(name_max) +
                    "); choose a shorter name");
  }
}

void WriteFileAtomically(const std::string& path, const std::string& text) {
  const fs::path target(path);
  std::error_code ec;
  if (target.has_parent_path()) {
    fs::create_directories(target.parent_path(), ec);
    if (ec)
      throw UserError(path + ": cannot create folder " + target.parent_path().string() + ": " +
                      ec.message());
  }
  CheckFileTarget(path);
  const std::string temp = AtomicTemporaryName(path);
  // A stale temporary (or a link planted under its name) is removed first, and the file is then
  // created exclusively without following a link, so the write never goes anywhere else.
  ::unlink(temp.c_str());
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
  if (fd < 0) {
    throw UserError(path + ": cannot write (temporary file " + temp + ": " + std::strerror(errno) +
                    ")");
  }
  size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string why = n < 0 ? std::strerror(errno) : "nothing written";
      ::close(fd);
      ::unlink(temp.c_str());
      throw UserError(path + ": write failed (" + why + "; disk full?)");
    }
    done += static_cast<size_t>(n);
  }
  if (::close(fd) != 0) {
    const std::string why = std::strerror(errno);
    ::unlink(temp.c_str());
    throw UserError(path + ": write failed (" + why + ")");
  }
  fs::rename(temp, target, ec);
  if (ec) {
    ::unlink(temp.c_str());
    throw UserError(path + ": cannot rename the temporary file into place: " + ec.message());
  }
}

void RefuseToReplace(const std::string& path, const std::string& what, bool force) {
  std::error_code ec;
  if (path.empty()) throw UserError(what + ": the file name is empty");
  if (!fs::exists(fs::symlink_status(path, ec))) return;
  if (!force) {
    throw UserError(what + ": " + path +
                    " exists; choose another name, or add --force to overwrite it");
  }
  // --force replaces a regular file, never a link (nor writes through one), a folder or a device.
  try {
    CheckFileTarget(path);
  } catch (const UserError& e) {
    throw UserError(what + ": " + e.what());
  }
}

}  // namespace bifilar
