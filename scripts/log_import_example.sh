#!/usr/bin/env bash
# The worked example of docs/log-import.md, command for command: raw multi-rate CSV logs
# (datasets/logs/) -> HDF5 sample set -> k tuned by cross-validation -> cross-validation table ->
# model -> one heat map per command. No Python. Run by ctest (log_import_example).
# Usage: scripts/log_import_example.sh [out-dir]   (dgmm from $DGMM, else build/app/dgmm;
#        rendering needs $DISPLAY or xvfb-run)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
dgmm=${DGMM:-$root/build/app/dgmm}
out=${1:-$root/out/log-example}
mkdir -p "$out"
cd "$root"

# 1. Join the three streams by time into samples: one per 1.5 s window inside each command.
"$dgmm" import-log \
  --commands datasets/logs/commands.csv --command-cols mode \
  --pose datasets/logs/pose.csv --pose-cols x_mm,y_mm,yaw_deg \
  --attitude datasets/logs/imu.csv --attitude-time t_ms --terrain-cols pitch_deg,roll_deg \
  --units x_mm=mm,y_mm=mm,yaw_deg=deg,t_ms=ms,pitch_deg=deg,roll_deg=deg \
  --window 1.5 --drop-invalid -o "$out/walk.h5"
"$dgmm" info "$out/walk.h5"

# 2. k, the S0 scale and the prior strength with the best cross-validated held-out
#    log-likelihood; tune's last two lines are the commands to run next.
"$dgmm" tune "$out/walk.h5" --folds 5 --repeats 2 --seed 1 | tee "$out/tune.txt"
fit=$(sed -n 's/^fit with: dgmm //p' "$out/tune.txt")
cv=$(sed -n 's/^cross-validate with: dgmm //p' "$out/tune.txt")
[ -n "$fit" ] && [ -n "$cv" ] || { echo "log_import_example: tune printed no recipe" >&2; exit 1; }

# 3. Cross-validation at those settings (DGMM and EM-BIC, with and without terrain), as printed.
# shellcheck disable=SC2086  # the printed line is split into words, as a shell would
"$dgmm" $cv | tee "$out/cv.txt"

# 4. The model (as printed, written to $out), and a heat map of p(dx, dy | command) per command
#    with the samples on top.
# shellcheck disable=SC2086
"$dgmm" ${fit% -o model.h5} -o "$out/walk_dgmm.h5"
for command in forward back left right turn_left turn_right stop; do
  "$dgmm" render "$out/walk_dgmm.h5" --command "$command" --x-dim dx --y-dim dy --marginalise \
    --data "$out/walk.h5" --size 640x520 -o "$out/heat_$command.png"
done
