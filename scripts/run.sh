#!/usr/bin/env bash
# The main job (the README's first command): install what is missing, build, and run the
# reproduction pipeline on its defaults. Outputs go to out/ (override with KNIT_OUT=DIR).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/setup.sh"
# Only the executables the pipeline runs; the test executables are built by scripts/test.sh.
"$root/scripts/build.sh" "$root/build" knit-meso knit-macro
out="${KNIT_OUT:-$root/out}"
mkdir -p "$out"
if [ -f "$root/scripts/pipeline.mk" ]; then
  make -f "$root/scripts/pipeline.mk" ROOT="$root" BUILD="$root/build" OUT="$out" -j"$(nproc)" all
  grep -m1 '^\*\*Summary' "$out/report.md" | sed 's/\*\*//g; s/^/run: /' || true
  echo "run: report in $out/report.md (figures in $out/figures, results in $out/results)"
else
  echo "run: the reproduction pipeline has not landed yet; built executables:"
  ls -1 "$root/build/bin"
  "$root/build/bin/knit-meso" --version
  "$root/build/bin/knit-macro" --version
fi
