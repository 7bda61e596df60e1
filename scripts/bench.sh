#!/usr/bin/env bash
# Benchmarks: speed figures printed against the issues' targets. Run on demand:
#   scripts/bench.sh [build-dir]     or     cmake --build build --target bench
# Each benchmark is a script scripts/bench/*.sh that prints its own lines.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:-$root/build}"
shopt -s nullglob
for b in "$root"/scripts/bench/*.sh; do
  echo "== $(basename "$b" .sh) =="
  bash "$b" "$build"
done
