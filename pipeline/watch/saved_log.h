// The log `bifilar watch` writes as the samples arrive (issue 34, "nothing is lost"): a CSV in the
// config's imu format (its columns, units and delimiter), so `bifilar fit` and `process` read it
// with the same config. Values are printed with 17 significant digits (a double read back is the
// same double), and the sample the watch fits is the one read back from the printed text, so the
// saved log and the live fit hold the same numbers. The file is created new (never over an
// existing file: O_EXCL) and flushed after every batch, so a crash loses nothing written before
// it. Lines the watch rejected (garbage, NaN, a time that went back) go beside it into
// FILE.rejected.txt with their reason, never into the log: the log always reads back cleanly.
#pragma once

#include <cstdio>
#include <string>

#include "pipeline/logs/imu_format.h"
#include "pipeline/watch/sample_parser.h"

namespace bifilar {

class SavedLog {
 public:
  // Creates `path` (its folder must exist); throws UserError naming it when it exists or cannot be
  // created. `marker` (the simulated-log mark of the stream, or "") goes first.
  SavedLog(const std::string& path, const ImuFormat& format, const std::string& marker);
  ~SavedLog();
  SavedLog(const SavedLog&) = delete;
  SavedLog& operator=(const SavedLog&) = delete;

  // Writes one sample; returns it as a reader of the file reads it back.
  WatchSample Write(const WatchSample& sample);
  void Reject(const RejectedLine& line);
  void Flush();

  const std::string& path() const { return path_; }
  long samples() const { return samples_; }
  long rejected() const { return rejected_; }

 private:
  std::string path_;
  ImuFormat format_;
  std::FILE* file_ = nullptr;
  std::FILE* rejected_file_ = nullptr;
  long samples_ = 0, rejected_ = 0;
};

// A new time-stamped name beside the config: <folder>/watch_YYYYmmdd_HHMMSS.csv (UTC), with _2,
// _3, ... when that exists.
std::string DefaultSavedLogPath(const std::string& config_path);

}  // namespace bifilar
