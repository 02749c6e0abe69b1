#!/usr/bin/env bash
# Reproduces section VI-A of Edgington, Kassahun & Kirchner (IROS 2009) on Old Faithful:
# Figure 2 (Gaussians after one pass against k), Figure 3 (EM beside DGMM, their difference),
# the MISE of DGMM (k = 0.7, runs ending with exactly 2 Gaussians) against EM, and held-out
# log-likelihood; for the paper's algorithm and the improved variant side by side.
# Writes docs/figures/old_faithful/*.png (all drawn by `dgmm render` / `dgmm plot`) and the
# old-faithful section of docs/reproduction.md. Uses the built binary in build/ (or
# $DGMM_BUILD_DIR) and xvfb-run. A few minutes on one core; not part of ctest.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${DGMM_BUILD_DIR:-$root/build}
dgmm=$build/app/dgmm
[[ -x $dgmm ]] || { echo "no $dgmm: run scripts/build.sh first (or set DGMM_BUILD_DIR)" >&2; exit 1; }
command -v xvfb-run >/dev/null || { echo "xvfb-run is needed (Debian package xvfb)" >&2; exit 1; }
# One virtual display for the whole run (several concurrent `xvfb-run -a` can race for a number).
if [[ -z ${DGMM_REPRO_XVFB:-} ]]; then
  DGMM_REPRO_XVFB=1 exec xvfb-run -a -n $((100 + RANDOM % 800)) -s "-screen 0 1280x1024x24" "$0" "$@"
fi
fig=$root/docs/figures/old_faithful
mkdir -p "$fig"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# Already under xvfb-run (see above); a render that loses the display is retried.
xvfb() { for _ in 1 2 3; do "$@" && return 0; sleep 1; done; return 1; }
start=$(date +%s)

echo "== import (standardised) and EM reference" >&2
"$dgmm" import "$root/datasets/old_faithful.csv" -o "$work/of.h5" \
  --pose-cols eruptions,waiting --standardize >/dev/null
"$dgmm" em "$work/of.h5" -o "$work/em.h5" --components 2 --n-init 10 --seed 1 >/dev/null

echo "== k sweep, MISE runs and cross-validation (faithful and improved)" >&2
"$dgmm" experiment old-faithful "$work/of.h5" --em "$work/em.h5" --out-dir "$work" \
  --variants faithful-blend,improved-prior --init-cov identity --prior-count 1 --k 0.7 --grid-points 19 --seeds-per-k 50 --runs 100 \
  --target 2 --folds 10 --cv-seeds 10 --seed 1 --json > "$work/summary.json"

echo "== raw units (minutes): how often a run at k = 0.7 ends with 1, 2, 3, ... Gaussians" >&2
# A genuine raw-unit fit (no standardisation), the paper's S0 = I, a fixed number of shuffles
# (--runs above --max-attempts: no stop at the 100th 2-Gaussian run); sweep and CV kept minimal.
"$dgmm" import "$root/datasets/old_faithful.csv" -o "$work/raw.h5" --pose-cols eruptions,waiting >/dev/null
"$dgmm" em "$work/raw.h5" -o "$work/em_raw.h5" --components 2 --n-init 10 --seed 1 >/dev/null
mkdir -p "$work/raw"
"$dgmm" experiment old-faithful "$work/raw.h5" --em "$work/em_raw.h5" --out-dir "$work/raw" \
  --variants faithful-literal,faithful-blend,improved-prior --init-cov identity --prior-count 1 \
  --k 0.7 --grid-points 2 --seeds-per-k 1 --runs 1000000 --max-attempts "${RAW_FITS:-400}" \
  --target 2 --folds 2 --cv-seeds 1 --seed 1 --json > "$work/raw/summary.json"

echo "== figures" >&2
python3 "$root/scripts/old_faithful_report.py" join "$work" > "$work/k_sweep.csv"
xvfb "$dgmm" plot --csv "$work/k_sweep.csv" --x k --y faithful-blend_mean,improved-prior_mean \
  --yerr faithful-blend_sd,improved-prior_sd --names "Algorithm 2 (blend reading),improved variant" --log-x \
  --title "Old Faithful: Gaussians after one pass (mean +- sd over 50 shuffles)" \
  --x-label "k (log scale)" --y-label "number of Gaussians" -o "$fig/figure2_k_sweep.png" >/dev/null
for variant in faithful-blend improved-prior; do
  xvfb "$dgmm" render --diff "$work/em.h5" "$work/${variant}_dgmm_median.h5" --data "$work/of.h5" \
    --labels "EM 2 components (10 restarts),DGMM k=0.7 ($variant) median-MISE run" \
    --size 620x520 -o "$fig/figure3_em_vs_dgmm_${variant%%-*}.png" >/dev/null
done
xvfb "$dgmm" render "$work/em.h5" --data "$work/of.h5" --size 700x560 \
  --title "EM (2 components, 10 restarts) on Old Faithful, raw units" -o "$fig/em.png" >/dev/null
python3 "$root/scripts/old_faithful_report.py" mise "$work" > "$work/mise_bars.csv"
xvfb "$dgmm" plot --csv "$work/mise_bars.csv" --kind bar --x method --y mean --yerr sd \
  --title "MISE against EM, 100 runs with 2 Gaussians (standardised units)" \
  --x-label "" --y-label "integrated squared error" -o "$fig/mise.png" >/dev/null
xvfb "$dgmm" plot --csv "$work/cv_summary.csv" --kind bar --x method --y mean --yerr sd \
  --title "Held-out log-likelihood, 10-fold CV (nats per sample, raw units)" \
  --x-label "" --y-label "mean log-likelihood" -o "$fig/cv.png" >/dev/null

seconds=$(( $(date +%s) - start ))
python3 "$root/scripts/old_faithful_report.py" section "$work" "$seconds" > "$work/section.md"
python3 "$root/scripts/replace_section.py" "$root/docs/reproduction.md" old-faithful "$work/section.md"
echo "wrote the old-faithful section of docs/reproduction.md and $fig/*.png (${seconds} s)" >&2
