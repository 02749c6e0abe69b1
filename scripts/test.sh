#!/usr/bin/env bash
# Installs what is missing, builds dgmm with its tests and runs them with ctest.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/deps.sh"
"$root/scripts/build.sh"
build=${DGMM_BUILD_DIR:-$root/build}

# Rendering tests need an X display. Without one, start a single virtual display for the whole
# run (many concurrent `xvfb-run -a` calls race for display numbers).
if [ -z "${DISPLAY:-}" ] && command -v Xvfb > /dev/null; then
  n=90
  while [ -e "/tmp/.X$n-lock" ] || [ -e "/tmp/.X11-unix/X$n" ]; do n=$((n + 1)); done
  Xvfb ":$n" -screen 0 1920x1080x24 -nolisten tcp > "$build/xvfb.log" 2>&1 &
  xvfb_pid=$!
  trap 'kill $xvfb_pid 2> /dev/null || true' EXIT
  for _ in $(seq 1 100); do [ -S "/tmp/.X11-unix/X$n" ] && break; sleep 0.1; done
  export DISPLAY=":$n"
  echo "test: virtual display $DISPLAY for the rendering tests"
fi

cd "$build"
ctest --output-on-failure -j "${DGMM_JOBS:-$(nproc)}" --timeout 600

# libFuzzer smoke run of each reader (docs/reliability.md), only when clang-14 is present; built
# apart in build-fuzz/ so the main build stays g++. DGMM_FUZZ_SECONDS=0 skips it.
if [ "${DGMM_FUZZ_SECONDS:-20}" -gt 0 ] && command -v clang++-14 > /dev/null; then
  DGMM_FUZZ_BUILD_DIR="$build-fuzz" "$root/scripts/fuzz.sh" "${DGMM_FUZZ_SECONDS:-20}"
fi
