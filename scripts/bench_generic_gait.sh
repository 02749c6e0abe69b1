#!/usr/bin/env bash
# Throughput of the generic gait (numerical inverse kinematics, lib/sim/generic_walker.cc) against
# the built-in closed-form gait on the same robot: the built-in octopod (datasets/robots/scorpion.xml)
# recorded with the paper protocol through datasets/robots/default.json (closed form) and through
# datasets/robots/scorpion_generic.json (a robot block: the generic gait). Runs alternate, REPS
# each (default 5); prints the median simulated seconds per CPU second of each and their ratio.
# Usage: scripts/bench_generic_gait.sh [build-dir] [reps]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
reps=${2:-5}
dgmm="$build/app/dgmm"
[ -x "$dgmm" ] || { echo "bench_generic_gait: $dgmm not built" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for i in $(seq "$reps"); do
  for which in default scorpion_generic; do
    "$dgmm" --quiet simulate --config "$root/datasets/robots/$which.json" --protocol paper --seed 390 \
      -o "$tmp/$which.h5" --json > "$tmp/$which.$i.json"
  done
done
/usr/bin/python3 - "$tmp" "$reps" <<'PY'
import json, statistics, sys
tmp, reps = sys.argv[1], int(sys.argv[2])
rate = {}
for which in ("default", "scorpion_generic"):
    runs = [json.load(open(f"{tmp}/{which}.{i}.json")) for i in range(1, reps + 1)]
    rate[which] = statistics.median(r["simulated_seconds"] / r["cpu_seconds"] for r in runs)
print(f"closed-form gait (default.json):        {rate['default']:.1f} simulated s per CPU s (median of {reps})")
print(f"generic gait (scorpion_generic.json):   {rate['scorpion_generic']:.1f} simulated s per CPU s")
print(f"generic / closed form: {rate['scorpion_generic'] / rate['default']:.2f} (the target: at least 0.80)")
PY
