// The use case behind `bifilar watch CONFIG SOURCE` (issue 34): read IMU samples as the body
// swings (pipeline/watch/watch_source.h), save every one as it arrives
// (pipeline/watch/saved_log.h), and tell the user, update by update, what I is, how sure, and
// whether to stop, swing again or fix the rig (pipeline/watch/watch_engine.h). At the end
// (end of the stream, Ctrl-C, --cycles, --stop-at-target) the final result is `RunFit` on the
// saved log: the very numbers `bifilar fit CONFIG SAVED.csv` prints. The CLI
// (pipeline/cli/cli_watch.cc) and Python's bifilar.watch call RunWatch.
#pragma once

#include <atomic>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/records/trace_record.h"
#include "pipeline/watch/sample_parser.h"
#include "pipeline/watch/watch_engine.h"

namespace bifilar {

struct WatchCommandOptions {
  std::string config_path;  // YAML: rig geometry, masses, IMU format (as for `bifilar fit`)
  std::string source;       // a source spec (pipeline/watch/watch_source.h)
  // The log every sample is written to; "": a new time-stamped file beside the config.
  std::string save_path;
  WatchEngineOptions engine;
  double counter_rate_hz = 0.0;          // > 0: the stream's time is a sample counter at this rate
  std::string counter_column = "count";  // the counter's column or key
  int stop_after_cycles = 0;             // > 0: end once the fitted window holds this many cycles
  bool stop_at_target = false;           // end at the first "enough"
  // End when no sample came for this long (s; the stream stopped); 0: keep waiting (a followed
  // file, a serial port). The watch says once, after idle_warn_s, that nothing is coming.
  double idle_end_s = 0.0;
  double idle_warn_s = 3.0;
  // After a disconnect or a restarted stream: true appends to the same log (samples whose time
  // goes back are rejected, counted), false closes it (with its final result) and starts a new
  // one.
  bool append_on_reconnect = false;
  bool handle_interrupt = false;  // install the Ctrl-C handler (CLI)
  // >= 0: serve the live page on 127.0.0.1:serve_port (0: any free port; the URL is told as an
  // event) (pipeline/watch/watch_server.h). -1: no page.
  int serve_port = -1;
  // Called for each update, each event (a line for the user: saved file, restart, disconnect,
  // idle), and each final result (one per saved log). Any may be empty.
  std::function<void(const WatchUpdate&)> on_update;
  std::function<void(const std::string&)> on_event;
  // Return false to stop the watch (Python's generator closed). Empty: never.
  std::function<bool()> keep_going;
  // The guess of a stream's columns (GuessCsvFormat); filled by RunWatch when empty.
  std::function<bool(const std::string&, ImuFormat*, std::string*)> guess_format;
};

// One saved log and the result of `fit` on it.
struct WatchLogResult {
  std::string path;
  long samples = 0;
  long rejected = 0;
  std::optional<TraceRecord> record;  // none when the log holds no sample
};

struct WatchCommandResult {
  std::vector<WatchLogResult> logs;  // in order; the last is the one being written at the end
  InputCounters counters;            // of the whole watch
  WatchUpdate last_update;
  std::vector<WatchUpdate> updates;  // every update (bounded by the caller's patience: small)
  std::string end_reason;            // "end of stream", "interrupted", "target reached", ...
  bool interrupted = false;
  std::string config_path_for_print;  // the CLI's config path, for the final lines
  nlohmann::json json;                // {logs: [{path, samples, rejected, record}], counters, ...}
  int ExitCode() const;               // 130 interrupted, 1 no log or its fit not ok, 0 otherwise
};

// Throws UserError on a bad config, source or option before any sample is read.
WatchCommandResult RunWatch(const WatchCommandOptions& options);

// The one terminal line of an update (no line end; the CLI prints it after a carriage return).
std::string WatchStatusLine(const WatchUpdate& update);

}  // namespace bifilar
