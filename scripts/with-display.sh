#!/usr/bin/env bash
# Runs a command that renders with an X display: the current $DISPLAY when one is set (e.g. the
# shared Xvfb that scripts/test.sh starts), else a private one from `xvfb-run -a`.
set -euo pipefail
if [ -n "${DISPLAY:-}" ]; then
  exec "$@"
fi
exec xvfb-run -a -s "-screen 0 1920x1080x24" "$@"
