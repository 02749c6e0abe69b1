#!/usr/bin/env bash
# Checks `dgmm tune-k` against a dense grid of `dgmm cv` on the same data, folds and random numbers
# (common random numbers: the same --seed, --folds and --repeats for every k). The k chosen by
# tune-k must score within one standard error of the grid's best; exits 1 otherwise.
#
# Usage: scripts/check_tune_k.sh [set.h5] [--without-terrain]
# Environment: DGMM_EXE (default build/app/dgmm), FOLDS (10), REPEATS (10), SEED (1),
#              GRID (dense grid points, 25), K_MIN (1e-3), K_MAX (10), JSON_OUT (write a summary).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
dgmm=${DGMM_EXE:-$root/build/app/dgmm}
set_path=${1:-$root/datasets/scorpion_sim_390.h5}
terrain_flag=${2:---with-terrain}
folds=${FOLDS:-10}
repeats=${REPEATS:-10}
seed=${SEED:-1}
grid=${GRID:-25}
k_min=${K_MIN:-1e-3}
k_max=${K_MAX:-10}
[ -x "$dgmm" ] || { echo "check_tune_k: no dgmm binary at $dgmm (build first or set DGMM_EXE)" >&2; exit 2; }
[ -f "$set_path" ] || { echo "check_tune_k: no sample set at $set_path" >&2; exit 2; }
case "$terrain_flag" in
  --with-terrain) row=dgmm_with_terrain ;;
  --without-terrain) row=dgmm_without_terrain ;;
  *) echo "check_tune_k: second argument must be --with-terrain or --without-terrain" >&2; exit 2 ;;
esac
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
common=(--folds "$folds" --repeats "$repeats" --seed "$seed")

echo "check_tune_k: $set_path, $repeats x $folds-fold, seed $seed, ${terrain_flag#--}"
# The S0-scale and nu0 grids are the library defaults, written out for binaries built before them.
"$dgmm" tune "$set_path" "${common[@]}" "$terrain_flag" --k-min "$k_min" --k-max "$k_max" \
  --init-scales 0.03,0.1,0.3,1,3,10 --prior-counts 1,4,16,64 --json > "$work/tune.json"
# The grid over k is run at tune's final S0 scale and prior pseudo-count.
read -r -a tuned < <(python3 -c '
import json, sys
t = json.load(open(sys.argv[1]))["recommended"]
flags = []
if t["init_scale"] is not None: flags += ["--init-scale", repr(t["init_scale"])]
if t["prior_count"] is not None: flags += ["--prior-count", repr(t["prior_count"])]
print(" ".join(flags))' "$work/tune.json")
python3 - "$k_min" "$k_max" "$grid" > "$work/grid.txt" <<'EOF'
import math, sys
lo, hi, n = math.log(float(sys.argv[1])), math.log(float(sys.argv[2])), int(sys.argv[3])
for i in range(n):
    print(f"{math.exp(lo + (hi - lo) * i / (n - 1)):.8g}")
EOF
while read -r k; do
  "$dgmm" cv "$set_path" "${common[@]}" "${tuned[@]}" --no-em --k "$k" --json > "$work/cv_$k.json"
done < "$work/grid.txt"

python3 - "$work" "$row" "${JSON_OUT:-}" <<'EOF'
import glob, json, os, sys
work, row, json_out = sys.argv[1], sys.argv[2], sys.argv[3]
tune = json.load(open(os.path.join(work, "tune.json")))
rec = tune["recommended"]
grid = []
for path in glob.glob(os.path.join(work, "cv_*.json")):
    cv = json.load(open(path))
    grid.append((cv["k"], cv["rows"][row]["mean"], cv["rows"][row]["standard_error"]))
grid.sort()
best = max(grid, key=lambda g: g[1])
print(f"{'k':>12} {'held-out LL':>14} {'std. error':>11}")
for k, ll, se in grid:
    print(f"{k:12.5g} {ll:14.2f} {se:11.2f}{'  <- grid best' if (k, ll, se) == best else ''}")
gap = best[1] - rec["log_likelihood"]
plateau = tune["k_search"]["plateau"]
if plateau["flat"]:
    print(f"tune reported a PLATEAU: k in [{plateau['k_range'][0]:.4g}, {plateau['k_range'][1]:.4g}] "
          f"within {plateau['tolerance']:.3g} of the best; it chose the simplest model there")
ok = gap <= best[2]
print(f"tune-k: k = {rec['k']:.5g}, held-out LL {rec['log_likelihood']:.2f} +- "
      f"{rec['standard_error']:.2f} ({len(tune['k_search']['curve'])} evaluations, {tune['seconds']:.1f} s)")
print(f"grid best: k = {best[0]:.5g}, held-out LL {best[1]:.2f} +- {best[2]:.2f} "
      f"({len(grid)} evaluations)")
print(f"gap to the grid's best: {gap:.2f} nats; one standard error: {best[2]:.2f} -> "
      f"{'PASS' if ok else 'FAIL'}")
if json_out:
    json.dump({"tune_k": {"k": rec["k"], "log_likelihood": rec["log_likelihood"],
                          "standard_error": rec["standard_error"],
                          "evaluations": len(tune["k_search"]["curve"]), "seconds": tune["seconds"]},
               "grid_best": {"k": best[0], "log_likelihood": best[1], "standard_error": best[2]},
               "grid_points": len(grid), "gap": gap, "pass": ok, "plateau": plateau,
               "init_scale": rec["init_scale"], "prior_count": rec["prior_count"]}, open(json_out, "w"), indent=2)
sys.exit(0 if ok else 1)
EOF
