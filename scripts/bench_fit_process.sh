#!/usr/bin/env bash
# Whole-process `dgmm fit` (defaults) on sets of 3 x 10^5 and 10^6 samples at d = 8 (6 pose +
# 2 terrain dimensions, 3 commands, two clusters per command, seeds 5 and 6), timed with GNU time.
# Given several dgmm binaries (e.g. builds of two commits), runs them alternately and prints the
# median wall time, CPU time and max RSS of each: the side-by-side figures of docs/performance.md
# ("Whole-process dgmm fit").
#   scripts/bench_fit_process.sh [dgmm ...]      (default: build/app/dgmm; $REPS runs, default 5)
# Each binary must read the sets written by the first one (format 2 for builds after 2026-11-23).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
[ $# -gt 0 ] || set -- "$root/build/app/dgmm"
reps=${REPS:-5}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for spec in "300000 5" "1000000 6"; do
  read -r n seed <<< "$spec"
  /usr/bin/python3 - "$n" "$seed" > "$work/set_$n.csv" <<'PY'
import random, sys
n, seed = int(sys.argv[1]), int(sys.argv[2])
rng = random.Random(seed)
out = sys.stdout
out.write("command,x1,x2,x3,x4,x5,x6,z1,z2\n")
for _ in range(n):
    c = rng.randrange(3)
    base = [c * 1.0, -c * 0.5, 0.2 * c, 0, 0.1, -0.1]
    k = rng.randrange(2)
    vals = [b + k * 0.8 + rng.gauss(0, 0.3) for b in base] + [rng.gauss(0, 0.05), rng.gauss(0, 0.05)]
    out.write(str(c) + "," + ",".join("%.6f" % v for v in vals) + "\n")
PY
  "$1" import "$work/set_$n.csv" -o "$work/set_$n.h5" --pose-cols x1,x2,x3,x4,x5,x6 \
    --terrain-cols z1,z2 --command-cols command > /dev/null
done
echo "| dgmm | samples | median wall s | median CPU s | median max RSS MB | runs |"
echo "|---|---|---|---|---|---|"
for n in 300000 1000000; do
  declare -A wall=() cpu=() rss=()
  for ((r = 0; r < reps; r++)); do
    for ((b = 1; b <= $#; b++)); do
      /usr/bin/time -f "%e %U %S %M" -o "$work/time" "${!b}" fit "$work/set_$n.h5" \
        -o "$work/model.h5" > /dev/null 2> /dev/null
      read -r w u s m < "$work/time"
      wall[$b]+="$w " cpu[$b]+="$(awk -v u="$u" -v s="$s" 'BEGIN {printf "%.2f", u + s}') "
      rss[$b]+="$m "
    done
  done
  for ((b = 1; b <= $#; b++)); do
    median() { tr ' ' '\n' | grep -v '^$' | sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
    printf '| %s | %d | %s | %s | %.0f | %d |\n' "${!b}" "$n" "$(echo "${wall[$b]}" | median)" \
      "$(echo "${cpu[$b]}" | median)" "$(($(echo "${rss[$b]}" | median) / 1024))" "$reps"
  done
  unset wall cpu rss
done
