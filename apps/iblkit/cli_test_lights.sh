#!/usr/bin/env bash
# End-to-end checks of `iblkit lights` / `iblkit eval` with the optimiser (CTest cli_lights): it ends by
# its stopping rule and says so, eval's table and CSV carry iterations and convergence and name the SH
# reference by its bands, bad optimiser options fail with a short message. Small normal sets keep it to a few seconds.
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
check eval-csv-sh ok "^sh-3band,9," -- cat "$T/ev.csv"
check eval-sh-bands ok "sh +4 .*reference: 2-band SH" -- \
  "$BIN" eval "$PROBE" --methods median-cut --counts 2 --normals-level 2 --sh-bands 2 --no-pictures --out "$T/ev2"
check eval-csv-sh-bands ok "^sh-2band,4," -- cat "$T/ev2.csv"
check bad-normals-level fail "normals-level" -- "$BIN" eval "$PROBE" --normals-level 8 --no-pictures --out "$T/ev3"
check bad-tolerance fail "tolerance" -- "$BIN" lights "$PROBE" --method optimize --tolerance 0
check bad-iterations fail "iterations" -- "$BIN" lights "$PROBE" --method optimize --iterations 0

echo "cli_lights: $pass passed, $fail failed"
[ $fail -eq 0 ]
