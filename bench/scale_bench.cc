// Scale (issue 9 item 12): cost linear in the input, memory proportional to it.
//   - an ellipse table of N rows, parsed and fitted with the default 2000 bootstrap replicates
//     (a 1e6-row table took 50 s and 1.6 GB);
//   - `process` with T logs and a fit.windows entry for each (cost grew with entries x traces);
//   - `process` with a tare list of K entries (150 k took over 30 s);
//   - `bifilar fit` of one long log: 60 s of swing at 11.7 / 23.3 / 46.7 kHz (0.7 / 1.4 / 2.8 M
//     rows, 7 columns; a 2.8 M-sample log took 69 s and 1.4 GB): read, swing axis, window, fit on
//     block means (fit/block_mean.h), amplitude sweep, residual statistics.
// The campaign benchmarks use a fake trace fit, so they time the pipeline around the fits.
// Run: build/bench/bifilar_bench --benchmark_filter='Scale'
// Each reports its complexity fit (BigO); linear means the per-item time stays flat.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include <benchmark/benchmark.h>

#include "base/units.h"
#include "fit/ellipse.h"
#include "pipeline/campaign/campaign.h"
#include "pipeline/commands/ellipse_table.h"
#include "pipeline/commands/simulate_spec.h"
#include "pipeline/config/config.h"
#include "pipeline/trace/trace_process.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;

std::string EllipseTable(int rows) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> pitch(-90.0, 90.0);
  std::normal_distribution<double> noise(0.0, 0.005);
  std::ostringstream text;
  text << "pitch_deg,inertia\n";
  text.precision(8);
  for (int i = 0; i < rows; ++i) {
    const double d = pitch(rng), t = d * kRadPerDeg;
    text << d << ','
         << 2.8 * std::cos(t) * std::cos(t) + 2.3 * std::sin(t) * std::sin(t) +
                0.02 * std::sin(2 * t) + noise(rng)
         << '\n';
  }
  return text.str();
}

void BM_ScaleEllipseTable(benchmark::State& state) {
  const std::string text = EllipseTable(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    const std::vector<EllipsePoint> points =
        ParseEllipseTable(text, "table.csv", DisplayUnits::kSi);
    EllipseResult result;
    std::string why;
    if (!FitEllipse(points, EllipseOptions(), &result, &why)) state.SkipWithError(why.c_str());
    benchmark::DoNotOptimize(result.ixz.value);
  }
  state.SetComplexityN(state.range(0));
}
BENCHMARK(BM_ScaleEllipseTable)
    ->RangeMultiplier(10)
    ->Range(10000, 1000000)
    ->Unit(benchmark::kMillisecond)
    ->Complexity(benchmark::oN);

// A campaign folder with `logs` fake logs at 6 angles ("I=<total>"), optional window entries for
// every log and a tare list of `tare` entries (missing files: error rows).
struct FakeCampaignDir {
  std::string dir;
  FakeCampaignDir(int logs, bool windows, int tare) {
    char tmpl[] = "/tmp/bifilar_scale_bench_XXXXXX";
    dir = mkdtemp(tmpl);
    std::ostringstream yaml;
    yaml << "rig:\n  filar_length_m: 2\n  filar_separation_m: 1\n  mass_kg: 2\n  inertia:\n";
    if (tare > 0) {
      yaml << "    tare:\n      logs:\n";
      for (int k = 0; k < tare; ++k) yaml << "        - tare/t" << k << ".csv\n";
    } else {
      yaml << "    inertia_kg_m2: 0.5\n";
    }
    yaml << "aircraft: {mass_kg: 10}\nruns: {root: logs, pattern: \"p{pitch_deg}/*.csv\"}\n"
         << "ellipse: {bootstrap: 0}\n";
    if (windows) yaml << "fit:\n  windows:\n";
    for (int i = 0; i < logs; ++i) {
      const int pitch = -60 + 30 * (i % 6);
      const std::string name = "p" + std::to_string(pitch) + "/l" + std::to_string(i) + ".csv";
      fs::create_directories(dir + "/logs/p" + std::to_string(pitch));
      const double t = pitch * kRadPerDeg;
      std::ofstream(dir + "/logs/" + name)
          << "I=" << 3 + std::sin(t) * std::sin(t) + 0.5 + 1e-6 * i << "\n";
      if (windows) yaml << "    " << name << ": [1, 20]\n";
    }
    std::ofstream(dir + "/campaign.yaml") << yaml.str();
  }
  ~FakeCampaignDir() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }

  void Run(benchmark::State& state) const {
    CampaignOptions options;
    options.out_dir = dir + "/out";
    options.jobs = 1;
    options.force = true;
    options.figures = false;
    options.write_report = false;
    options.fit_function = [](const CampaignConfig&, const std::string& path,
                              const TraceProcessOptions& o) {
      std::ifstream in(path);
      std::string text;
      std::getline(in, text);
      TraceRecord r;
      r.file = o.display_name;
      r.status = TraceStatus::kOk;
      r.inertia_total_kg_m2 = std::stod(text.substr(2));
      r.inertia_total_std_kg_m2 = 1e-4;
      r.model = "full";
      return r;
    };
    const CampaignConfig config = LoadCampaignConfig(dir + "/campaign.yaml");
    const CampaignResult result = RunCampaign(config, options);
    benchmark::DoNotOptimize(result.summary.n_traces);
    (void)state;
  }
};

void BM_ScaleCampaignWindows(benchmark::State& state) {
  const FakeCampaignDir campaign(static_cast<int>(state.range(0)), true, 0);
  for (auto _ : state) campaign.Run(state);
  state.SetComplexityN(state.range(0));
}
BENCHMARK(BM_ScaleCampaignWindows)
    ->RangeMultiplier(4)
    ->Range(250, 4000)
    ->Unit(benchmark::kMillisecond)
    ->Complexity(benchmark::oN);

void BM_ScaleTareList(benchmark::State& state) {
  const FakeCampaignDir campaign(60, false, static_cast<int>(state.range(0)));
  for (auto _ : state) campaign.Run(state);
  state.SetComplexityN(state.range(0));
}
BENCHMARK(BM_ScaleTareList)
    ->RangeMultiplier(4)
    ->Range(1000, 16000)
    ->Unit(benchmark::kMillisecond)
    ->Complexity(benchmark::oN);

// One simulated log of 60 s free swing at `rate_hz` (the `bifilar simulate --trace` defaults:
// I = 4.1 kg m^2, m = 6.75 kg, L = 2 m, D = 1.8 m, 20 deg, gyro and accelerometer) and its config.
struct LongLogDir {
  std::string dir, log, config;
  explicit LongLogDir(double rate_hz) {
    char tmpl[] = "/tmp/bifilar_scale_log_XXXXXX";
    dir = mkdtemp(tmpl);
    log = dir + "/long.csv";
    config = dir + "/fit.yaml";
    SimulateSpec spec = ParseSimulateSpec("seed: 1\n", "bench");
    spec.trace.inertia_kg_m2 = 4.1;
    spec.trace.mass_kg = 6.75;
    spec.trace.filar_length_m = 2.0;
    spec.trace.filar_separation_m = 1.8;
    spec.options.timeline.free_s = {60.0, 60.0};
    SetSampleRateFromFlag(&spec, rate_hz);
    RunSimulateTrace(spec, log);
    std::ofstream(config) << "rig: {filar_length_m: 2.0, filar_separation_m: 1.8, mass_kg: 6.75}\n";
  }
  ~LongLogDir() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

void BM_ScaleLongLogFit(benchmark::State& state) {
  const LongLogDir files(static_cast<double>(state.range(0)));
  ConfigLoadOptions load;
  load.require_runs = false;
  const CampaignConfig config = LoadCampaignConfig(files.config, load);
  TraceRecord record;
  for (auto _ : state) {
    record = ProcessTrace(config, files.log, TraceProcessOptions());
    if (!record.ok()) state.SkipWithError(record.message.c_str());
  }
  const size_t rows = static_cast<size_t>(60.0 * state.range(0));  // ~ samples (1 % dropped)
  state.SetComplexityN(static_cast<int64_t>(rows));
  state.counters["rows"] = static_cast<double>(rows);
  state.counters["I_kg_m2"] = record.inertia_total_kg_m2;
}
BENCHMARK(BM_ScaleLongLogFit)
    ->Arg(11667)
    ->Arg(23333)
    ->Arg(46667)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(2)
    ->Complexity(benchmark::oN);

}  // namespace
}  // namespace bifilar
