// Integration of one 60 s, 100 Hz trace (6000 samples), the unit of work of a trace fit
// (issue 2: at most 2 ms median with sensitivities). Rig I = 1.5 kg m^2, m = 10 kg, L = 2 m,
// D = 0.8 m, released from rest at 20 deg, small damping. Default tolerances (1e-10/1e-12 for
// rk853, 3e-11/3e-13 for cvodes: IntegratorOptions::WithMethod).
//
//   build/bench/bifilar_bench --benchmark_filter=Pendulum --benchmark_repetitions=10
//       --benchmark_report_aggregates_only=true   (one command line)
//
// Arguments: model (0 full, 1 jardin, 2 linear), sensitivities (0/1), timestamps (0 uniform,
// 1 jittered: +-3 ms jitter and 2 % dropped samples, like a wireless IMU log).
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "pendulum/integrator.h"

namespace bifilar {
namespace {

std::vector<double> TraceTimes(bool jittered) {
  std::vector<double> t;
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> jitter(-0.003, 0.003);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int k = 0; k < 6000; ++k) {
    double tk = 0.01 * k;
    if (jittered && k > 0) {
      if (unit(rng) < 0.02) continue;  // dropped packet
      tk += jitter(rng);
    }
    t.push_back(tk);
  }
  return t;
}

void BM_PendulumIntegrate(benchmark::State& state, IntegratorMethod method) {
  const PendulumModel models[] = {PendulumModel::kFull, PendulumModel::kJardin,
                                  PendulumModel::kLinear};
  const PendulumModel model = models[state.range(0)];
  const bool with_sensitivities = state.range(1) != 0;
  const std::vector<double> t = TraceTimes(state.range(2) != 0);
  RigGeometry geometry;
  geometry.filar_length_m = 2.0;
  geometry.filar_separation_m = 0.8;
  geometry.mass_kg = 10.0;
  PendulumParams params;
  params.inertia_kg_m2 = 1.5;
  params.drag_coeff_kg_m2 = 0.01;
  params.viscous_coeff_kg_m2_per_s = 0.005;
  // What a user gets: for cvodes the tolerances are 0.3x (IntegratorOptions::WithMethod).
  const IntegratorOptions options = IntegratorOptions().WithMethod(method);
  PendulumIntegrator integrator(model, geometry, options);
  Trajectory trajectory;
  std::string why;
  for (auto _ : state) {
    if (!integrator.Integrate(params, 0.349, 0.0, t, with_sensitivities, &trajectory, &why)) {
      state.SkipWithError(why.c_str());
      break;
    }
    benchmark::DoNotOptimize(trajectory.rate_rad_per_s.data());
  }
  state.counters["steps"] = static_cast<double>(integrator.last_stats().steps);
  state.counters["rejected"] = static_cast<double>(integrator.last_stats().rejected_steps);
  state.SetLabel(std::string(ToString(model)) + (with_sensitivities ? " +sens" : "") +
                 (state.range(2) ? " jittered" : ""));
}

void PendulumArgs(benchmark::internal::Benchmark* b) {
  for (int model = 0; model < 3; ++model) {
    for (int sens = 0; sens < 2; ++sens) b->Args({model, sens, 0});
  }
  b->Args({0, 1, 1});  // full model, sensitivities, jittered timestamps with drops
  b->Unit(benchmark::kMillisecond);
}

BENCHMARK_CAPTURE(BM_PendulumIntegrate, rk853, IntegratorMethod::kRungeKutta)->Apply(PendulumArgs);
BENCHMARK_CAPTURE(BM_PendulumIntegrate, cvodes, IntegratorMethod::kCvodes)->Apply(PendulumArgs);

// The README's integrator table: both methods on the benchmark trace (full model, uniform
// timestamps, with the 5 sensitivities) at tolerances rel = 10^(-arg/10), abs = rel / 100,
// with the global error against a reference (rk853 at rel 1e-13, abs 1e-15):
//   rate_err  max |psi'(t_k) - reference| (rad/s),
//   sens_err  max over the 5 columns of max_k |d psi'/dp_j - reference| / max_k |reference|.
//
//   build/bench/bifilar_bench --benchmark_filter=PendulumIntegratorTable
//       --benchmark_repetitions=10 --benchmark_report_aggregates_only=true
void BM_PendulumIntegratorTable(benchmark::State& state, IntegratorMethod method) {
  const std::vector<double> t = TraceTimes(false);
  RigGeometry geometry;
  geometry.filar_length_m = 2.0;
  geometry.filar_separation_m = 0.8;
  geometry.mass_kg = 10.0;
  PendulumParams params;
  params.inertia_kg_m2 = 1.5;
  params.drag_coeff_kg_m2 = 0.01;
  params.viscous_coeff_kg_m2_per_s = 0.005;
  std::string why;
  Trajectory reference;
  {
    IntegratorOptions tight;
    tight.rel_tol = 1e-13;
    tight.abs_tol = 1e-15;
    PendulumIntegrator integrator(PendulumModel::kFull, geometry, tight);
    if (!integrator.Integrate(params, 0.349, 0.0, t, true, &reference, &why)) {
      state.SkipWithError(why.c_str());
      return;
    }
  }
  IntegratorOptions options;
  options.method = method;
  options.rel_tol = std::pow(10.0, -0.1 * static_cast<double>(state.range(0)));
  options.abs_tol = options.rel_tol / 100.0;
  PendulumIntegrator integrator(PendulumModel::kFull, geometry, options);
  Trajectory trajectory;
  for (auto _ : state) {
    if (!integrator.Integrate(params, 0.349, 0.0, t, true, &trajectory, &why)) {
      state.SkipWithError(why.c_str());
      return;
    }
    benchmark::DoNotOptimize(trajectory.rate_rad_per_s.data());
  }
  double rate_err = 0.0;
  for (size_t k = 0; k < t.size(); ++k) {
    rate_err =
        std::max(rate_err, std::abs(trajectory.rate_rad_per_s[k] - reference.rate_rad_per_s[k]));
  }
  double sens_err = 0.0;
  for (int j = 0; j < kNumSensitivities; ++j) {
    const double scale = reference.d_rate.col(j).cwiseAbs().maxCoeff();
    sens_err = std::max(
        sens_err,
        (trajectory.d_rate.col(j) - reference.d_rate.col(j)).cwiseAbs().maxCoeff() / scale);
  }
  state.counters["rel_tol"] = options.rel_tol;
  state.counters["steps"] = static_cast<double>(integrator.last_stats().steps);
  state.counters["rhs_evals"] = static_cast<double>(integrator.last_stats().rhs_evals);
  state.counters["rate_err"] = rate_err;
  state.counters["sens_err"] = sens_err;
}
BENCHMARK_CAPTURE(BM_PendulumIntegratorTable, rk853, IntegratorMethod::kRungeKutta)
    ->Arg(80)
    ->Arg(100)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_PendulumIntegratorTable, cvodes, IntegratorMethod::kCvodes)
    ->Arg(80)
    ->Arg(100)
    ->Arg(105)
    ->Arg(110)
    ->Arg(115)
    ->Arg(120)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace bifilar
