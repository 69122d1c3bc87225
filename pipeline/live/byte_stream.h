// Byte transports for `bifilar watch` (issue 34): a serial port (a USB CDC-ACM logger, a flight
// controller's USB or telemetry port) and a UDP socket (MAVLink from PX4 SITL, mavlink-router or
// a telemetry radio, usually port 14550). Both are standalone Asio (Debian libasio-dev,
// header-only): one portable API for serial ports and sockets, with the read timeouts a live
// source needs done by the io_context (run_for) instead of hand-written select()/termios code.
//
// A ByteStream is used from one thread. Read waits at most timeout_s for bytes; "no bytes yet"
// is not the end of the stream (Read returns true with nothing appended); a closed or failed
// device is (false, with the reason).
#pragma once

#include <cstddef>
#include <memory>
#include <string>

namespace bifilar::live {

// The most bytes one Read appends (64 kB: a 1 kHz MAVLink stream brings ~60 kB/s).
inline constexpr std::size_t kByteStreamMaxReadBytes = std::size_t{64} << 10;

class ByteStream {
 public:
  virtual ~ByteStream() = default;
  // Appends up to kByteStreamMaxReadBytes bytes to *chunk, waiting at most timeout_s (>= 0) for
  // the first. Returns true while the stream is open (possibly having appended nothing: a
  // timeout); false at end of stream / disconnect, with the reason in *why.
  virtual bool Read(std::string* chunk, double timeout_s, std::string* why) = 0;
  // What the stream reads, for messages: "serial /dev/ttyACM0 at 115200 baud", "udp 0.0.0.0:14550".
  virtual std::string Describe() const = 0;
};

// Opens `device` (e.g. /dev/ttyACM0) at `baud` (8N1, no flow control, raw). A baud rate the
// system does not know, a missing device or one without permission: nullptr, reason in *error.
std::unique_ptr<ByteStream> OpenSerial(const std::string& device, int baud, std::string* error);

// Binds a UDP socket to bind_host:port ("0.0.0.0" or "127.0.0.1"; port 1..65535; port 0 binds
// an ephemeral port, which Describe() names). Each datagram's bytes are appended in arrival
// order. An address in use or not local: nullptr, reason in *error.
std::unique_ptr<ByteStream> OpenUdp(const std::string& bind_host, int port, std::string* error);
// The same, and the port bound in *bound_port (the ephemeral one when port is 0: tests).
std::unique_ptr<ByteStream> OpenUdp(const std::string& bind_host, int port, int* bound_port,
                                    std::string* error);

}  // namespace bifilar::live
