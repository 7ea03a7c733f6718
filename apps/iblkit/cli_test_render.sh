#!/usr/bin/env bash
# End-to-end checks of `iblkit render` (CTest cli_render): several lightings in one run, the lab
# photograph comparison, an SH grid that does not contain the object (warn and clamp), lights with
# positions, a near-field dataset, and bad input failing with one short line.
set -u
source "$(dirname "$0")/cli_check.sh" "$1"

if ! "$BIN" --help | grep -q "^  render"; then echo "no render subcommand in this build: skipped"; exit 0; fi

# A small SH grid of low-scene2 (volume (-0.5,0.5,-0.5)..(0.5,1.5,0.5)).
"$BIN" lab capture low-scene2 --random 60 --mapping mirrorball --size 16 --out "$T/cap" --quiet >/dev/null 2>&1
"$BIN" ilf build "$T/cap/sequence.json" --grid 4 --bands 3 --out "$T/g4.shgrid" --quiet >/dev/null 2>&1
check grid-inside ok "SH grid 4x4x4" -- "$BIN" render blob --light "$T/g4.shgrid" --at 0,1,0 --object-size 0.3 --size 48x36 \
  --backend cpu --out "$T/in.png"
out=$("$BIN" render blob --light "$T/g4.shgrid" --at 0,1,0 --object-size 0.3 --size 48x36 --backend cpu --out "$T/in.png" 2>&1)
if grep -q "outside the SH grid" <<<"$out"; then echo "FAIL grid-inside warns: $out"; fail=$((fail+1)); else pass=$((pass+1)); fi
check grid-outside-warns ok "outside the SH grid's volume" -- "$BIN" render blob --light "$T/g4.shgrid" --at 0,0,0 --size 48x36 \
  --backend cpu --out "$T/out.png"

# The GL path's SH-basis table variant (where this machine has GL), and a table size it refuses.
if "$BIN" render sphere --light "$T/g4.shgrid" --size 8x8 --backend gl --out "$T/gl_probe.png" >/dev/null 2>&1; then
  check grid-sh-table ok "gl backend" -- "$BIN" render blob --light "$T/g4.shgrid" --at 0,1,0 --object-size 0.3 --gloss 0.3 \
    --size 48x36 --backend gl --sh-table 64 --out "$T/table.png"
  check grid-sh-table-bad fail "SH table size 1 is out of range" -- "$BIN" render blob --light "$T/g4.shgrid" --at 0,1,0 \
    --size 48x36 --backend gl --sh-table 1 --out "$T/table.png"
else
  echo "no GL here: the --sh-table checks are skipped"; skip=$((skip+1))
fi

# Without OpenGL (EGL finds no vendor library): auto says so and renders on the CPU; an explicit
# --backend gl fails with the reason.
if "$BIN" render sphere --light "$T/g4.shgrid" --size 8x8 --backend gl --out "$T/gl_probe.png" 2>&1 | grep -q "this build has no OpenGL"; then
  echo "a build without the GL renderer: the no-GL checks are skipped"; skip=$((skip+1))
else
  check no-gl-auto ok "no OpenGL here.*rendering on the CPU" -- env __EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent.json \
    "$BIN" render sphere --light "$T/g4.shgrid" --size 16x12 --out "$T/nogl.png"
  check no-gl-explicit fail "no OpenGL here" -- env __EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent.json \
    "$BIN" render sphere --light "$T/g4.shgrid" --size 16x12 --backend gl --out "$T/nogl.png"
fi

# Two lightings, one photograph: one frame each and the comparison sheet.
check truth-two-lights ok "object relative L1" -- "$BIN" render blob --light "$T/g4.shgrid" --light "$PROBE" --at 0,0.85,0 \
  --object-size 0.35 --floor-size 0.8 --eye 0,1.45,1.5 --target 0,0.8,0 --size 64x48 --backend cpu --truth low-scene2 \
  --truth-samples 1 --out "$T/f9.png"
for f in f9_g4.png f9_forest.png f9_truth.exr f9_compare.png; do
  if [ -s "$T/$f" ]; then pass=$((pass+1)); else echo "FAIL truth-two-lights wrote no $f"; fail=$((fail+1)); fi
done

# Lights with positions (fusion's localised lights) are point lights.
cat > "$T/point.json" <<'JSON'
{"format": "iblkit.lights/1", "method": "test", "origin": [0, 0, 0],
 "lights": [{"direction": [0, 1, 0], "irradiance": [1, 1, 1], "position": [0, 2, 0]},
            {"direction": [1, 0, 0], "irradiance": [0.5, 0.5, 0.5]}]}
JSON
check point-lights ok "1 point lights and 1 directional" -- "$BIN" render sphere --light "$T/point.json" --size 48x36 --backend cpu \
  --out "$T/p.exr"

# Bad input.
printf '{"format": "iblkit.nothing/1"}' > "$T/bad.json"
check bad-format fail "iblkit.nearfield/1" -- "$BIN" render blob --light "$T/bad.json" --size 48x36 --out "$T/x.png"
check object-size-zero-blob fail "object-size must be > 0" -- "$BIN" render blob --light "$PROBE" --object-size 0 --size 48x36 --out "$T/x.png"
check missing-texture fail "nothere.png" -- "$BIN" render sphere --light "$PROBE" --texture "$T/nothere.png" --size 48x36 --out "$T/x.png"
check truth-unknown-scene fail "nowhere" -- "$BIN" render blob --light "$PROBE" --truth nowhere --size 48x36 --backend cpu --out "$T/x.png"

# A near-field luminaire's textured spotlights (when this build has the nearfield subcommand): the
# crypt lit by a small simulated dataset, on the CPU reference.
if "$BIN" --help | grep -q "^  nearfield"; then
  "$BIN" nearfield simulate bikelight --grid 3x3 --resolution 32 --out "$T/nf/nf.json" >/dev/null 2>&1
  check nearfield ok "textured spotlights" -- "$BIN" render "$(dirname "$0")/../../examples/crypt.obj" --object-size 0 --floor-size 0 \
    --light "$T/nf/nf.json" --luminaire=-0.55,0.45,-0.75 --luminaire-dir=-0.75,-0.2,-0.85 --eye 0.9,1.5,0.9 --target=-1.1,0.3,-1.5 \
    --fov 55 --size 64x64 --backend cpu --out "$T/nf.png"
else
  echo "no nearfield subcommand: the near-field render check is skipped"; skip=$((skip+1))
fi

echo "$pass passed, $fail failed, $skip skipped"
[ $fail -eq 0 ]
