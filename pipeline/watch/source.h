// The interface of a source of `bifilar watch` samples (what pipeline/watch/watch_source.h opens
// from a spec, and pipeline/watch/live_source.h's transports implement).
#pragma once

#include <string>
#include <vector>

#include "pipeline/watch/sample_parser.h"

namespace bifilar {

class WatchSource {
 public:
  virtual ~WatchSource() = default;
  // Waits up to timeout_s for data and appends what came. False at the end of the stream or a
  // disconnect (*why says which); true otherwise, also when nothing came.
  virtual bool Next(std::vector<WatchSample>* samples, std::vector<RejectedLine>* rejected,
                    double timeout_s, std::string* why) = 0;
  // True once after the stream started over (truncated or rotated file); cleared by the call.
  virtual bool TakeRestart() { return false; }
  // Forget the last time (a new log starts: its clock may start again from zero).
  virtual void ResetClock() = 0;
  // A stream that may come back after a disconnect (a serial port, a WebSocket, UDP); standard
  // input and files end for good.
  virtual bool CanReconnect() const { return false; }
  // Open again after a disconnect; false (and *why) when it cannot be opened now.
  virtual bool Reconnect(std::string* why) {
    *why = "this source cannot reconnect";
    return false;
  }
  virtual const InputCounters& counters() const = 0;
  virtual std::string Describe() const = 0;
  // The simulated-log mark seen in the stream ("" when none).
  virtual std::string simulated_marker() const { return ""; }
  // How the columns were found ("the config's columns: ...", "guessed columns: ...").
  virtual std::string format_description() const { return ""; }
};

}  // namespace bifilar
