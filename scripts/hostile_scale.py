#!/usr/bin/env python3
"""Time and memory of `bifilar fit --repeats` on hostile sizes (issue 33 items 3 and 4).

Not a test: speed goes here, not into the suite. Each case runs the real binary and reports the
wall time and the peak resident memory of the child (getrusage):

  same-size   N logs of the same size, each a different swing (one digit changed): the time
              until the groups are printed (the duplicate scan and the grouping, before any
              fit); the run is stopped there.
  runs-table  a --runs-table of 4 million rows (96 MB), one of one 50 MB line, and the largest
              accepted (100,000 rows): refused or read, and how fast.
  group-by    the --group-by patterns of the issue (100 kB, 20,000 nested groups, '/((.|/)*)x'
              on a 16 kB path, '(a+)+$' on 28 a's and a b): the time to the answer.

    scripts/hostile_scale.py --bifilar build/bifilar [--logs 1000]
"""
import argparse
import os
import subprocess
import sys
import tempfile
import time

CONFIG = """rig: {filar_length_m: 1.5, filar_separation_m: 0.5, mass_kg: 3}
imu:
  time: {column: t, unit: s}
  gyro: {columns: [gx, gy, gz], unit: rad/s}
"""


def vm_hwm_mb(pid):
    """Peak resident memory (MB) of a running process, from /proc (nan when unreadable)."""
    try:
        with open(f"/proc/{pid}/status", encoding="utf-8") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return float("nan")


def run_until(argv, marker):
    """Runs argv; returns (seconds until a stdout line holds `marker` or the end, exit code or
    None when stopped at the marker, peak resident memory in MB, the output's last line)."""
    start = time.monotonic()
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            errors="replace")
    last = ""
    for line in proc.stdout:
        last = line.strip()
        if marker and marker in line:
            seconds = time.monotonic() - start
            peak = vm_hwm_mb(proc.pid)
            proc.kill()
            proc.wait()
            return seconds, None, peak, last[:160]
    _, status, usage = os.wait4(proc.pid, 0)
    seconds = time.monotonic() - start
    proc.returncode = os.waitstatus_to_exitcode(status)
    return seconds, proc.returncode, usage.ru_maxrss / 1024.0, last[:160]


def same_size_logs(bifilar, folder, n):
    log = os.path.join(folder, "swing.csv")
    subprocess.run([bifilar, "simulate", "--trace", log, "--inertia-kg-m2", "0.1", "--mass-kg",
                    "3", "-L", "1.5", "-D", "0.5", "--duration-s", "20", "--seed", "33"],
                   check=True, stdout=subprocess.DEVNULL)
    lines = open(log, encoding="utf-8").read().split("\n")
    first_data = next(i for i, l in enumerate(lines) if l and l[0].isdigit())
    paths = []
    for k in range(n):
        copy = list(lines)
        row = copy[first_data + 1 + k % 500].split(",")
        digit = row[1][-1]
        row[1] = row[1][:-1] + str((int(digit) + 1 + k // 500) % 10) if digit.isdigit() else row[1]
        copy[first_data + 1 + k % 500] = ",".join(row)
        path = os.path.join(folder, f"swing-{k + 1}.csv")
        with open(path, "w", encoding="utf-8") as f:
            f.write("\n".join(copy))
        paths.append(path)
    sizes = {os.path.getsize(p) for p in paths}
    return paths, len(sizes)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--bifilar", required=True)
    parser.add_argument("--logs", type=int, default=1000)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="bifilar_scale_") as folder:
        config = os.path.join(folder, "c.yaml")
        with open(config, "w", encoding="utf-8") as f:
            f.write(CONFIG)
        paths, n_sizes = same_size_logs(args.bifilar, folder, args.logs)
        seconds, _, peak, _ = run_until([args.bifilar, "fit", config, *paths, "--repeats"],
                                        "repeats:")
        print(f"same-size: {len(paths)} logs ({n_sizes} size(s)) grouped in {seconds:.2f} s, "
              f"peak {peak:.0f} MB")

        table = os.path.join(folder, "runs.csv")
        with open(table, "w", encoding="utf-8") as f:
            f.write("path,group\n")
            for block in range(40):
                f.write("".join(f"logs/run_{block:02d}{k:05d}.csv,g{k % 9}\n"
                                for k in range(100000)))
        line = os.path.join(folder, "line.csv")
        with open(line, "w", encoding="utf-8") as f:  # in 1 MB pieces: this script stays small
            f.write("path,group\n")
            for _ in range(50):
                f.write("x" * 1_000_000)
            f.write(",A\n")
        largest = os.path.join(folder, "largest.csv")  # the most rows accepted
        with open(largest, "w", encoding="utf-8") as f:
            f.write("path,group\n" + "".join(f"logs/run_{k:07d}.csv,-0\n" for k in range(99998)))
            f.write(f"{os.path.basename(paths[0])},0\n{os.path.basename(paths[1])},-0\n")
        for name, path in (("4-million-row table", table), ("50 MB one-line table", line),
                           ("100,000-row table", largest)):
            seconds, code, peak, last = run_until(
                [args.bifilar, "fit", config, paths[0], paths[1], "--repeats", "--runs-table",
                 path], "repeats:")
            size_mb = os.path.getsize(path) / 1e6
            print(f"runs-table: {name} ({size_mb:.0f} MB): "
                  f"{'read' if code is None else f'exit {code}'} in {seconds:.2f} s, "
                  f"peak {peak:.0f} MB: {last}")

        deep = "/" + "a/" * 8000
        cases = [("100 kB pattern", "a" * 100000, paths[:2]),
                 ("20,000 nested groups", "(" * 20000 + "a" + ")" * 20000, paths[:2]),
                 ("'/((.|/)*)x' on a 16 kB path", "/((.|/)*)x",
                  [deep + "swing-1.csv", deep + "swing-2.csv"]),
                 ("'(a+)+$' on 28 a's and a b", "(a+)+$",
                  [os.path.join(folder, "a" * 28 + "b"), os.path.join(folder, "a" * 28 + "ab")])]
        for name, pattern, logs in cases:
            seconds, code, _, last = run_until(
                [args.bifilar, "fit", config, *logs, "--repeats", "--group-by", pattern],
                "repeats:")
            print(f"group-by: {name}: {'grouped' if code is None else f'exit {code}'} in "
                  f"{seconds:.2f} s: {last}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
