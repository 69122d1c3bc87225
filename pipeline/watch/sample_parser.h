// The text a logger streams, turned into IMU samples (SI, IMU axes) for `bifilar watch`: CSV with
// a header row, or JSON lines with one object per sample ({"t": 0.01, "gx": ...}). The columns
// (or keys) are the config's imu columns when the stream has them all; otherwise they are guessed
// from the header and the first rows, as `bifilar inspect` guesses a CSV file's (the guess comes
// through WatchInputOptions::guess_format, which the command line and Python fill with
// GuessCsvFormat). A logger that sends a sample counter instead of a time (the ESP32 bifilar
// logger sends {"count", "ax", "ay", "az", "gyrox", "gyroy", "gyroz"} at 40 Hz) is read with
// counter_rate_hz: t = counter / rate, or the sample's index / rate when there is no counter.
//
// Bad input never stops the stream: a line that is not a row of numbers, a NaN or infinite value,
// a value no sensor reads, a time that does not move forward are each counted under their own
// name (InputCounters) and the line is handed back as rejected, with the reason, so the caller
// can keep it apart from the saved log.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pipeline/logs/imu_format.h"

namespace bifilar {

struct WatchSample {
  double t_s = 0.0;
  Eigen::Vector3d gyro_rad_per_s = Eigen::Vector3d::Zero();
  bool has_accel = false;
  Eigen::Vector3d accel_mps2 = Eigen::Vector3d::Zero();
};

// A line kept out of the samples, and why ("garbage", "non_finite", "time_back", "out_of_range",
// "missing_key").
struct RejectedLine {
  std::string line;
  std::string reason;
};

struct InputCounters {
  long lines = 0;         // non-blank lines after the header
  long samples = 0;       // samples accepted
  long garbage = 0;       // not a row of numbers (or not a JSON object of numbers)
  long non_finite = 0;    // NaN or infinite value
  long out_of_range = 0;  // a rate or specific force no sensor reads (a corrupt value)
  long time_back = 0;     // time equal to or before the previous sample's
  long bad_checksum = 0;  // MAVLink frames with a bad checksum (the transport counts them)
  long restarts = 0;      // the stream started over (a new header, a truncated or rotated file)
  long Rejected() const { return garbage + non_finite + out_of_range + time_back; }
  // "3 garbage lines, 1 NaN sample, 2 times that went back" ("" when nothing was rejected).
  std::string Text() const;
};

struct WatchInputOptions {
  // The config's format: a stream holding all its columns is read with its units.
  ImuFormat format;
  // > 0: the time is a sample counter at this rate (Hz): counter_column / rate, or the
  // sample's index / rate when the stream has no such column. 0: the stream carries a time.
  double counter_rate_hz = 0.0;
  std::string counter_column = "count";
  // Rows read before the columns and units are fixed (the guess looks at them). >= 1, default 25.
  // When the config's columns are not the stream's, the units are guessed from the data, and
  // rows of a body at rest say nothing of the unit (a gyro in deg/s at rest reads as rad/s): the
  // rows are then held until they hold motion (a rate 20 times the first rows' noise), up to
  // max_rows_held, and guessed again as they double.
  int rows_to_guess = 25;
  int max_rows_held = 262144;  // (count) >= rows_to_guess
  // The format guessed from a CSV text (header + first rows): true and *format, or false and
  // *why. Empty: only the config's columns are accepted.
  std::function<bool(const std::string& text, ImuFormat* format, std::string* why)> guess_format;
};

class SampleParser {
 public:
  explicit SampleParser(const WatchInputOptions& options);

  // Feeds bytes as they arrive (any split: a line may come in pieces). Complete samples are
  // appended to *samples and rejected lines to *rejected. Throws UserError when the columns can
  // be neither found nor guessed (the stream cannot be read at all).
  void Feed(const std::string& bytes, std::vector<WatchSample>* samples,
            std::vector<RejectedLine>* rejected);
  // The end of the stream: a last line without a line end, and rows still held for the guess.
  void Finish(std::vector<WatchSample>* samples, std::vector<RejectedLine>* rejected);
  // The stream starts over (a rotated or truncated file, a reconnect): expect a header again.
  // The last time is kept, so a new stream that starts at an earlier time is rejected as
  // time_back rather than misread.
  void Restart();
  // A new log starts: forget the last time (its clock may start again from zero).
  void ResetClock() { last_t_ = -1e300; }

  const InputCounters& counters() const { return counters_; }
  InputCounters& counters() { return counters_; }
  // "csv" or "json" once the first line was seen; "" before.
  const std::string& mode() const { return mode_; }
  // The format the stream is read with (valid once resolved()), and what was guessed.
  bool resolved() const { return resolved_; }
  const ImuFormat& input_format() const { return input_format_; }
  const std::string& description() const { return description_; }
  // The simulated-log mark of the stream (pipeline/logs/simulated_log.h), "" when none.
  const std::string& simulated_marker() const { return simulated_marker_; }

 private:
  void Line(std::string line, std::vector<WatchSample>* samples,
            std::vector<RejectedLine>* rejected);
  bool Cells(const std::string& line, std::vector<std::string>* cells) const;
  void Resolve();
  bool ColumnsAreTheConfigs() const;
  std::string HeldText() const;
  bool HeldRowsShowMotion() const;
  void Row(const std::string& line, const std::vector<std::string>& cells,
           std::vector<WatchSample>* samples, std::vector<RejectedLine>* rejected);

  WatchInputOptions options_;
  std::string partial_;
  std::string mode_;
  char delimiter_ = ',';
  std::vector<std::string> header_;
  std::vector<std::pair<std::string, std::vector<std::string>>> held_;  // rows before Resolve
  bool resolved_ = false;
  size_t next_guess_rows_ = 0;  // held rows at which the motion check runs again
  ImuFormat input_format_;
  std::string description_;
  int time_index_ = -1, counter_index_ = -1;
  int gyro_index_[3] = {-1, -1, -1}, accel_index_[3] = {-1, -1, -1};
  double last_t_ = -1e300;
  long index_ = 0;
  std::string simulated_marker_;
  InputCounters counters_;
};

}  // namespace bifilar
