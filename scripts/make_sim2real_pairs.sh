#!/usr/bin/env bash
# Makes the shipped sim-vs-real pairs in datasets/sim2real/ with the MuJoCo simulator
# (`dgmm simulate`); the physics of each pair is in datasets/sim2real/configs/<pair>.json.
#   sim.h5             nominal physics, protocol paper with 166 placements (830 samples), seed 100:
#                      the same recording protocol as the "real" sets, so that a comparison pooled
#                      over terrain is not confounded by a different spread of headings
#   <pair>/real.h5     the "real" recordings, protocol paper (390 samples)
#   <pair>/oracle.h5   an independent recording of the same physics (seed 301): the analysis
#                      fitted on (sim, oracle) defines the planted value in the effect's units
# Pairs: slip (sliding friction 0.7 instead of 1.0), payload (2 kg at 12 cm to the left, 5 cm up),
# weak_leg (leg 1, left middle, at 30% actuator gain), null (nominal physics, another seed).
# Usage: scripts/make_sim2real_pairs.sh [build-dir]   (about 5 min on 2 idle cores)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-${DGMM_BUILD_DIR:-$root/build}}
dgmm="$build/app/dgmm"
out="$root/datasets/sim2real"
cfg="$out/configs"
[ -x "$dgmm" ] || { echo "make_sim2real_pairs: $dgmm not built" >&2; exit 1; }
"$dgmm" simulate --config "$cfg/nominal.json" --protocol paper --placements 166 --seed 100 -o "$out/sim.h5"
declare -A seeds=([slip]=204 [payload]=204 [weak_leg]=204 [null]=204)
for pair in slip payload weak_leg null; do
  mkdir -p "$out/$pair"
  config="$cfg/$pair.json"
  [ "$pair" = null ] && config="$cfg/nominal.json"
  "$dgmm" simulate --config "$config" --protocol paper --seed "${seeds[$pair]}" -o "$out/$pair/real.h5"
  if [ "$pair" != null ]; then
    "$dgmm" simulate --config "$config" --protocol paper --seed 301 -o "$out/$pair/oracle.h5"
  fi
done
echo "make_sim2real_pairs: pairs in $out"
