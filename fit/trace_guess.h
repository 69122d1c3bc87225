// Initial guess for the trace fit from the data alone (no solver): docs/physics.md §2.
//
//   period     least-squares line through the zero crossings (with hysteresis, linear
//              interpolation between the real timestamps), so jitter and drops do not matter
//   bias       mean rate over an integer number of cycles (between the first and the last
//              upward crossing)
//   damping    from the half-cycle peaks: the local log decrement against amplitude is a line,
//              lambda_v + kappa A, whose intercept gives C = 2 I lambda_v and slope the
//              quadratic drag K_D = 3 pi I kappa / (4 omega)
//   psi'(t0)   damped sinusoid + constant fitted by linear least squares to the first cycle,
//              with the decay rate at the first peak's amplitude
//   psi(t0)    the angle whose derivative is that damped sinusoid (zero mean about equilibrium)
//   I          small-angle formula from the undamped period, corrected for amplitude by
//              integrating the chosen model over one period at the window's RMS amplitude
//              (exact for `jardin`/`linear`, where the period scales with sqrt(I) at fixed
//              amplitude; two iterations for `full`)
#pragma once

#include <string>
#include <vector>

#include "fit/trace_input.h"
#include "pendulum/integrator.h"
#include "pendulum/model.h"

namespace bifilar {

// Sample-to-sample noise of a smooth signal at non-uniform times: the residual of each sample
// against the straight line through its neighbours, normalised by its variance factor
// 1 + w0^2 + w2^2, robust scale (1.4826 * median |e|). Signal curvature adds about
// 0.5 |psi'''| dt^2, below 5 % of 0.25 deg/s noise at 100 Hz on a 1 Hz swing.
double EstimateSampleNoise(const std::vector<double>& t_s, const std::vector<double>& x);

// Fills *guess. Returns false with *why when the data cannot support a fit: too few samples,
// constant data, no oscillation above the noise, fewer than min_periods periods.
bool EstimateTraceGuess(const TraceFitInput& input, PendulumModel model,
                        const IntegratorOptions& integrator, double min_periods,
                        TraceInitialGuess* guess, std::string* why);

}  // namespace bifilar
