#!/bin/bash
# Glitch samples dropped by `bifilar fit` (docs/method.md section 1, "Short runs"): on real
# Crazyflie logs, if a folder of them is given, and on the simulator's presets at seeds 1-6
# (quadrotor without and with its one 5 rad/s spike, the non-ideal fixed-wing rig) and the sample
# campaign's spec. Prints one line per data set: logs, logs not ok, glitch samples dropped.
#   scripts/glitch_survey.sh build/bifilar [CRAZYFLIE_DIR]
set -euo pipefail
B=$(realpath "$1"); DATA=${2:-}
SRC=$(cd "$(dirname "$0")/.." && pwd); W=$(mktemp -d); trap 'rm -rf "$W"' EXIT
quad_fit() {
  printf 'gravity_mps2: 9.8066\nrig: {filar_length_m: 0.594, filar_separation_m: 0.030, mass_kg: %s}\nimu:\n  time: {column: t, unit: s}\n  gyro: {columns: [wx, wy, wz], unit: rad/s}\n  accel: null\n' "$1"
}
quad_fit 0.0343 > "$W/quad.yaml"; quad_fit 0.0381 > "$W/narrow.yaml"
printf 'rig: {filar_length_m: 0.74, filar_separation_m: 0.16, mass_kg: 3.34}\nimu:\n  time: {column: t, unit: ms}\n  gyro: {columns: [gx, gy, gz], unit: deg/s}\n  accel: null\n' > "$W/nonideal.yaml"
count() {  # count SET CONFIG LOG...: status and glitch samples of each log -> one summary line
  local set=$1 config=$2; shift 2
  for log in "$@"; do
    "$B" fit "$config" "$log" --json 2>/dev/null || true
  done | python3 -c '
import json, re, sys
text = sys.stdin.read()
decoder, i, logs, bad, dropped = json.JSONDecoder(), 0, 0, 0, 0
while i < len(text):
    if text[i].isspace(): i += 1; continue
    records, i = decoder.raw_decode(text, i)
    for r in records:
        logs += 1; bad += r["status"] != "ok"
        dropped += sum(int(re.match(r"\d+", w).group()) for w in r["warnings"] if "glitch sample" in w)
print(f"{sys.argv[1]}: {logs} logs, {bad} not ok, {dropped} glitch samples dropped")' "$set"
}
if [ -n "$DATA" ]; then
  count "crazyflie BaseModel" "$W/quad.yaml" "$DATA"/BaseModel_*.csv
  count "crazyflie NarrowMedium" "$W/narrow.yaml" "$DATA"/NarrowMedium_*.csv
fi
sed 's/spike_count: 1 /spike_count: 0 /' "$SRC/configs/simulate_quadrotor.yaml" > "$W/quad_clean.yaml"
for seed in 1 2 3 4 5 6; do
  "$B" simulate "$W/quad_clean.yaml" --out "$W/quadclean_$seed" --seed $seed > /dev/null
  "$B" simulate "$SRC/configs/simulate_quadrotor.yaml" --out "$W/quadspike_$seed" --seed $seed > /dev/null
  "$B" simulate "$SRC/configs/simulate_nonideal_rig.yaml" --out "$W/nonideal_$seed" --seed $seed > /dev/null
done
"$B" simulate "$SRC/configs/simulate_prandtl_d.yaml" --out "$W/prandtl" --seed 1 > /dev/null
count "quadrotor, no spike" "$W/quad.yaml" $(find "$W"/quadclean_* -name 'trial_*.csv' | sort)
count "quadrotor, one 5 rad/s spike" "$W/quad.yaml" $(find "$W"/quadspike_* -name 'trial_*.csv' | sort)
count "non-ideal fixed-wing" "$W/nonideal.yaml" $(find "$W"/nonideal_* -name 'trial_*.csv' | sort)
count "sample spec (prandtl_d)" "$SRC/configs/prandtl_d.yaml" $(find "$W/prandtl" -name 'trial_*.csv*' | sort)
