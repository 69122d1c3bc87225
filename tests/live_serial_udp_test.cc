// The serial and UDP byte streams (pipeline/live/byte_stream.h) with feeders: a pseudo-terminal
// pair stands for the USB serial port (the feeder writes the master side, OpenSerial reads the
// slave) and a loopback socket for the flight controller. Each replays a simulated swing, as a
// CSV log's lines or as MAVLink frames, in real time and as fast as it can; what arrives must be
// exactly what was sent. Timing is only paced, never asserted.
#define ASIO_STANDALONE  // Debian libasio-dev: Asio without Boost
#include <pty.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <asio.hpp>

#include "pipeline/live/byte_stream.h"
#include "pipeline/live/mavlink.h"
#include "pipeline/logs/imu_log_writer.h"
#include "tests/live_feed.h"

namespace bifilar::live {
namespace {

using Clock = std::chrono::steady_clock;
using testing::AsMavlinkSamples;
using testing::ExpectHighresEqual;
using testing::HighresFrames;
using testing::SimulatedSwing;

constexpr double kHangGuardS = 30;  // a test that waits longer than this has hung

// A pseudo-terminal pair: the master is the feeder's end.
struct Pty {
  int master = -1;
  int slave = -1;
  std::string slave_name;
  Pty() {
    char name[256] = {};
    EXPECT_EQ(openpty(&master, &slave, name, nullptr, nullptr), 0);
    slave_name = name;
  }
  ~Pty() {
    if (master >= 0) close(master);
    if (slave >= 0) close(slave);
  }
};

// Writes `pieces` to fd, piece i at pace_s * times_s[i] after the start (pace_s 0: at once),
// then, once the reader has had every byte (*read_bytes; a pty drops what the slave has not
// read when the master closes), closes fd.
void Feed(int fd, const std::vector<std::string>& pieces, const std::vector<double>& times_s,
          double pace_s, const std::atomic<std::size_t>* read_bytes) {
  std::size_t total = 0;
  const Clock::time_point start = Clock::now();
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    if (pace_s > 0) {
      std::this_thread::sleep_until(start +
                                    std::chrono::duration_cast<Clock::duration>(
                                        std::chrono::duration<double>(pace_s * times_s[i])));
    }
    for (std::size_t done = 0; done < pieces[i].size();) {
      const ssize_t n = write(fd, pieces[i].data() + done, pieces[i].size() - done);
      if (n <= 0) return;
      done += static_cast<std::size_t>(n);
    }
    total += pieces[i].size();
  }
  while (read_bytes->load() < total &&
         Clock::now() - start < std::chrono::duration<double>(kHangGuardS)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  close(fd);
}

// Everything the stream delivers until it ends (the count so far in *read_bytes); the reason
// in *why.
std::string ReadToEnd(ByteStream& stream, std::atomic<std::size_t>* read_bytes, std::string* why) {
  std::string all;
  const Clock::time_point start = Clock::now();
  while (stream.Read(&all, 0.2, why)) {
    *read_bytes = all.size();
    if (Clock::now() - start > std::chrono::duration<double>(kHangGuardS)) {
      ADD_FAILURE() << "no end of stream after " << kHangGuardS << " s";
      break;
    }
  }
  return all;
}

// The CSV log of a simulated swing as lines, header first, and the time of each line.
void CsvLines(const ImuData& data, std::vector<std::string>* lines, std::vector<double>* times) {
  const std::string text = FormatImuLog(data, ImuFormat());
  std::size_t at = 0;
  double t = data.t_s.front();
  for (std::size_t i = 0; at < text.size(); ++i) {
    const std::size_t end = text.find('\n', at);
    lines->push_back(text.substr(at, end - at + 1));
    at = end + 1;
    if (i >= 1) t = data.t_s[i - 1];
    times->push_back(t - data.t_s.front());
  }
}

TEST(SerialStream, CsvLinesArriveExactlyInRealTimeAndFaster) {
  const ImuData data = SimulatedSwing(1.0, 100.0, 11);
  std::vector<std::string> lines;
  std::vector<double> times;
  CsvLines(data, &lines, &times);
  std::string sent;
  for (const auto& l : lines) sent += l;
  for (const double pace : {1.0, 0.0}) {  // real time, then as fast as the pty takes it
    Pty pty;
    std::string error;
    auto stream = OpenSerial(pty.slave_name, 115200, &error);
    ASSERT_NE(stream, nullptr) << error;
    EXPECT_EQ(stream->Describe(), "serial " + pty.slave_name + " at 115200 baud");
    std::atomic<std::size_t> read_bytes{0};
    std::thread feeder(Feed, pty.master, lines, times, pace, &read_bytes);
    pty.master = -1;  // the feeder closes it: the end of the stream
    close(pty.slave);
    pty.slave = -1;
    std::string why;
    const std::string got = ReadToEnd(*stream, &read_bytes, &why);
    feeder.join();
    EXPECT_EQ(got.size(), sent.size()) << "pace " << pace;
    EXPECT_TRUE(got == sent) << "pace " << pace;
    EXPECT_NE(why.find(pty.slave_name), std::string::npos) << why;
    std::string again, why_again;
    EXPECT_FALSE(stream->Read(&again, 0.0, &why_again));  // stays closed, for the same reason
    EXPECT_EQ(why_again, why);
  }
}

TEST(SerialStream, MavlinkFramesDecodeToTheSentSamples) {
  const auto samples = AsMavlinkSamples(SimulatedSwing(1.0, 250.0, 12));
  const auto frames = HighresFrames(samples);
  std::vector<double> times;
  for (const auto& s : samples) times.push_back(s.t_s - samples.front().t_s);
  for (const double pace : {1.0, 0.0}) {
    Pty pty;
    std::string error;
    auto stream = OpenSerial(pty.slave_name, 921600, &error);
    ASSERT_NE(stream, nullptr) << error;
    std::atomic<std::size_t> read_bytes{0};
    std::thread feeder(Feed, pty.master, frames, times, pace, &read_bytes);
    pty.master = -1;
    MavlinkDecoder decoder;
    std::vector<MavlinkImuSample> got;
    std::string chunk, why;
    const Clock::time_point start = Clock::now();
    while (got.size() < samples.size() &&
           Clock::now() - start < std::chrono::duration<double>(kHangGuardS)) {
      chunk.clear();
      if (!stream->Read(&chunk, 0.1, &why)) break;
      read_bytes += chunk.size();
      for (const auto& s : decoder.Feed(chunk)) got.push_back(s);
    }
    feeder.join();
    EXPECT_TRUE(why.empty()) << why;
    ASSERT_EQ(got.size(), samples.size()) << "pace " << pace;
    for (std::size_t i = 0; i < got.size(); ++i) ExpectHighresEqual(samples[i], got[i]);
    EXPECT_EQ(decoder.counters().bad_crc, 0);
    EXPECT_EQ(decoder.counters().bytes_skipped, 0);
  }
}

TEST(SerialStream, TimeoutIsNotTheEnd) {
  Pty pty;
  std::string error, chunk, why;
  auto stream = OpenSerial(pty.slave_name, 57600, &error);
  ASSERT_NE(stream, nullptr) << error;
  EXPECT_TRUE(stream->Read(&chunk, 0.05, &why));  // nothing sent: a timeout
  EXPECT_TRUE(chunk.empty());
  ASSERT_EQ(write(pty.master, "t,gx\n", 5), 5);
  const Clock::time_point start = Clock::now();
  while (chunk.size() < 5 && Clock::now() - start < std::chrono::duration<double>(kHangGuardS)) {
    ASSERT_TRUE(stream->Read(&chunk, 0.1, &why)) << why;
  }
  EXPECT_EQ(chunk, "t,gx\n");
}

TEST(SerialStream, BadDeviceOrBaudIsAClearError) {
  std::string error;
  EXPECT_EQ(OpenSerial("/dev/ttyNOSUCH0", 115200, &error), nullptr);
  EXPECT_NE(error.find("/dev/ttyNOSUCH0"), std::string::npos) << error;
  Pty pty;
  EXPECT_EQ(OpenSerial(pty.slave_name, 12345, &error), nullptr);
  EXPECT_NE(error.find("baud rate 12345"), std::string::npos) << error;
  EXPECT_EQ(OpenSerial(pty.slave_name, 0, &error), nullptr);
  EXPECT_NE(error.find("baud"), std::string::npos) << error;
}

// A loopback sender: frames in datagrams of `per_datagram` frames, never more than kWindow
// frames ahead of what the reader has decoded (UDP drops what overflows the socket buffer;
// the window keeps the test exact on a loaded machine), paced at pace_s * t.
void SendUdp(int port, const std::vector<std::string>& frames, const std::vector<double>& times,
             double pace_s, std::size_t per_datagram, const std::atomic<std::size_t>* decoded) {
  asio::io_context io;
  asio::ip::udp::socket socket(io, asio::ip::udp::endpoint(asio::ip::udp::v4(), 0));
  const asio::ip::udp::endpoint to(asio::ip::make_address("127.0.0.1"),
                                   static_cast<unsigned short>(port));
  const Clock::time_point start = Clock::now();
  // 64 datagrams: well inside the default receive buffer (212992 bytes; each datagram costs
  // ~1 kB of it, whatever its size).
  constexpr std::size_t kWindow = 64;
  for (std::size_t i = 0; i < frames.size(); i += per_datagram) {
    if (pace_s > 0) {
      std::this_thread::sleep_until(start + std::chrono::duration_cast<Clock::duration>(
                                                std::chrono::duration<double>(pace_s * times[i])));
    }
    while (i > decoded->load() + kWindow) {
      if (Clock::now() - start > std::chrono::duration<double>(kHangGuardS)) return;
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    std::string datagram;
    for (std::size_t k = i; k < std::min(frames.size(), i + per_datagram); ++k) {
      datagram += frames[k];
    }
    socket.send_to(asio::buffer(datagram), to);
  }
}

TEST(UdpStream, MavlinkFromALoopbackSenderInRealTimeAndFaster) {
  const auto samples = AsMavlinkSamples(SimulatedSwing(1.0, 500.0, 13));
  const auto frames = HighresFrames(samples);
  std::vector<double> times;
  for (const auto& s : samples) times.push_back(s.t_s - samples.front().t_s);
  struct Case {
    double pace;
    std::size_t per_datagram;
  };
  for (const Case c : {Case{1.0, 1}, Case{0.0, 1}, Case{0.0, 7}}) {
    int port = 0;
    std::string error;
    auto stream = OpenUdp("127.0.0.1", 0, &port, &error);
    ASSERT_NE(stream, nullptr) << error;
    ASSERT_GT(port, 0);
    EXPECT_EQ(stream->Describe(), "udp 127.0.0.1:" + std::to_string(port));
    std::atomic<std::size_t> decoded{0};
    std::thread sender(SendUdp, port, frames, times, c.pace, c.per_datagram, &decoded);
    MavlinkDecoder decoder;
    std::vector<MavlinkImuSample> got;
    std::string chunk, why;
    const Clock::time_point start = Clock::now();
    while (got.size() < samples.size() &&
           Clock::now() - start < std::chrono::duration<double>(kHangGuardS)) {
      chunk.clear();
      ASSERT_TRUE(stream->Read(&chunk, 0.1, &why)) << why;
      ASSERT_LE(chunk.size(), kByteStreamMaxReadBytes);
      for (const auto& s : decoder.Feed(chunk)) got.push_back(s);
      decoded = got.size();
    }
    sender.join();
    ASSERT_EQ(got.size(), samples.size()) << "pace " << c.pace << ", " << c.per_datagram << ": "
                                          << decoder.counters().bytes_skipped << " bytes skipped";
    for (std::size_t i = 0; i < got.size(); ++i) ExpectHighresEqual(samples[i], got[i]);
    EXPECT_EQ(decoder.counters().bytes_skipped, 0);
  }
}

TEST(UdpStream, PortInUseOrBadAddressIsAClearError) {
  int port = 0;
  std::string error;
  auto first = OpenUdp("127.0.0.1", 0, &port, &error);
  ASSERT_NE(first, nullptr) << error;
  EXPECT_EQ(OpenUdp("127.0.0.1", port, &error), nullptr);
  EXPECT_NE(error.find("cannot bind"), std::string::npos) << error;
  EXPECT_NE(error.find(std::to_string(port)), std::string::npos) << error;
  EXPECT_EQ(OpenUdp("not-an-address", 14550, &error), nullptr);
  EXPECT_NE(error.find("not an IP address"), std::string::npos) << error;
  EXPECT_EQ(OpenUdp("0.0.0.0", 70000, &error), nullptr);
  EXPECT_NE(error.find("1..65535"), std::string::npos) << error;
  std::string chunk, why;
  EXPECT_TRUE(first->Read(&chunk, 0.02, &why));  // nothing sent: a timeout, not the end
  EXPECT_TRUE(chunk.empty());
}

}  // namespace
}  // namespace bifilar::live
