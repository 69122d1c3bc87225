#include "fit/trace_synth.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "base/units.h"

namespace bifilar {

SyntheticTraceOptions ExampleRigTraceOptions(double amplitude_deg, uint64_t seed) {
  SyntheticTraceOptions o;
  o.geometry.filar_length_m = 2.0;
  o.geometry.filar_separation_m = 0.88;
  o.geometry.mass_kg = 6.0;
  o.params.inertia_kg_m2 = 1.1616;
  o.params.drag_coeff_kg_m2 = 0.004;
  o.params.viscous_coeff_kg_m2_per_s = 0.002;
  o.amplitude_deg = amplitude_deg;
  o.seed = seed;
  return o;
}

bool MakeSyntheticTrace(const SyntheticTraceOptions& o, TraceFitInput* input) {
  std::mt19937_64 rng(o.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double dt = 1.0 / o.sample_rate_hz;
  const long n_nominal = static_cast<long>(std::floor(o.duration_s * o.sample_rate_hz)) + 1;
  TraceFitInput out;
  out.geometry = o.geometry;
  out.t_s.reserve(n_nominal);
  if (o.irregular_steps) {
    for (double t = 0.0; t <= o.duration_s;) {
      out.t_s.push_back(t);
      t += std::clamp(dt * std::exp(0.75 * normal(rng)), 0.008, 0.160);
    }
  } else {
    for (long k = 0; k < n_nominal; ++k) {
      const bool keep = k == 0 || unit(rng) >= o.drop_fraction;
      const double jitter = k == 0 ? 0.0 : (2.0 * unit(rng) - 1.0) * o.jitter_fraction * dt;
      if (keep) out.t_s.push_back(k * dt + jitter);
    }
  }
  IntegratorOptions tight;
  tight.rel_tol = 1e-12;
  tight.abs_tol = 1e-14;
  PendulumIntegrator integrator(o.model, o.geometry, tight);
  Trajectory traj;
  std::string why;
  if (!integrator.Integrate(o.params, o.amplitude_deg * kRadPerDeg, o.rate0_deg_per_s * kRadPerDeg,
                            out.t_s, false, &traj, &why)) {
    return false;
  }
  const double sigma = o.noise_deg_per_s * kRadPerDeg, bias = o.bias_deg_per_s * kRadPerDeg;
  out.rate_rad_per_s.resize(out.t_s.size());
  const double phi = o.noise_ar1_phi;
  double e = normal(rng);
  for (size_t k = 0; k < out.t_s.size(); ++k) {
    if (k > 0) e = phi * e + std::sqrt(1.0 - phi * phi) * normal(rng);
    out.rate_rad_per_s[k] = traj.rate_rad_per_s[k] + bias + sigma * e;
  }
  out.noise_rad_per_s = sigma;
  *input = std::move(out);
  return true;
}

}  // namespace bifilar
