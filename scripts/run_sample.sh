#!/usr/bin/env bash
# The main job: installs what is missing, builds the program (the `bifilar` target, and the
# Python module bifilar_python; the tests are scripts/test.sh's), and processes the sample campaign
# sample_runs/prandtl_d/logs/ with configs/prandtl_d.yaml, writing into out/prandtl_d/ (ignored
# by git). The committed outputs in sample_runs/prandtl_d/out/ are left as they are, so running
# this leaves the checkout unmodified; tests/pipeline_small_things_test.cc checks that they still
# hold the numbers the code computes.
# Extra arguments go to `bifilar process` (for example --force or --jobs 1).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="$here/out/prandtl_d"
"$here/scripts/setup.sh" "$here/build" bifilar
# The Python module too (README "Python": PYTHONPATH=build/python), when CMake configured it
# (pybind11, python3-dev and numpy found): its one unity source costs ~14 CPU-s over the
# program's ~166, as the libraries are already built position-independent.
help="$(cmake --build "$here/build" --target help 2>/dev/null || true)"
if grep -q bifilar_python <<< "$help"; then
  cmake --build "$here/build" -j"$(nproc)" --target bifilar_python
else
  echo "run_sample: the Python module is not configured (needs pybind11-dev, python3-dev and" \
       "python3-numpy); the command line works without it"
fi
"$here/build/bifilar" process "$here/configs/prandtl_d.yaml" --out "$out" "$@"
echo "run_sample: open $out/report.html (committed copy: sample_runs/prandtl_d/out/report.html)"
