#!/usr/bin/env python3
"""Compares two snapshots of scripts/numbers_snapshot.sh, number by number.

Every number in every results.json under A is compared with the same key in B at a relative
tolerance (default 1e-12; an absolute floor of 1e-300 for zeros). Keys that name the program,
its version, a time or a path are skipped. Prints each difference (key, A, B, relative) and a
count per file; exits 1 when a number differs beyond the tolerance or a key is missing.
Usage: scripts/compare_numbers.py A B [--rtol 1e-12] [--ignore REGEX ...]
"""
import argparse
import json
import math
import pathlib
import re
import sys

SKIP = re.compile(r"(^|\.)(program|version|build|elapsed\w*|cpu_seconds|fit_seconds|time_s|wall\w*|config_file|"
                  r"outputs|path|file|root|figures|cache\w*|created\w*)($|\.|\[)")


def walk(node, prefix=""):
    if isinstance(node, dict):
        for key, value in node.items():
            yield from walk(value, f"{prefix}.{key}" if prefix else key)
    elif isinstance(node, list):
        for index, value in enumerate(node):
            yield from walk(value, f"{prefix}[{index}]")
    else:
        yield prefix, node


def compare(a_path, b_path, rtol, ignore):
    a = dict(walk(json.loads(a_path.read_text())))
    b = dict(walk(json.loads(b_path.read_text())))
    differences = []
    for key, value in a.items():
        if SKIP.search(key) or any(pattern.search(key) for pattern in ignore):
            continue
        if key not in b:
            differences.append((key, value, "<missing>", math.inf))
            continue
        other = b[key]
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            if value != other:
                differences.append((key, value, other, math.inf))
            continue
        if not isinstance(other, (int, float)) or isinstance(other, bool):
            differences.append((key, value, other, math.inf))
            continue
        scale = max(abs(value), abs(other), 1e-300)
        relative = abs(value - other) / scale
        if relative > rtol:
            differences.append((key, value, other, relative))
    return len(a), differences


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("a")
    parser.add_argument("b")
    parser.add_argument("--rtol", type=float, default=1e-12)
    parser.add_argument("--ignore", action="append", default=[])
    args = parser.parse_args()
    ignore = [re.compile(pattern) for pattern in args.ignore]
    failed = False
    for a_file in sorted(pathlib.Path(args.a).glob("*/results.json")):
        b_file = pathlib.Path(args.b) / a_file.relative_to(args.a)
        if not b_file.exists():
            print(f"{b_file}: missing")
            failed = True
            continue
        count, differences = compare(a_file, b_file, args.rtol, ignore)
        name = a_file.parent.name
        print(f"{name}: {count} values, {len(differences)} differ beyond {args.rtol:g}")
        for key, value, other, relative in differences[:200]:
            print(f"  {key}: {value!r} -> {other!r} (relative {relative:.3g})")
        failed = failed or bool(differences)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
