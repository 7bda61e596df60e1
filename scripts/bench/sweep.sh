#!/usr/bin/env bash
# Mesoscale database sweep benchmark (issues #7, #11): the full default database (5 loop lengths
# x (13 paper paths x 20 steps + 25 coverage + 12 held-out paths), fit included) on 2 cores, against the target of <= 5 minutes (the
# paper's code: ~30 min per loop length on 6 cores). Prints the time per case and the total.
#   scripts/bench/sweep.sh BUILD_DIR [SWEEP.json] [THREADS]
# Set KNIT_BENCH_SWEEP_SKIP=1 to skip it (it takes minutes and all the cores);
# KNIT_BENCH_SWEEP_KEEP=FILE keeps the database it wrote.
set -uo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${1:-$root/build}"
input="${2:-$root/cases/sweep/default.json}"
threads="${3:-2}"
exe="$build/bin/knit-meso"
if [[ "${KNIT_BENCH_SWEEP_SKIP:-0}" == 1 ]]; then
  echo "sweep: skipped (KNIT_BENCH_SWEEP_SKIP=1)"
  exit 0
fi
if [[ ! -x "$exe" ]]; then
  echo "sweep: n/a ($exe missing)"
  exit 0
fi
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
start=$(date +%s.%N)
"$exe" sweep "$input" --output "$out/db.h5" --threads "$threads" --plain --force \
  > "$out/log.txt" 2> "$out/progress.txt"
rc=$?
end=$(date +%s.%N)
cat "$out/log.txt"
if [[ -n "${KNIT_BENCH_SWEEP_KEEP:-}" && -f "$out/db.h5" ]]; then
  cp "$out/db.h5" "$KNIT_BENCH_SWEEP_KEEP" && echo "kept the database as $KNIT_BENCH_SWEEP_KEEP"
fi
wall=$(echo "$end - $start" | bc)
echo "sweep benchmark: $(basename "$input"), $threads threads: wall $wall s (exit code $rc)"
echo "load average at the end: $(cut -d' ' -f1-3 /proc/loadavg) (the machine is shared)"
echo "target: full default database (5 x 50 paths, fit included) <= 300 s on 2 cores" \
  "(paper: ~1800 s per loop length on 6 cores)"
awk -v w="$wall" 'BEGIN { printf "verdict: %s (%.0f%% of the target)\n", (w <= 300 ? "MET" : "NOT MET"), 100 * w / 300 }'
