#!/usr/bin/env python3
"""How often `bifilar fit --repeats` calls a group "two set-ups" (issue 26, item 3).

Simulates GROUPS ideal groups of 4 repeats (one I per group, released at 10-25 deg, seeds
fixed), fits them all with `fit --repeats --json` and counts the groups that look like two
set-ups (the answer should be 0); with --pairs it also simulates that many pairs of hangings
10 % apart in I, two logs each, named as one group, and counts those found (should be all).
With --data DIR it runs the 24 Crazyflie logs of DIR/crazyflie too (two configs, 12 logs each).

    scripts/setups_survey.py --bifilar build/bifilar --groups 100 --pairs 20 --data ../shared/data
"""
import argparse
import json
import os
import random
import subprocess
import sys
import tempfile

FIT_CONFIG = """rig: {filar_length_m: 1.5, filar_separation_m: 0.5, mass_kg: 3}
imu:
  time: {column: t, unit: s}
  gyro: {columns: [gx, gy, gz], unit: rad/s}
  accel: {columns: [ax, ay, az], unit: m/s^2}
"""

CRAZYFLIE_CONFIG = """gravity_mps2: 9.8066
rig: {filar_length_m: 0.594, filar_separation_m: 0.030, mass_kg: %s}
imu:
  time: {column: t, unit: s}
  gyro: {columns: [wx, wy, wz], unit: rad/s}
  accel: null
"""


def simulate(bifilar, path, inertia, seed, amplitude, duration):
    subprocess.run([bifilar, "simulate", "--trace", path, "--inertia-kg-m2", "%.6g" % inertia,
                    "--mass-kg", "3", "-L", "1.5", "-D", "0.5", "--seed", str(seed),
                    "--amplitude-deg", "%.3f" % amplitude, "--duration-s", str(duration),
                    "--force"], check=True, stdout=subprocess.DEVNULL)


def fit(bifilar, config, logs):
    out = subprocess.run([bifilar, "fit", config] + logs + ["--repeats", "--json"],
                         check=False, stdout=subprocess.PIPE)
    return json.loads(out.stdout)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--bifilar", default="build/bifilar")
    p.add_argument("--groups", type=int, default=100)
    p.add_argument("--pairs", type=int, default=0)
    p.add_argument("--duration", type=float, default=30.0)
    p.add_argument("--data", default="")
    a = p.parse_args()
    rng = random.Random(26)
    with tempfile.TemporaryDirectory(prefix="setups_survey_") as tmp:
        config = os.path.join(tmp, "fit.yaml")
        with open(config, "w") as f:
            f.write(FIT_CONFIG)
        logs = []
        for g in range(a.groups):
            inertia = rng.uniform(0.05, 0.2)
            for k in range(1, 5):
                path = os.path.join(tmp, "ideal%03d_%d.csv" % (g, k))
                simulate(a.bifilar, path, inertia, 100000 + 10 * g + k, rng.uniform(10, 25),
                         a.duration)
                logs.append(path)
        for g in range(a.pairs):
            inertia = rng.uniform(0.05, 0.2)
            for k in range(1, 5):
                path = os.path.join(tmp, "pair%03d_%d.csv" % (g, k))
                simulate(a.bifilar, path, inertia * (1.1 if k > 2 else 1.0),
                         200000 + 10 * g + k, rng.uniform(10, 25), a.duration)
                logs.append(path)
        result = fit(a.bifilar, config, logs)
        false_two = found = tested = 0
        for group in result["repeats"]:
            two = group["setups"]["two_setups"]
            tested += group["setups"]["tested"]
            if "/ideal" in group["name"]:
                false_two += two
            else:
                found += two
        print("ideal groups: %d, tested (Q p < 0.001): %d, called two set-ups: %d"
              % (a.groups, sum(g["setups"]["tested"] for g in result["repeats"] if "/ideal" in g["name"]), false_two))
        if a.pairs:
            print("pairs of hangings 10 %% apart: %d, called two set-ups: %d" % (a.pairs, found))
        if a.data:
            crazy = os.path.join(a.data, "crazyflie")
            total = 0
            for airframe, mass in (("BaseModel", "0.0343"), ("NarrowMedium", "0.0381")):
                cfg = os.path.join(tmp, airframe + ".yaml")
                with open(cfg, "w") as f:
                    f.write(CRAZYFLIE_CONFIG % mass)
                crazy_logs = sorted(os.path.join(crazy, n) for n in os.listdir(crazy)
                                    if n.startswith(airframe + "_") and n.endswith(".csv"))
                groups = fit(a.bifilar, cfg, crazy_logs)["repeats"]
                total += sum(g["setups"]["two_setups"] for g in groups)
                print("%s: %d logs in %d groups, called two set-ups: %d"
                      % (airframe, len(crazy_logs), len(groups),
                         sum(g["setups"]["two_setups"] for g in groups)))
            false_two += total
    return 1 if false_two else 0


if __name__ == "__main__":
    sys.exit(main())
