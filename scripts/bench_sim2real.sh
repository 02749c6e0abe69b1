#!/usr/bin/env bash
# Times `dgmm sim2real` on a shipped pair (datasets/sim2real/payload: 390 real vs 830 sim samples,
# the sim set's own recorded config, default settings, no figures): uncached (a fresh recording
# cache, so every knob signature is recorded) with --threads 1 and with --threads N, then cached
# (the same analysis again with N threads), and uncached with N threads and --confirm-all-knobs
# (the run again with every execution records every knob, as before 2026-11-29) beside it; writes
# the `sim2real` section of docs/performance.md. N is the machine's core count (`nproc`);
# DGMM_BENCH_THREADS="N" skips the 1-thread run. Usage:
#   scripts/bench_sim2real.sh [build-dir]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-${DGMM_BUILD_DIR:-$root/build}}
dgmm="$build/app/dgmm"
data="$root/datasets/sim2real"
[ -x "$dgmm" ] || { echo "bench_sim2real: $dgmm not built" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cores=$(nproc)
pair=payload
# run NAME THREADS CACHE [ARGS...]: one analysis; prints its wall seconds; the report is in $tmp/NAME.
run() {
  local start end name=$1 threads=$2 cache=$3
  shift 3
  start=$(date +%s.%N)
  "$dgmm" --quiet sim2real --sim "$data/sim.h5" --real "$data/$pair/real.h5" -o "$tmp/$name" --no-figures \
    --threads "$threads" --cache "$cache" "$@" > /dev/null
  end=$(date +%s.%N)
  echo "$end - $start" | bc -l
}
field() { python3 -c "import json; j=json.load(open('$tmp/$1/report.json')); print($2)"; }
rows=""
# uncached NAME THREADS LABEL [ARGS...]: one uncached analysis as a table row.
uncached() {
  local name=$1 threads=$2 label=$3 t sig n
  shift 3
  t=$(run "$name" "$threads" "$tmp/cache-$name" "$@")
  sig=$(field "$name" "'%.0f' % j['seconds']['candidates']")
  n=$(field "$name" "j['knobs']['recordings']['signatures'] + j['knobs']['recordings']['refinement']")
  rows+="| $label | $threads | $(printf '%.0f' "$t") | $sig | $n |"$'\n'
  echo "sim2real $pair $label, $threads thread(s): ${t}s ($n recordings, signatures ${sig}s)"
}
for threads in ${DGMM_BENCH_THREADS:-1 $cores}; do
  uncached "uncached-$threads" "$threads" uncached
done
uncached all-knobs "$cores" "uncached, --confirm-all-knobs" --confirm-all-knobs
t=$(run cached "$cores" "$tmp/cache-uncached-$cores")
n=$(field cached "j['knobs']['recordings']['signatures'] + j['knobs']['recordings']['refinement']")
rows+="| cached | $cores | $(printf '%.1f' "$t") | - | $n |"$'\n'
echo "sim2real $pair cached, $cores thread(s): ${t}s ($n recordings)"
design=$(field cached "'%d placements of %d executions' % (j['knobs']['placements_per_recording'], j['knobs']['executions_per_placement']) + (' (stages 3-8 ran twice: ' + j['knobs']['every_execution_because'] + ')' if j['knobs']['every_execution_because'] else '')")
verdict_of() { field "$1" "j['verdict']['status'] + ': ' + '; '.join('%s %.3g' % (n['knob'], n['value']) for n in j['verdict']['named'])"; }
verdict=$(verdict_of cached)
verdict_all=$(verdict_of all-knobs)
cat > "$tmp/section.md" <<MD
### sim2real (\`scripts/bench_sim2real.sh\`)

\`dgmm sim2real\` on the shipped payload pair (390 real vs 830 sim samples), the sim set's recorded
config, default settings ($design per recording, 20 bootstrap resamples, 1000 permutations
per test), no figures; $(date -u +%Y-%m-%d) on $cores cores ($(uptime | sed 's/.*load average/load average/')). Uncached: a
fresh recording cache; cached: the same analysis again; --confirm-all-knobs: the run again with every
execution records every knob, not only those the first look screened in. Verdict: $verdict
(with --confirm-all-knobs: $verdict_all). Targets (issue #22):
uncached <= 90 s on 2 cores and <= 30 s with 16 threads, cached <= 10 s.

| run | threads | wall s | signatures s | recordings made |
|---|---|---|---|---|
$rows
MD
cat "$tmp/section.md"
python3 "$root/scripts/replace_section.py" "$root/docs/performance.md" sim2real "$tmp/section.md"
