#!/usr/bin/env bash
# Shell solver timing (issue 14 "And speed"; printed figures, never a timed test):
#  * dense/sparse crossover: the Sze cantilever (p = 3) at 2..32 x 1 elements with every
#    linear-solver path (dense/sparse x LU/LDLT), one thread;
#  * the Sze cantilever at 16x1, 32x1, 64x1 with the defaults (target: 64x1/16x1 <= 4.5);
#  * the tensile patch at p = 4, 8 x 40 elements (1,584 DOFs, 1,440 unknowns, 40 steps;
#    targets <= 5 s on one core, <= 15 ms per Newton iteration) and 16 x 100 elements
#    (6,240 DOFs, 6,000 unknowns; <= 60 ms per iteration), with the time per Newton
#    iteration split into assembly and solve, as wall and as CPU time (on a loaded machine
#    the CPU figures of the one-thread runs are the cost); each also with the SimplicialLDLT
#    instead of CHOLMOD's supernodal Cholesky;
#  * indefinite tangents (session 38): a square compressed past its limit point, p = 4, 32 x 32
#    to 128 x 128 elements, the tangents the supernodal Cholesky refuses factorized by MUMPS's
#    multifrontal LDLT and by Eigen's SimplicialLDLT (filter "bench: indefinite*", ~7 min).
# Figures of 30 Nov 2026: docs/solver.md "Benchmark" (rounds 1-4). A solver change must leave the results
# unchanged: run the same case before and after and compare the two results.h5 with
# scripts/bench/compare_results.py (1e-8 relative).
# Usage: scripts/bench/solver.sh [BUILD_DIR] [CATCH_TEST_NAME_FILTER]
set -euo pipefail
BUILD_DIR=${1:-build}
exe="$BUILD_DIR/bin/test_macro"
if [[ ! -x "$exe" ]]; then
  echo "solver bench: $exe not found (build test_macro first)" >&2
  exit 1
fi
# The machine is shared: the load average beside the figures (the CPU times of the one-thread
# runs are the costs; wall times, and the two-thread gain, only mean something when idle).
echo "solver start $(date -u +%H:%M:%S) UTC, load average $(cut -d' ' -f1-3 /proc/loadavg)"
"$exe" "${2:-[.bench_solver]}" | grep '^solver'
echo "solver end $(date -u +%H:%M:%S) UTC, load average $(cut -d' ' -f1-3 /proc/loadavg)"
