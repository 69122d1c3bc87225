#include "pipeline/watch/watch_source.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <thread>

#include "base/text_format.h"
#include "base/user_error.h"
#include "pipeline/logs/imu_log.h"
#include "pipeline/logs/simulated_log.h"
#include "pipeline/watch/live_source.h"

namespace bifilar {
namespace {

constexpr size_t kChunkBytes = 1 << 16;

void Sleep(double seconds) {
  std::this_thread::sleep_for(std::chrono::duration<double>(std::max(0.0, seconds)));
}

// Standard input (or any descriptor) as text: read what poll says is there.
class DescriptorSource : public WatchSource {
 public:
  DescriptorSource(int fd, std::string name, const WatchInputOptions& input)
      : fd_(fd), name_(std::move(name)), options_(input), parser_(input) {}
  bool Next(std::vector<WatchSample>* samples, std::vector<RejectedLine>* rejected,
            double timeout_s, std::string* why) override {
    pollfd p{fd_, POLLIN, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(timeout_s * 1000));
    if (ready <= 0) return true;  // nothing yet (or EINTR: Ctrl-C is checked by the caller)
    char buffer[kChunkBytes];
    const ssize_t n = ::read(fd_, buffer, sizeof(buffer));
    if (n <= 0) {
      parser_.Finish(samples, rejected);
      *why = n == 0 ? name_ + " ended" : name_ + ": read failed";
      return false;
    }
    parser_.Feed(std::string(buffer, static_cast<size_t>(n)), samples, rejected);
    return true;
  }
  void ResetClock() override { parser_.ResetClock(); }
  const InputCounters& counters() const override { return parser_.counters(); }
  std::string Describe() const override { return name_; }
  std::string simulated_marker() const override { return parser_.simulated_marker(); }
  std::string format_description() const override { return parser_.description(); }

 private:
  int fd_;
  std::string name_;
  WatchInputOptions options_;
  SampleParser parser_;
};

bool LooksBinary(const std::string& head) {
  if (head.rfind("ULog", 0) == 0) return true;
  return head.size() >= 2 && static_cast<unsigned char>(head[0]) == 0xA3 &&
         static_cast<unsigned char>(head[1]) == 0x95;
}

// A log file being written. CSV (text): the new bytes since the last read go to the parser.
// ULog and DataFlash (binary): when the file has grown, it is read whole again with the reader
// `fit` uses, and the samples after the last one handed out are new (a message cut short at the
// end of a growing file makes the read fail: it is tried again when more has come).
class FollowedFile : public WatchSource {
 public:
  FollowedFile(std::string path, const CampaignConfig& config, const WatchInputOptions& input)
      : path_(std::move(path)), config_(config), input_(input), parser_(input) {}
  ~FollowedFile() override {
    if (fd_ >= 0) ::close(fd_);
  }

  bool Next(std::vector<WatchSample>* samples, std::vector<RejectedLine>* rejected,
            double timeout_s, std::string* why) override {
    (void)why;  // a file being written never ends; Ctrl-C or --idle-end stops the watch
    struct stat by_name {};
    if (::stat(path_.c_str(), &by_name) != 0) {
      Sleep(timeout_s);
      return true;
    }
    if (fd_ >= 0) {
      struct stat open_file {};
      ::fstat(fd_, &open_file);
      const bool rotated = open_file.st_ino != by_name.st_ino;
      // Rotated: the old file's rest is still readable through fd_, and a busy machine may not
      // have read it all yet: a text log is read to its end before the new one (a binary one is
      // re-read by name, so what it had is what was read).
      if (rotated && binary_known_ && !binary_ && open_file.st_size > offset_) {
        return NextText(samples, rejected, timeout_s);
      }
      if (rotated || by_name.st_size < offset_) {
        ::close(fd_);  // rotated (a new file under the name) or truncated: start again
        fd_ = -1;
        restarted_ = true;
        parser_.Restart();
        return true;  // the caller sees the restart (TakeRestart) before any byte of the new file
      }
    }
    if (fd_ < 0) {
      fd_ = ::open(path_.c_str(), O_RDONLY | O_CLOEXEC);
      offset_ = 0;
      binary_known_ = false;
      if (fd_ < 0) {
        Sleep(timeout_s);
        return true;
      }
    }
    if (!binary_known_) {
      char head[8];
      const ssize_t n = ::pread(fd_, head, sizeof(head), 0);
      if (n < 2) {
        Sleep(timeout_s);
        return true;
      }
      binary_ = LooksBinary(std::string(head, static_cast<size_t>(n)));
      binary_known_ = true;
    }
    return binary_ ? NextBinary(by_name.st_size, samples, timeout_s)
                   : NextText(samples, rejected, timeout_s);
  }
  bool TakeRestart() override {
    const bool r = restarted_;
    restarted_ = false;
    return r;
  }
  void ResetClock() override {
    parser_.ResetClock();
    last_t_ = -1e300;
  }
  const InputCounters& counters() const override {
    return binary_ ? binary_counters_ : parser_.counters();
  }
  std::string Describe() const override { return path_; }
  std::string simulated_marker() const override {
    return binary_ ? simulated_marker_ : parser_.simulated_marker();
  }
  std::string format_description() const override {
    return binary_ ? "a binary log read with the config's imu settings" : parser_.description();
  }

 private:
  bool NextText(std::vector<WatchSample>* samples, std::vector<RejectedLine>* rejected,
                double timeout_s) {
    char buffer[kChunkBytes];
    const ssize_t n = ::pread(fd_, buffer, sizeof(buffer), offset_);
    if (n <= 0) {
      Sleep(timeout_s);
      return true;
    }
    offset_ += n;
    parser_.Feed(std::string(buffer, static_cast<size_t>(n)), samples, rejected);
    return true;
  }

  bool NextBinary(off_t size, std::vector<WatchSample>* samples, double timeout_s) {
    if (size == offset_) {
      Sleep(timeout_s);
      return true;
    }
    ImuData data;
    std::string error;
    ImuLogOptions options;
    if (!TryReadImuLog(path_, config_.imu.format, options, &data, &error)) {
      Sleep(timeout_s);  // most likely a message cut short: wait for the rest
      return true;
    }
    offset_ = size;
    for (const std::string& w : data.warnings) {
      if (IsSimulatedLogWarning(w)) simulated_marker_ = "# " + w;
    }
    for (size_t i = 0; i < data.size(); ++i) {
      if (!(data.t_s[i] > last_t_)) continue;
      WatchSample s;
      s.t_s = data.t_s[i];
      s.gyro_rad_per_s = data.gyro_in_imu[i];
      s.has_accel = data.has_accel() && config_.imu.format.has_accel();
      if (s.has_accel) s.accel_mps2 = data.accel_in_imu[i];
      last_t_ = s.t_s;
      ++binary_counters_.samples;
      samples->push_back(s);
    }
    return true;
  }

  std::string path_;
  CampaignConfig config_;
  WatchInputOptions input_;
  SampleParser parser_;
  int fd_ = -1;
  off_t offset_ = 0;
  bool binary_known_ = false, binary_ = false, restarted_ = false;
  double last_t_ = -1e300;
  InputCounters binary_counters_;
  std::string simulated_marker_;
};

bool StartsWith(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }

}  // namespace

std::unique_ptr<WatchSource> OpenWatchSource(const std::string& spec, const CampaignConfig& config,
                                             const WatchInputOptions& input) {
  if (spec.empty()) throw UserError("watch: no source given (a log file, - for stdin, ...)");
  if (spec == "-" || spec == "stdin") {
    return std::make_unique<DescriptorSource>(0, "standard input", input);
  }
  if (std::unique_ptr<WatchSource> live = OpenLiveSource(spec, input)) return live;
  const std::string path = StartsWith(spec, "file:") ? spec.substr(5) : spec;
  return std::make_unique<FollowedFile>(path, config, input);
}

long ReplayLog(const std::string& path, const CampaignConfig& config, double speed, int out_fd) {
  const ImuData data = ReadImuLog(path, config.imu.format);
  const ImuFormat& f = config.imu.format;
  const bool accel = f.has_accel() && data.has_accel();
  std::string head;
  for (const std::string& w : data.warnings) {
    if (IsSimulatedLogWarning(w)) head += "# " + w + "\n";
  }
  head +=
      f.time_column + "," + f.gyro_columns[0] + "," + f.gyro_columns[1] + "," + f.gyro_columns[2];
  if (accel) head += "," + f.accel_columns[0] + "," + f.accel_columns[1] + "," + f.accel_columns[2];
  head += "\n";
  auto write_all = [out_fd](const std::string& text) {
    size_t done = 0;
    while (done < text.size()) {
      const ssize_t n = ::write(out_fd, text.data() + done, text.size() - done);
      if (n <= 0) return false;  // the reader went away
      done += static_cast<size_t>(n);
    }
    return true;
  };
  if (!write_all(head)) return 0;
  const auto start = std::chrono::steady_clock::now();
  long written = 0;
  std::string batch;
  for (size_t i = 0; i < data.size(); ++i) {
    if (speed > 0) {  // send what is due, then wait for this sample's time
      const double due = (data.t_s[i] - data.t_s[0]) / speed;
      const double now =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (due > now + 0.01) {
        if (!batch.empty() && !write_all(batch)) return written;
        written = static_cast<long>(i);
        batch.clear();
        Sleep(due - now);
      }
    }
    batch += Fmt("%.17g", data.t_s[i] / ToSi(f.time_unit));
    for (int k = 0; k < 3; ++k) batch += Fmt(",%.17g", data.gyro_in_imu[i][k] / ToSi(f.gyro_unit));
    for (int k = 0; k < 3 && accel; ++k) {
      batch += Fmt(",%.17g", data.accel_in_imu[i][k] / ToSi(f.accel_unit));
    }
    batch += "\n";
  }
  if (!batch.empty() && write_all(batch)) written = static_cast<long>(data.size());
  return written;
}

}  // namespace bifilar
