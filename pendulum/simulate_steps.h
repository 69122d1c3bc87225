// Private to pendulum/ (simulate.cc, simulate_campaign.cc): what the campaign simulation takes
// from the one-trace simulation: the portable random numbers and the range check of a
// UniformRange.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <string>

#include "base/option_check.h"
#include "base/units.h"
#include "pendulum/simulate.h"

namespace bifilar {

// Portable random numbers: std::mt19937_64 is fully specified by the standard, but the standard
// distributions are not, so uniforms and normals are made here (same seed -> same bytes anywhere).
class Rng {
 public:
  explicit Rng(uint64_t seed) : engine_(seed) {}
  double Uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }  // [0, 1)
  double Uniform(const UniformRange& r) { return r.min + (r.max - r.min) * Uniform(); }
  double Normal() {                     // Box-Muller, one value per call (no cached state)
    const double u1 = 1.0 - Uniform();  // (0, 1]
    const double u2 = Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
  }
  double Normal(double sigma) { return sigma * Normal(); }

 private:
  std::mt19937_64 engine_;
};

// A UniformRange [min, max] of `field`: both ends finite, min <= max, min above `lower`.
bool CheckUniformRange(const UniformRange& r, const std::string& field, double lower,
                       bool lower_open, CheckFailure* f);

}  // namespace bifilar
