#!/usr/bin/env bash
# The main job: installs what is missing, builds, and processes the sample campaign
# sample_runs/prandtl_d/ with configs/prandtl_d.yaml, writing into sample_runs/prandtl_d/out/
# (simulating the logs first when they are missing).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
"$here/scripts/setup.sh" "$here/build"
# The logs (about 20 MB) are not committed: the simulator regenerates them, byte for byte, from
# the seeded spec in about a second.
if [ ! -f "$here/sample_runs/prandtl_d/logs/truth.json" ]; then
  "$here/build/bifilar" simulate "$here/configs/simulate_prandtl_d.yaml" --out "$here/sample_runs/prandtl_d/logs"
fi
"$here/build/bifilar" process "$here/configs/prandtl_d.yaml" --out "$here/sample_runs/prandtl_d/out" "$@"
