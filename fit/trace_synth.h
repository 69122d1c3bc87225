// Synthetic free-oscillation windows with known truth, for the trace-fit tests and benchmarks:
// the model integrated at jittered timestamps with dropped samples, plus a gyro bias and white
// noise. Only the free oscillation (no rest, twist or hold: that is pendulum/simulate.h's job).
// Conventions: docs/physics.md §2.
#pragma once

#include <cstdint>

#include "fit/trace_fit.h"

namespace bifilar {

struct SyntheticTraceOptions {
  PendulumModel model = PendulumModel::kFull;  // truth's equation of motion
  RigGeometry geometry;                        // L, D, m, g
  PendulumParams params;                       // true I, K_D, C
  double amplitude_deg = 20.0;                 // psi(t0) (deg)
  double rate0_deg_per_s = 0.0;                // psi'(t0) (deg/s)
  double duration_s = 60.0;                    // window length (s); > 0
  double sample_rate_hz = 100.0;               // nominal rate (Hz); > 0
  double jitter_fraction = 0.2;                // timestamp jitter, uniform +-this * dt; [0, 0.45]
  double drop_fraction = 0.01;                 // samples lost at random; [0, 0.5)
  double noise_deg_per_s = 0.25;               // white gyro noise sigma (deg/s); >= 0
  double bias_deg_per_s = 0.3;                 // constant gyro bias (deg/s)
  // Coloured noise: AR(1) over the samples, e_k = phi e_(k-1) + sqrt(1 - phi^2) w_k (marginal
  // std noise_deg_per_s); [0, 0.99].
  double noise_ar1_phi = 0.0;
  // Irregular sampling: every step drawn log-normal around 1/sample_rate_hz (ln-std 0.75),
  // clipped to [8, 160] ms, like a 30 Hz radio link (jitter and drops then unused).
  bool irregular_steps = false;
  uint64_t seed = 1;
};

// The example rig of docs/physics.md §2 (L 2.0 m, D 0.88 m, m 6 kg; I 1.1616 kg m^2, where
// m (D/2)^2 / I = 1 and the full model's kinetic term matters; K_D 0.004 kg m^2, C 0.002 kg m^2/s;
// period ~2.8 s) released at `amplitude_deg`: the tests' and benchmarks' common truth.
SyntheticTraceOptions ExampleRigTraceOptions(double amplitude_deg, uint64_t seed);

// The window (t_s, rate_rad_per_s, geometry, noise_rad_per_s = the true sigma). The truth is
// integrated with CVODE at rel_tol 1e-12. Returns false if the integration fails.
bool MakeSyntheticTrace(const SyntheticTraceOptions& options, TraceFitInput* input);

}  // namespace bifilar
