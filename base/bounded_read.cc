#include "base/bounded_read.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "base/user_error.h"

namespace bifilar {
namespace {

// What a non-regular file is, for "PATH: is a FIFO (named pipe), not a regular file".
std::string KindOf(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

std::string NotRegular(const std::string& path, const InputCap& cap, mode_t mode) {
  return path + ": is " + KindOf(mode) + ", not a regular file; a " + cap.what +
         " is read from a regular file only";
}

}  // namespace

InputCap LogCap(uint64_t max_bytes) {
  return {max_bytes, "log", "raise limits.max_log_mb (MB) in the config"};
}
InputCap DecompressedLogCap(uint64_t max_bytes) {
  return {max_bytes, "log once decompressed",
          "raise limits.max_decompressed_log_mb (MB) in the config"};
}
InputCap ConfigCap() { return {kMaxConfigBytes, "config", ""}; }
InputCap TableCap(const char* what) { return {kMaxTableBytes, what, ""}; }
InputCap ManifestCap() { return {kMaxManifestBytes, "manifest", ""}; }
InputCap CacheEntryCap() { return {kMaxCacheEntryBytes, "cache entry", ""}; }
InputCap OutputFileCap() { return {kMaxOutputFileBytes, "result file", ""}; }
InputCap FigureCap() { return {kMaxFigureBytes, "figure", ""}; }

std::string CapExceeded(const InputCap& cap, uint64_t size, bool size_known) {
  std::string text =
      std::string("too large for a ") + cap.what + ": " +
      (size_known ? std::to_string(size) + " bytes > cap " : "more than the cap of ") +
      std::to_string(cap.max_bytes) + " bytes";
  return text + (cap.raise.empty() ? "; is this the right file?" : "; " + cap.raise);
}

bool ReadRegularFile(const std::string& path, const InputCap& cap, std::string* bytes,
                     std::string* why) {
  bytes->clear();
  struct stat before;
  if (::stat(path.c_str(), &before) != 0) {
    *why = path + ": cannot open the " + cap.what + ": " + std::strerror(errno);
    return false;
  }
  if (!S_ISREG(before.st_mode)) {
    *why = NotRegular(path, cap, before.st_mode);
    return false;
  }
  // O_NONBLOCK: should the path have been swapped for a FIFO since the stat, open returns at once
  // instead of waiting for a writer; fstat below then refuses it.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) {
    *why = path + ": cannot open the " + cap.what + ": " + std::strerror(errno);
    return false;
  }
  auto fail = [&](const std::string& message) {
    ::close(fd);
    bytes->clear();
    bytes->shrink_to_fit();
    *why = message;
    return false;
  };
  struct stat opened;
  if (::fstat(fd, &opened) != 0) return fail(path + ": cannot stat: " + std::strerror(errno));
  if (!S_ISREG(opened.st_mode)) return fail(NotRegular(path, cap, opened.st_mode));
  const uint64_t size = static_cast<uint64_t>(opened.st_size);
  if (size > cap.max_bytes) return fail(path + ": " + CapExceeded(cap, size, true));
  bytes->reserve(static_cast<size_t>(size));
  // At most max_bytes + 1: one byte more than the cap proves the file grew past it.
  char buffer[1 << 16];
  for (;;) {
    const uint64_t room = cap.max_bytes + 1 - bytes->size();
    const ssize_t n = ::read(fd, buffer, room < sizeof(buffer) ? room : sizeof(buffer));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return fail(path + ": read error: " + std::strerror(errno));
    if (n == 0) break;
    bytes->append(buffer, static_cast<size_t>(n));
    if (bytes->size() > cap.max_bytes) {
      return fail(path + ": " + CapExceeded(cap, 0, false) + " (it grew while read)");
    }
  }
  ::close(fd);
  return true;
}

std::string ReadRegularFileOrThrow(const std::string& path, const InputCap& cap) {
  std::string bytes, why;
  if (!ReadRegularFile(path, cap, &bytes, &why)) throw UserError(why);
  return bytes;
}

}  // namespace bifilar
