#!/usr/bin/env python3
"""Fit one bifilar trace from Python and plot it (if matplotlib is installed).

    PYTHONPATH=build/python python3 examples/fit_trace.py            # a simulated trace
    PYTHONPATH=build/python python3 examples/fit_trace.py CONFIG LOG  # a real log
    ... --save fit.png                                               # write the figure

Without arguments a trace is simulated with known inertia (2.5 kg m^2), then fitted.
"""
import argparse

import bifilar

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("config", nargs="?", help="YAML config (configs/README.md)")
parser.add_argument("log", nargs="?", help="IMU log (CSV)")
parser.add_argument("--save", help="write the figure here instead of showing it")
args = parser.parse_args()

if args.log:
    series = bifilar.read_log(args.log, args.config)
    t, rate = series.t_s, series.rate_rad_per_s
    result = bifilar.fit_trace(t, rate, config=args.config, name=args.log)
else:
    sim = bifilar.simulate(inertia_kg_m2=2.5, mass_kg=6.0, length_m=2.0, separation_m=0.9,
                           amplitude_deg=20, duration_s=60, seed=1)
    t, rate = sim.t_s, sim.gyro_rad_per_s[:, 2]  # pitch 0, IMU on body axes: swing = z gyro
    result = bifilar.fit_trace(t, rate, length_m=2.0, separation_m=0.9, mass_kg=6.0,
                               name="simulated")
    print(f"truth: I = {sim.truth.traces[0].inertia_total_kg_m2} kg m^2")

print(f"{result.file}: {result.status}  I = {result.inertia_total_kg_m2:.6g} "
      f"+- {result.inertia_total_std_kg_m2:.2g} kg m^2  window {result.window_s} s  "
      f"{result.message}")

try:
    import matplotlib
    if args.save:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib is not installed: no plot (Debian: python3-matplotlib)")
else:
    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(10, 6),
                                      gridspec_kw={"height_ratios": [2, 1]})
    top.plot(t, rate, color="0.7", lw=0.8, label="measured swing rate")
    top.plot(result.t_s, result.fitted_rad_per_s, color="C0", lw=1, label="fit")
    top.set_ylabel("rad/s")
    top.set_title(f"I = {result.inertia_total_kg_m2:.6g} kg m$^2$ ({result.model} model)")
    top.legend(loc="upper right")
    bottom.plot(result.t_s, result.residual_rad_per_s, color="C3", lw=0.5)
    bottom.set_ylabel("meas. - fit (rad/s)")
    bottom.set_xlabel("t (s)")
    fig.tight_layout()
    if args.save:
        fig.savefig(args.save, dpi=120)
        print(f"wrote {args.save}")
    else:
        plt.show()
