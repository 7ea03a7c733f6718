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
# Issue 30: the kernel chosen for an object's neighbourhood (--focus); refused without a choice to make, far from every
# probe, non-finite or malformed.
check focus-summary ok "focus     0,1,0 " -- "$BIN" ilf build "$T/cap/sequence.json" --grid 4 --focus 0,1,0,0.1 --out "$T/f.shgrid"
check focus-json ok '"focus_error"' -- "$BIN" --quiet --json ilf build "$T/cap/sequence.json" --grid 4 --focus 0,1,0 --out "$T/f.shgrid"
check focus-fixed-kernel fail "kernel auto" -- "$BIN" --quiet ilf build "$T/cap/sequence.json" --grid 4 --kernel 3 --focus 0,1,0 --out "$T/f2.shgrid"
check focus-far fail "no probe" -- "$BIN" --quiet ilf build "$T/cap/sequence.json" --grid 4 --focus 100,100,100 --out "$T/f2.shgrid"
check focus-nan fail "focus" -- "$BIN" --quiet ilf build "$T/cap/sequence.json" --grid 4 --focus nan,1,0 --out "$T/f2.shgrid"
check focus-count fail "focus" -- "$BIN" --quiet ilf build "$T/cap/sequence.json" --grid 4 --focus 0,1 --out "$T/f2.shgrid"
check focus-nothing-written ok "" -- test ! -e "$T/f2.shgrid"

# Issue 15 §4: adaptive grids. adapt at tolerance 0 answers as the dense grid; densify gives it back
# byte for byte; query, slice, info, export-threejs read .shtree; a cut file and a cv-error volume fail.
check adapt-build ok "" -- "$BIN" --quiet ilf build "$T/cap/sequence.json" --grid 9 --kernel 3 --cv-folds 0 --out "$T/a.shgrid"
check adapt-zero ok '"max_point_error": ?0(\.0)?,' -- "$BIN" --quiet --json ilf adapt "$T/a.shgrid" --tolerance 0 --out "$T/a0.shtree"
check adapt-densify ok "" -- "$BIN" --quiet ilf densify "$T/a0.shtree" --out "$T/a0.shgrid"
check adapt-same-bytes ok "" -- cmp "$T/a.shgrid" "$T/a0.shgrid"
check adapt-query ok "" -- bash -c "diff <(\"$BIN\" --quiet --json ilf query \"$T/a.shgrid\" --at 0.1,1.1,-0.2 | grep -A3 irradiance) <(\"$BIN\" --quiet --json ilf query \"$T/a0.shtree\" --at 0.1,1.1,-0.2 | grep -A3 irradiance)"
check adapt-tolerance ok "largest point error" -- "$BIN" ilf adapt "$T/a.shgrid" --tolerance 0.05 --brick 2 --out "$T/a5.shtree"
check adapt-info ok '"adaptive": ?true' -- "$BIN" --quiet --json ilf info "$T/a5.shtree"
check adapt-slice ok "answering level" -- "$BIN" ilf slice "$T/a5.shtree" --plane y=1 --size 16 --levels --out "$T/lv.png"
check adapt-slice-irr ok "max irradiance" -- "$BIN" ilf slice "$T/a5.shtree" --plane y=1 --size 16 --out "$T/lv2.png"
check adapt-threejs ok "" -- "$BIN" --quiet ilf export-threejs "$T/a5.shtree" --out "$T/web3"
check adapt-levels-dense fail "not an adaptive grid" -- "$BIN" --quiet ilf slice "$T/a.shgrid" --plane y=1 --levels --out "$T/x.png"
check adapt-cut fail "truncated" -- bash -c "head -c 2000 \"$T/a5.shtree\" > \"$T/cut.shtree\" && \"$BIN\" --quiet ilf query \"$T/cut.shtree\" --at 0,1,0"
check adapt-error-volume fail "not radiance SH" -- "$BIN" --quiet ilf adapt "$T/e.shgrid" --tolerance 0.1 --out "$T/x.shtree"
check adapt-brick-range fail "brick" -- "$BIN" --quiet ilf adapt "$T/a.shgrid" --brick 1 --out "$T/x.shtree"
check query-points ok '"points": ?2' -- bash -c "echo '[[0,1,0],[0.2,1.1,-0.3]]' > \"$T/pts.json\" && \"$BIN\" --quiet --json ilf query \"$T/a5.shtree\" --points \"$T/pts.json\""
check query-points-bad fail "point 1 is not" -- bash -c "echo '[[0,1,0],[1,2]]' > \"$T/bad.json\" && \"$BIN\" --quiet --json ilf query \"$T/a.shgrid\" --points \"$T/bad.json\""
check query-needs-point fail "--at" -- "$BIN" --quiet ilf query "$T/a.shgrid"
check densify-not-tree fail "not an .shtree" -- "$BIN" --quiet ilf densify "$T/a.shgrid" --out "$T/x.shgrid"

echo "cli_ilf: $pass passed, $fail failed"
[ $fail -eq 0 ]
