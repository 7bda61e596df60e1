#!/usr/bin/env bash
# Fails if a tracked C++ file does not follow .clang-format. Fix with: scripts/check_format.sh --fix
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
mapfile -t files < <(git ls-files '*.cpp' '*.hpp' '*.h' '*.cc')
[ ${#files[@]} -eq 0 ] && exit 0
if [ "${1:-}" = "--fix" ]; then
  clang-format -i "${files[@]}"
  exit 0
fi
if ! clang-format --dry-run -Werror "${files[@]}" 2>/tmp/knit-format.$$; then
  grep -E "^[^ ].*: (error|warning):" /tmp/knit-format.$$ | cut -d: -f1 | sort -u | sed 's/^/  not formatted: /' >&2
  rm -f /tmp/knit-format.$$
  echo "format: run scripts/check_format.sh --fix" >&2
  exit 1
fi
rm -f /tmp/knit-format.$$
echo "format: ${#files[@]} files follow .clang-format"
