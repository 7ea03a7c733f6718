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

# Issue 15: a ball camera with parallax writes ball_radius; the build starts rays on the ball unless
# --no-parallax; --kernel auto and the cross-validation in the summary and --json; the error volume.
check ball-capture ok "" -- "$BIN" --quiet lab capture low-scene2 --random 20 --camera ball --ball-radius 0.05 --parallax --size 16 --look 0,1,0 --out "$T/ball"
check ball-radius ok "0.05" -- python3 -c "import json; print(json.load(open('$T/ball/sequence.json'))['ball_radius'])"
check ball-build ok '"ball_radius": ?0.05' -- "$BIN" --quiet --json ilf build "$T/ball/sequence.json" --grid 4 --kernel 3 --cv-folds 0 --out "$T/b.shgrid"
check ball-no-parallax ok '"ball_radius": ?0(\.0)?[,}]' -- "$BIN" --quiet --json ilf build "$T/ball/sequence.json" --grid 4 --kernel 3 --cv-folds 0 --no-parallax --out "$T/b.shgrid"
check cv-summary ok "cv error" -- "$BIN" ilf build "$T/cap/sequence.json" --grid 4 --error-grid "$T/e.shgrid" --out "$T/g.shgrid"
check cv-json ok '"crossval"' -- "$BIN" --quiet --json ilf build "$T/cap/sequence.json" --grid auto --out "$T/g.shgrid"
check cv-slice ok "cross-validated relative error" -- "$BIN" ilf slice "$T/e.shgrid" --plane y=1 --size 16 --out "$T/e.png"
check cv-not-light fail "not radiance SH" -- "$BIN" --quiet ilf query "$T/e.shgrid" --at 0,1,0
check cv-error-grid-needs-folds fail "cv-folds" -- "$BIN" --quiet ilf build "$T/cap/sequence.json" --grid 4 --cv-folds 0 --error-grid "$T/x.shgrid" --out "$T/g.shgrid"
check cv-folds-range fail "cv-folds" -- "$BIN" --quiet ilf build "$T/cap/sequence.json" --grid 4 --cv-folds 1 --out "$T/g.shgrid"
check kernel-word fail "kernel" -- "$BIN" --quiet ilf build "$T/cap/sequence.json" --grid 4 --kernel wide --out "$T/g.shgrid"

echo "cli_ilf: $pass passed, $fail failed"
[ $fail -eq 0 ]
