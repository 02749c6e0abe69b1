#!/usr/bin/env bash
# Times `dgmm sim2real` (default settings: 20 selection bootstraps, 1000 permutations per test) on
# every shipped pair (390 real vs 830 sim samples), 3 runs each, and writes the medians into the
# `sim2real` section of docs/performance.md. Usage: scripts/bench_sim2real.sh [build-dir]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-${DGMM_BUILD_DIR:-$root/build}}
dgmm="$build/app/dgmm"
data="$root/datasets/sim2real"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
runs=3
figures_flag=(--no-figures)
wrap=()
if command -v xvfb-run > /dev/null; then wrap=(xvfb-run -a); figures_flag=(); fi
median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
rows=""
for pair in slip payload weak_leg null; do
  times=()
  for i in $(seq $runs); do
    start=$(date +%s.%N)
    "${wrap[@]}" "$dgmm" sim2real --sim "$data/sim.h5" --real "$data/$pair/real.h5" -o "$tmp/$pair" \
      "${figures_flag[@]}" > /dev/null
    end=$(date +%s.%N)
    times+=("$(echo "$end - $start" | bc -l)")
  done
  med=$(printf '%s\n' "${times[@]}" | median)
  analysis=$(python3 -c "import json; print('%.1f' % json.load(open('$tmp/$pair/report.json'))['seconds'])")
  rows+="| $pair | $(printf '%.1f' "$med") | $analysis |"$'\n'
  echo "sim2real $pair: median wall ${med}s over $runs runs (analysis ${analysis}s)"
done
# One run with --sim-config (4 re-simulations of 200 samples each for the friction scan).
start=$(date +%s.%N)
"$dgmm" sim2real --sim "$data/sim.h5" --real "$data/slip/real.h5" -o "$tmp/recal" --no-figures \
  --sim-config "$data/configs/nominal.json" > /dev/null
recal=$(echo "$(date +%s.%N) - $start" | bc -l)
echo "sim2real slip with --sim-config: ${recal}s"
cat > "$tmp/section.md" <<MD
### sim2real (\`scripts/bench_sim2real.sh\`)

One \`dgmm sim2real\` run, 390 real vs 830 sim samples (the shipped MuJoCo pairs), default
settings (20 bootstrap resamples of the selection, 200 of the parameters, 1000 permutations per
MMD test), figures ${figures_flag[*]:-rendered under xvfb-run}. Median of $runs runs on $(nproc) cores,
$(date -u +%Y-%m-%d). Target: under 120 s.

| pair | wall s (median, incl. reading, figures, report) | analysis s (last run) |
|---|---|---|
$rows
With \`--sim-config\` (friction re-simulated at four values, 200 samples each), slip pair, one run:
$(printf '%.1f' "$recal") s wall.
MD
python3 "$root/scripts/replace_section.py" "$root/docs/performance.md" sim2real "$tmp/section.md"
