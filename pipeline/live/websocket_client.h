// A WebSocket client for `bifilar watch` (issue 34): text messages from a logger that streams
// one JSON object per message (the ESP32 bifilar logger sends {"count", "ax", "ay", "az",
// "gyrox", "gyroy", "gyroz", ...} at 40 Hz). websocketpp (Debian libwebsocketpp-dev, header-only,
// over standalone Asio): the RFC 6455 handshake, framing, masking, fragmentation, ping/pong and
// close codes are the library's, not hand-written here. The connection runs on its own thread;
// Next hands the messages over in the order they arrived, none dropped.
#pragma once

#include <memory>
#include <string>

namespace bifilar::live {

class MessageStream {
 public:
  virtual ~MessageStream() = default;
  // The next text message into *message, waiting at most timeout_s (>= 0). Returns true with
  // *message filled, or true with *message empty on a timeout; false once the connection is
  // closed and every message received before has been handed over (reason in *why: the close
  // code and reason the server sent, or the network error).
  virtual bool Next(std::string* message, double timeout_s, std::string* why) = 0;
  // "websocket ws://host:port/path".
  virtual std::string Describe() const = 0;
};

// Connects to `url` (ws://host[:port][/path]; wss:// is refused: no TLS in the build) and waits
// for the handshake (at most 10 s). A bad URL, a refused connection or a failed handshake:
// nullptr, reason in *error.
std::unique_ptr<MessageStream> OpenWebSocket(const std::string& url, std::string* error);

}  // namespace bifilar::live
