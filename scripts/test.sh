#!/usr/bin/env bash
# Installs what is missing, builds dgmm with its tests and runs them with ctest.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/deps.sh"
"$root/scripts/build.sh"
build=${DGMM_BUILD_DIR:-$root/build}
cd "$build"
ctest --output-on-failure -j "${DGMM_JOBS:-$(nproc)}" --timeout 600
