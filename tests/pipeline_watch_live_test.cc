// `bifilar watch` over the transports of pipeline/live/: MAVLink 2 HIGHRES_IMU frames over UDP
// (with a frame whose checksum is wrong, counted and never a sample) and CSV text over a serial
// port (a pseudo-terminal), each a simulated swing; the final result is `fit` on the saved log.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <pty.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "pipeline/commands/fit_command.h"
#include "pipeline/commands/simulate_spec.h"
#include "pipeline/commands/watch_command.h"
#include "pipeline/live/mavlink.h"
#include "pipeline/live/mavlink_writer.h"
#include "pipeline/logs/imu_log.h"
#include "tests/test_support.h"

namespace bifilar {
namespace {

using test_support::ReadFile;
using test_support::TempDir;
using test_support::WriteFile;

std::string Simulate(const TempDir& dir, ImuData* data) {
  SimulateCommandOptions s;
  s.trace_csv = dir.path + "/sw.csv";
  s.o.seed = 37;
  s.o.inertia_kg_m2 = 0.05;
  s.o.mass_kg = 2.0;
  s.o.length_m = 1.0;
  s.o.separation_m = 0.3;
  s.o.duration_s = 20.0;
  RunSimulate(s);
  *data = ReadImuLog(s.trace_csv, ImuFormat());
  return WriteFile(dir.path + "/c.yaml",
                   "rig: {filar_length_m: 1.0, filar_separation_m: 0.3, mass_kg: 2}\n");
}

TraceRecord FitLog(const std::string& config, const std::string& log) {
  FitCommandOptions fit;
  fit.config_path = config;
  fit.logs = {log};
  return RunFit(fit).records.at(0);
}

int FreeUdpPort() {
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = 0;
  bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a));
  socklen_t n = sizeof(a);
  getsockname(fd, reinterpret_cast<sockaddr*>(&a), &n);
  close(fd);
  return ntohs(a.sin_port);
}

TEST(WatchLive, MavlinkOverUdpGivesFitsNumbersAndCountsABadChecksum) {
  TempDir dir("watch_mavlink");
  ImuData data;
  const std::string config = Simulate(dir, &data);
  std::vector<std::string> frames;
  live::MavlinkFrameOptions frame;
  for (size_t i = 0; i < data.size(); ++i) {
    live::MavlinkImuSample s{};
    s.t_s = data.t_s[i];
    for (int k = 0; k < 3; ++k) {
      s.gyro_rad_per_s[k] = data.gyro_in_imu[i][k];
      s.accel_m_per_s2[k] = data.accel_in_imu[i][k];
    }
    s.has_accel = true;
    frames.push_back(live::EncodeHighresImu(
        s, live::kHighresImuUpdatedAccel | live::kHighresImuUpdatedGyro, frame));
    frame.seq = (frame.seq + 1) % 256;
  }
  std::string bad = frames[500];
  bad[bad.size() - 1] = static_cast<char>(bad.back() ^ 0x5a);  // the checksum's last byte
  frames.insert(frames.begin() + 501, bad);
  const int port = FreeUdpPort();
  std::thread sender([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(500));  // the watch binds first
    const int fd = socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    to.sin_port = htons(static_cast<uint16_t>(port));
    // At five times the IMU's own pace (20 s in 4 s): loopback UDP drops datagrams only when
    // the receive buffer (some hundred frames) fills while the watch fits.
    const auto start = std::chrono::steady_clock::now();
    for (size_t i = 0; i < frames.size(); ++i) {
      const double due = (data.t_s[std::min(i, data.size() - 1)] - data.t_s[0]) / 5.0;
      std::this_thread::sleep_until(start + std::chrono::duration_cast<std::chrono::nanoseconds>(
                                                std::chrono::duration<double>(due)));
      sendto(fd, frames[i].data(), frames[i].size(), 0, reinterpret_cast<sockaddr*>(&to),
             sizeof(to));
    }
    close(fd);
  });
  WatchCommandOptions o;
  o.config_path = config;
  o.source = "mavlink-udp:127.0.0.1:" + std::to_string(port);
  o.save_path = dir.path + "/saved.csv";
  o.idle_end_s = 2.0;
  const WatchCommandResult r = RunWatch(o);
  sender.join();
  ASSERT_EQ(r.logs.size(), 1u);
  // UDP may lose a datagram on a loaded machine; a lost one is never a wrong sample.
  EXPECT_GE(r.logs[0].samples, static_cast<long>(0.95 * data.size()));
  EXPECT_LE(r.logs[0].samples, static_cast<long>(data.size()));
  EXPECT_LE(r.counters.bad_checksum, 1);
  if (r.logs[0].samples == static_cast<long>(data.size())) {
    EXPECT_EQ(r.counters.bad_checksum, 1);
  }
  EXPECT_EQ(r.logs[0].rejected, 0);
  ASSERT_TRUE(r.logs[0].record.has_value());
  const TraceRecord fit = FitLog(config, dir.path + "/saved.csv");
  ASSERT_TRUE(fit.ok()) << fit.message;
  EXPECT_LE(std::abs(r.logs[0].record->inertia_total_kg_m2 - fit.inertia_total_kg_m2),
            1e-12 * fit.inertia_total_kg_m2);
  EXPECT_NEAR(fit.inertia_total_kg_m2, 0.05, 5 * fit.inertia_total_std_total_kg_m2);
}

TEST(WatchLive, CsvOverASerialPort) {
  TempDir dir("watch_serial");
  ImuData data;
  const std::string config = Simulate(dir, &data);
  const std::string text = ReadFile(dir.path + "/sw.csv");
  int master = -1, slave = -1;
  char name[256] = {0};
  ASSERT_EQ(openpty(&master, &slave, name, nullptr, nullptr), 0);
  std::thread feeder([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    for (size_t at = 0; at < text.size(); at += 2000) {
      const std::string piece = text.substr(at, 2000);
      if (write(master, piece.data(), piece.size()) < 0) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  });
  WatchCommandOptions o;
  o.config_path = config;
  o.source = std::string("serial:") + name + "@115200";
  o.save_path = dir.path + "/saved.csv";
  o.idle_end_s = 2.0;
  const WatchCommandResult r = RunWatch(o);
  feeder.join();
  close(master);
  close(slave);
  ASSERT_EQ(r.logs.size(), 1u);
  EXPECT_EQ(r.logs[0].samples, static_cast<long>(data.size()));
  ASSERT_TRUE(r.logs[0].record.has_value());
  const TraceRecord fit = FitLog(config, dir.path + "/saved.csv");
  EXPECT_LE(std::abs(r.logs[0].record->inertia_total_kg_m2 - fit.inertia_total_kg_m2),
            1e-12 * fit.inertia_total_kg_m2);
}

}  // namespace
}  // namespace bifilar
