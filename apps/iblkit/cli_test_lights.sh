#!/usr/bin/env bash
# End-to-end checks of `iblkit lights` / `iblkit eval` with the optimiser (CTest cli_lights): it ends by
# its stopping rule and says so, eval's table and CSV carry iterations and convergence, bad optimiser
# options fail with a short message. Small normal sets keep it to a few seconds.
set -u
source "$(dirname "$0")/cli_check.sh" "$1"
[ -f "$PROBE" ] || { echo "SKIP: blender-data probe missing"; exit 0; }

check optimize-converges ok "optimiser: [0-9]+ iterations .*converged" -- \
  "$BIN" lights "$PROBE" --method optimize --count 8 --normals-level 3 --out "$T/o.json"
check optimize-json ok '"converged": ?true' -- \
  "$BIN" lights "$PROBE" --method optimize --count 4 --normals-level 3 --json
check eval-table ok "optimize +16 .* it \([0-9]+ on all normals\), cost ×[0-9.e-]+, converged" -- \
  "$BIN" eval "$PROBE" --methods median-cut,optimize --counts 2,16 --normals-level 3 --no-pictures --out "$T/ev"
check eval-csv ok "^optimize,16,.*,yes," -- cat "$T/ev.csv"
check bad-tolerance fail "tolerance" -- "$BIN" lights "$PROBE" --method optimize --tolerance 0
check bad-iterations fail "iterations" -- "$BIN" lights "$PROBE" --method optimize --iterations 0

echo "cli_lights: $pass passed, $fail failed"
[ $fail -eq 0 ]
