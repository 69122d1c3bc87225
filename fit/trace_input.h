// The data of one trace fit and its initial guess: the types fit/trace_fit.h and
// fit/trace_guess.h share (a header of their own, so the two do not include each other).
#pragma once

#include <string>
#include <vector>

#include "pendulum/model.h"

namespace bifilar {

struct TraceFitInput {
  std::vector<double> t_s;             // sample times of the window (s), strictly increasing
  std::vector<double> rate_rad_per_s;  // swing rate omega_meas = gyro . n (rad/s), same size
  double noise_rad_per_s = 0.0;        // gyro noise std from the rest segment; <= 0: unknown
  double secondary_motion_ratio = -1;  // other-axes energy / swing-axis energy; < 0: unknown
  RigGeometry geometry;                // L, D, m, g
  std::string label;                   // file name or other tag used in messages (optional)
};

// The initial guess, from the data alone (fit/trace_guess.h).
struct TraceInitialGuess {
  double period_s = 0.0;                  // mean period over the window (zero crossings)
  double rate_amplitude_rad_per_s = 0.0;  // rate amplitude of the first cycle
  double decay_rate_per_s = 0.0;          // envelope decay rate lambda (amplitude ~ exp(-lambda t))
  double cycles = 0.0;                    // periods covered by the window
  PendulumParams params;                  // I (amplitude-corrected), K_D, C
  double angle0_rad = 0.0;                // psi(t0)
  double rate0_rad_per_s = 0.0;           // psi'(t0)
  double bias_rad_per_s = 0.0;            // mean over an integer number of cycles
  double data_noise_rad_per_s = 0.0;      // sample-to-sample scatter estimate of the noise
};

}  // namespace bifilar
