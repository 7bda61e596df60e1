#!/usr/bin/env bash
# The whole test suite: install what is missing, build (Release), run every CTest test, then
# build the unit tests under AddressSanitizer + UndefinedBehaviorSanitizer and run them.
# This is the README's second command and what CI runs (.ci/run).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# Each phase's wall time, printed at the end, also when a phase fails (session 51: the
# suite's ~15-minute aim is kept in view phase by phase; docs/build.md).
phase_times=()
phase_start=$SECONDS
phase() {  # phase NAME: closes the running phase's clock under NAME
  phase_times+=("$1 $((SECONDS - phase_start)) s")
  phase_start=$SECONDS
}
print_phase_times() {
  local joined=""
  ((${#phase_times[@]})) && printf -v joined '%s, ' "${phase_times[@]}"
  echo "== suite: ${joined}total ${SECONDS} s on $(nproc) core(s) =="
}
trap print_phase_times EXIT
KNIT_SETUP_TESTS=1 "$root/scripts/setup.sh"   # python3-vtk9 too, for CTest vtk_check
phase "setup"
jobs="$(nproc)"

echo "== build (Release) =="
"$root/scripts/build.sh" "$root/build"
phase "build"
echo "== tests (Release) =="
(cd "$root/build" && ctest --output-on-failure --parallel "$jobs")
phase "tests"

echo "== unit tests under ASan + UBSan =="
# Only test files with a [unit] test are compiled in this build (tests/CMakeLists.txt).
san="$root/build-sanitize"
gen=()
command -v ninja >/dev/null && [ ! -f "$san/Makefile" ] && gen=(-G Ninja)
# -O1 with line tables only: what ASan recommends, and about half the compile time of -O2 -g.
# The code that runs once per process (CLI, input, output, Catch2's runner: KNIT_OPT_COLD) and
# the test files (KNIT_OPT_TESTS) at -Og: under ASan + UBSan they compile in ~35-50 % less time
# than at -O1 (-O0 saves no more, and made the tests that refine or fuzz cases several times
# slower); the library's numerical code, where the tests spend their time, stays at -O1
# (KNIT_OPT_HOT empty). Build type None; the unity groups apply as in Release (docs/build.md).
# UBSan's null and alignment checks are left out (KNIT_SANITIZE_EXCLUDE in CMakeLists.txt: they
# doubled the compile of the Eigen fixed-size code; ASan reports a null dereference itself).
cmake -S "$root" -B "$san" "${gen[@]}" -DCMAKE_BUILD_TYPE=None -DCMAKE_CXX_FLAGS="-O1 -g1" \
  -DKNIT_OPT_COLD=-Og -DKNIT_OPT_TESTS=-Og -DKNIT_SANITIZE=ON >/dev/null
cmake --build "$san" --parallel "$jobs"
phase "sanitizer build"
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:halt_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
(cd "$san" && ctest --output-on-failure --parallel "$jobs")
phase "sanitizer tests"

echo "== formatting (.clang-format) =="
"$root/scripts/check_format.sh"
phase "format"
