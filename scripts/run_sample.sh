#!/usr/bin/env bash
# The main job: installs what is missing, builds the program (only the `bifilar` target: the
# tests are scripts/test.sh's), and processes the sample campaign
# sample_runs/prandtl_d/logs/ with configs/prandtl_d.yaml, writing into out/prandtl_d/ (ignored
# by git). The committed outputs in sample_runs/prandtl_d/out/ are left as they are, so running
# this leaves the checkout unmodified; tests/pipeline_small_things_test.cc checks that they still
# hold the numbers the code computes.
# Extra arguments go to `bifilar process` (for example --force or --jobs 1).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="$here/out/prandtl_d"
"$here/scripts/setup.sh" "$here/build" bifilar
"$here/build/bifilar" process "$here/configs/prandtl_d.yaml" --out "$out" "$@"
echo "run_sample: open $out/report.html (committed copy: sample_runs/prandtl_d/out/report.html)"
