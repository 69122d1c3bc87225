#!/usr/bin/env bash
# Survey of issue 32's numbers (not a test: minutes). For N seeds each, simulates and processes
#   other-rig three-axis and tensor campaigns (configs/simulate_*_other_rig.yaml): the share marked
#     not physical with the right attitude named (roll 0, pitch 0);
#   healthy three-axis and tensor campaigns (configs/simulate_three_axes.yaml, simulate_tensor.yaml):
#     the share flagged not physical;
#   three-axis campaigns with the y-axis logs scattered by 1 % (simulate_three_axes_scatter.yaml):
#     the 95 % interval coverage of I_xx and I_zz (the components the y swings do not touch), and
#     of I_yy; processed with the rig's inertia drawn from its stated std (every stated error
#     realised, as coverage needs).
# Usage: scripts/physical_survey.sh [N=200] [BIFILAR=build/bifilar] [WORK=/tmp/bifilar_physical_survey]
set -euo pipefail
n=${1:-200}
bifilar=$(realpath "${2:-build/bifilar}")
work=${3:-/tmp/bifilar_physical_survey}
here=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$work"
run() {  # kind spec seed
  local kind=$1 spec=$2 seed=$3 dir="$work/$1_$3"
  rm -rf "$dir" && mkdir -p "$dir"
  sed "s/^seed: .*/seed: $seed/" "$here/configs/$spec" > "$dir/spec.yaml"
  "$bifilar" simulate "$dir/spec.yaml" --out "$dir/logs" > /dev/null
  local rc=0 config="$here/configs/tensor_uav.yaml"
  if [[ $kind == scatter_three ]]; then
    # Coverage needs every stated error realised: the config's rig inertia (0.02 +- 0.0001 kg m^2)
    # is drawn from its std, as a real rig's measured inertia is off by a draw of it.
    local drawn
    drawn=$(python3 -c "import random; random.seed($seed * 7919); print('%.8f' % (0.02 + random.gauss(0, 1e-4)))")
    sed "s/inertia: {inertia_kg_m2: 0.02,/inertia: {inertia_kg_m2: $drawn,/" "$config" > "$dir/config.yaml"
    config="$dir/config.yaml"
  fi
  "$bifilar" process "$config" --runs-root "$dir/logs" --out "$dir/out" \
    --jobs 1 > "$dir/console.txt" 2>&1 || rc=$?
  python3 - "$kind" "$seed" "$rc" "$dir/out/results.json" <<'PY' >> "$work/rows.txt"
import json, sys
kind, seed, rc, path = sys.argv[1:5]
j = json.load(open(path))
p = j.get("physical") or {}
t = j.get("tensor") or {}
truth = {"Ixx": 0.2, "Iyy": 0.3, "Izz": 0.45}
cover = []
for k in ("Ixx", "Iyy", "Izz"):
    ci = t.get(k + "_kg_m2_ci95")
    cover.append("nan" if not ci else str(int(ci[0] <= truth[k] <= ci[1])))
w = p.get("worst") or {}
print(kind, seed, rc, p.get("status", "none"), p.get("attitude", "").replace(" ", "_") or "-",
      w.get("z"), *cover)
PY
  rm -rf "$dir/logs" "$dir/out/cache" "$dir/out/figures"
}
: > "$work/rows.txt"
for seed in $(seq 1 "$n"); do
  run other_three simulate_three_axes_other_rig.yaml "$seed"
  run other_tensor simulate_tensor_other_rig.yaml "$seed"
  run healthy_three simulate_three_axes.yaml "$seed"
  run healthy_tensor simulate_tensor.yaml "$seed"
  run scatter_three simulate_three_axes_scatter.yaml "$seed"
done
python3 - "$work/rows.txt" <<'PY'
import sys, collections
rows = [l.split() for l in open(sys.argv[1])]
by = collections.defaultdict(list)
for r in rows: by[r[0]].append(r)
for kind in ("other_three", "other_tensor"):
    rs = by[kind]
    hit = sum(1 for r in rs if r[3] == "not_physical" and r[4] == "roll_0,_pitch_0_deg")
    flagged = sum(1 for r in rs if r[3] == "not_physical")
    print(f"{kind}: {len(rs)} campaigns, not physical {flagged}, of them with roll 0, pitch 0 named {hit} ({100*hit/max(1,len(rs)):.1f} %)")
for kind in ("healthy_three", "healthy_tensor"):
    rs = by[kind]
    flagged = sum(1 for r in rs if r[3] == "not_physical")
    border = sum(1 for r in rs if r[3] == "borderline")
    print(f"{kind}: {len(rs)} campaigns, flagged not physical {flagged} ({100*flagged/max(1,len(rs)):.1f} %), borderline {border}")
rs = by["scatter_three"]
for i, k in enumerate(("Ixx", "Iyy", "Izz")):
    c = [r[-3 + i] for r in rs if r[-3 + i] != "nan"]
    print(f"scatter_three {k}: 95 % interval covers the truth in {sum(map(int, c))} of {len(c)} ({100*sum(map(int, c))/max(1,len(c)):.1f} %)")
PY
