#!/usr/bin/env bash
# Material database benchmarks (issue #4): load time, material evaluations per second, and
# knit tensile cases. Usage: scripts/bench/database.sh BUILD_DIR
# The energy-law line also times the law of the main job's database (out/database.h5, or
# KNIT_BENCH_DATABASE=FILE) when there is one.
set -uo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${1:-$root/build}"
bin="$build/bin"
db="${KNIT_BENCH_DATABASE:-$root/out/database.h5}"
[[ -f "$db" ]] && export KNIT_BENCH_DATABASE="$db"
"$bin/test_common" "bench: response-surface evaluations per second" 2>/dev/null |
  grep "^material evaluation" || echo "material evaluation: n/a (test_common missing)"
"$bin/test_common" "bench: energy-law evaluations per second" 2>/dev/null |
  grep "^energy-law evaluation" || echo "energy-law evaluation: n/a (test_common missing)"
"$bin/test_common" "bench: six-lane kernels" 2>/dev/null |
  grep "^six-lane kernel" || echo "six-lane kernels: n/a (test_common missing)"
"$bin/test_common" "bench: loading the material database" 2>/dev/null |
  grep "^database load" || echo "database load: n/a (needs knit/io)"
if [[ -x "$bin/test_macro" ]]; then
  "$bin/test_macro" "bench: knit tensile cases" 2>/dev/null | grep -E "^knit tensile" ||
    echo "knit tensile cases: n/a (needs the shell's case runner)"
fi
