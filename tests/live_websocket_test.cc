// The WebSocket client (pipeline/live/websocket_client.h) against a websocketpp server
// (tests/fake_ws_logger.h) that behaves as the ESP32 bifilar logger: one JSON object per text
// message, {"count", "ax", "ay", "az", "gyrox", "gyroy", "gyroz"}, at 40 Hz (and as fast as it
// can), from a simulated swing. Every message must arrive, in order, unchanged; the end (a close
// frame, or the server gone) must come back as false with the reason. Timing is only paced.
#include "tests/fake_ws_logger.h"  // first: Asio standalone (Debian libasio-dev, no Boost)

#include <chrono>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pipeline/live/websocket_client.h"
#include "tests/live_feed.h"

namespace bifilar::live {
namespace {

using Clock = std::chrono::steady_clock;
using testing::FakeLogger;
using testing::LoggerMessage;
using testing::SimulatedSwing;

constexpr double kHangGuardS = 30;

// The logger's messages for a simulated swing sampled at 40 Hz (accel in g, gyro in deg/s, as
// an MPU6050 sketch prints them).
std::vector<std::string> LoggerMessages(double duration_s) {
  const ImuData data = SimulatedSwing(duration_s, 40.0, 21);
  std::vector<std::string> out;
  for (std::size_t i = 0; i < data.size(); ++i) {
    out.push_back(LoggerMessage(i, data.accel_in_imu[i], data.gyro_in_imu[i]));
  }
  return out;
}

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
