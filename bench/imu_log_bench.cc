// Reading a 60 s, 100 Hz IMU log (7 columns) and finding its swing axis and free-oscillation
// window. Run: build/bench/bifilar_bench --benchmark_filter='ImuLog|SwingAxis|Window'
#include <filesystem>
#include <fstream>
#include <string>

#include <benchmark/benchmark.h>
#include <unistd.h>

#include "fit/swing_axis.h"
#include "fit/window.h"
#include "pendulum/simulate.h"
#include "pipeline/logs/imu_log.h"
#include "pipeline/logs/imu_log_writer.h"

namespace bifilar {
namespace {

// A simulated 60 s log (rest 3 s, twist 1 s, hold 1.5 s, free 54.5 s) at 100 Hz.
const SimulatedTrace& Trace60s() {
  static const SimulatedTrace trace = [] {
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
    return t;
  }();
  return trace;
}

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
  const std::string path =
      (std::filesystem::temp_directory_path() / ("bifilar_bench_" + std::to_string(::getpid()) + ".csv")).string();
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
    FreeOscillationWindow w = FindFreeOscillationWindow(imu.t_s, axis.rate_rad_per_s, WindowOptions());
    AmplitudeBand band = TrimToAmplitudeBand(imu.t_s, axis.rate_rad_per_s, w, AmplitudeBandOptions());
    benchmark::DoNotOptimize(band.t0_s);
  }
}
BENCHMARK(BM_SwingAxisAndWindow)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace bifilar
