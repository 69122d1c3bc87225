// `bifilar watch` (issue 34): what an update costs at a 1 kHz IMU rate over a long stream, and
// where "enough" comes against `fit` on the log so far. Not timed tests: numbers to read.
//
//   build/bench/bifilar_bench --benchmark_filter=WatchStream     (one-hour stream at 1 kHz)
//   build/bench/bifilar_bench --benchmark_filter=WatchEnoughSurvey   (100 simulated swings)
//
// BM_WatchStream/<seconds>: a simulated 60 s swing at 1 kHz (rest, release, free swing) replayed
// back to back, each replay shifted in time, as a user swinging again and again, into one
// WatchEngine (default options: at most 4096 points fitted, block means beyond). Counters:
// updates, the mean and largest CPU time of one update (ms, this thread's CPU clock), and the
// process's peak resident memory (MB) at the end. Issue 34 asks for <= 50 ms per update and
// < 200 MB over an hour.
//
// BM_WatchEnoughSurvey: 100 swings (seeds 1..100) at 50 Hz, target 0.05 %: the time of the first
// "enough" against the first cut (on a grid of an eighth of a period) where ProcessTraceData on
// the log up to the cut reaches the target. Counters: swings, within_one_cycle, the largest
// difference in cycles, and swings where neither reached the target.
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <string>

#include <benchmark/benchmark.h>

#include "pipeline/commands/simulate_spec.h"
#include "pipeline/config/config.h"
#include "pipeline/logs/imu_log.h"
#include "pipeline/trace/trace_process.h"
#include "pipeline/watch/watch_engine.h"
#include "tests/watch_support.h"

namespace bifilar {
namespace {

// The watch tests' rig and swing (tests/watch_support.h).
CampaignConfig Config() {
  ConfigLoadOptions load;
  load.require_runs = false;
  return LoadCampaignConfigText(watch_support::kSwingConfig, "/tmp/bifilar_watch_bench.yaml", load);
}

ImuData Swing(uint64_t seed, double rate_hz, double duration_s) {
  char tmpl[] = "/tmp/bifilar_watch_bench_XXXXXX";
  const std::string dir = mkdtemp(tmpl);
  const std::string csv = dir + "/sw.csv";
  watch_support::SimulateSwing(csv, {seed, duration_s, 15.0, rate_hz});
  ImuData data = ReadImuLog(csv, ImuFormat());
  std::remove(csv.c_str());
  std::remove((dir + "/sw.truth.json").c_str());
  rmdir(dir.c_str());
  return data;
}

double ThreadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

void BM_WatchStream(benchmark::State& state) {
  const double seconds = static_cast<double>(state.range(0));
  const ImuData swing = Swing(1, 1000.0, 55.0);
  const CampaignConfig config = Config();
  const double span = swing.t_s.back() - swing.t_s.front() + 1e-3;
  for (auto _ : state) {
    WatchEngine engine(config, WatchEngineOptions());
    long updates = 0;
    double total = 0.0, largest = 0.0;
    for (int r = 0; r * span < seconds; ++r) {
      for (size_t i = 0; i < swing.size(); ++i) {
        const double t = swing.t_s[i] + r * span;
        if (t - swing.t_s.front() > seconds) break;
        if (!engine.Add(t, swing.gyro_in_imu[i], &swing.accel_in_imu[i])) continue;
        const double start = ThreadCpuSeconds();
        benchmark::DoNotOptimize(engine.Update());
        const double used = ThreadCpuSeconds() - start;
        total += used;
        largest = std::max(largest, used);
        ++updates;
      }
    }
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    state.counters["updates"] = static_cast<double>(updates);
    state.counters["mean_update_ms"] = 1e3 * total / std::max(1L, updates);
    state.counters["max_update_ms"] = 1e3 * largest;
    state.counters["peak_rss_MB"] = static_cast<double>(usage.ru_maxrss) / 1024.0;
    state.counters["swings_closed"] = static_cast<double>(engine.swings().size());
  }
}
BENCHMARK(BM_WatchStream)->Arg(600)->Arg(3600)->Unit(benchmark::kSecond)->Iterations(1);

// The first time the engine says "enough" (NaN: never), and its last period.
double FirstEnough(const CampaignConfig& config, const ImuData& data, double target_percent,
                   double* period) {
  WatchEngineOptions options;
  options.target_percent = target_percent;
  WatchEngine engine(config, options);
  for (size_t i = 0; i < data.size(); ++i) {
    if (!engine.Add(data.t_s[i], data.gyro_in_imu[i], &data.accel_in_imu[i])) continue;
    const WatchUpdate u = engine.Update();
    if (std::isfinite(u.period_s)) *period = u.period_s;
    if (u.verdict == WatchVerdict::kEnough) return u.t_s;
  }
  return NAN;
}

void BM_WatchEnoughSurvey(benchmark::State& state) {
  const CampaignConfig config = Config();
  constexpr double kTargetPercent = 0.05;
  for (auto _ : state) {
    int swings = 0, within = 0, neither = 0;
    double largest_cycles = 0.0;
    for (uint64_t seed = 1; seed <= 100; ++seed) {
      const ImuData data = Swing(seed, 50.0, 25.0);
      double period = 2.0;
      const double t_enough = FirstEnough(config, data, kTargetPercent, &period);
      const double until = std::isfinite(t_enough) ? t_enough + 2.0 * period : data.t_s.back();
      const double t_fit =
          watch_support::FirstFitReaching(config, data, kTargetPercent, period / 8, until);
      ++swings;
      if (std::isnan(t_enough) && std::isnan(t_fit)) {
        ++neither;
        ++within;
        continue;
      }
      const double cycles = std::abs(t_enough - t_fit) / period;  // NaN when only one reached
      if (cycles <= 1.0) ++within;
      largest_cycles = std::isfinite(cycles) ? std::max(largest_cycles, cycles) : INFINITY;
    }
    state.counters["swings"] = swings;
    state.counters["within_one_cycle"] = within;
    state.counters["neither_reached"] = neither;
    state.counters["largest_difference_cycles"] = largest_cycles;
  }
}
BENCHMARK(BM_WatchEnoughSurvey)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace
}  // namespace bifilar
