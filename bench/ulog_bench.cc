// Reading PX4 ULog logs against the CSV reader, per sample (items_per_second = samples/s), on
// the same simulated 60 s, 100 Hz log as bench/imu_log_bench.cc, plus the real PX4 log when
// present (its sensor_combined is 1298 of 17 thousand messages of 70 topics).
// Run: build/bench/bifilar_bench --benchmark_filter='Ulog|ImuLogCsvPerSample'
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <benchmark/benchmark.h>

#include "bench/bench_support.h"
#include "pendulum/simulate.h"
#include "pipeline/logs/imu_log.h"
#include "pipeline/logs/imu_log_writer.h"
#include "pipeline/logs/ulog.h"
#include "pipeline/logs/ulog_writer.h"

namespace bifilar {
namespace {

// The simulated log of bench/imu_log_bench.cc: 60 s at 100 Hz, 7 channels.
const ImuData& Log60s() { return BenchTrace60s().imu; }

void BM_ImuLogCsvPerSample(benchmark::State& state) {
  const std::string text = FormatImuLog(Log60s(), ImuFormat());
  for (auto _ : state) {
    ImuData d = ReadImuLogFromString(text, "bench.csv", ImuFormat());
    benchmark::DoNotOptimize(d.t_s.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(Log60s().size()));
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(text.size()));
}
BENCHMARK(BM_ImuLogCsvPerSample)->Unit(benchmark::kMicrosecond);

void BM_UlogPerSample(benchmark::State& state) {
  const std::string bytes = FormatImuUlog(Log60s());
  for (auto _ : state) {
    ImuData d = ReadImuLogFromString(bytes, "bench.ulg", ImuFormat());  // detected by its magic
    benchmark::DoNotOptimize(d.t_s.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(Log60s().size()));
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(bytes.size()));
}
BENCHMARK(BM_UlogPerSample)->Unit(benchmark::kMicrosecond);

// A real PX4 flight log: every message of every topic is walked, only sensor_combined decoded;
// items = sensor_combined samples.
void BM_UlogRealPx4Log(benchmark::State& state) {
  const std::string path =
      std::string(BIFILAR_SOURCE_DIR) + "/../shared/data/px4/sample_log_small.ulg";
  if (!std::filesystem::exists(path)) {
    state.SkipWithError("real PX4 log absent");
    return;
  }
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  const std::string bytes = s.str();
  size_t samples = 0;
  for (auto _ : state) {
    ImuData d = ReadImuLogFromString(bytes, path, ImuFormat());
    samples = d.size();
    benchmark::DoNotOptimize(d.t_s.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(samples));
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(bytes.size()));
}
BENCHMARK(BM_UlogRealPx4Log)->Unit(benchmark::kMicrosecond);

// `inspect`'s topic listing (issue 23): N subscriptions with 3 samples each, every topic's
// count and rate in one pass (it took one pass per subscription: 13-24 s for 2000). Linear in N.
void BM_UlogTopicListing(benchmark::State& state) {
  const int topics = static_cast<int>(state.range(0));
  UlogWriter w(0);
  for (int k = 0; k < topics; ++k) {
    w.Format("t" + std::to_string(k) + ":uint64_t timestamp;float v;");
    w.AddLogged("t" + std::to_string(k), 0, static_cast<uint16_t>(k));
  }
  for (int s = 0; s < 3; ++s) {
    for (int k = 0; k < topics; ++k) {
      w.Data(static_cast<uint16_t>(k), UlogPayload().U64(1000000 + 1000 * s).F32(0.0f).str());
    }
  }
  UlogRequest request;
  request.topic_timestamps = true;
  for (auto _ : state) {
    const UlogContents c = ParseUlog(w.bytes(), "many.ulg", request);
    benchmark::DoNotOptimize(c.subscriptions.data());
  }
  state.SetItemsProcessed(state.iterations() * topics);
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(w.bytes().size()));
}
BENCHMARK(BM_UlogTopicListing)->Arg(200)->Arg(2000)->Arg(20000)->Unit(benchmark::kMillisecond);

// A 1.2 kB file whose nested arrays would flatten to gigabytes: refused by its size bound.
void BM_UlogNestedArraysRefused(benchmark::State& state) {
  UlogWriter w(0);
  w.Format("l0:uint8_t[255] b;");
  for (int k = 1; k < 8; ++k) {
    w.Format("l" + std::to_string(k) + ":l" + std::to_string(k - 1) + "[255] a;");
  }
  w.Format("sensor_combined:uint64_t timestamp;l7[255] blob;");
  w.AddLogged("sensor_combined", 0, 0);
  UlogRequest request{"sensor_combined", 0, {"timestamp"}};
  for (auto _ : state) {
    try {
      ParseUlog(w.bytes(), "nested.ulg", request);
      state.SkipWithError("not refused");
    } catch (const std::exception& e) {
      benchmark::DoNotOptimize(e.what());
    }
  }
}
BENCHMARK(BM_UlogNestedArraysRefused)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace bifilar
