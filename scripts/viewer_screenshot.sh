#!/usr/bin/env bash
# Regenerates the screenshots of `dgmm view` in docs/figures/viewer/ under a virtual display
# (scripts/with-display.sh): a DGMM learnt from datasets/scorpion_sim_830.h5 at the settings
# `dgmm tune` chose for it with terrain in docs/reproduction.md's Table I (k = 10, S0 scale 1,
# nu0 = 4; seed 1), and an EM model (4 components, seed 1) to compare with.
# The windows are driven by recorded event streams (docs/figures/viewer/*.events): a terrain
# slider moved with the keyboard and the cursor over the densest region, then the whole window
# is written with --screenshot.
#   scripts/viewer_screenshot.sh
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${DGMM_BUILD_DIR:-$root/build}
cmake --build "$build" -j "${DGMM_JOBS:-2}" --target dgmm > /dev/null
dgmm=$build/app/dgmm
figures=$root/docs/figures/viewer
mkdir -p "$figures"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
set830=$root/datasets/scorpion_sim_830.h5
"$dgmm" fit "$set830" -o "$work/dgmm.h5" --k 10 --init-scale 1 --prior-count 4 --seed 1 > /dev/null
"$dgmm" em "$set830" -o "$work/em.h5" --components 4 --seed 1 > /dev/null

view() { "$root/scripts/with-display.sh" "$dgmm" view "$@"; }
# One panel with the samples near the chosen terrain, component ellipses on.
# The terrain starts at pitch 0.01, roll 0.27; the events move the pitch to ~0.12, onto one of the
# slopes this command was recorded on.
terrain=(--condition pitch=0.01 --condition roll=0.27)
view "$work/dgmm.h5" --data "$set830" --command +0.5,0,0 "${terrain[@]}" --ellipses \
  --replay "$figures/single.events" --screenshot "$figures/viewer.png"
# DGMM (A) against EM (B), A - B.
view "$work/dgmm.h5" --compare "$work/em.h5" --data "$set830" --command +0.5,0,0 "${terrain[@]}" \
  --replay "$figures/compare.events" --screenshot "$figures/viewer_compare.png"
ls -l "$figures"/*.png
