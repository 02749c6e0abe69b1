#!/usr/bin/env bash
# Regenerates the shipped multi-rate robot log datasets/logs/ with the MuJoCo simulator:
#   dgmm simulate-log --seed 11 --sessions 6 --commands-per-session 30
# (the built-in eight-legged robot on its 18 degree slope, datasets/robots/default.json):
#   commands.csv  10 Hz, t [s], mode (text), v_long, v_lat, v_turn (joystick values, jitter 0.03)
#   pose.csv      30 Hz, t [s], x_mm, y_mm, z_mm, roll_deg, pitch_deg, yaw_deg (tracker noise,
#                 stamp jitter, yaw wrapped to +-180, ~0.3% dropouts logged as nan)
#   imu.csv       50 Hz, t_ms [ms], roll_deg, pitch_deg (attitude relative to gravity, IMU noise)
# Sessions (placements at random position and heading) are separated by 20-60 s logging gaps.
# Usage: scripts/make_log_dataset.sh [build-dir]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-${DGMM_BUILD_DIR:-$root/build}}
dgmm="$build/app/dgmm"
[ -x "$dgmm" ] || { echo "make_log_dataset: $dgmm not built" >&2; exit 1; }
mkdir -p "$root/datasets/logs"
"$dgmm" simulate-log --config "$root/datasets/robots/default.json" --seed 11 --sessions 6 \
  --commands-per-session 30 -o "$root/datasets/logs" --quiet
