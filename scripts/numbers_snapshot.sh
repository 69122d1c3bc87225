#!/usr/bin/env bash
# Writes the numbers that a refactoring must not change into DIR, so that two builds can be
# compared with scripts/compare_numbers.py (issue 36: "equal to 1e-12 relative before and after"):
#   DIR/sample/results.json   the sample campaign (configs/prandtl_d.yaml), from scratch (no cache)
#   DIR/tensor/results.json   a simulated tensor campaign (configs/simulate_tensor.yaml)
#   DIR/crazyflie_*/results.json  the 24 quadrotor records, when the real logs exist (DATA_DIR)
# Usage: scripts/numbers_snapshot.sh BIFILAR DIR [DATA_DIR]
set -euo pipefail
bin="$(realpath "$1")"; out="$(realpath -m "$2")"; data="${3:-}"
here="$(cd "$(dirname "$0")/.." && pwd)"
mkdir -p "$out"
cd "$here"
"$bin" process configs/prandtl_d.yaml --out "$out/sample" --force >/dev/null 2>&1 || true
rm -rf "$out/tensor_logs"
"$bin" simulate configs/simulate_tensor.yaml --out "$out/tensor_logs" >/dev/null
"$bin" process configs/tensor_uav.yaml --runs-root "$out/tensor_logs" --out "$out/tensor" --force \
  >/dev/null 2>&1 || true
if [[ -n "$data" && -d "$data/crazyflie" ]]; then
  for airframe in basemodel narrowmedium; do
    "$bin" process "configs/crazyflie_$airframe.yaml" --runs-root "$data/crazyflie" \
      --out "$out/crazyflie_$airframe" --force >/dev/null 2>&1 || true
  done
fi
echo "numbers_snapshot: wrote $out"
