// The page of `bifilar watch --serve PORT` (issue 34, "A page for the rig"): on 127.0.0.1 only,
// one self-contained HTML page (inline script and SVG, no font or script from outside: the rig is
// often offline) with the live swing rate and fit, I against cycles with its std band, and the
// verdict in large type, updated by server-sent events (GET /events; GET /state gives the last
// message). Built on cpp-httplib (Debian libcpp-httplib-dev, header-only): an HTTP server with
// chunked responses for server-sent events in one header, so the watch needs no web framework
// and no WebSocket for a one-way feed.
#pragma once

#include <memory>
#include <string>

#include "pipeline/watch/watch_engine.h"

namespace bifilar {

class WatchServer {
 public:
  // Listens on 127.0.0.1:port (0: any free port) in a thread of its own. Throws UserError when
  // the port cannot be bound.
  explicit WatchServer(int port);
  ~WatchServer();  // stops the server and ends the event streams
  WatchServer(const WatchServer&) = delete;
  WatchServer& operator=(const WatchServer&) = delete;

  int port() const;
  std::string url() const;
  // Sends an update (and the I-against-cycles history of its swing) to every page.
  void Publish(const WatchUpdate& update);
  // Sends a line of news (saved file, disconnect, end) to every page.
  void Event(const std::string& text);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// The page itself (for the tests: it must be self-contained).
std::string WatchPageHtml();

}  // namespace bifilar
