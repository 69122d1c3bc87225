#!/bin/sh
# Monte-Carlo check of `bifilar plan --rig` (issue 27): for the two worked examples of
# docs/guide.md ("Designing a rig"), simulate N swings (default 200) on the recommended rig with
# the stated gyro noise and with L, D and the mass drawn from their stds, fit each with the trace
# fit (the nominal L, D, m configured), and compare the scatter of I with the predicted std of one
# swing. Prints one line per example; exits 1 when a ratio lies outside [0.85, 1.15].
#   scripts/rig_plan_mc.sh [BIFILAR] [N]
set -eu
BIFILAR=${1:-build/bifilar}
N=${2:-200}
status=0
run() {
  name=$1
  shift
  line=$("$BIFILAR" plan --rig "$@" --monte-carlo "$N" | grep 'Monte-Carlo:')
  echo "$name: $line"
  ratio=$(echo "$line" | sed -n 's/.*ratio \([0-9.]*\)).*/\1/p')
  if ! awk -v r="$ratio" 'BEGIN { exit !(r >= 0.85 && r <= 1.15) }'; then status=1; fi
}
# The 34 g quadrotor of the public logs: L 0.594 m, D 0.030 m at most, tape +-0.5 mm, 30 Hz.
run quadrotor --mass 0.0343 --inertia 1.6e-5 --inertia-max 2.9e-5 --max-length 0.594 \
  --max-separation 0.030 --length-std 0.0005 --separation-std 0.0005 --target-percent 1 \
  --imu-rate 30
# A 3.3 kg fixed-wing (3.24 kg + 0.1 kg cradle, I 0.05 kg m^2) under a 2.5 m ceiling.
run fixed-wing --mass 3.24 --cradle-mass 0.1 --inertia 0.05 --max-length 2.5 \
  --max-separation 0.6 --length-std 0.001 --separation-std 0.001 --target-percent 1 \
  --imu-rate 50 --gyro-noise 0.3
exit $status
