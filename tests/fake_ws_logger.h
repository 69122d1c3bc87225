// A websocketpp server that behaves as the ESP32 bifilar logger, for the tests of the WebSocket
// client (tests/live_websocket_test.cc) and of `bifilar watch` over a WebSocket
// (tests/pipeline_watch_live_test.cc): one JSON object per text message, {"count", "ax", "ay",
// "az", "gyrox", "gyroy", "gyroz"} (accel in g, gyro in deg/s, as an MPU6050 sketch prints them),
// at a stated rate or as fast as it can, then a close frame or a connection that just ends.
// Include it first: it builds Asio standalone (Debian libasio-dev, no Boost).
#pragma once

#ifndef ASIO_STANDALONE
#define ASIO_STANDALONE
#endif
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Core>
#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

#include "base/units.h"

namespace bifilar::live::testing {

// The logger's message for one sample (accel in m/s^2 and gyro in rad/s, IMU axes).
inline std::string LoggerMessage(std::size_t count, const Eigen::Vector3d& accel_mps2,
                                 const Eigen::Vector3d& gyro_rad_per_s) {
  char text[256];
  std::snprintf(text, sizeof text,
                "{\"count\":%zu,\"ax\":%.4f,\"ay\":%.4f,\"az\":%.4f,\"gyrox\":%.3f,"
                "\"gyroy\":%.3f,\"gyroz\":%.3f}",
                count, accel_mps2[0] / kStandardGravityMps2, accel_mps2[1] / kStandardGravityMps2,
                accel_mps2[2] / kStandardGravityMps2, gyro_rad_per_s[0] * kDegPerRad,
                gyro_rad_per_s[1] * kDegPerRad, gyro_rad_per_s[2] * kDegPerRad);
  return text;
}

// A logger on 127.0.0.1 (an ephemeral port): on the first connection it sends `messages` at
// `rate_hz` (0: as fast as it can), then ends as `ending` says. With stop_listening, it also
// stops accepting connections at the end (a logger that is gone: a reconnect is refused);
// otherwise it keeps listening and a later connection gets no message.
class FakeLogger {
 public:
  enum class Ending { kCloseFrame, kVanish };
  using Server = websocketpp::server<websocketpp::config::asio>;
  using Clock = std::chrono::steady_clock;
  static constexpr double kHangGuardS = 30;

  FakeLogger(std::vector<std::string> messages, double rate_hz, Ending ending,
             bool stop_listening = false)
      : messages_(std::move(messages)),
        rate_hz_(rate_hz),
        ending_(ending),
        stop_listening_(stop_listening) {
    server_.clear_access_channels(websocketpp::log::alevel::all);
    server_.clear_error_channels(websocketpp::log::elevel::all);
    server_.init_asio();
    server_.set_reuse_addr(true);
    server_.set_pong_handler([this](websocketpp::connection_hdl, std::string) { Ponged(); });
    server_.set_open_handler([this](websocketpp::connection_hdl h) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!sender_.joinable()) sender_ = std::thread([this, h] { Send(h); });
    });
    server_.listen(asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
    server_.start_accept();
    std::error_code ec;
    port_ = server_.get_local_endpoint(ec).port();
    io_thread_ = std::thread([this] { server_.run(); });
  }

  ~FakeLogger() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (sender_.joinable()) sender_.join();
    }
    server_.stop();
    if (io_thread_.joinable()) io_thread_.join();
  }

  int port() const { return port_; }
  std::string Url(const std::string& path = "/ws") const {
    return "ws://127.0.0.1:" + std::to_string(port_) + path;
  }

 private:
  void Send(websocketpp::connection_hdl h) {
    const Clock::time_point start = Clock::now();
    for (std::size_t i = 0; i < messages_.size(); ++i) {
      if (rate_hz_ > 0) {
        std::this_thread::sleep_until(start + std::chrono::duration_cast<Clock::duration>(
                                                  std::chrono::duration<double>(i / rate_hz_)));
      }
      asio::post(server_.get_io_service(), [this, h, i] {
        std::error_code ec;
        server_.send(h, messages_[i], websocketpp::frame::opcode::text, ec);
      });
    }
    if (ending_ == Ending::kVanish) WaitUntilRead(h);
    asio::post(server_.get_io_service(), [this, h] {
      std::error_code ec;
      if (stop_listening_) server_.stop_listening(ec);
      if (ending_ == Ending::kCloseFrame) {
        server_.close(h, websocketpp::close::status::going_away, "logger stopped", ec);
      } else {  // the logger loses power: the TCP connection ends without a close frame
        Server::connection_ptr con = server_.get_con_from_hdl(h, ec);
        if (con) con->get_raw_socket().close(ec);
      }
    });
  }

  // Until the client has read every message sent on h: a ping after them, and its pong (the
  // client answers once it has read what came before). websocketpp's buffered amount falls to
  // zero when a write is handed to Asio, before it reaches the socket: closing then would cut it.
  void WaitUntilRead(websocketpp::connection_hdl h) {
    asio::post(server_.get_io_service(), [this, h] {
      std::error_code ec;
      server_.ping(h, "end", ec);
      if (ec) Ponged();  // the connection is already gone: nothing to wait for
    });
    std::unique_lock<std::mutex> lock(pong_mutex_);
    pong_changed_.wait_for(lock, std::chrono::duration<double>(kHangGuardS),
                           [this] { return ponged_; });
  }

  void Ponged() {
    std::lock_guard<std::mutex> lock(pong_mutex_);
    ponged_ = true;
    pong_changed_.notify_all();
  }

  std::vector<std::string> messages_;
  double rate_hz_;
  Ending ending_;
  bool stop_listening_;
  Server server_;
  int port_ = 0;
  std::mutex mutex_;
  std::thread sender_;
  std::thread io_thread_;
  std::mutex pong_mutex_;
  std::condition_variable pong_changed_;
  bool ponged_ = false;
};

}  // namespace bifilar::live::testing
