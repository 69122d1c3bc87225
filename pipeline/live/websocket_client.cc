// A WebSocket client over websocketpp and standalone Asio (websocket_client.h).
#include "pipeline/live/websocket_client.h"

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <thread>

#include <websocketpp/client.hpp>
#include <websocketpp/config/asio_no_tls_client.hpp>
#include <websocketpp/uri.hpp>

namespace bifilar::live {
namespace {

using Client = websocketpp::client<websocketpp::config::asio_client>;

constexpr double kHandshakeTimeoutS = 10;
constexpr long kCloseHandshakeTimeoutMs = 1000;

std::chrono::steady_clock::duration Seconds(double s) {
  const double wait_s = std::isfinite(s) ? std::min(std::max(s, 0.0), 1e6) : 1e6;
  return std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(wait_s));
}

// The connection runs on its own thread (the client's io_context); the handlers fill a queue
// under the mutex, Next empties it.
class WebSocketStream : public MessageStream {
 public:
  explicit WebSocketStream(std::string url) : url_(std::move(url)) {}

  ~WebSocketStream() override {
    bool open;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      open = state_ == State::kOpen;
    }
    if (open) {
      std::error_code ec;
      client_.close(connection_, websocketpp::close::status::going_away, "bifilar watch stopped",
                    ec);
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait_for(lock, std::chrono::milliseconds(2 * kCloseHandshakeTimeoutMs),
                        [this] { return state_ == State::kClosed; });
    }
    client_.stop();
    if (thread_.joinable()) thread_.join();
  }

  bool Connect(std::string* error) {
    client_.clear_access_channels(websocketpp::log::alevel::all);
    client_.clear_error_channels(websocketpp::log::elevel::all);
    std::error_code ec;
    client_.init_asio(ec);
    if (ec) {
      *error = Describe() + ": " + ec.message();
      return false;
    }
    client_.set_open_handshake_timeout(static_cast<long>(kHandshakeTimeoutS * 1000));
    client_.set_close_handshake_timeout(kCloseHandshakeTimeoutMs);
    client_.set_open_handler([this](websocketpp::connection_hdl) { SetState(State::kOpen, ""); });
    client_.set_fail_handler([this](websocketpp::connection_hdl h) {
      SetState(State::kClosed, "cannot connect: " + Reason(h, false));
    });
    client_.set_close_handler(
        [this](websocketpp::connection_hdl h) { SetState(State::kClosed, Reason(h, true)); });
    client_.set_message_handler([this](websocketpp::connection_hdl, Client::message_ptr m) {
      std::lock_guard<std::mutex> lock(mutex_);
      messages_.push_back(m->get_payload());
      changed_.notify_all();
    });
    Client::connection_ptr con = client_.get_connection(url_, ec);
    if (ec) {
      *error = Describe() + ": " + ec.message();
      return false;
    }
    connection_ = con->get_handle();
    client_.connect(con);
    thread_ = std::thread([this] {
      try {
        client_.run();
      } catch (const std::exception& e) {  // a handler that threw (out of memory)
        SetState(State::kClosed, std::string("connection thread stopped: ") + e.what());
      }
    });
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait_for(lock, Seconds(kHandshakeTimeoutS + 1),
                      [this] { return state_ != State::kConnecting; });
    // Opened, even when the server closed again at once: the messages it sent are read, then
    // Next reports the close.
    if (state_ == State::kOpen || opened_) return true;
    *error = Describe() + ": " + (why_.empty() ? "no answer to the handshake" : why_);
    return false;
  }

  bool Next(std::string* message, double timeout_s, std::string* why) override {
    message->clear();
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait_for(lock, Seconds(timeout_s),
                      [this] { return !messages_.empty() || state_ == State::kClosed; });
    if (!messages_.empty()) {
      *message = std::move(messages_.front());
      messages_.pop_front();
      return true;
    }
    if (state_ != State::kClosed) return true;  // a timeout
    *why = Describe() + ": " + why_;
    return false;
  }

  std::string Describe() const override { return "websocket " + url_; }

 private:
  enum class State { kConnecting, kOpen, kClosed };

  void SetState(State state, const std::string& why) {
    std::lock_guard<std::mutex> lock(mutex_);
    state_ = state;
    if (state == State::kOpen) opened_ = true;
    if (state == State::kClosed && why_.empty()) why_ = why;
    changed_.notify_all();
  }

  // Why connection h closed or failed: the server's close code and reason, or the error.
  std::string Reason(websocketpp::connection_hdl h, bool was_open) {
    std::error_code ec;
    Client::connection_ptr con = client_.get_con_from_hdl(h, ec);
    if (ec || !con) return "connection lost";
    const auto code = con->get_remote_close_code();
    if (was_open && code != websocketpp::close::status::abnormal_close &&
        code != websocketpp::close::status::no_status) {
      std::string text = "closed by the server (code " + std::to_string(code) + ", " +
                         websocketpp::close::status::get_string(code);
      if (!con->get_remote_close_reason().empty()) {
        text += ": " + con->get_remote_close_reason();
      }
      return text + ")";
    }
    const std::error_code error = con->get_ec();
    return (was_open ? "connection lost: " : "") +
           (error ? error.message() : std::string("no close frame from the server"));
  }

  std::string url_;
  Client client_;
  websocketpp::connection_hdl connection_;
  std::thread thread_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::string> messages_;
  State state_ = State::kConnecting;
  bool opened_ = false;  // the handshake completed once (guarded by mutex_)
  std::string why_;
};

}  // namespace

std::unique_ptr<MessageStream> OpenWebSocket(const std::string& url, std::string* error) {
  websocketpp::uri uri(url);
  if (!uri.get_valid() || uri.get_secure()) {
    *error = "websocket " + url + ": " +
             (uri.get_valid() ? std::string("wss:// (TLS) is not supported; use ws://")
                              : std::string("not a ws://host[:port][/path] URL"));
    return nullptr;
  }
  auto stream = std::make_unique<WebSocketStream>(url);
  if (!stream->Connect(error)) return nullptr;
  return stream;
}

}  // namespace bifilar::live
