#!/usr/bin/env bash
# Builds the libFuzzer harnesses of tests/fuzz/harnesses with clang-14 (ASan + libFuzzer, in
# build-fuzz/, apart from the g++ build) and runs each for a while on a working copy of the seed
# corpus tests/fuzz/corpus/<target>. Exits non-zero on any crash, hang (> 10 s) or OOM (> 2 GB);
# the reproducer is written to build-fuzz/artifacts/<target>/ (add it to the corpus once fixed).
#   scripts/fuzz.sh [seconds per fuzzer, default 25] [target ...]   (targets: csv sample_set
#   model sim_config; all by default). Prints one line per target with its exec count.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
seconds=${1:-25}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(csv sample_set model sim_config)
if ! command -v clang++-14 > /dev/null; then
  echo "fuzz: clang++-14 not found (Debian: clang-14 libclang-rt-14-dev); skipped"
  exit 0
fi
build=${DGMM_FUZZ_BUILD_DIR:-$root/build-fuzz}
mkdir -p "$build"
cmake -S "$root/tests/fuzz/harnesses" -B "$build" -DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_C_COMPILER=clang-14 \
  > "$build/configure.log" 2>&1 || { cat "$build/configure.log"; exit 1; }
nice -n 5 cmake --build "$build" -j "${DGMM_JOBS:-2}" > "$build/build.log" 2>&1 \
  || { tail -40 "$build/build.log"; exit 1; }
status=0
for t in "${targets[@]}"; do
  work="$build/corpus/$t" artifacts="$build/artifacts/$t"
  mkdir -p "$work" "$artifacts"
  log="$build/$t.log"
  if ASAN_OPTIONS=detect_leaks=0:allocator_may_return_null=1 nice -n 5 "$build/${t}_fuzz" \
      -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
      -artifact_prefix="$artifacts/" "$work" "$root/tests/fuzz/corpus/$t" > "$log" 2>&1; then
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
    echo "fuzz: $t: $runs runs in ${seconds} s, no crash, hang or OOM"
  else
    status=1
    echo "fuzz: $t: FAILED (see $log; reproducer in $artifacts/)"
    grep -E "ERROR|SUMMARY|Test unit written" "$log" | head -5
  fi
done
exit $status
