#!/usr/bin/env bash
# The main job: installs what is missing, builds, and processes the sample campaign
# sample_runs/prandtl_d/logs/ with configs/prandtl_d.yaml, writing into sample_runs/prandtl_d/out/.
# Extra arguments go to `bifilar process` (for example --force or --jobs 1).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
"$here/scripts/setup.sh" "$here/build"
"$here/build/bifilar" process "$here/configs/prandtl_d.yaml" --out "$here/sample_runs/prandtl_d/out" "$@"
