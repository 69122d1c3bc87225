// The WebSocket client (pipeline/live/websocket_client.h) against a websocketpp server in the
// test that behaves as the ESP32 bifilar logger: one JSON object per text message,
// {"count", "ax", "ay", "az", "gyrox", "gyroy", "gyroz"}, at 40 Hz (and as fast as it can),
// from a simulated swing. Every message must arrive, in order, unchanged; the end (a close
// frame, or the server gone) must come back as false with the reason. Timing is only paced.
#define ASIO_STANDALONE  // Debian libasio-dev: Asio without Boost
#include <atomic>
#include <chrono>
#include <cstdio>
#include <future>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

#include "pipeline/live/websocket_client.h"
#include "tests/live_feed.h"

namespace bifilar::live {
namespace {

using Clock = std::chrono::steady_clock;
using Server = websocketpp::server<websocketpp::config::asio>;
using testing::SimulatedSwing;

constexpr double kHangGuardS = 30;

// The logger's messages for a simulated swing sampled at 40 Hz (accel in g, gyro in deg/s, as
// an MPU6050 sketch prints them).
std::vector<std::string> LoggerMessages(double duration_s) {
  const ImuData data = SimulatedSwing(duration_s, 40.0, 21);
  std::vector<std::string> out;
  for (std::size_t i = 0; i < data.size(); ++i) {
    char text[256];
    std::snprintf(text, sizeof text,
                  "{\"count\":%zu,\"ax\":%.4f,\"ay\":%.4f,\"az\":%.4f,\"gyrox\":%.3f,"
                  "\"gyroy\":%.3f,\"gyroz\":%.3f}",
                  i, data.accel_in_imu[i][0] / kStandardGravityMps2,
                  data.accel_in_imu[i][1] / kStandardGravityMps2,
                  data.accel_in_imu[i][2] / kStandardGravityMps2,
                  data.gyro_in_imu[i][0] * kDegPerRad, data.gyro_in_imu[i][1] * kDegPerRad,
                  data.gyro_in_imu[i][2] * kDegPerRad);
    out.push_back(text);
  }
  return out;
}

// A logger on 127.0.0.1 (an ephemeral port): on the first connection it sends `messages` at
// `rate_hz` (0: as fast as it can), then ends as `ending` says.
class FakeLogger {
 public:
  enum class Ending { kCloseFrame, kVanish };

  FakeLogger(std::vector<std::string> messages, double rate_hz, Ending ending)
      : messages_(std::move(messages)), rate_hz_(rate_hz), ending_(ending) {
    server_.clear_access_channels(websocketpp::log::alevel::all);
    server_.clear_error_channels(websocketpp::log::elevel::all);
    server_.init_asio();
    server_.set_reuse_addr(true);
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

  std::string Url() const { return "ws://127.0.0.1:" + std::to_string(port_) + "/ws"; }

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
    if (ending_ == Ending::kVanish) WaitUntilWritten(h);
    asio::post(server_.get_io_service(), [this, h] {
      std::error_code ec;
      if (ending_ == Ending::kCloseFrame) {
        server_.close(h, websocketpp::close::status::going_away, "logger stopped", ec);
      } else {  // the logger loses power: the TCP connection ends without a close frame
        Server::connection_ptr con = server_.get_con_from_hdl(h, ec);
        if (con) con->get_raw_socket().close(ec);
      }
    });
  }

  // Until every message queued on h is in the kernel's socket buffer (which a close still
  // delivers, before the end of the connection).
  void WaitUntilWritten(websocketpp::connection_hdl h) {
    const Clock::time_point start = Clock::now();
    while (Clock::now() - start < std::chrono::duration<double>(kHangGuardS)) {
      std::promise<std::size_t> queued;
      std::future<std::size_t> answer = queued.get_future();
      asio::post(server_.get_io_service(), [this, h, &queued] {
        std::error_code ec;
        Server::connection_ptr con = server_.get_con_from_hdl(h, ec);
        queued.set_value(con ? con->get_buffered_amount() : 0);
      });
      if (answer.get() == 0) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }

  std::vector<std::string> messages_;
  double rate_hz_;
  Ending ending_;
  Server server_;
  int port_ = 0;
  std::mutex mutex_;
  std::thread sender_;
  std::thread io_thread_;
};

// Every message until the stream ends; the reason in *why.
std::vector<std::string> ReadAll(MessageStream& stream, std::string* why) {
  std::vector<std::string> got;
  std::string message;
  const Clock::time_point start = Clock::now();
  while (stream.Next(&message, 0.2, why)) {
    if (!message.empty()) got.push_back(message);
    if (Clock::now() - start > std::chrono::duration<double>(kHangGuardS)) {
      ADD_FAILURE() << "no end of stream after " << kHangGuardS << " s";
      break;
    }
  }
  return got;
}

TEST(WebSocketClient, LoggerMessagesArriveInOrderAt40HzAndFaster) {
  struct Case {
    double duration_s;
    double rate_hz;
  };
  for (const Case c : {Case{1.0, 40.0}, Case{100.0, 0.0}}) {  // 40 messages paced; 4000 at once
    const std::vector<std::string> sent = LoggerMessages(c.duration_s);
    FakeLogger logger(sent, c.rate_hz, FakeLogger::Ending::kCloseFrame);
    std::string error, why;
    auto stream = OpenWebSocket(logger.Url(), &error);
    ASSERT_NE(stream, nullptr) << error;
    EXPECT_EQ(stream->Describe(), "websocket " + logger.Url());
    const std::vector<std::string> got = ReadAll(*stream, &why);
    ASSERT_EQ(got.size(), sent.size()) << "rate " << c.rate_hz << ": " << why;
    EXPECT_TRUE(got == sent) << "rate " << c.rate_hz;
    EXPECT_NE(why.find("logger stopped"), std::string::npos) << why;
    EXPECT_NE(why.find("1001"), std::string::npos) << why;
    std::string message;
    EXPECT_FALSE(stream->Next(&message, 0.0, &why));  // stays closed
  }
}

TEST(WebSocketClient, ALoggerThatVanishesEndsTheStreamWithAReason) {
  const std::vector<std::string> sent = LoggerMessages(1.0);
  FakeLogger logger(sent, 0.0, FakeLogger::Ending::kVanish);
  std::string error, why;
  auto stream = OpenWebSocket(logger.Url(), &error);
  ASSERT_NE(stream, nullptr) << error;
  const std::vector<std::string> got = ReadAll(*stream, &why);
  // Every message the logger had written before the end arrives first, then the end.
  ASSERT_EQ(got.size(), sent.size()) << why;
  EXPECT_TRUE(got == sent);
  EXPECT_NE(why.find("connection lost"), std::string::npos) << why;
}

TEST(WebSocketClient, TimeoutIsNotTheEnd) {
  FakeLogger logger({}, 0.0, FakeLogger::Ending::kCloseFrame);
  std::string error, why, message = "stale";
  auto stream = OpenWebSocket(logger.Url(), &error);
  ASSERT_NE(stream, nullptr) << error;
  // The logger closes right away; before that, or after it, never a message.
  while (stream->Next(&message, 0.01, &why)) EXPECT_TRUE(message.empty());
  EXPECT_NE(why.find("logger stopped"), std::string::npos) << why;
}

TEST(WebSocketClient, BadUrlOrNoServerIsAClearError) {
  std::string error;
  EXPECT_EQ(OpenWebSocket("http//nonsense", &error), nullptr);
  EXPECT_NE(error.find("not a ws://"), std::string::npos) << error;
  EXPECT_EQ(OpenWebSocket("wss://127.0.0.1:1/ws", &error), nullptr);
  EXPECT_NE(error.find("wss://"), std::string::npos) << error;
  // A port with nothing listening (bound, never listened: connections are refused).
  asio::io_context io;
  asio::ip::tcp::acceptor closed(io);
  closed.open(asio::ip::tcp::v4());
  closed.bind(asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
  const std::string url = "ws://127.0.0.1:" + std::to_string(closed.local_endpoint().port());
  EXPECT_EQ(OpenWebSocket(url, &error), nullptr);
  EXPECT_NE(error.find("cannot connect"), std::string::npos) << error;
  EXPECT_NE(error.find(url), std::string::npos) << error;
}

}  // namespace
}  // namespace bifilar::live
