#!/usr/bin/env bash
# Bounded work of `dgmm fit` (issue #13, docs/reliability.md "Bounded work"):
#  1. per-sample cost against the number of components: k = 1e-9 (a component per sample until
#     the cap) on N = 20000 samples with --max-components K for K = 100 .. 1600; seconds per
#     sample should grow about linearly in K (it grew quadratically before the incremental mode
#     search), and
#  2. `fit --k 1e-9` on 10^6 samples with the default cap (target: under 30 s, with the warning).
# Data: y = x||z, dx = 2, dz = 1, one command, a 3-cluster Gaussian mixture drawn with seed 7.
#   scripts/bench_fit_cap.sh [N for part 2, default 1000000]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${DGMM_BUILD_DIR:-$root/build}
dgmm=$build/app/dgmm
n_big=${1:-1000000}
work=$build/bench-fit-cap
mkdir -p "$work"
make_set() {  # make_set <n> <file.h5>
  [ -f "$2" ] && return
  python3 - "$1" > "$work/data.csv" <<'PY'
import random, sys
rng = random.Random(7)
centres = [(0.0, 0.0, 0.0), (3.0, 1.0, 0.5), (-2.0, 2.5, -0.5)]
out = ["x,y,z"]
for _ in range(int(sys.argv[1])):
    c = rng.choice(centres)
    out.append("%.6f,%.6f,%.6f" % tuple(v + rng.gauss(0, 0.5) for v in c))
print("\n".join(out))
PY
  "$dgmm" import "$work/data.csv" -o "$2" --pose-cols x,y --terrain-cols z > /dev/null
}
seconds() {  # "wall cpu" seconds of a command (cpu = user + sys; the machine may be shared)
  /usr/bin/time -f "%e %U %S" -o "$work/time" "$@" > /dev/null 2> "$work/stderr"
  awk '{printf "%.2f %.2f\n", $1, $2 + $3}' "$work/time"
}
make_set 20000 "$work/n20000.h5"
echo "| components K | wall s | CPU s | CPU microseconds per sample per component |"
echo "|---|---|---|---|"
for k in 100 200 400 800 1600; do
  read -r wall cpu < <(seconds nice -n 5 "$dgmm" fit "$work/n20000.h5" -o "$work/m.h5" --k 1e-9 \
    --max-components "$k")
  python3 -c "print(f'| $k | $wall | $cpu | {1e6 * $cpu / 20000 / $k:.3f} |')"
done
make_set "$n_big" "$work/n$n_big.h5"
read -r wall cpu < <(seconds nice -n 5 "$dgmm" fit "$work/n$n_big.h5" -o "$work/m.h5" --k 1e-9)
echo
echo "fit --k 1e-9 on $n_big samples (default cap): $wall s wall, $cpu s CPU"
grep -o "reached --max-components [0-9]*" "$work/stderr" | head -1 || echo "(no cap warning)"
