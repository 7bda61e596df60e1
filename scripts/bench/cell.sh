#!/usr/bin/env bash
# Unit-cell speed (issue #6): one path of 20 steps on the 4.5 mm cell <= 4 s on one core
# (the database's 5-minute goal). Prints the time per step and the Newton iterations.
#   scripts/bench/cell.sh BUILD_DIR
set -euo pipefail
build="${1:?usage: cell.sh BUILD_DIR}"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
for path in "--biaxial 0.3 0" "--shear 30"; do
  line="$(taskset -c 0 "$build/bin/knit-meso" path --loop-length 4.5 $path --steps 20 --no-vtp \
            --out "$out" 2>/dev/null | tail -1 || true)"
  if [[ -z "$line" ]]; then
    line="$("$build/bin/knit-meso" path --loop-length 4.5 $path --steps 20 --no-vtp --out "$out" | tail -1)"
  fi
  secs="$(echo "$line" | sed -E 's/.* in ([0-9.]+) s .*/\1/')"
  echo "cell: l=4.5 mm, $path, 20 steps (32 elements): $secs s wall (target <= 4 s) -- $line"
done
