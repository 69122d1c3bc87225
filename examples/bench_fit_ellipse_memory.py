#!/usr/bin/env python3
"""Peak memory of fit_ellipse on N points, against `bifilar ellipse` on the same table (issue 15).

    PYTHONPATH=build/python python3 examples/bench_fit_ellipse_memory.py [--points 1e6]
        [--bootstrap 0] [--binary build/bifilar]

Each side runs in its own child process; its peak resident set comes from wait4: the
Python child imports numpy and bifilar, builds N moments at uniform random pitch (seed 1) and
calls fit_ellipse; a baseline child does the same without the call, so "fit_ellipse adds" is
the memory of the call itself. The CLI reads the same points from a CSV table.
"""
import argparse
import os
import subprocess
import sys
import tempfile

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--points", type=float, default=1e6, help="points (default 1e6)")
parser.add_argument("--bootstrap", type=int, default=0, help="replicates (default 0)")
parser.add_argument("--binary", default="build/bifilar", help="the CLI (default build/bifilar)")
parser.add_argument("--child", choices=["fit", "baseline"], help=argparse.SUPPRESS)
parser.add_argument("--table", help=argparse.SUPPRESS)
args = parser.parse_args()
n = int(args.points)

if args.child or args.table:
    import numpy as np

    rng = np.random.default_rng(1)
    pitch = rng.uniform(-90, 90, n)
    theta = np.radians(pitch)
    inertia = (4.0 * np.cos(theta) ** 2 + 2.0 * np.sin(theta) ** 2 + 0.1 * np.sin(2 * theta)
               + rng.normal(0, 0.01, n))
    if args.table:
        np.savetxt(args.table, np.column_stack([pitch, inertia]), delimiter=",", fmt="%.9g",
                   header="pitch_deg,inertia", comments="")
        sys.exit(0)
    if args.child == "fit":
        import bifilar

        result = bifilar.fit_ellipse(pitch, inertia, bootstrap=args.bootstrap)
        assert len(result.residuals) == n
    else:
        import bifilar  # noqa: F401  (the same imports as the fit child)
    sys.exit(0)


def peak_kb(argv):
    """Runs argv; its own peak resident set (kB), from wait4."""
    process = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(process.pid, 0)
    process.returncode = os.waitstatus_to_exitcode(status)
    if process.returncode != 0:
        sys.exit(f"{argv[:3]} failed: {process.stderr.read().decode()}")
    return usage.ru_maxrss


me = [sys.executable, __file__, "--points", str(n), "--bootstrap", str(args.bootstrap)]
baseline_kb = peak_kb(me + ["--child", "baseline"])
fit_kb = peak_kb(me + ["--child", "fit"])
with tempfile.TemporaryDirectory() as folder:
    table = os.path.join(folder, "moments.csv")
    peak_kb(me + ["--table", table])
    cli_kb = peak_kb([args.binary, "ellipse", table, "--bootstrap", str(args.bootstrap)])
print(f"{n} points, bootstrap {args.bootstrap}:")
print(f"  python: fit_ellipse adds {(fit_kb - baseline_kb) / 1024:.0f} MB "
      f"({(fit_kb - baseline_kb) * 1024 / n:.0f} bytes/point; process peak {fit_kb / 1024:.0f} MB, "
      f"of which numpy and the arrays {baseline_kb / 1024:.0f} MB)")
print(f"  bifilar ellipse: peak {cli_kb / 1024:.0f} MB ({cli_kb * 1024 / n:.0f} bytes/point)")
