// Reading PX4 ULog logs against the CSV reader, per sample (items_per_second = samples/s), on
// the same simulated 60 s, 100 Hz log as bench/imu_log_bench.cc, plus the real PX4 log when
// present (its sensor_combined is 1298 of 17 thousand messages of 70 topics).
// Run: build/bench/bifilar_bench --benchmark_filter='Ulog|ImuLogCsvPerSample'
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <benchmark/benchmark.h>

#include "pendulum/simulate.h"
#include "pipeline/logs/imu_log.h"
#include "pipeline/logs/imu_log_writer.h"
#include "pipeline/logs/ulog.h"
#include "pipeline/logs/ulog_writer.h"

namespace bifilar {
namespace {

// The simulated log of bench/imu_log_bench.cc: 60 s at 100 Hz, 7 channels.
const ImuData& Log60s() {
  static const ImuData imu = [] {
    TraceSetup setup;
    setup.geometry.filar_length_m = 2.0;
    setup.geometry.filar_separation_m = 0.7;
    setup.geometry.mass_kg = 10.0;
    setup.params.inertia_kg_m2 = 0.8;
    setup.params.drag_coeff_kg_m2 = 0.005;
    setup.params.viscous_coeff_kg_m2_per_s = 0.001;
    setup.amplitude_rad = 0.35;
    SimulationOptions options;
    options.timeline.rest_before_s = {3.0, 3.0};
    options.timeline.twist_s = {1.0, 1.0};
    options.timeline.hold_s = {1.5, 1.5};
    options.timeline.free_s = {54.5, 54.5};
    options.timeline.stop_probability = 0.0;
    SimulatedTrace t;
    std::string why;
    if (!SimulateTrace(setup, options, 42, &t, &why)) std::abort();
    return t.imu;
  }();
  return imu;
}

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
  const std::string path = std::string(BIFILAR_SOURCE_DIR) + "/../shared/data/px4/sample_log_small.ulg";
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

}  // namespace
}  // namespace bifilar
