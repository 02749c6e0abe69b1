#!/usr/bin/env bash
# Throughput of the generic gait (numerical inverse kinematics, lib/sim/generic_walker.cc) against
# the built-in closed-form gait on the same robot: the built-in octopod (datasets/robots/scorpion.xml)
# recorded with the paper protocol through datasets/robots/default.json (closed form) and through
# datasets/robots/scorpion_generic.json (a robot block: the generic gait), and the latter with the
# gait's servo feedforward (robot.gait.servo_feedforward). Runs alternate, REPS each (default 5);
# prints the median simulated seconds per CPU second of each and their ratios.
# Usage: scripts/bench_generic_gait.sh [build-dir] [reps]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
reps=${2:-5}
dgmm="$build/app/dgmm"
[ -x "$dgmm" ] || { echo "bench_generic_gait: $dgmm not built" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cp "$root/datasets/robots/default.json" "$root/datasets/robots/scorpion_generic.json" "$tmp/"
/usr/bin/python3 - "$root/datasets/robots" "$tmp" <<'PY'
import json, os, sys
robots, tmp = sys.argv[1], sys.argv[2]
for name in ("default", "scorpion_generic"):  # the copies point at the shipped models
    c = json.load(open(f"{tmp}/{name}.json"))
    if c.get("mjcf_path"):
        c["mjcf_path"] = os.path.join(robots, c["mjcf_path"])
    json.dump(c, open(f"{tmp}/{name}.json", "w"))
c["robot"].setdefault("gait", {})["servo_feedforward"] = True
json.dump(c, open(f"{tmp}/feedforward.json", "w"))
PY
for i in $(seq "$reps"); do
  for which in default scorpion_generic feedforward; do
    "$dgmm" --quiet simulate --config "$tmp/$which.json" --protocol paper --seed 390 \
      -o "$tmp/$which.h5" --json > "$tmp/$which.$i.json"
  done
done
/usr/bin/python3 - "$tmp" "$reps" <<'PY'
import json, statistics, sys
tmp, reps = sys.argv[1], int(sys.argv[2])
rate = {}
for which in ("default", "scorpion_generic", "feedforward"):
    runs = [json.load(open(f"{tmp}/{which}.{i}.json")) for i in range(1, reps + 1)]
    rate[which] = statistics.median(r["simulated_seconds"] / r["cpu_seconds"] for r in runs)
print(f"closed-form gait (default.json):        {rate['default']:.1f} simulated s per CPU s (median of {reps})")
print(f"generic gait (scorpion_generic.json):   {rate['scorpion_generic']:.1f} simulated s per CPU s")
print(f"generic gait with the servo feedforward: {rate['feedforward']:.1f} simulated s per CPU s")
print(f"generic / closed form: {rate['scorpion_generic'] / rate['default']:.2f} (the target: at least 0.80)")
print(f"with the feedforward / closed form: {rate['feedforward'] / rate['default']:.2f}")
PY
