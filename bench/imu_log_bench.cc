// Reading a 60 s, 100 Hz IMU log (7 columns) and finding its swing axis and free-oscillation
// window. Run: build/bench/bifilar_bench --benchmark_filter='ImuLog|SwingAxis|Window'
#include <filesystem>
#include <fstream>
#include <string>

#include <benchmark/benchmark.h>
#include <unistd.h>

#include "bench/bench_support.h"
#include "fit/swing_axis.h"
#include "fit/window.h"
#include "pendulum/simulate.h"
#include "pipeline/logs/imu_log.h"
#include "pipeline/logs/imu_log_writer.h"

namespace bifilar {
namespace {

const SimulatedTrace& Trace60s() { return BenchTrace60s(); }

const std::string& CsvText() {
  static const std::string text = FormatImuLog(Trace60s().imu, ImuFormat());
  return text;
}

void BM_ImuLogParseString(benchmark::State& state) {
  const std::string& text = CsvText();
  for (auto _ : state) {
    ImuData d = ReadImuLogFromString(text, "bench.csv", ImuFormat());
    benchmark::DoNotOptimize(d.t_s.data());
  }
  state.counters["rows"] = static_cast<double>(Trace60s().imu.size());
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * text.size()));
}
BENCHMARK(BM_ImuLogParseString)->Unit(benchmark::kMicrosecond);

void BM_ImuLogReadFile(benchmark::State& state) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("bifilar_bench_" + std::to_string(::getpid()) + ".csv"))
                               .string();
  std::ofstream(path, std::ios::binary) << CsvText();
  for (auto _ : state) {
    ImuData d = ReadImuLog(path, ImuFormat());
    benchmark::DoNotOptimize(d.t_s.data());
  }
  std::filesystem::remove(path);
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * CsvText().size()));
}
BENCHMARK(BM_ImuLogReadFile)->Unit(benchmark::kMicrosecond);

void BM_SwingAxisAndWindow(benchmark::State& state) {
  const ImuData& imu = Trace60s().imu;
  for (auto _ : state) {
    SwingAxis axis;
    std::string why;
    if (!EstimateSwingAxis(imu, SwingAxisOptions(), std::nullopt, &axis, &why)) std::abort();
    FreeOscillationWindow w =
        FindFreeOscillationWindow(imu.t_s, axis.rate_rad_per_s, WindowOptions());
    AmplitudeBand band =
        TrimToAmplitudeBand(imu.t_s, axis.rate_rad_per_s, w, AmplitudeBandOptions());
    benchmark::DoNotOptimize(band.t0_s);
  }
}
BENCHMARK(BM_SwingAxisAndWindow)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace bifilar
