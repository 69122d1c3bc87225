// What `fit --plot` adds to `fit` (issue 25: at most ~50 %): one yaw log of the non-ideal rig
// preset (configs/simulate_nonideal_rig.yaml: I grows with amplitude, the result comes from the
// lowest-amplitude band, 150 s at 50 Hz), processed as `bifilar fit` does, without figures and
// with the four of --plot (fit and sweep, SVG and PNG).
//
//   build/bench/bifilar_bench --benchmark_filter=FitPlot --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true   (one command line)
//
// Measured 2026-11-26 (shared 2-core machine, CPU time): BM_FitPlot/0 0.236 s, BM_FitPlot/1
// 0.306 s (+30 %); the whole 8-log preset: `fit` 2.15 s user, `fit --plot` 2.69 s user.
#include <cstdlib>
#include <filesystem>
#include <string>

#include <benchmark/benchmark.h>

#include "pipeline/commands/simulate_spec.h"
#include "pipeline/config/config.h"
#include "pipeline/logs/imu_log.h"
#include "pipeline/trace/trace_process.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;

struct PlotBenchLog {
  std::string dir;
  CampaignConfig config;
  ImuData data;
  std::string log;
  PlotBenchLog() {
    dir = (fs::temp_directory_path() / "bifilar_fit_plot_bench").string();
    fs::remove_all(dir);
    fs::create_directories(dir);
    std::string spec;
    {
      const std::string path =
          std::string(BIFILAR_SOURCE_DIR) + "/configs/simulate_nonideal_rig.yaml";
      std::FILE* f = std::fopen(path.c_str(), "rb");
      if (f == nullptr) std::abort();
      char buf[4096];
      size_t n = 0;
      while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) spec.append(buf, n);
      std::fclose(f);
    }
    spec.replace(spec.find("pitch_deg: [0, 90]"), 18, "pitch_deg: [0]");
    spec.replace(spec.find("trials_per_pitch: 4"), 19, "trials_per_pitch: 1");
    RunSimulateCampaign(ParseSimulateSpec(spec, "nonideal.yaml"), dir + "/logs");
    const std::string yaml = dir + "/c.yaml";
    std::FILE* f = std::fopen(yaml.c_str(), "wb");
    std::fputs(
        "rig: {filar_length_m: 0.74, filar_separation_m: 0.16, mass_kg: 3.34}\n"
        "imu:\n  time: {column: t, unit: ms}\n"
        "  gyro: {columns: [gx, gy, gz], unit: deg/s}\n  accel: null\n",
        f);
    std::fclose(f);
    ConfigLoadOptions load;
    load.require_runs = false;
    config = LoadCampaignConfig(yaml, load);
    log = dir + "/logs/pitch_0/trial_1.csv";
    std::string why;
    if (!TryReadImuLog(log, config.imu.format, config.limits.LogOptions(), &data, &why))
      std::abort();
  }
};

// Argument 0: fit only; 1: fit and the --plot figures.
void BM_FitPlot(benchmark::State& state) {
  static PlotBenchLog* b = new PlotBenchLog();
  TraceProcessOptions options;
  if (state.range(0) == 1) {
    options.figure_paths = {b->dir + "/fit.svg", b->dir + "/fit.png"};
    options.sweep_figure_paths = {b->dir + "/fit_sweep.svg", b->dir + "/fit_sweep.png"};
  }
  for (auto _ : state) {
    const TraceRecord r = ProcessTraceData(b->config, b->data, b->log, options, nullptr);
    benchmark::DoNotOptimize(r.inertia_total_kg_m2);
  }
}
BENCHMARK(BM_FitPlot)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();

}  // namespace
}  // namespace bifilar
