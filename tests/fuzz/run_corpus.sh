#!/usr/bin/env bash
# Regression test (ctest fuzz_corpus_cli): every file of the fuzz corpus, crashers included,
# through the dgmm command line. Each run must end with an exit code (0 or a one-line error),
# never a signal, within 60 s.   tests/fuzz/run_corpus.sh <dgmm> <corpus folder>
set -uo pipefail
dgmm=$1 corpus=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0 runs=0
check() {  # check <what> <command...>
  local what=$1
  shift
  timeout 60 "$@" > /dev/null 2> "$work/err"
  local code=$?
  runs=$((runs + 1))
  if [ $code -ge 124 ]; then
    echo "FAIL ($code: signal or timeout): $what"
    failures=$((failures + 1))
  elif [ $code -ne 0 ] && [ "$(grep -c . "$work/err")" -ne 1 ]; then
    echo "FAIL (not one line on stderr): $what"
    cat "$work/err"
    failures=$((failures + 1))
  fi
}
for f in "$corpus"/sample_set/*; do
  check "info $f" "$dgmm" info "$f"
  check "fit $f" "$dgmm" fit "$f" -o "$work/m.h5"
done
for f in "$corpus"/model/*; do
  check "export $f" "$dgmm" export "$f" -o "$work/m.json"
done
for f in "$corpus"/csv/*; do
  tail -c +2 "$f" > "$work/in.csv"  # the first byte is the harness's option flags
  check "import $f" "$dgmm" import "$work/in.csv" -o "$work/s.h5" --pose-cols x,y
done
for f in "$corpus"/sim_config/*; do
  check "simulate --config $f" "$dgmm" simulate --config "$f" --print-config
done
echo "fuzz corpus through the CLI: $runs runs, $failures failures"
[ $failures -eq 0 ]
