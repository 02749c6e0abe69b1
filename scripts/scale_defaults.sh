#!/usr/bin/env bash
# Evidence for the default S0 scale f and prior pseudo-count nu0 (docs/dgmm.md, "Why these
# defaults"): for each (f, nu0), (a) how many of 20 metre-scale bimodal streams end with >= 2
# Gaussians at k = 0.7, (b) the 390 set's 3 x 10-fold held-out log-likelihood without / with
# terrain at k = 0.7. Prints a Markdown table. About a minute; uses build/app/dgmm (or DGMM_EXE).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
dgmm=${DGMM_EXE:-$root/build/app/dgmm}
set390=$root/datasets/scorpion_sim_390.h5
[ -x "$dgmm" ] || { echo "scale_defaults: no $dgmm (build first or set DGMM_EXE)" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# The bimodal stream: dx = +-1 cm (equal odds) + N(0, 2 mm), dyaw ~ N(0, 1 mrad), 300 samples.
for seed in $(seq 101 120); do
  python3 - "$seed" > "$work/bi_$seed.csv" <<'PY'
import random, sys
r = random.Random(int(sys.argv[1]))
print("dx,dyaw")
for _ in range(300):
    m = 0.01 if r.random() < 0.5 else -0.01
    print("%.8f,%.8f" % (m + 0.002 * r.gauss(0, 1), 0.001 * r.gauss(0, 1)))
PY
  "$dgmm" import "$work/bi_$seed.csv" -o "$work/bi_$seed.h5" --pose-cols dx,dyaw > /dev/null
done
components() { python3 -c 'import json,sys; print(json.load(sys.stdin)["commands"][0]["components"])'; }
cv390() {
  "$dgmm" cv "$set390" --repeats 3 --no-em --k 0.7 --json "$@" | python3 -c '
import json, sys
r = json.load(sys.stdin)["rows"]
print("%.0f / %.0f" % (r["dgmm_without_terrain"]["mean"], r["dgmm_with_terrain"]["mean"]))'
}
echo "| f, nu0 | bimodal runs with >= 2 Gaussians (of 20) | 390 set, 3 x 10-fold, L without / with terrain |"
echo "|---|---|---|"
row() {
  local name=$1; shift
  local several=0
  for seed in $(seq 101 120); do
    c=$("$dgmm" fit "$work/bi_$seed.h5" -o "$work/m.h5" --seed "$seed" --json "$@" 2> /dev/null | components)
    [ "$c" -ge 2 ] && several=$((several + 1))
  done
  echo "| $name | $several | $(cv390 "$@") |"
}
row "identity, blend (version 1)" --init-cov identity --covariance blend --floor 1e-6
for f in 0.1 0.3 1 3; do
  for nu in 1 4; do row "$f, $nu" --init-scale "$f" --prior-count "$nu"; done
done

# Raw-unit Old Faithful (minutes, minutes) at k = 0.7, S0 = I, streamed in file order, 40 seeds:
# how many runs end with 1, 2, 3, ... Gaussians under each covariance reading.
"$dgmm" import "$root/datasets/old_faithful.csv" -o "$work/of_raw.h5" \
  --pose-cols eruptions,waiting > /dev/null
echo
echo "| raw-unit Old Faithful, k = 0.7, S0 = I, 40 seeds | runs ending with 1 / 2 / 3 / 4+ Gaussians |"
echo "|---|---|"
for rule in literal blend prior; do
  counts=(0 0 0 0 0)
  for seed in $(seq 1 40); do
    c=$("$dgmm" fit "$work/of_raw.h5" -o "$work/m.h5" --seed "$seed" --init-cov identity \
      --covariance "$rule" --prior-count 1 --floor-relative 1e-6 --json 2> /dev/null | components)
    [ "$c" -gt 4 ] && c=4
    counts[$c]=$((counts[c] + 1))
  done
  echo "| $rule | ${counts[1]} / ${counts[2]} / ${counts[3]} / ${counts[4]} |"
done
