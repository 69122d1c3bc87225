// `bifilar plan --rig` (issue 27): one whole plan (grid search, the recommended rig and its
// alternatives each simulated and fitted with FitTrace, the reference object) must take under a
// second. The quadrotor of the public logs (30 Hz) and the 3.3 kg fixed-wing (50 Hz).
#include <benchmark/benchmark.h>

#include "pipeline/commands/rig_plan.h"

namespace bifilar {
namespace {

void BM_RigPlanQuadrotor(benchmark::State& state) {
  RigPlanOptions o;
  o.mass_kg = 0.0343;
  o.inertia_kg_m2 = 1.6e-5;
  o.inertia_max_kg_m2 = 2.9e-5;
  o.max_length_m = 0.594;
  o.max_separation_m = 0.030;
  o.length_std_m = o.separation_std_m = 0.0005;
  o.target_percent = 1.0;
  o.imu_rate_hz = 30.0;
  for (auto _ : state) benchmark::DoNotOptimize(RunRigPlan(o));
}
BENCHMARK(BM_RigPlanQuadrotor)->Unit(benchmark::kMillisecond);

void BM_RigPlanFixedWing(benchmark::State& state) {
  RigPlanOptions o;
  o.mass_kg = 3.24;
  o.cradle_mass_kg = 0.1;
  o.inertia_kg_m2 = 0.05;
  o.max_length_m = 2.5;
  o.max_separation_m = 0.6;
  o.target_percent = 1.0;
  o.imu_rate_hz = 50.0;
  o.gyro_noise_deg_per_s = 0.3;
  for (auto _ : state) benchmark::DoNotOptimize(RunRigPlan(o));
}
BENCHMARK(BM_RigPlanFixedWing)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace bifilar
