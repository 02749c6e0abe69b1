#!/usr/bin/env bash
# Slider-redraw benchmark of `dgmm view` (tests/benchmarks/viewer_benchmark.cc) under a display
# (scripts/with-display.sh), written into the `viewer-slider` section of docs/performance.md.
# Models: the DGMM the benchmark learns from datasets/scorpion_sim_830.h5 (k = 10, S0 scale 1, nu0 = 4: Table I's tuned settings; seed 1), and
# an EM model of the same set with 4 components per command (`dgmm em`, seed 1), so the cost is
# also seen with several components. Each is run twice: llvmpipe's default threads (wall clock,
# what a user waits) and LP_NUM_THREADS=0 (all rasterisation on the benchmark's thread, so its
# CPU time is the whole CPU cost of a redraw).
#   scripts/bench_viewer.sh [repetitions=5]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${DGMM_BUILD_DIR:-$root/build}
reps=${1:-5}
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DDGMM_BUILD_BENCHMARKS=ON > /dev/null
cmake --build "$build" -j "${DGMM_JOBS:-2}" --target viewer_benchmark dgmm > /dev/null
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$build/app/dgmm" em "$root/datasets/scorpion_sim_830.h5" -o "$work/em4.h5" --components 4 \
  --seed 1 > /dev/null
bench() {  # name, then environment assignments
  local name=$1
  shift
  env "$@" "$root/scripts/with-display.sh" "$build/tests/benchmarks/viewer_benchmark" \
    --benchmark_repetitions="$reps" --benchmark_report_aggregates_only=true \
    --benchmark_format=json > "$work/$name.json"
}
bench dgmm_threads
bench dgmm_single LP_NUM_THREADS=0
bench em_threads DGMM_VIEW_MODEL="$work/em4.h5"
bench em_single DGMM_VIEW_MODEL="$work/em4.h5" LP_NUM_THREADS=0
python3 - "$work" "$reps" <<'PY' | "$root/scripts/replace_section.py" "$root/docs/performance.md" viewer-slider -
import json, sys
work, reps = sys.argv[1], sys.argv[2]
def medians(name):
    data = json.load(open(f"{work}/{name}.json"))
    out = {}
    for b in data["benchmarks"]:
        if b.get("aggregate_name") == "median":
            out[b["run_name"]] = b
    return data["context"], out
rows = []
ctx = None
for model, label in (("dgmm", "DGMM, tuned (k = 10)"), ("em", "EM, 4 components")):
    ctx, threads = medians(f"{model}_threads")
    _, single = medians(f"{model}_single")
    for run, what in (("BM_SliderRedraw/compare:0/real_time", "one panel 800 x 640"),
                      ("BM_SliderRedraw/compare:1/real_time", "A, B, A - B, 3 x 560 x 448"),
                      ("BM_SliderRecompute/real_time", "recompute only (no VTK), one panel")):
        t, s = threads.get(run), single.get(run)
        if not t or not s:
            continue
        rows.append((label, what, int(t.get("components", 0)), t["real_time"], s["real_time"],
                     s["cpu_time"]))
print("## Viewer: slider redraw\n")
print(f"`scripts/bench_viewer.sh` (Google Benchmark `tests/benchmarks/viewer_benchmark`, median of "
      f"{reps} repetitions, under a virtual X display with Mesa's llvmpipe): terrain slider 0 moved "
      "between 25% and 75% of its span on an 8-D model (6 pose + 2 terrain) with 26 commands "
      "learnt from `datasets/scorpion_sim_830.h5`; each move conditions (eqs. 15-19), fills the "
      "200 x 200 grid, contours, rebuilds the VTK chart and renders the window "
      "(`Viewer::MoveSlider`, what the slider widget calls).\n")
print(f"Machine: {ctx.get('num_cpus')} CPUs, load average "
      f"{', '.join(f'{x:.1f}' for x in ctx.get('load_avg', []))} at the start of the last run "
      f"(shared with other jobs); run {ctx.get('date')}.\n")
print("| model | panels | components (first command) | wall ms (llvmpipe threads) | "
      "wall ms (LP_NUM_THREADS=0) | CPU ms (LP_NUM_THREADS=0) |")
print("|---|---|---|---|---|---|")
for label, what, k, wall, wall1, cpu1 in rows:
    print(f"| {label} | {what} | {k} | {wall:.1f} | {wall1:.1f} | {cpu1:.1f} |")
print("\nTarget: < 50 ms per redraw on 2 cores. The CPU column is the whole cost of a redraw on "
      "one core (rasterisation included); wall-clock figures exceed it whenever other processes "
      "share the cores (see the load average).")
PY
sed -n '/BEGIN viewer-slider/,/END viewer-slider/p' "$root/docs/performance.md"
