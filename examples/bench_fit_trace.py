#!/usr/bin/env python3
"""Overhead of a Python fit_trace call over the same work done in C++ (issue 11: <= 5 %).

    PYTHONPATH=build/python python3 examples/bench_fit_trace.py [--repeats 200]

Both sides fit the same 60 s, 100 Hz simulated trace (full model, ~6000 samples: the trace of
bench/trace_fit_bench.cc's size). C++: bifilar._core.time_fit_trace repeats in C++ the exact
work of one fit_trace call (in-memory log, window, amplitude band, fit, the JSON record), with
no Python in the loop. Python: wall time of bifilar.fit_trace(t, rate, ...) from Python,
including argument checks, array copies, the record's conversion to Python objects and the
numpy series. Medians of interleaved rounds, so that machine load affects both alike.
"""
import argparse
import statistics
import time

import bifilar
from bifilar import _core

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--repeats", type=int, default=200, help="calls per side (default 200)")
args = parser.parse_args()

sim = bifilar.simulate(inertia_kg_m2=1.1616, mass_kg=6.0, length_m=2.0, separation_m=0.88,
                       amplitude_deg=20, duration_s=60, sample_rate_hz=100, seed=9)
t, rate = sim.t_s, sim.gyro_rad_per_s[:, 2]
settings = dict(length_m=2.0, separation_m=0.88, mass_kg=6.0)
check = bifilar.fit_trace(t, rate, **settings)
assert check.status == "ok", check.message
print(f"trace: {t.size} samples, window {check.window_s[1] - check.window_s[0]:.1f} s, "
      f"{check.t_s.size} fitted, {check.iterations} iterations")

cpp, python = [], []
for _ in range(args.repeats // 10):  # interleave: 10 C++ calls, then 10 Python calls
    cpp += _core.time_fit_trace(t, rate, 10, **settings)
    for _ in range(10):
        start = time.perf_counter()
        bifilar.fit_trace(t, rate, **settings)
        python.append(time.perf_counter() - start)

cpp_ms, py_ms = 1e3 * statistics.median(cpp), 1e3 * statistics.median(python)
print(f"C++    median {cpp_ms:.3f} ms  (min {1e3 * min(cpp):.3f})")
print(f"Python median {py_ms:.3f} ms  (min {1e3 * min(python):.3f})")
print(f"overhead {py_ms - cpp_ms:+.3f} ms = {100 * (py_ms / cpp_ms - 1):+.2f} % "
      f"(min to min {100 * (min(python) / min(cpp) - 1):+.2f} %)")
