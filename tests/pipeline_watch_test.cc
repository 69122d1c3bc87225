// `bifilar watch` (issue 34): the live fit is `fit`'s, the saved log gives `fit`'s numbers, bad
// input is counted and kept out of the log, "enough" comes where `fit` on the log so far first
// reaches the target, and a source whose transport is not built says so.
#include <chrono>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "base/user_error.h"
#include "pipeline/commands/fit_command.h"
#include "pipeline/commands/simulate_spec.h"
#include "pipeline/commands/watch_command.h"
#include "pipeline/logs/imu_log.h"
#include "pipeline/trace/trace_process.h"
#include "pipeline/watch/saved_log.h"
#include "pipeline/watch/watch_engine.h"
#include "pipeline/watch/watch_source.h"
#include "tests/test_support.h"
#include "tests/watch_support.h"

namespace bifilar {
namespace {

using test_support::Bifilar;
using test_support::ReadFile;
using test_support::TempDir;
using test_support::WriteFile;
using watch_support::FitLog;

constexpr double kTrueInertia = watch_support::kSwingInertia;

// A swing of 15 deg on the watch rig (tests/watch_support.h: period ~2.1 s) into dir/NAME.
// Returns the config path.
std::string SimulateSwing(const TempDir& dir, double duration_s, uint64_t seed,
                          double rate_hz = 100.0, const std::string& name = "sw.csv") {
  watch_support::SimulateSwing(dir.path + "/" + name, {seed, duration_s, 15.0, rate_hz});
  return watch_support::WriteSwingConfig(dir.path + "/c.yaml");
}

std::vector<nlohmann::json> JsonLines(const std::string& text) {
  std::vector<nlohmann::json> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) lines.push_back(nlohmann::json::parse(line));
  }
  return lines;
}

void ExpectRelativelyEqual(double a, double b, double tolerance) {
  EXPECT_LE(std::abs(a - b), tolerance * std::abs(b)) << a << " vs " << b;
}

TEST(Watch, PipedSimulationGivesFitsNumbersOnTheSavedLog) {
  TempDir dir("watch_pipe");
  const std::string config = SimulateSwing(dir, 30.0, 3);
  const std::string b = BIFILAR_BINARY;
  const std::string command = b + " watch " + config + " --feed " + dir.path +
                              "/sw.csv --speed 0 | " + b + " watch " + config + " - --save " +
                              dir.path + "/saved.csv --json > " + dir.path + "/out.jsonl 2> " +
                              dir.path + "/err.txt";
  ASSERT_EQ(std::system(command.c_str()), 0) << ReadFile(dir.path + "/err.txt");
  const std::vector<nlohmann::json> lines = JsonLines(ReadFile(dir.path + "/out.jsonl"));
  ASSERT_FALSE(lines.empty());
  const nlohmann::json& final = lines.back();
  ASSERT_TRUE(final.value("final", false));
  int updates = 0, swinging = 0;
  for (const nlohmann::json& j : lines) {
    if (!j.contains("verdict")) continue;
    ++updates;
    for (const char* key : {"t_s", "cycles", "amplitude_deg", "period_s", "inertia_kg_m2",
                            "inertia_std_stat_kg_m2", "inertia_std_total_kg_m2", "reason"}) {
      EXPECT_TRUE(j.contains(key)) << key;
    }
    if (j["verdict"] != "waiting") ++swinging;
  }
  EXPECT_GT(updates, 20);  // every half-cycle (1 s) or 0.5 s over 30 s of data
  EXPECT_GT(swinging, 5);
  // The saved log holds every sample of the simulated one, and fit on it gives the final numbers.
  const ImuData original = ReadImuLog(dir.path + "/sw.csv", ImuFormat());
  const ImuData saved = ReadImuLog(dir.path + "/saved.csv", ImuFormat());
  ASSERT_EQ(saved.size(), original.size());
  for (size_t i = 0; i < saved.size(); ++i) {
    ASSERT_EQ(saved.t_s[i], original.t_s[i]);
    ASSERT_EQ(saved.gyro_in_imu[i], original.gyro_in_imu[i]);
  }
  const TraceRecord fit = FitLog(config, dir.path + "/saved.csv");
  ASSERT_TRUE(fit.ok()) << fit.message;
  const nlohmann::json& record = final["logs"][0]["record"];
  ExpectRelativelyEqual(record["inertia_total_kg_m2"].get<double>(), fit.inertia_total_kg_m2,
                        1e-12);
  ExpectRelativelyEqual(record["inertia_total_std_kg_m2"].get<double>(),
                        fit.inertia_total_std_kg_m2, 1e-12);
  EXPECT_NEAR(fit.inertia_total_kg_m2, kTrueInertia, 5 * fit.inertia_total_std_total_kg_m2);
}

// The live fit over the whole saved log (no swing closed, no block means) is `fit` on it: the
// samples the engine fits are the ones the file gives back.
TEST(Watch, EngineOnEverySampleIsFitOnTheSavedLog) {
  TempDir dir("watch_engine");
  const std::string config_path = SimulateSwing(dir, 20.0, 5);
  ConfigLoadOptions load;
  load.require_runs = false;
  const CampaignConfig config = LoadCampaignConfig(config_path, load);
  const ImuData data = ReadImuLog(dir.path + "/sw.csv", config.imu.format);
  WatchEngineOptions options;
  options.max_fit_samples = 100000;
  options.log_name = dir.path + "/saved.csv";
  WatchEngine engine(config, options);
  {
    SavedLog log(dir.path + "/saved.csv", config.imu.format, "");
    for (size_t i = 0; i < data.size(); ++i) {
      WatchSample s;
      s.t_s = data.t_s[i];
      s.gyro_rad_per_s = data.gyro_in_imu[i];
      s.has_accel = true;
      s.accel_mps2 = data.accel_in_imu[i];
      const WatchSample back = log.Write(s);
      engine.Add(back.t_s, back.gyro_rad_per_s, &back.accel_mps2);
    }
  }
  const WatchUpdate u = engine.Update();
  const TraceRecord fit = FitLog(config_path, dir.path + "/saved.csv");
  ASSERT_TRUE(fit.ok()) << fit.message;
  ExpectRelativelyEqual(u.inertia_kg_m2, fit.inertia_total_kg_m2, 1e-12);
  ExpectRelativelyEqual(u.inertia_std_stat_kg_m2, fit.inertia_total_std_kg_m2, 1e-12);
  ExpectRelativelyEqual(u.inertia_std_total_kg_m2, fit.inertia_total_std_total_kg_m2, 1e-12);
  EXPECT_NE(u.verdict, WatchVerdict::kWaiting);
}

TEST(Watch, BadInputIsCountedNamedAndKeptOutOfTheLog) {
  TempDir dir("watch_bad");
  const std::string config = SimulateSwing(dir, 25.0, 7);
  std::istringstream in(ReadFile(dir.path + "/sw.csv"));
  std::string text, line;
  int row = 0;
  long good = 0;
  while (std::getline(in, line)) {
    text += line + "\n";
    if (line.empty() || !std::isdigit(static_cast<unsigned char>(line[0]))) continue;
    ++good;
    if (++row == 300) text += "garbage, not a row\n";
    if (row == 500) text += "\x01\x02\xff binary noise\n";
    if (row == 700) text += "nan,0,0,0.1,0,0,-9.8\n";
    if (row == 900) text += "1.5,0,0,0.1,0,0,-9.8\n";  // the clock jumps back
    if (row == 1100) text += "1e9,1,2\n";              // a short row
  }
  WriteFile(dir.path + "/input.csv", text);
  // The stream stops (end of input): the watch ends with what it has.
  const auto run = Bifilar(dir, "watch " + config + " - --json --save " + dir.path +
                                    "/saved.csv < " + dir.path + "/input.csv");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json final = JsonLines(run.out).back();
  EXPECT_EQ(final["counters"]["garbage"], 3);
  EXPECT_EQ(final["counters"]["non_finite"], 1);
  EXPECT_EQ(final["counters"]["time_back"], 1);
  EXPECT_EQ(final["counters"]["samples"], good);
  EXPECT_EQ(final["logs"][0]["samples"], good);
  EXPECT_EQ(final["logs"][0]["rejected"], 5);
  const std::string rejected = ReadFile(dir.path + "/saved.csv.rejected.txt");
  EXPECT_NE(rejected.find("time_back\t1.5,0,0"), std::string::npos) << rejected;
  EXPECT_NE(rejected.find("non_finite\tnan"), std::string::npos) << rejected;
  // The log reads back whole and clean: no warning of a repaired row.
  const ImuData saved = ReadImuLog(dir.path + "/saved.csv", ImuFormat());
  EXPECT_EQ(static_cast<long>(saved.size()), good);
  for (const std::string& w : saved.warnings) EXPECT_EQ(w.find("line"), std::string::npos) << w;
  const TraceRecord fit = FitLog(config, dir.path + "/saved.csv");
  ExpectRelativelyEqual(final["logs"][0]["record"]["inertia_total_kg_m2"].get<double>(),
                        fit.inertia_total_kg_m2, 1e-12);
}

// The ESP32 logger's JSON lines: a counter at 40 Hz, no time, its own key names.
TEST(Watch, JsonLinesWithACounterAtAStatedRate) {
  TempDir dir("watch_json");
  const std::string config = SimulateSwing(dir, 30.0, 11, 40.0);
  const ImuData data = ReadImuLog(dir.path + "/sw.csv", ImuFormat());
  std::string text;
  for (size_t i = 0; i < data.size(); ++i) {
    const long count = std::lround(data.t_s[i] * 40.0);
    nlohmann::ordered_json j;
    j["count"] = count;
    j["ax"] = data.accel_in_imu[i][0];
    j["ay"] = data.accel_in_imu[i][1];
    j["az"] = data.accel_in_imu[i][2];
    j["gyrox"] = data.gyro_in_imu[i][0];
    j["gyroy"] = data.gyro_in_imu[i][1];
    j["gyroz"] = data.gyro_in_imu[i][2];
    text += j.dump() + "\n";
  }
  WriteFile(dir.path + "/input.jsonl", text);
  const auto run = Bifilar(dir, "watch " + config + " - --json --counter-rate-hz 40 --save " +
                                    dir.path + "/saved.csv < " + dir.path + "/input.jsonl");
  ASSERT_EQ(run.exit_code, 0) << run.err << run.out.substr(0, 2000);
  const nlohmann::json final = JsonLines(run.out).back();
  EXPECT_EQ(final["logs"][0]["samples"], static_cast<long>(data.size()));
  const TraceRecord fit = FitLog(config, dir.path + "/saved.csv");
  ASSERT_TRUE(fit.ok()) << fit.message;
  ExpectRelativelyEqual(final["logs"][0]["record"]["inertia_total_kg_m2"].get<double>(),
                        fit.inertia_total_kg_m2, 1e-12);
  EXPECT_NEAR(fit.inertia_total_kg_m2, kTrueInertia, 5 * fit.inertia_total_std_total_kg_m2);
}

// A log being written, then replaced by a new one (rotation): the watch follows the first,
// starts a new saved log for the second, and never reads the new file as the old one's rest.
TEST(Watch, FollowsAGrowingFileAndARotation) {
  TempDir dir("watch_follow");
  const std::string config = SimulateSwing(dir, 20.0, 13);
  const std::string text = ReadFile(dir.path + "/sw.csv");
  const std::string live = dir.path + "/live.csv";
  std::thread writer([&] {
    {
      std::ofstream out(live, std::ios::binary);
      for (size_t at = 0; at < text.size(); at += 20000) {
        out << text.substr(at, 20000) << std::flush;
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(400));
    WriteFile(live + ".new", text);
    std::filesystem::rename(live + ".new", live);
  });
  WatchCommandOptions o;
  o.config_path = config;
  o.source = live;
  o.save_path = dir.path + "/saved_1.csv";
  o.idle_end_s = 1.5;
  std::vector<std::string> events;
  o.on_event = [&events](const std::string& e) { events.push_back(e); };
  const WatchCommandResult r = RunWatch(o);
  writer.join();
  ASSERT_EQ(r.logs.size(), 2u);
  EXPECT_EQ(r.counters.restarts, 1);
  const ImuData original = ReadImuLog(dir.path + "/sw.csv", ImuFormat());
  for (const WatchLogResult& log : r.logs) {
    EXPECT_EQ(log.samples, static_cast<long>(original.size())) << log.path;
    ASSERT_TRUE(log.record.has_value());
    const TraceRecord fit = FitLog(config, log.path);
    ExpectRelativelyEqual(log.record->inertia_total_kg_m2, fit.inertia_total_kg_m2, 1e-12);
  }
  bool said = false;
  for (const std::string& e : events) said = said || e.find("started over") != std::string::npos;
  EXPECT_TRUE(said);
}

// A PX4 ULog and an ArduPilot DataFlash log being written: re-read as they grow, every sample
// saved once, and the saved CSV gives `fit`'s numbers on the binary log itself.
TEST(Watch, FollowsGrowingUlogAndDataflashLogs) {
  for (const char* name : {"sw.ulg", "sw.bin"}) {
    TempDir dir("watch_binary");
    const std::string config = SimulateSwing(dir, 20.0, 19, 100.0, name);
    const std::string bytes = ReadFile(dir.path + "/" + name);
    const std::string live = dir.path + "/live_" + name;
    std::thread writer([&] {
      std::ofstream out(live, std::ios::binary);
      for (size_t at = 0; at < bytes.size(); at += 7919) {  // cuts inside messages
        out << bytes.substr(at, 7919) << std::flush;
        std::this_thread::sleep_for(std::chrono::milliseconds(30));
      }
    });
    WatchCommandOptions o;
    o.config_path = config;
    o.source = live;
    o.save_path = dir.path + "/saved.csv";
    o.idle_end_s = 1.0;
    const WatchCommandResult r = RunWatch(o);
    writer.join();
    ASSERT_EQ(r.logs.size(), 1u) << name;
    const TraceRecord on_binary = FitLog(config, dir.path + "/" + name);
    const TraceRecord on_saved = FitLog(config, dir.path + "/saved.csv");
    ASSERT_TRUE(on_binary.ok()) << name << ": " << on_binary.message;
    ConfigLoadOptions load;
    load.require_runs = false;
    const ImuData data =
        ReadImuLog(dir.path + "/" + name, LoadCampaignConfig(config, load).imu.format);
    EXPECT_EQ(r.logs[0].samples, static_cast<long>(data.size())) << name;
    ASSERT_TRUE(r.logs[0].record.has_value());
    ExpectRelativelyEqual(r.logs[0].record->inertia_total_kg_m2, on_saved.inertia_total_kg_m2,
                          1e-12);
    ExpectRelativelyEqual(on_saved.inertia_total_kg_m2, on_binary.inertia_total_kg_m2, 1e-12);
  }
}

// Ctrl-C: the watch ends (exit 130), fits what it saved and says so.
TEST(Watch, CtrlCEndsWithTheFitOfTheSavedLog) {
  TempDir dir("watch_sigint");
  const std::string config = SimulateSwing(dir, 60.0, 23);
  const std::string b = BIFILAR_BINARY;
  const std::string script = b + " watch " + config + " --feed " + dir.path +
                             "/sw.csv --speed 4 | " + b + " watch " + config + " - --json --save " +
                             dir.path + "/saved.csv > " + dir.path + "/out.jsonl 2> " + dir.path +
                             "/err.txt & w=$!; sleep 4; kill -INT $w; wait $w; echo $? > " +
                             dir.path + "/rc.txt";
  ASSERT_EQ(std::system(("sh -c '" + script + "'").c_str()), 0);
  EXPECT_EQ(ReadFile(dir.path + "/rc.txt"), "130\n") << ReadFile(dir.path + "/err.txt");
  const nlohmann::json final = JsonLines(ReadFile(dir.path + "/out.jsonl")).back();
  EXPECT_TRUE(final["interrupted"].get<bool>());
  const TraceRecord fit = FitLog(config, dir.path + "/saved.csv");
  ASSERT_TRUE(final["logs"][0]["record"].is_object());
  ExpectRelativelyEqual(final["logs"][0]["record"]["inertia_total_kg_m2"].get<double>(),
                        fit.inertia_total_kg_m2, 1e-12);
  EXPECT_LT(final["logs"][0]["samples"].get<long>(), 5500);  // stopped before the end
}

// A rig that sways (a strong second oscillation about another axis): `fit` rejects the swing,
// and the watch says "fix the rig" with fit's reason.
TEST(Watch, SwayIsFixTheRigWithFitsReason) {
  TempDir dir("watch_sway");
  const std::string config_path = SimulateSwing(dir, 25.0, 29);
  ConfigLoadOptions load;
  load.require_runs = false;
  const CampaignConfig config = LoadCampaignConfig(config_path, load);
  ImuData data = ReadImuLog(dir.path + "/sw.csv", config.imu.format);
  for (size_t i = 0; i < data.size(); ++i) {
    data.gyro_in_imu[i][0] += 0.5 * std::sin(2 * 3.0 * data.t_s[i]);  // ~1 Hz sway, 0.5 rad/s
  }
  WatchEngine engine(config, WatchEngineOptions());
  int fix_rig = 0;
  std::string reason;
  for (size_t i = 0; i < data.size(); ++i) {
    if (!engine.Add(data.t_s[i], data.gyro_in_imu[i], &data.accel_in_imu[i])) continue;
    const WatchUpdate u = engine.Update();
    if (u.verdict == WatchVerdict::kFixRig) {
      ++fix_rig;
      reason = u.reason;
    }
    EXPECT_NE(u.verdict, WatchVerdict::kEnough) << u.t_s << ": " << u.reason;
  }
  EXPECT_GT(fix_rig, 3);
  EXPECT_NE(reason.find("secondary motion"), std::string::npos) << reason;
}

// Two swings of one set-up in one stream: the first is closed when it has died out, and the
// second is compared with it.
TEST(Watch, SecondSwingIsComparedWithTheFirst) {
  TempDir dir("watch_repeat");
  const std::string config_path = SimulateSwing(dir, 30.0, 31);
  ConfigLoadOptions load;
  load.require_runs = false;
  const CampaignConfig config = LoadCampaignConfig(config_path, load);
  const ImuData data = ReadImuLog(dir.path + "/sw.csv", config.imu.format);
  const double span = data.t_s.back() - data.t_s.front() + 0.01;
  WatchEngine engine(config, WatchEngineOptions());
  WatchUpdate last_of_second;
  for (int swing = 0; swing < 2; ++swing) {
    for (size_t i = 0; i < data.size(); ++i) {
      if (!engine.Add(data.t_s[i] + swing * span, data.gyro_in_imu[i], &data.accel_in_imu[i])) {
        continue;
      }
      const WatchUpdate u = engine.Update();
      if (swing == 1 && u.swing == 2 && std::isfinite(u.inertia_kg_m2)) last_of_second = u;
    }
  }
  ASSERT_EQ(engine.swings().size(), 2u);  // both died out before the stream ended
  EXPECT_NEAR(engine.swings()[0].inertia_kg_m2, kTrueInertia, 0.001);
  ASSERT_EQ(last_of_second.earlier_swings_kg_m2.size(), 1u);
  EXPECT_EQ(last_of_second.repeat_agreement, "agrees");  // the same data: the same I
}

// "enough" at the first update where `fit` on the log so far reaches the target: within one
// period of the first cut (on a grid of an eighth of a period) where it does.
TEST(Watch, EnoughWithinOneCycleOfFitOnTheLogSoFar) {
  TempDir dir("watch_enough");
  const std::string config_path = SimulateSwing(dir, 25.0, 17, 50.0);
  ConfigLoadOptions load;
  load.require_runs = false;
  const CampaignConfig config = LoadCampaignConfig(config_path, load);
  const ImuData data = ReadImuLog(dir.path + "/sw.csv", config.imu.format);
  WatchEngineOptions options;
  options.target_percent = 0.05;
  WatchEngine engine(config, options);
  double t_enough = NAN, period = NAN;
  for (size_t i = 0; i < data.size() && std::isnan(t_enough); ++i) {
    if (!engine.Add(data.t_s[i], data.gyro_in_imu[i], &data.accel_in_imu[i])) continue;
    const WatchUpdate u = engine.Update();
    if (std::isfinite(u.period_s)) period = u.period_s;
    if (u.verdict == WatchVerdict::kEnough) t_enough = u.t_s;
  }
  ASSERT_TRUE(std::isfinite(t_enough)) << "never enough";
  const double t_fit = watch_support::FirstFitReaching(config, data, options.target_percent,
                                                       period / 8, data.t_s.back());
  ASSERT_TRUE(std::isfinite(t_fit));
  EXPECT_LE(std::abs(t_enough - t_fit), period) << t_enough << " vs " << t_fit;
}

TEST(Watch, BlockMeansKeepTheFitBounded) {
  ConfigLoadOptions load;
  load.require_runs = false;
  TempDir dir("watch_bound");
  const CampaignConfig config =
      LoadCampaignConfigText("rig: {filar_length_m: 1.0, filar_separation_m: 0.3, mass_kg: 2}\n",
                             dir.path + "/c.yaml", load);
  WatchEngineOptions options;
  options.max_fit_samples = 256;
  WatchEngine engine(config, options);
  const Eigen::Vector3d accel(0, 0, -9.8);
  for (int i = 0; i < 100000; ++i) {
    engine.Add(i * 1e-3, Eigen::Vector3d(0, 0, 0.1 * std::sin(0.05 * i * 1e-3)), &accel);
  }
  EXPECT_LE(engine.points().size(), 256u);
  EXPECT_GE(engine.points().size(), 128u);
  EXPECT_EQ(engine.samples(), 100000);
  // Block means (0.5 s) of a slow sine (0.008 Hz): the points lie on it.
  const ImuData& p = engine.points();
  for (size_t i = 0; i < p.size(); i += 17) {
    EXPECT_NEAR(p.gyro_in_imu[i][2], 0.1 * std::sin(0.05 * p.t_s[i]), 1e-4);
  }
}

TEST(Watch, TransportSpecsThatCannotOpenSaySo) {
  ConfigLoadOptions load;
  load.require_runs = false;
  const CampaignConfig config = LoadCampaignConfigText(
      "rig: {filar_length_m: 1.0, filar_separation_m: 0.3, mass_kg: 2}\n", "/tmp/c.yaml", load);
  const std::pair<const char*, const char*> cases[] = {
      {"serial:/dev/bifilar_no_such_port@115200", "/dev/bifilar_no_such_port"},
      {"serial:/dev/ttyACM0", "DEVICE@BAUD"},
      {"mavlink:/dev/ttyACM0@fast", "DEVICE@BAUD"},
      {"mavlink-udp:0.0.0.0", "HOST:PORT"},
      {"ws://127.0.0.1:1/", "ws://127.0.0.1:1/"}};
  for (const auto& [spec, named] : cases) {
    try {
      OpenWatchSource(spec, config, WatchInputOptions());
      ADD_FAILURE() << spec << " opened";
    } catch (const UserError& e) {
      EXPECT_NE(std::string(e.what()).find(named), std::string::npos) << e.what();
    }
  }
}

TEST(Watch, NeverWritesOverAFile) {
  TempDir dir("watch_save");
  WriteFile(dir.path + "/taken.csv", "keep me\n");
  EXPECT_THROW(SavedLog(dir.path + "/taken.csv", ImuFormat(), ""), UserError);
  EXPECT_EQ(ReadFile(dir.path + "/taken.csv"), "keep me\n");
  const std::string a = DefaultSavedLogPath(dir.path + "/c.yaml");
  WriteFile(a, "x");
  EXPECT_NE(DefaultSavedLogPath(dir.path + "/c.yaml"), a);
}

}  // namespace
}  // namespace bifilar
