#!/usr/bin/env bash
# Simulation throughput on rough ground against the plane (issue #23: within 2x): the built-in
# octopod records the paper protocol on its plane (datasets/robots/default.json) and on the
# height field of a rough-ground config (default datasets/robots/rough_ground.json), alternating,
# REPS runs each (default 5); prints the median simulated seconds per CPU second and the ratio.
# Usage: scripts/bench_terrain.sh [build-dir] [reps] [rough-config]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
reps=${2:-5}
rough=${3:-$root/datasets/robots/rough_ground.json}
dgmm="$build/app/dgmm"
[ -x "$dgmm" ] || { echo "bench_terrain: $dgmm not built" >&2; exit 1; }
[ -f "$rough" ] || { echo "bench_terrain: $rough: no such config" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for i in $(seq "$reps"); do
  "$dgmm" --quiet simulate --config "$root/datasets/robots/default.json" --protocol paper --seed 390 \
    -o "$tmp/plane.h5" --json > "$tmp/plane.$i.json"
  "$dgmm" --quiet simulate --config "$rough" --protocol paper --seed 390 -o "$tmp/rough.h5" --json > "$tmp/rough.$i.json"
done
/usr/bin/python3 - "$tmp" "$reps" "$rough" <<'PY'
import json, statistics, sys
tmp, reps, rough = sys.argv[1], int(sys.argv[2]), sys.argv[3]
rate = {}
for which in ("plane", "rough"):
    runs = [json.load(open(f"{tmp}/{which}.{i}.json")) for i in range(1, reps + 1)]
    rate[which] = statistics.median(r["simulated_seconds"] / r["cpu_seconds"] for r in runs)
print(f"plane (default.json):   {rate['plane']:.1f} simulated s per CPU s (median of {reps})")
print(f"rough ({rough.split('/')[-1]}): {rate['rough']:.1f} simulated s per CPU s")
print(f"rough / plane: {rate['rough'] / rate['plane']:.2f} (issue #23: at least 0.50)")
PY
