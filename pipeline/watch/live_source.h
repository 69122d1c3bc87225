// The sources of `bifilar watch` that come through the transports of pipeline/live/: a serial port
// or a WebSocket carrying the text formats of pipeline/watch/sample_parser.h, and MAVLink 2
// (HIGHRES_IMU, SCALED_IMU, RAW_IMU) over a serial port or UDP. Specs: see
// pipeline/watch/watch_source.h. A disconnect ends Next (with the reason); Reconnect opens the
// same spec again.
#pragma once

#include <memory>
#include <string>

#include "pipeline/watch/sample_parser.h"
#include "pipeline/watch/source.h"

namespace bifilar {

// nullptr when `spec` is not one of these sources; throws UserError when it is but cannot be
// opened (a bad spec, a device that does not open, a refused connection).
std::unique_ptr<WatchSource> OpenLiveSource(const std::string& spec,
                                            const WatchInputOptions& input);

}  // namespace bifilar
