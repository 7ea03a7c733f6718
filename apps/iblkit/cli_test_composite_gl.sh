#!/usr/bin/env bash
# End-to-end checks of the GL compositor (CTest cli_composite_gl): `iblkit composite --backend gl` and
# `--backend auto` on a small low-scene2 photograph (measured against the lab's truth; the pixels far from the
# object are the photograph exactly), and `iblkit view --composite` under Xvfb writing a screenshot that shows
# the object over the photograph. Skips what needs GL, a display server or the viewer where they are missing.
set -u
source "$(dirname "$0")/cli_check.sh" "$1"

if ! "$BIN" --help | grep -q "^  composite"; then echo "no composite subcommand in this build: skipped"; exit 0; fi
CAM=(--eye 0,1.3,2.2 --target 0,0.3,0 --fov 40)
OBJ=(--object blob --at 0.1,0.2,0.1 --object-size 0.3 --triangles 3000)
"$BIN" lab photograph low-scene2 "${CAM[@]}" --width 96 --height 72 --samples 2 --out "$T/photo.exr" --quiet >/dev/null 2>&1
"$BIN" lab photograph low-scene2 "${CAM[@]}" --width 96 --height 72 --samples 2 "${OBJ[@]}" --out "$T/truth.exr" --quiet >/dev/null 2>&1
"$BIN" lab capture low-scene2 --fusion --probe 0.1,0.2,0.1 --size 32 --out "$T/one" --quiet >/dev/null 2>&1

out=$("$BIN" composite "$T/photo.exr" "${CAM[@]}" --probes "$T/one/probes.json" "${OBJ[@]}" --backend auto --samples 8 \
      --out "$T/auto.exr" --json 2>&1); rc=$?
if [ $rc -eq 0 ] && grep -q '"backend": "cpu"' <<<"$out" && grep -q "no OpenGL context" <<<"$out"; then
  echo "no OpenGL context here (auto chose the CPU, saying why): the GL checks are skipped"; skip=$((skip+1))
  echo "$pass passed, $fail failed, $skip skipped"; exit 0
fi
if [ $rc -eq 0 ] && grep -q '"backend": "gl"' <<<"$out"; then pass=$((pass+1)); else echo "FAIL auto: rc $rc: $out"; fail=$((fail+1)); fi
check gl ok "against .*object .* shadow .* unchanged" -- "$BIN" composite "$T/photo.exr" "${CAM[@]}" --probes "$T/one/probes.json" \
  "${OBJ[@]}" --backend gl --samples 8 --out "$T/gl.exr" --layers "$T/layers" --truth "$T/truth.exr"
for f in mask difference albedo render_with render_without; do
  if [ -f "$T/layers/$f.exr" ]; then pass=$((pass+1)); else echo "FAIL layers: no $f.exr"; fail=$((fail+1)); fi
done
# The material as on the CPU: a glossy, textured object composites on the GL path too.
"$BIN" --quiet convert "$PROBE" "$T/tex.exr" --mapping latlong --size 16 >/dev/null 2>&1
check gl-material ok "composite|wrote" -- "$BIN" composite "$T/photo.exr" "${CAM[@]}" --probes "$T/one/probes.json" \
  "${OBJ[@]}" --backend gl --samples 8 --gloss 0.3 --exponent 30 --lobe blinn --texture "$T/tex.exr" --out "$T/gl_material.exr"
check bad-backend fail "expected cpu, gl or auto" -- "$BIN" composite "$T/photo.exr" "${CAM[@]}" --probes "$T/one/probes.json" --backend vulkan
# Beyond the object's reach (its shadow maps' taps, its sphere's share below the cut-off) the composite is the
# photograph exactly: here about half the frame (the far walls and floor); the object's pixels are not.
if command -v oiiotool >/dev/null; then
  changed=$(oiiotool "$T/gl.exr" "$T/photo.exr" --diff 2>&1 | grep -m1 "over 1e-06" | sed -E 's/.*\(([0-9.]+)%\).*/\1/')
  near=$(oiiotool "$T/gl.exr" --cut 20x20+40+36 "$T/photo.exr" --cut 20x20+40+36 --diff 2>&1 | grep -c "PASS")
  if awk -v c="${changed:-100}" 'BEGIN{exit !(c < 70)}' && [ "$near" -eq 0 ]; then pass=$((pass+1));
  else echo "FAIL unchanged: ${changed:-?} % of the pixels differ from the photograph (expected < 70), object region same: $near"; fail=$((fail+1)); fi
fi

if "$BIN" --help | grep -q "^  view" && command -v xvfb-run >/dev/null; then
  out=$(xvfb-run -a "$BIN" view blob --composite "$T/photo.exr" "${CAM[@]}" --probes "$T/one/probes.json" --at 0.1,0.2,0.1 \
        --object-size 0.3 --triangles 3000 --frames 3 --screenshot "$T/shot.png" --json 2>&1); rc=$?
  if [ $rc -eq 0 ] && grep -q '"frames": *3' <<<"$out" && grep -q '"mode": *"composite"' <<<"$out" && [ -s "$T/shot.png" ]; then
    pass=$((pass+1)); else echo "FAIL view-composite: rc $rc: $out"; fail=$((fail+1)); fi
  # The screenshot is the photograph's frame, and the bright blob stands on the floor near its centre.
  if command -v oiiotool >/dev/null && [ -s "$T/shot.png" ]; then
    size=$(oiiotool --info "$T/shot.png" 2>/dev/null | grep -Eo "96 x +72")
    mid=$(oiiotool "$T/shot.png" --cut 12x12+48+30 --printstats 2>/dev/null | awk '/Stats Max/{print $3}')
    if [ -n "$size" ] && awk -v m="$mid" 'BEGIN{exit !(m > 0.5)}'; then pass=$((pass+1)); else echo "FAIL screenshot: size '$size', max near the object $mid"; fail=$((fail+1)); fi
  fi
  check view-no-light fail "light" -- env "$BIN" view blob --frames 1
else
  echo "no viewer or no xvfb-run: the view checks are skipped"; skip=$((skip+1))
fi
echo "$pass passed, $fail failed, $skip skipped"
[ $fail -eq 0 ]
