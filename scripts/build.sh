#!/usr/bin/env bash
# Configures and builds knitscale into build/ (Release).
# Usage: scripts/build.sh [build-dir [target...]]   (no target: everything, tests included)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:-$root/build}"
shift || true
targets=()
for t in "$@"; do targets+=(--target "$t"); done
gen=()
command -v ninja >/dev/null && [ ! -f "$build/Makefile" ] && gen=(-G Ninja)
cmake -S "$root" -B "$build" "${gen[@]}" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" "${targets[@]}" --parallel "$(nproc)"
