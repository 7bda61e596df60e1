#!/usr/bin/env bash
# Rod solver speed (issue #5): a 3-D rod with 100 control points, 20 load steps, <= 0.5 s on one core.
#   scripts/bench/rod.sh BUILD_DIR
set -euo pipefail
build="${1:?usage: rod.sh BUILD_DIR}"
"$build/bin/test_meso" "[.bench]" --use-colour no | grep -E "^rod:|FAILED|passed|failed" || true
