// What the `bifilar watch` tests (tests/pipeline_watch*_test.cc) and the watch benchmark
// (bench/watch_bench.cc) share: a swing simulated on one small rig, that rig's `bifilar fit`
// config, `fit` on a log, and the first cut of a log where `fit` reaches a target. Header-only and
// without GoogleTest, so the benchmark includes it.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <optional>
#include <string>

#include "pipeline/commands/fit_command.h"
#include "pipeline/commands/simulate_spec.h"
#include "pipeline/config/config.h"
#include "pipeline/trace/trace_process.h"

namespace bifilar {
namespace watch_support {

// The rig: filars 1 m long and 0.3 m apart, 2 kg, I = 0.05 kg m^2 (period ~2.1 s).
constexpr double kSwingInertia = 0.05;
constexpr char kSwingConfig[] = "rig: {filar_length_m: 1.0, filar_separation_m: 0.3, mass_kg: 2}\n";

struct Swing {
  uint64_t seed = 1;
  double duration_s = 20.0;              // free oscillation (s)
  std::optional<double> amplitude_deg;   // unset: the simulator's default
  std::optional<double> sample_rate_hz;  // unset: the simulator's default
};

// Simulates `swing` on the rig into the log `path` (CSV, or ULog for .ulg, DataFlash for .bin),
// with its truth JSON beside it, as `bifilar simulate --trace PATH` does.
inline void SimulateSwing(const std::string& path, const Swing& swing) {
  SimulateCommandOptions s;
  s.trace_csv = path;
  s.o.seed = swing.seed;
  s.o.inertia_kg_m2 = kSwingInertia;
  s.o.mass_kg = 2.0;
  s.o.length_m = 1.0;
  s.o.separation_m = 0.3;
  s.o.amplitude_deg = swing.amplitude_deg;
  s.o.duration_s = swing.duration_s;
  s.sample_rate = swing.sample_rate_hz;
  RunSimulate(s);
}

// Writes the rig's config (kSwingConfig) to `path`; returns the path.
inline std::string WriteSwingConfig(const std::string& path) {
  std::ofstream(path, std::ios::binary) << kSwingConfig;
  return path;
}

// The record `bifilar fit CONFIG LOG` gives.
inline TraceRecord FitLog(const std::string& config, const std::string& log) {
  FitCommandOptions fit;
  fit.config_path = config;
  fit.logs = {log};
  return RunFit(fit).records.at(0);
}

// The first cut where `fit` on the log so far reaches the target (NaN: none before `until`).
inline double FirstFitReaching(const CampaignConfig& config, const ImuData& data,
                               double target_percent, double step, double until) {
  for (double cut = data.t_s.front() + 2.0; cut <= std::min(until, data.t_s.back()); cut += step) {
    ImuData part;
    for (size_t i = 0; i < data.size() && data.t_s[i] <= cut; ++i) {
      part.t_s.push_back(data.t_s[i]);
      part.gyro_in_imu.push_back(data.gyro_in_imu[i]);
      part.accel_in_imu.push_back(data.accel_in_imu[i]);
    }
    const TraceRecord r = ProcessTraceData(config, part, "sw.csv", TraceProcessOptions());
    if (r.ok() && 100.0 * r.inertia_total_std_kg_m2 / r.inertia_total_kg_m2 <= target_percent) {
      return cut;
    }
  }
  return NAN;
}

}  // namespace watch_support
}  // namespace bifilar
