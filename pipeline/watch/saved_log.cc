#include "pipeline/watch/saved_log.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>

#include "base/text_format.h"
#include "base/user_error.h"

namespace bifilar {
namespace {

// The value as the file holds it ("%.17g" of the SI value in the file's unit) and that text read
// back in SI, as the CSV reader computes it (value * ToSi(unit)).
double PrintAndReadBack(double si, double to_si, std::string* out) {
  char text[40];
  std::snprintf(text, sizeof(text), "%.17g", si / to_si);
  *out += text;
  return std::strtod(text, nullptr) * to_si;
}

}  // namespace

SavedLog::SavedLog(const std::string& path, const ImuFormat& format, const std::string& marker)
    : path_(path), format_(format) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) {
    throw UserError(
        path + ": cannot create the watch log (" + std::strerror(errno) +
        (errno == EEXIST ? "; watch never writes over a file: name another --save)" : ")"));
  }
  file_ = ::fdopen(fd, "w");
  if (file_ == nullptr) {
    ::close(fd);
    throw UserError(path + ": cannot open the watch log for writing");
  }
  std::string head;
  if (!marker.empty()) head += marker + "\n";
  const std::string d(1, format.delimiter);
  head += format.time_column;
  for (const std::string& c : format.gyro_columns) head += d + c;
  if (format.has_accel()) {
    for (const std::string& c : format.accel_columns) head += d + c;
  }
  head += "\n";
  std::fputs(head.c_str(), file_);
  std::fflush(file_);
}

SavedLog::~SavedLog() {
  if (file_ != nullptr) std::fclose(file_);
  if (rejected_file_ != nullptr) std::fclose(rejected_file_);
}

WatchSample SavedLog::Write(const WatchSample& s) {
  WatchSample back = s;
  std::string line;
  const std::string d(1, format_.delimiter);
  back.t_s = PrintAndReadBack(s.t_s, ToSi(format_.time_unit), &line);
  for (int k = 0; k < 3; ++k) {
    line += d;
    back.gyro_rad_per_s[k] = PrintAndReadBack(s.gyro_rad_per_s[k], ToSi(format_.gyro_unit), &line);
  }
  back.has_accel = format_.has_accel();
  if (format_.has_accel()) {
    for (int k = 0; k < 3; ++k) {
      line += d;
      back.accel_mps2[k] = PrintAndReadBack(s.accel_mps2[k], ToSi(format_.accel_unit), &line);
    }
  }
  line += "\n";
  std::fputs(line.c_str(), file_);
  ++samples_;
  return back;
}

void SavedLog::Reject(const RejectedLine& rejected) {
  if (rejected_file_ == nullptr) {
    rejected_file_ = std::fopen((path_ + ".rejected.txt").c_str(), "a");
    if (rejected_file_ == nullptr) return;  // the count still says how many
    std::fputs("# lines bifilar watch kept out of the log beside this file: reason<TAB>line\n",
               rejected_file_);
  }
  std::fprintf(rejected_file_, "%s\t%s\n", rejected.reason.c_str(),
               PrintableAscii(rejected.line, 4000).c_str());
  ++rejected_;
}

void SavedLog::Flush() {
  std::fflush(file_);
  if (rejected_file_ != nullptr) std::fflush(rejected_file_);
}

std::string DefaultSavedLogPath(const std::string& config_path) {
  const std::filesystem::path folder = std::filesystem::path(config_path).parent_path();
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char stamp[32];
  std::strftime(stamp, sizeof(stamp), "%Y%m%d_%H%M%S", &utc);
  const std::string base = (folder / ("watch_" + std::string(stamp))).string();
  std::string path = base + ".csv";
  for (int n = 2; std::filesystem::exists(path); ++n)
    path = base + "_" + std::to_string(n) + ".csv";
  return path;
}

}  // namespace bifilar
