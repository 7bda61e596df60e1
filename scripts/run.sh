#!/usr/bin/env bash
# The main job (the README's first command): install what is missing, build, and run the
# reproduction pipeline on its defaults. Outputs go to out/ (override with KNIT_OUT=DIR).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="${KNIT_OUT:-$root/out}"
# A KNIT_OUT of the user's is written only if it is new, empty or an earlier run's output (the
# marker file .knitscale-output, written below): the pipeline writes figures/, results/, logs/
# ... into it and `make clean` removes them, so another directory's files are not ours to
# replace. The default out/ of the checkout is the pipeline's own.
marker="$out/.knitscale-output"
# make cannot carry every path: a space splits it into two words (`make clean` then removed
# "DIR/my" and "out/..." of the current directory: session 36's red team), a $ is expanded by
# make (the outputs went to another directory, exit 0), ; # : = % and quotes break its syntax.
# The output path is refused before anything is written, with the character named.
case "$out" in
  *[!A-Za-z0-9/._+@-]*)
    bad=$(printf '%s' "$out" | tr -d 'A-Za-z0-9/._+@-' | cut -c1)
    echo "run: KNIT_OUT=$out holds the character '$bad', which the pipeline's makefile cannot" \
      "carry in a path (use letters, digits and / . _ - + @); give another directory" >&2
    exit 2 ;;
esac
if [ -n "${KNIT_OUT:-}" ]; then
  if [ -L "$out" ] && [ ! -e "$out" ]; then
    echo "run: KNIT_OUT=$out is a dangling symbolic link; give a real directory" >&2
    exit 2
  fi
  # The output of another knitscale program (knit-macro run writes the same marker file, with
  # its own name; session 36's red team: such a directory was taken for the pipeline's).
  if [ -f "$marker" ] && ! head -n 1 "$marker" | grep -q "reproduction pipeline"; then
    echo "run: KNIT_OUT=$out is the output of another program ($(head -n 1 "$marker")), not" \
      "of the pipeline: its files are not ours to replace; give another directory" >&2
    exit 2
  fi
  if [ -e "$out" ] && [ ! -d "$out" ]; then
    echo "run: KNIT_OUT=$out exists and is not a directory" >&2
    exit 2
  fi
  # Inside a run's output (a marker with a "for:" or "file:" line; the review of session 46:
  # the pipeline wrote figures/, logs/ and report.md into a design's output, whose next design
  # was then refused). The pipeline's own OUT, a container, says neither.
  p=$(dirname "$(realpath -m "$out")")
  while [ "$p" != / ]; do
    if [ -f "$p/.knitscale-output" ] && grep -q -E '^(for|file): ' "$p/.knitscale-output"; then
      echo "run: KNIT_OUT=$out lies inside $p, the output of a knitscale run (its" \
        ".knitscale-output says so): the pipeline would change that run's files; give a path" \
        "outside it" >&2
      exit 2
    fi
    p=$(dirname "$p")
  done
  if [ -d "$out" ] && [ -n "$(ls -A "$out")" ] && [ ! -f "$marker" ]; then
    echo "run: KNIT_OUT=$out is a non-empty directory that is not a knitscale output (no" \
      ".knitscale-output file): its files are not ours to replace; give a new or empty directory" >&2
    exit 2
  fi
fi
# The output path is judged first (above), then what is missing is installed.
"$root/scripts/setup.sh"
mkdir -p "$out"
[ -f "$marker" ] || echo "knitscale output: the reproduction pipeline (scripts/run.sh)" > "$marker"
if [ -f "$root/scripts/pipeline.mk" ]; then
  # Only the executables the pipeline runs; the test executables are built by scripts/test.sh.
  pipeline=(make -f "$root/scripts/pipeline.mk" ROOT="$root" BUILD="$root/build" OUT="$out")
  # knit-meso first; then the material database (the mesoscale sweep, the pipeline's longest
  # step, which needs knit-meso only) runs while knit-macro is compiled: the cores idle at
  # neither's serial ends (the last compiles and links; the sweep's last cases and its fit).
  # docs/build.md "Main job".
  # The background job also draws what needs knit-meso only (make target meso: Figs. 5 and 6,
  # the sensitivity figure) once the database is there.
  "$root/scripts/build.sh" "$root/build" knit-meso
  "${pipeline[@]}" meso &
  db_pid=$!
  build_rc=0
  "$root/scripts/build.sh" "$root/build" knit-macro || build_rc=$?
  db_rc=0
  wait "$db_pid" || db_rc=$?
  [ "$build_rc" -eq 0 ] || { echo "run: building knit-macro failed"; exit "$build_rc"; }
  [ "$db_rc" -eq 0 ] || { echo "run: the material database (make target meso) failed (see $out/logs)"; exit "$db_rc"; }
  "${pipeline[@]}" -j"$(nproc)" all
  grep -m1 '^\*\*Summary' "$out/report.md" | sed 's/\*\*//g; s/^/run: /' || true
  echo "run: report in $out/report.md (figures in $out/figures, results in $out/results)"
else
  "$root/scripts/build.sh" "$root/build" knit-meso knit-macro
  echo "run: the reproduction pipeline has not landed yet; built executables:"
  ls -1 "$root/build/bin"
  "$root/build/bin/knit-meso" --version
  "$root/build/bin/knit-macro" --version
fi
