#!/usr/bin/env bash
# Converts every .h5 under datasets/ (or the folders given) to dgmm format version 2 in place,
# with `dgmm upgrade` (docs/file-format.md). Idempotent: version-2 files are skipped.
#   scripts/upgrade_datasets.sh [folder ...]      (DGMM=path/to/dgmm, default build/app/dgmm)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
dgmm=${DGMM:-${DGMM_BUILD_DIR:-$root/build}/app/dgmm}
[ -x "$dgmm" ] || { echo "upgrade_datasets: no dgmm at $dgmm (build first or set DGMM)" >&2; exit 1; }
[ $# -gt 0 ] || set -- "$root/datasets"
converted=0 skipped=0
while IFS= read -r -d '' f; do
  tmp="$f.upgrading.h5"
  rm -f "$tmp"
  "$dgmm" upgrade "$f" -o "$tmp" > /dev/null
  if [ -f "$tmp" ]; then
    mv -f "$tmp" "$f"
    converted=$((converted + 1))
    echo "upgraded $f"
  else
    skipped=$((skipped + 1))
  fi
done < <(find "$@" -name '*.h5' ! -name '*.upgrading.h5' -type f -print0 | sort -z)
echo "upgrade_datasets: $converted converted, $skipped already version 2"
