#!/usr/bin/env bash
# Times `dgmm sim2real` on a shipped pair (datasets/sim2real/payload: 390 real vs 830 sim samples,
# the sim set's own recorded config, default settings, no figures): uncached (a fresh recording
# cache, so every knob signature is recorded) with --threads 1 and with --threads N, then cached
# (the same analysis again with N threads), and writes the `sim2real` section of
# docs/performance.md. N is the machine's core count (`nproc`). Usage:
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
# run NAME THREADS CACHE: one analysis; prints its wall seconds; the report is in $tmp/NAME.
run() {
  local start end
  start=$(date +%s.%N)
  "$dgmm" --quiet sim2real --sim "$data/sim.h5" --real "$data/$pair/real.h5" -o "$tmp/$1" --no-figures \
    --threads "$2" --cache "$3" > /dev/null
  end=$(date +%s.%N)
  echo "$end - $start" | bc -l
}
field() { python3 -c "import json; j=json.load(open('$tmp/$1/report.json')); print($2)"; }
rows=""
for threads in 1 "$cores"; do
  t=$(run "uncached-$threads" "$threads" "$tmp/cache-$threads")
  sig=$(field "uncached-$threads" "'%.0f' % j['seconds']['candidates']")
  n=$(field "uncached-$threads" "j['knobs']['recordings']['signatures'] + j['knobs']['recordings']['refinement']")
  rows+="| uncached | $threads | $(printf '%.0f' "$t") | $sig | $n |"$'\n'
  echo "sim2real $pair uncached, $threads thread(s): ${t}s ($n recordings, signatures ${sig}s)"
done
t=$(run cached "$cores" "$tmp/cache-$cores")
n=$(field cached "j['knobs']['recordings']['signatures'] + j['knobs']['recordings']['refinement']")
rows+="| cached | $cores | $(printf '%.1f' "$t") | - | $n |"$'\n'
echo "sim2real $pair cached, $cores thread(s): ${t}s ($n recordings)"
design=$(field cached "'%d placements of %d executions' % (j['knobs']['placements_per_recording'], j['knobs']['executions_per_placement']) + (' (stages 3-8 ran twice: ' + j['knobs']['every_execution_because'] + ')' if j['knobs']['every_execution_because'] else '')")
verdict=$(field cached "j['verdict']['status'] + ': ' + '; '.join('%s %.3g' % (n['knob'], n['value']) for n in j['verdict']['named'])")
cat > "$tmp/section.md" <<MD
### sim2real (\`scripts/bench_sim2real.sh\`)

\`dgmm sim2real\` on the shipped payload pair (390 real vs 830 sim samples), the sim set's recorded
config, default settings ($design per recording, 20 bootstrap resamples, 1000 permutations
per test), no figures; $(date -u +%Y-%m-%d) on $cores cores ($(uptime | sed 's/.*load average/load average/')). Uncached: a
fresh recording cache; cached: the same analysis again. Verdict: $verdict. Targets (issue #22):
uncached <= 90 s on 2 cores and <= 30 s with 16 threads, cached <= 10 s.

| run | threads | wall s | signatures s | recordings made |
|---|---|---|---|---|
$rows
MD
cat "$tmp/section.md"
python3 "$root/scripts/replace_section.py" "$root/docs/performance.md" sim2real "$tmp/section.md"
