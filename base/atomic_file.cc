#include "base/atomic_file.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <system_error>

#include "base/user_error.h"

namespace bifilar {

std::string AtomicTemporaryName(const std::string& path) {
  return path + ".tmp." + std::to_string(::getpid());
}

void WriteFileAtomically(const std::string& path, const std::string& text) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  std::error_code ec;
  if (target.has_parent_path()) {
    fs::create_directories(target.parent_path(), ec);
    if (ec)
      throw UserError(path + ": cannot create folder " + target.parent_path().string() + ": " +
                      ec.message());
  }
  // A rename would replace a folder, device, FIFO or socket by a file (or fail half-way for a
  // folder); refuse before writing anything. A link to a regular file is replaced like a file.
  const fs::file_status status = fs::status(target, ec);  // follows symlinks
  if (fs::is_directory(status)) throw UserError(path + ": is a folder, expected a file name");
  if (fs::exists(status) && !fs::is_regular_file(status)) {
    throw UserError(path +
                    ": exists and is not a regular file (a device, FIFO or socket); "
                    "bifilar writes only regular files: move it away or choose another path");
  }
  const std::string temp = AtomicTemporaryName(path);
  // A stale temporary (or a link planted under its name) is removed first, so the write below
  // creates a fresh file and never writes through a link to a file outside the folder.
  ::unlink(temp.c_str());
  {
    std::ofstream file(temp, std::ios::binary | std::ios::trunc);
    if (!file) throw UserError(path + ": cannot write (temporary file " + temp + ")");
    file.write(text.data(), static_cast<std::streamsize>(text.size()));
    file.flush();
    if (!file) {
      fs::remove(temp, ec);
      throw UserError(path + ": write failed (disk full?)");
    }
  }
  fs::rename(temp, target, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(temp, ignored);
    throw UserError(path + ": cannot rename the temporary file into place: " + ec.message());
  }
}

}  // namespace bifilar
