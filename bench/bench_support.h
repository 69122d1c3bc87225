// What the benchmarks share: the simulated 60 s log that the log-reading benchmarks read.
#pragma once

#include <cstdlib>
#include <string>

#include "pendulum/simulate.h"

namespace bifilar {

// A simulated 60 s log (rest 3 s, twist 1 s, hold 1.5 s, free 54.5 s) at 100 Hz, 7 channels.
inline const SimulatedTrace& BenchTrace60s() {
  static const SimulatedTrace trace = [] {
    TraceSetup setup;
    setup.geometry.filar_length_m = 2.0;
    setup.geometry.filar_separation_m = 0.7;
    setup.geometry.mass_kg = 10.0;
    setup.params.inertia_kg_m2 = 0.8;
    setup.params.drag_coeff_kg_m2 = 0.005;
    setup.params.viscous_coeff_kg_m2_per_s = 0.001;
    setup.amplitude_rad = 0.35;
    SimulationOptions options;
    options.timeline = FixedTimeline(3.0, 1.0, 1.5, 54.5);
    SimulatedTrace t;
    std::string why;
    if (!SimulateTrace(setup, options, 42, &t, &why)) std::abort();
    return t;
  }();
  return trace;
}

}  // namespace bifilar
