#!/usr/bin/env bash
# Section VI-A of Edgington et al. read every way the paper allows (issue #10): the literal eq. 13
# beside the blend (version 1) and the prior rule, for both variants, in standardised and in raw
# units (genuine raw-unit fits, not rescaled standardised ones), with the paper's S0 = I and with
# S0 from the data; the MISE against EM at k = 0.7 over runs ending with 2 Gaussians, how often a
# run ends with 2, and Figure 2 (Gaussians after one pass against k) on a known generating
# distribution as in the paper, with Old Faithful as a second panel. Writes the
# old-faithful-readings section of docs/reproduction.md and docs/figures/old_faithful/readings_*.
# Uses build/app/dgmm (or DGMM_EXE); plots need X (run under xvfb-run when DISPLAY is unset).
# Environment: RUNS (100 MISE runs per reading), SEEDS_PER_K (30).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
dgmm=${DGMM_EXE:-$root/build/app/dgmm}
runs=${RUNS:-100}
seeds_per_k=${SEEDS_PER_K:-30}
[ -x "$dgmm" ] || { echo "old_faithful_readings: no $dgmm (build first or set DGMM_EXE)" >&2; exit 2; }
x=()
[ -z "${DISPLAY:-}" ] && x=(xvfb-run -a -s "-screen 0 1280x1024x24")
fig=$root/docs/figures/old_faithful
mkdir -p "$fig"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
start=$(date +%s)
readings=faithful-literal,faithful-blend,faithful-prior,improved-literal,improved-blend,improved-prior
experiment() {  # name set em init-cov prior-count
  mkdir -p "$work/$1"
  "$dgmm" experiment old-faithful "$2" --em "$3" --out-dir "$work/$1" --variants "$readings" \
    --init-cov "$4" --prior-count "$5" --k 0.7 --grid-points 13 --seeds-per-k "$seeds_per_k" \
    --runs "$runs" --max-attempts 3000 --target 2 --folds 10 --cv-seeds 2 --seed 1 --json \
    > /dev/null
}

echo "== Old Faithful, standardised and raw units" >&2
"$dgmm" import "$root/datasets/old_faithful.csv" -o "$work/std.h5" --pose-cols eruptions,waiting \
  --standardize > /dev/null
"$dgmm" import "$root/datasets/old_faithful.csv" -o "$work/raw.h5" --pose-cols eruptions,waiting \
  > /dev/null
"$dgmm" em "$work/std.h5" -o "$work/em_std.h5" --components 2 --n-init 10 --seed 1 > /dev/null
"$dgmm" em "$work/raw.h5" -o "$work/em_raw.h5" --components 2 --n-init 10 --seed 1 > /dev/null
# nu0 = 1: the prior reading closest to "S0 kept as one pseudo-sample".
experiment std_identity "$work/std.h5" "$work/em_std.h5" identity 1
experiment raw_identity "$work/raw.h5" "$work/em_raw.h5" identity 1
experiment raw_data "$work/raw.h5" "$work/em_raw.h5" data 4

echo "== a known generating distribution (Figure 2 as in the paper)" >&2
# Two Gaussians in 2-D (weights 0.35 / 0.65), 272 samples like Old Faithful, seed 1.
python3 - > "$work/known.csv" <<'PY'
import math, random
r = random.Random(1)
comps = [(0.35, (-1.0, -1.0), (0.30, 0.10, 0.25)), (0.65, (1.0, 0.8), (0.35, -0.05, 0.30))]
print("a,b")
for _ in range(272):
    w, (ma, mb), (sa, rho, sb) = comps[0] if r.random() < comps[0][0] else comps[1]
    u, v = r.gauss(0, 1), r.gauss(0, 1)
    print("%.6f,%.6f" % (ma + sa * u, mb + sb * (rho * u + math.sqrt(1 - rho * rho) * v)))
PY
"$dgmm" import "$work/known.csv" -o "$work/known.h5" --pose-cols a,b > /dev/null
"$dgmm" em "$work/known.h5" -o "$work/em_known.h5" --components 2 --n-init 10 --seed 1 > /dev/null
experiment known_identity "$work/known.h5" "$work/em_known.h5" identity 1

python3 "$root/scripts/old_faithful_report.py" readings "$work" "$fig" > "$work/section.md"
# A virtual display that fails to come up (several helpers start Xvfb at once) is retried.
plot() { for _ in 1 2 3; do "${x[@]}" "$dgmm" plot "$@" && return 0; sleep 2; done; return 1; }
for panel in known_identity std_identity; do
  plot --csv "$work/$panel/figure2.csv" --x k \
    --y faithful-literal_mean,faithful-blend_mean,faithful-prior_mean,improved-prior_mean \
    --names "literal eq. 13,blend (v1),prior nu0=1,improved + prior" --log-x \
    --title "$( [ $panel = known_identity ] && echo "Known 2-Gaussian distribution" || echo "Old Faithful (standardised)"): Gaussians after one pass, S0 = I" \
    --x-label "k (log scale)" --y-label "number of Gaussians (mean over $seeds_per_k shuffles)" \
    -o "$fig/readings_figure2_$panel.png" > /dev/null
done
seconds=$(( $(date +%s) - start ))
sed -i "s/@SECONDS@/$seconds/" "$work/section.md"
python3 "$root/scripts/replace_section.py" "$root/docs/reproduction.md" old-faithful-readings \
  "$work/section.md"
echo "wrote the old-faithful-readings section of docs/reproduction.md (${seconds} s)" >&2
