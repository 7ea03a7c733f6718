#!/usr/bin/env bash
# End-to-end checks of `iblkit lab photograph` and `iblkit composite` (CTest cli_composite): a tiny
# low-scene2 photograph with and without the blob, a one-probe fusion set, the composite measured
# against the truth, the layers, a camera file, and bad input failing with one short line.
set -u
source "$(dirname "$0")/cli_check.sh" "$1"

if ! "$BIN" --help | grep -q "^  composite"; then echo "no composite subcommand in this build: skipped"; exit 0; fi

CAM=(--eye 0,1.3,2.2 --target 0,0.3,0 --fov 40)
OBJ=(--object blob --at 0,0.2,0 --object-size 0.3 --triangles 2000)
check photo ok "photographed low-scene2" -- "$BIN" lab photograph low-scene2 "${CAM[@]}" --width 48 --height 36 --samples 1 \
  --out "$T/photo.exr"
check truth ok "the object covers" -- "$BIN" lab photograph low-scene2 "${CAM[@]}" --width 48 --height 36 --samples 1 "${OBJ[@]}" \
  --mask "$T/mask.exr" --out "$T/truth.exr"
"$BIN" lab capture low-scene2 --fusion --probe 0,0.5,0 --size 16 --out "$T/fus" --quiet >/dev/null 2>&1
check composite ok "against .*object .* shadow .* unchanged" -- "$BIN" composite "$T/photo.exr" "${CAM[@]}" --probes "$T/fus/probes.json" \
  "${OBJ[@]}" --samples 16 --object-samples 32 --out "$T/comp.exr" --layers "$T/layers" --truth "$T/truth.exr"
if [ -f "$T/layers/proxy_overlay.png" ]; then pass=$((pass+1)); else echo "FAIL layers: no proxy_overlay.png"; fail=$((fail+1)); fi
for f in mask difference albedo render_with render_without; do
  if [ -f "$T/layers/$f.exr" ]; then pass=$((pass+1)); else echo "FAIL layers: no $f.exr"; fail=$((fail+1)); fi
done
check json ok '"object_pixels"' -- "$BIN" composite "$T/photo.exr" "${CAM[@]}" --probes "$T/fus/probes.json" "${OBJ[@]}" --samples 4 \
  --object-samples 4 --out "$T/comp.png" --json

# Ordinary photographs in and out: an 8-bit JPEG and a 16-bit TIFF backplate, composited in linear light and
# written back through the same response, bit depth and metadata; far pixels keep their codes (oiiotool --diff).
if command -v oiiotool >/dev/null; then
  oiiotool "$T/photo.exr" --mulc 0.4 --colorconvert linear sRGB -d uint8 --compression jpeg:85 -o "$T/photo.jpg" \
    --attrib Make iblkit-test >/dev/null 2>&1
  oiiotool "$T/photo.exr" --mulc 1.5 -d uint16 -o "$T/photo16.tif" >/dev/null 2>&1
  check ldr-jpeg ok '"jpeg_quality": 85' -- "$BIN" composite "$T/photo.jpg" "${CAM[@]}" --probes "$T/fus/probes.json" "${OBJ[@]}" \
    --samples 4 --object-samples 4 --out "$T/comp.jpg" --json
  check ldr-jpeg-exif ok 'iblkit-test' -- iinfo -v "$T/comp.jpg"
  check ldr-tiff16 ok '"bits": 16' -- "$BIN" composite "$T/photo16.tif" "${CAM[@]}" --probes "$T/fus/probes.json" "${OBJ[@]}" \
    --response linear --samples 4 --object-samples 4 --out "$T/comp16.tif" --json
  check ldr-tiff16-saturated ok '"saturated_pixels": [1-9]' -- "$BIN" composite "$T/photo16.tif" "${CAM[@]}" \
    --probes "$T/fus/probes.json" "${OBJ[@]}" --response linear --samples 4 --object-samples 4 --out "$T/comp16b.tif" --json
  # A photograph one stop brighter than the probe: the match's gain doubles (the lab's probe here carries fewer
  # bounces than its photograph, so the gain of the photograph as it is is not 1 but their ratio).
  oiiotool "$T/photo.exr" --mulc 2 -o "$T/photo_x2.exr" >/dev/null 2>&1
  g1=$("$BIN" composite "$T/photo.exr" "${CAM[@]}" --probes "$T/fus/probes.json" "${OBJ[@]}" --samples 4 --object-samples 4 \
    --out "$T/c_x1.exr" --json 2>/dev/null | python3 -c 'import json,sys; print(json.load(sys.stdin)["match"]["gain"][1])')
  g2=$("$BIN" composite "$T/photo_x2.exr" "${CAM[@]}" --probes "$T/fus/probes.json" "${OBJ[@]}" --samples 4 --object-samples 4 \
    --out "$T/c_x2.exr" --json 2>/dev/null | python3 -c 'import json,sys; print(json.load(sys.stdin)["match"]["gain"][1])')
  check match-one-stop ok "" -- python3 -c "import sys; r = $g2 / $g1; print(r); sys.exit(0 if abs(r - 2) < 0.02 else 1)"
  # A grey card: the match from the pixels of one patch of floor (rows 28-33 of the 48x36 photograph).
  g3=$("$BIN" composite "$T/photo_x2.exr" "${CAM[@]}" --probes "$T/fus/probes.json" "${OBJ[@]}" --samples 4 --object-samples 4 \
    --grey-card 14,28,20,6 --out "$T/c_card.exr" --json 2>/dev/null | python3 -c 'import json,sys; print(json.load(sys.stdin)["match"]["gain"][1])')
  g0=$("$BIN" composite "$T/photo.exr" "${CAM[@]}" --probes "$T/fus/probes.json" "${OBJ[@]}" --samples 4 --object-samples 4 \
    --grey-card 14,28,20,6 --out "$T/c_card0.exr" --json 2>/dev/null | python3 -c 'import json,sys; print(json.load(sys.stdin)["match"]["gain"][1])')
  check match-grey-card ok "" -- python3 -c "import sys; r = $g3 / $g0; print(r); sys.exit(0 if abs(r - 2) < 0.02 else 1)"
  check match-grey-card-off-frame fail "must lie inside" -- "$BIN" composite "$T/photo_x2.exr" "${CAM[@]}" \
    --probes "$T/fus/probes.json" "${OBJ[@]}" --grey-card 40,30,20,20 --out "$T/c_card2.exr"
  check match-grey-card-no-rect fail "give the card" -- "$BIN" composite "$T/photo_x2.exr" "${CAM[@]}" \
    --probes "$T/fus/probes.json" "${OBJ[@]}" --match grey-card --out "$T/c_card3.exr"
  check match-off ok "composited" -- "$BIN" composite "$T/photo_x2.exr" "${CAM[@]}" --probes "$T/fus/probes.json" "${OBJ[@]}" \
    --samples 4 --object-samples 4 --match off --out "$T/c_x2off.exr"
  check ldr-bad-response fail "no-such.json" -- "$BIN" composite "$T/photo.jpg" "${CAM[@]}" --probes "$T/fus/probes.json" \
    "${OBJ[@]}" --response "$T/no-such.json" --out "$T/c_bad.jpg"
else
  echo "oiiotool not found (apt install openimageio-tools): the LDR backplate checks skipped"; skip=$((skip+1))
fi

# A camera file: the same frame; one of another size is refused.
echo '{"format":"iblkit.camera/1","eye":[0,1.3,2.2],"target":[0,0.3,0],"up":[0,1,0],"fov_y_deg":40}' >"$T/cam.json"
check camera-file ok "composited" -- "$BIN" composite "$T/photo.exr" --camera "$T/cam.json" --probes "$T/fus/probes.json" "${OBJ[@]}" \
  --samples 4 --object-samples 4 --out "$T/c2.exr"
echo '{"format":"iblkit.camera/1","eye":[0,1.3,2.2],"target":[0,0.3,0],"fov_y_deg":40,"width":640,"height":480}' >"$T/cam640.json"
check camera-size fail "is 640x480 but the photograph" -- "$BIN" composite "$T/photo.exr" --camera "$T/cam640.json" \
  --probes "$T/fus/probes.json" "${OBJ[@]}" --out "$T/c3.exr"

# Bad input.
check resting-on-floor ok "composited" -- "$BIN" composite "$T/photo.exr" "${CAM[@]}" --probes "$T/fus/probes.json" \
  --object sphere --at 0,0.15,0 --object-size 0.3 --samples 4 --object-samples 4 --out "$T/c_rest.exr"
check object-in-floor fail "the object intersects the proxy" -- "$BIN" composite "$T/photo.exr" "${CAM[@]}" --probes "$T/fus/probes.json" \
  --object blob --at 0,0.05,0 --object-size 0.3 --triangles 2000 --out "$T/c4.exr"
check no-camera fail "give the photograph's camera" -- "$BIN" composite "$T/photo.exr" --probes "$T/fus/probes.json" --out "$T/c5.exr"
check no-light fail "give the light" -- "$BIN" composite "$T/photo.exr" "${CAM[@]}" "${OBJ[@]}" --out "$T/c6.exr"
check probe-no-position fail "needs its position" -- "$BIN" composite "$T/photo.exr" "${CAM[@]}" "${OBJ[@]}" --light "$T/fus/probes/p0.exr" \
  --proxy "$T/fus/proxy.obj" --out "$T/c7.exr"
check probe-outside-warns ok "lies outside the proxy" -- "$BIN" composite "$T/photo.exr" "${CAM[@]}" "${OBJ[@]}" --light "$T/fus/probes/p0.exr" \
  --at-probe 0,5,0 --proxy "$T/fus/proxy.obj" --samples 4 --object-samples 4 --out "$T/c8.exr"
check bad-backend fail "expected cpu, gl or auto" -- "$BIN" composite "$T/photo.exr" "${CAM[@]}" --probes "$T/fus/probes.json" --backend vulkan \
  --out "$T/c9.exr"

# The object's surface: a texture at its UVs, a glossy lobe (as render's options).
"$BIN" preview "$T/photo.exr" "$T/tex.png" --quiet >/dev/null 2>&1
check texture ok "composited" -- "$BIN" composite "$T/photo.exr" "${CAM[@]}" --probes "$T/fus/probes.json" "${OBJ[@]}" --texture "$T/tex.png" \
  --samples 4 --object-samples 4 --out "$T/c10.exr"
check gloss ok "composited" -- "$BIN" composite "$T/photo.exr" "${CAM[@]}" --probes "$T/fus/probes.json" "${OBJ[@]}" --gloss 0.3 \
  --exponent 40 --lobe blinn --samples 4 --object-samples 4 --out "$T/c11.exr"
check texture-missing fail "nonexistent" -- "$BIN" composite "$T/photo.exr" "${CAM[@]}" --probes "$T/fus/probes.json" "${OBJ[@]}" \
  --texture "$T/nonexistent.png" --out "$T/c12.exr"
check gloss-range fail "gloss" -- "$BIN" composite "$T/photo.exr" "${CAM[@]}" --probes "$T/fus/probes.json" "${OBJ[@]}" --gloss 2 \
  --out "$T/c13.exr"
check albedo-range fail "must lie in \[0, 1\]" -- "$BIN" composite "$T/photo.exr" "${CAM[@]}" --probes "$T/fus/probes.json" \
  --object blob --at 0,0.2,0 --albedo 1.5,0.5,0.5 --out "$T/c14.exr"

# The object outside the light's volume: under the room's floor (outside its proxy), outside an SH grid.
check object-outside-proxy fail "lies outside the proxy of" -- "$BIN" composite "$T/photo.exr" "${CAM[@]}" --probes "$T/fus/probes.json" \
  --object blob --at 0,-1,0 --object-size 0.3 --triangles 2000 --out "$T/c15.exr"
check object-outside-proxy-light fail "lies outside the proxy of" -- "$BIN" composite "$T/photo.exr" "${CAM[@]}" \
  --light "$T/fus/probes/p0.exr" --at-probe 0,0.5,0 --proxy "$T/fus/proxy.obj" --object blob --at 0,-1,0 --object-size 0.3 --triangles 2000 \
  --out "$T/c16.exr"
"$BIN" lab capture low-scene2 --grid 2,2,2 --volume "-0.3,0.1,-0.3;0.3,0.7,0.3" --size 8 --out "$T/seq" --quiet >/dev/null 2>&1
"$BIN" ilf build "$T/seq/sequence.json" --grid 2 --bands 2 --out "$T/grid.shgrid" --quiet >/dev/null 2>&1
check grid ok "composited" -- "$BIN" composite "$T/photo.exr" "${CAM[@]}" --light "$T/grid.shgrid" --proxy "$T/fus/proxy.obj" "${OBJ[@]}" \
  --samples 4 --object-samples 4 --out "$T/c17.exr"
check object-outside-grid fail "outside the SH grid's volume" -- "$BIN" composite "$T/photo.exr" "${CAM[@]}" --light "$T/grid.shgrid" \
  --proxy "$T/fus/proxy.obj" --object blob --at 0.6,0.4,0 --object-size 0.3 --triangles 2000 --out "$T/c18.exr"
check object-reaches-outside-grid ok "reaches outside the SH grid's volume" -- "$BIN" composite "$T/photo.exr" "${CAM[@]}" \
  --light "$T/grid.shgrid" --proxy "$T/fus/proxy.obj" --object blob --at 0.25,0.3,0 --object-size 0.3 --triangles 2000 --samples 4 \
  --object-samples 4 --out "$T/c19.exr"
# A probe set whose one probe is said to stand above the room's ceiling: fusion turns the proxy to face it (with
# a warning), and the object then lies outside that proxy: an error, not a composite lit from the wrong side.
python3 -c 'import json, sys; j = json.load(open(sys.argv[1])); j["probes"][0]["position"] = [0, 5, 0]; json.dump(j, open(sys.argv[2], "w"))' \
  "$T/fus/probes.json" "$T/fus/above.json"
check probe-set-outside fail "lies outside the proxy of" -- "$BIN" composite "$T/photo.exr" "${CAM[@]}" \
  --probes "$T/fus/above.json" "${OBJ[@]}" --samples 4 --object-samples 4 --out "$T/c20.exr"

echo "$pass passed, $fail failed, $skip skipped"
[ $fail -eq 0 ]
