#!/usr/bin/env python3
# %% [markdown]
# # A first look at one bifilar log, from Python
#
# Notebook-style: each `# %%` cell runs on its own in Jupyter, VS Code or Spyder, or run the
# whole file:
#
#     python3 examples/first_look.py [LOG [CONFIG]] [--out DIR]
#
# (after `pip install .`, or with `PYTHONPATH=build/python`). Without arguments it looks at a
# log of the sample campaign (sample_runs/prandtl_d) with its config, configs/prandtl_d.yaml.
# The steps: inspect the log without a config, fit it, plot the fit and its residual, and look
# at the uncertainty: how big, and where it comes from.

# %%
import argparse
import os
import pathlib

import numpy as np

import bifilar

REPO = pathlib.Path(__file__).resolve().parents[1]
parser = argparse.ArgumentParser(description="A first look at one bifilar log.")
parser.add_argument("log", nargs="?",
                    default=str(REPO / "sample_runs/prandtl_d/logs/pitch_0/trial_1.csv.gz"))
parser.add_argument("config", nargs="?", default=str(REPO / "configs/prandtl_d.yaml"))
parser.add_argument("--out", default=".", help="folder for the figure (first_look.png)")
args, _ = parser.parse_known_args()  # parse_known_args: Jupyter passes its own arguments

# %% [markdown]
# ## 1. Inspect the log: no config needed
# `read_log(path)` guesses the time and gyro columns and their units as `bifilar inspect` does,
# and says what it guessed. Check the guesses before trusting anything after them.

# %%
raw = bifilar.read_log(args.log)
print(raw)  # a short summary; raw.keys() lists everything
for guess in raw.format_guessed.guesses:
    print("guessed:", guess)
steps = np.diff(raw.t_s)
print(f"{raw.t_s.size} samples over {raw.t_s[-1] - raw.t_s[0]:.1f} s, "
      f"{1 / np.median(steps):.1f} Hz (median step {np.median(steps) * 1000:.1f} ms)")
print("swing axis in the IMU frame:", np.round(raw.axis_in_imu, 3), f"({raw.axis_source})")
for warning in raw.warnings:
    print("warning:", warning)

# %% [markdown]
# ## 2. Fit it
# With the rig's config (filar length and separation, masses, uncertainties), the same fit as
# `bifilar fit CONFIG LOG`. The config's `imu` section, not the guess, says how to read the log.

# %%
series = bifilar.read_log(args.log, args.config)
result = bifilar.fit_trace(series.t_s, series.rate_rad_per_s, config=args.config,
                           name=args.log)
print(result)
print(f"status {result.status}: {result.message or 'every quality check passed'}")
for warning in result.warnings:
    print("warning:", warning)

# %% [markdown]
# ## 3. Plot the fit and the residual
# The residual is measured − fitted (the sign of the command line's figures). It should look
# like noise: a pattern in it (a beat, a drift) means the model misses something.

# %%
def svg_plot(path, t, measured, fitted, residual, title):
    """The same two panels as a plain SVG, for when matplotlib is not installed."""
    width, height, left = 900, 480, 100
    panels = ((30, 300, [(measured, "dots"), (fitted, "#1f77b4")], "deg/s"),
              (350, 440, [(residual, "#d62728")], "meas. − fit"))
    t0, t1 = t[0], t[-1]
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
           'font-family="sans-serif" font-size="12"><rect width="100%" height="100%" '
           f'fill="white"/><text x="{left}" y="18">{title}</text>']
    for top, bottom, series, label in panels:
        limit = max(float(np.max(np.abs(y))) for y, _ in series) or 1.0
        x = left + (t - t0) / (t1 - t0) * (width - left - 10)
        out.append(f'<rect x="{left}" y="{top}" width="{width - left - 10}" '
                   f'height="{bottom - top}" fill="none" stroke="#888"/>'
                   f'<text x="5" y="{(top + bottom) / 2}">{label}</text>'
                   f'<text x="5" y="{top + 12}">{limit:.3g}</text>')
        for y, style in series:
            py = (top + bottom) / 2 - y / limit * (bottom - top) / 2
            if style == "dots":
                out += [f'<circle cx="{a:.1f}" cy="{b:.1f}" r="1.2"/>' for a, b in zip(x, py)]
            else:
                points = " ".join(f"{a:.1f},{b:.1f}" for a, b in zip(x, py))
                out.append(f'<polyline points="{points}" fill="none" stroke="{style}"/>')
    out.append(f'<text x="{width / 2}" y="{height - 10}">t (s), {t0:.1f} to {t1:.1f}</text>'
               "</svg>")
    pathlib.Path(path).write_text("\n".join(out), encoding="utf-8")


title = (f"{pathlib.Path(args.log).name}: I = {result.inertia_total_kg_m2:.5g} "
         f"± {result.inertia_total_std_total_kg_m2:.2g} kg m² ({result.model} model)")
try:
    import matplotlib
    if not os.environ.get("DISPLAY") and "ipykernel" not in os.sys.modules:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    plt = None
if result.t_s.size and plt is not None:
    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(10, 6),
                                      gridspec_kw={"height_ratios": [2, 1]})
    top.plot(result.t_s, np.degrees(result.fitted_rad_per_s), color="C0", lw=1, label="fit")
    top.plot(result.t_s, np.degrees(result.measured_rad_per_s), ".", ms=2, color="k",
             label="measured")
    top.set_ylabel("swing rate (deg/s)")
    top.set_title(title)
    top.legend(loc="upper right")
    bottom.plot(result.t_s, np.degrees(result.residual_rad_per_s), color="C3", lw=0.5)
    bottom.set_ylabel("meas. − fit (deg/s)")
    bottom.set_xlabel("t (s)")
    fig.tight_layout()
    figure = pathlib.Path(args.out) / "first_look.png"
    fig.savefig(figure, dpi=100)
    print("wrote", figure)
elif result.t_s.size:
    figure = pathlib.Path(args.out) / "first_look.svg"
    svg_plot(figure, result.t_s, *(np.degrees(y) for y in (
        result.measured_rad_per_s, result.fitted_rad_per_s, result.residual_rad_per_s)), title)
    print("wrote", figure, "(matplotlib is not installed: a plain SVG)")
residual_deg = np.degrees(result.residual_rad_per_s)
if residual_deg.size:
    print(f"residual: rms {np.sqrt(np.mean(residual_deg ** 2)):.3f} deg/s, "
          f"{result.rms_over_noise:.2f} x the gyro noise, lag-1 autocorrelation "
          f"{result.residual_autocorrelation.lag1:.2f}")

# %% [markdown]
# ## 4. The uncertainty
# `inertia_total_std_total_kg_m2` is the number to quote: the fit's statistical part plus the
# rig's (filar length and separation, mass, gravity, gyro scale). The statistical part alone
# (`inertia_total_std_kg_m2`) is usually far smaller, and too small to quote on its own.

# %%
total = result.inertia_total_std_total_kg_m2
print(f"I_total = {result.inertia_total_kg_m2:.5g} ± {total:.2g} kg m² "
      f"({100 * total / result.inertia_total_kg_m2:.2f} %, 1 sigma)")
print(f"  statistical (fit) {result.inertia_total_std_kg_m2:.2g} kg m²")
for term in sorted(result.uncertainty.terms, key=lambda term: -term.std_kg_m2):
    print(f"  {term.name:<18} {term.std_kg_m2:.2g} kg m²  ({term.kind})")
