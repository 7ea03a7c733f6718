#!/usr/bin/env bash
# End-to-end checks of the lab options the ILF accuracy measurement relies on (registered with CTest
# as cli_ilf; a few seconds): `lab capture --look` writes the rotation into the manifest and
# `ilf build` accepts it; `lab truth --blind-cone/--blind-axis` gives sh_visible; bad values fail
# with a one-line message.
set -u
source "$(dirname "$0")/cli_check.sh" "$1"

check look-up ok "" -- "$BIN" --quiet lab capture low-scene2 --random 12 --mapping mirrorball --size 16 --dead-angle 4.2 --look 0,1,0 --out "$T/cap"
# the probe's +Z is world +Y: the rotation's third column is (0, 1, 0)
check look-rotation ok "ok" -- python3 -c "import json,sys; r=json.load(open('$T/cap/sequence.json'))['rotation']; print('ok' if [r[0][2],r[1][2],r[2][2]]==[0,1,0] else r)"
check look-build ok "" -- "$BIN" --quiet ilf build "$T/cap/sequence.json" --grid 4 --out "$T/g.shgrid"
check look-zero fail "look" -- "$BIN" --quiet lab capture low-scene2 --probe 0,1,0 --look 0,0,0 --out "$T/bad"
check blind-cone ok '"sh_visible"' -- "$BIN" --quiet --json lab truth low-scene2 --at 0,1,0 --size 16 --samples 1 --bands 3 --blind-cone 4.2 --blind-axis 0,-1,0
check blind-cone-none ok "" -- bash -c "! \"$BIN\" --quiet --json lab truth low-scene2 --at 0,1,0 --size 16 --samples 1 --bands 3 | grep -q sh_visible"
check blind-cone-range fail "blind cone" -- "$BIN" --quiet lab truth low-scene2 --at 0,1,0 --size 16 --samples 1 --bands 3 --blind-cone 200
check blind-axis-zero fail "axis" -- "$BIN" --quiet lab truth low-scene2 --at 0,1,0 --size 16 --samples 1 --bands 3 --blind-cone 4 --blind-axis 0,0,0

echo "cli_ilf: $pass passed, $fail failed"
[ $fail -eq 0 ]
