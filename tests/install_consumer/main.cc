// A client of the installed library: simulates a log of a known inertia with the pendulum
// simulator, fits its free swing and checks the fitted inertia against the truth. Exit 0 when
// the fit is ok and within its noise of the truth; 1 otherwise, saying why.
#include <cmath>
#include <cstdio>
#include <string>

#include "bifilar/base/version.h"
#include "bifilar/fit/trace_fit.h"
#include "bifilar/pendulum/simulate.h"

int main() {
  using namespace bifilar;
  TraceSetup setup;  // a small rig: L 1 m, D 0.4 m, m 1.5 kg
  setup.geometry.filar_length_m = 1.0;
  setup.geometry.filar_separation_m = 0.4;
  setup.geometry.mass_kg = 1.5;
  setup.params.inertia_kg_m2 = 0.05;  // the truth
  setup.params.drag_coeff_kg_m2 = 0.002;
  setup.params.viscous_coeff_kg_m2_per_s = 0.0005;
  setup.amplitude_rad = 0.35;
  SimulationOptions options;
  options.timeline = FixedTimeline(3.0, 1.0, 1.5, 30.0);  // rest, twist, hold, free swing (s)
  SimulatedTrace trace;
  std::string why;
  if (!SimulateTrace(setup, options, 7, &trace, &why)) {
    std::printf("simulation failed: %s\n", why.c_str());
    return 1;
  }
  // The free swing from 1 s after release, on the gyro's z axis (pitch 0: the swing axis).
  TraceFitInput input;
  input.geometry = setup.geometry;
  input.label = "consumer";
  for (size_t k = 0; k < trace.imu.size(); ++k) {
    if (trace.imu.t_s[k] < trace.truth.t_release_s + 1.0) continue;
    input.t_s.push_back(trace.imu.t_s[k]);
    input.rate_rad_per_s.push_back(trace.imu.gyro_in_imu[k].z());
  }
  const TraceFitResult fit = FitTrace(input, TraceFitOptions());
  const double truth = setup.params.inertia_kg_m2;
  const double fitted = fit.params.inertia_kg_m2;
  const double std = fit.inertia_std_kg_m2;
  std::printf("bifilar %s (results schema %d): I = %.9f +- %.9f kg m^2, truth %.9f, status %s\n",
              ProgramVersion(), kResultsSchemaVersion, fitted, std, truth, ToString(fit.status));
  if (fit.status != TraceFitStatus::kOk) {
    std::printf("the fit is not ok: %s\n", fit.message.c_str());
    return 1;
  }
  // Within 4 of its own stds (a 1-in-15,000 event for a Gaussian), the std itself honest: at
  // most 1 % of I for this clean log.
  if (!(std > 0.0 && std < 0.01 * truth && std::fabs(fitted - truth) < 4.0 * std)) {
    std::printf("the fitted inertia is not within 4 std of the truth\n");
    return 1;
  }
  return 0;
}
