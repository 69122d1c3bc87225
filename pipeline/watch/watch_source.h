// Where `bifilar watch` reads samples from (issue 34, "Sources"). A source spec is:
//   "-" or "stdin"            standard input: CSV with a header, or JSON lines
//   PATH (or "file:PATH")     a log being written: CSV followed as it grows; a PX4 ULog or an
//                             ArduPilot DataFlash log re-read as it grows (new samples only)
//   "serial:DEVICE@BAUD"      a serial port sending the same text formats
//   "ws://HOST:PORT/PATH"     a WebSocket sending one JSON object per message
//   "mavlink:DEVICE@BAUD"     MAVLink 2 (HIGHRES_IMU, SCALED_IMU, RAW_IMU) over a serial port
//   "mavlink-udp:HOST:PORT"   MAVLink 2 over UDP (bound on HOST:PORT)
// The serial, WebSocket and MAVLink transports are pipeline/live/'s
// (pipeline/watch/live_source.h).
//
// A followed file that shrinks (truncated) or is replaced (a new file under the name: rotation)
// is read again from its start and the source says so (restarted()); the CSV header is read
// again, so a new file is never misread as the rest of the old one.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "pipeline/config/config.h"
#include "pipeline/watch/sample_parser.h"
#include "pipeline/watch/source.h"

namespace bifilar {

// Opens the source `spec` (above). Throws UserError naming the spec on a bad spec, a missing
// transport or a source that cannot be opened (a file that does not exist yet is waited for).
std::unique_ptr<WatchSource> OpenWatchSource(const std::string& spec, const CampaignConfig& config,
                                             const WatchInputOptions& input);

// Feeder for tests and the guide's example: replays the log `path` (any format `fit` reads, with
// `config`'s imu format) as CSV text into `out` (a file descriptor), pacing the samples by their
// own time divided by `speed` (0: as fast as possible). The CSV carries the config's columns
// and the simulated-log mark when the log has one. Returns the samples written.
long ReplayLog(const std::string& path, const CampaignConfig& config, double speed, int out_fd);

}  // namespace bifilar
