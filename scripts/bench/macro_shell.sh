#!/usr/bin/env bash
# Macroscale shell timing (issue #3): the paper's 50 x 50 mm tensile patch, 20 load steps,
# at p = 5 with one element (target <= 0.2 s) and p = 7 with 4 x 4 elements (target <= 2 s),
# with 1 and 2 assembly threads. Prints wall and CPU seconds (CPU time is the fair figure on a
# loaded machine). Usage: scripts/bench/macro_shell.sh BUILD_DIR
set -euo pipefail
BUILD_DIR=${1:-build}
exe="$BUILD_DIR/bin/test_macro"
if [[ ! -x "$exe" ]]; then
  echo "macro_shell: $exe not found (build the tests first)" >&2
  exit 1
fi
"$exe" "[.bench]" | grep '^macro_shell'
