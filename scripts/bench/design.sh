#!/usr/bin/env bash
# Inverse-design speed (issue 13, docs/design.md): example (b) (cases/design/graded_wale.json:
# 8 variables, p = 5, h = 1) optimized on one core. Targets: converged in <= 20 s; one
# gradient (forward run + sensitivities) <= 1.5 forward solves. Prints the figures.
#   scripts/bench/design.sh BUILD_DIR [DATABASE.h5]   (default: out/database.h5, else the synthetic
#   stand-in written by knit-meso synth)
set -euo pipefail
build="${1:?usage: design.sh BUILD_DIR [DATABASE.h5]}"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
db="${2:-$root/out/database.h5}"
if [[ ! -f "$db" ]]; then  # no pipeline database: the synthetic stand-in (other figures)
  db="$out/synth.h5"
  "$build/bin/knit-meso" synth --out "$db" > /dev/null
  echo "design: no out/database.h5, using the SYNTHETIC stand-in (knit-meso synth)"
fi
db="$(realpath "$db")"
for f in graded_wale graded_wale_case; do
  /usr/bin/python3 "$root/scripts/figures/resolve_case.py" "$root/cases/design/$f.json" "$db" "$out/$f.json"
done
start=$(date +%s.%N)
rc=0
/usr/bin/time -f "%U %S" -o "$out/cpu" taskset -c 0 "$build/bin/knit-macro" design \
  "$out/graded_wale.json" --output "$out/result" > "$out/log" 2>&1 || rc=$?
end=$(date +%s.%N)
s="$out/result/summary.txt"
[[ -f "$s" ]] || { cat "$out/log"; echo "design.sh: no result (exit $rc)"; exit 1; }
get() { sed -n "s/^$1: //p" "$s" | head -1; }
wall=$(awk "BEGIN{printf \"%.2f\", $end - $start}")
echo "design (b) graded_wale: 8 variables, p = 5, h = 1, database $db"
echo "  status: $(get status) (exit $rc); J $(get J_initial) -> $(get J_final)"
echo "  iterations $(get iterations), evaluations $(get evaluations) (each one forward run + gradient)"
cpu=$(awk '{printf "%.2f", $1 + $2}' "$out/cpu")
echo "  optimizer: $(get seconds) s wall; whole command (with the final run and its outputs): $wall s wall, $cpu s CPU on one core (target <= 20 s; wall > CPU when the core is shared)"
echo "  forward solves $(get forward_seconds) s, sensitivities $(get gradient_seconds) s over $(get gradients) gradients"
echo "  one gradient = $(get gradient_cost_in_forward_solves) forward solves (target <= 1.5)"
