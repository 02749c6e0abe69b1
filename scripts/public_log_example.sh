#!/usr/bin/env bash
# The second worked example of docs/log-import.md, command for command, on a public log nobody
# here made (datasets/f1tenth: 41 three-second trials of an F1tenth car, a folder per trial with
# headerless CSVs and no time column, no terrain): raw files -> sample set -> tune with its
# defaults -> the two command lines tune prints (cross-validation, model) run as printed -> heat
# maps -> a sim2real comparison of two recording runs (locate only: no simulator config).
# Run by ctest (public_log_example); it fails on any error, so the doc cannot go stale.
# Usage: scripts/public_log_example.sh [out-dir]   (dgmm from $DGMM, else build/app/dgmm;
#        rendering needs $DISPLAY or xvfb-run)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
dgmm=${DGMM:-$root/build/app/dgmm}
out=${1:-$root/out/public-log}
mkdir -p "$out"
cd "$root"
data=datasets/f1tenth
SECONDS=0
stamp() { printf 'public_log_example: %s done at %d s\n' "$1" "$SECONDS"; }

# 1. One sample per 1 s window of each command, every trial its own episode.
"$dgmm" import-log \
  --commands "$data/measurement_*/input.csv" --command-cols 1,2 \
  --pose "$data/measurement_*/trajectory.csv" --pose-cols 1,2,3 \
  --no-header --rate 40 --window 1 -o "$out/car.h5"
stamp import

# 2. Tune with the defaults; the last two lines are the commands to run next.
"$dgmm" tune "$out/car.h5" --plot "$out/tune_k.png" | tee "$out/tune.txt"
stamp tune
fit=$(sed -n 's/^fit with: dgmm //p' "$out/tune.txt")
cv=$(sed -n 's/^cross-validate with: dgmm //p' "$out/tune.txt")
[ -n "$fit" ] && [ -n "$cv" ] || { echo "public_log_example: tune printed no recipe" >&2; exit 1; }

# 3. Run them as printed (the model goes to $out instead of ./model.h5).
# shellcheck disable=SC2086  # the printed lines are split into words, as a shell would
"$dgmm" $cv | tee "$out/cv.txt"
# shellcheck disable=SC2086
"$dgmm" ${fit% -o model.h5} -o "$out/car_dgmm.h5"
stamp "cv and fit"

# 4. p(dx, dy | command) for the straight and the sharpest left command at 0.4 m/s.
for command in 0,0.4 0.2,0.4; do
  "$dgmm" render "$out/car_dgmm.h5" --command "$command" --x-dim dx --y-dim dy --marginalise \
    --data "$out/car.h5" --size 640x520 -o "$out/heat_$command.png"
done
stamp render

# 5. Two recording runs of the protocol: steering held for the whole trial, and switched every
#    second. Where do their 1 s pose changes differ?
"$dgmm" import-log \
  --commands "$data/measurement_{[1-5],1[2-6],2[3-7]}/input.csv" --command-cols 1,2 \
  --pose "$data/measurement_{[1-5],1[2-6],2[3-7]}/trajectory.csv" --pose-cols 1,2,3 \
  --no-header --rate 40 --window 1 -o "$out/held.h5"
"$dgmm" import-log \
  --commands "$data/measurement_{[6-9],1[01],1[7-9],2[0-2],2[89],3[0-3]}/input.csv" \
  --command-cols 1,2 \
  --pose "$data/measurement_{[6-9],1[01],1[7-9],2[0-2],2[89],3[0-3]}/trajectory.csv" \
  --pose-cols 1,2,3 --no-header --rate 40 --window 1 -o "$out/switched.h5"
"$dgmm" sim2real --sim "$out/held.h5" --real "$out/switched.h5" -o "$out/held_vs_switched" --seed 1
stamp sim2real
