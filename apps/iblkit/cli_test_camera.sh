#!/usr/bin/env bash
# End-to-end checks of `iblkit camera solve | calibrate | check` (CTest cli_camera): exact points projected
# through a known camera by OpenCV (camera_test_tool.py, the peer) give the camera back with a reprojection
# error < 0.01 px, in depth and on the floor, with --fov, with the focal length solved and through a
# calibrated distorted lens; chessboards rendered by OpenCV's remap are found and solved; a lens is
# calibrated from six board photographs; bad input fails in one line naming the option, nothing written.
set -u
source "$(dirname "$0")/cli_check.sh" "$1"
TOOL="$(dirname "$0")/camera_test_tool.py"
PY=/usr/bin/python3
if ! $PY -c 'import cv2, numpy' 2>/dev/null; then echo "SKIP: python3-opencv missing (scripts/install-deps)"; exit 0; fi
if ! "$BIN" camera solve --help >/dev/null 2>&1; then echo "SKIP: this build has no iblkit camera"; exit 0; fi

cat > "$T/truth.json" <<'JSON'
{"format":"iblkit.camera/1","eye":[0.35,1.15,2.3],"target":[0.05,0.25,0.1],"up":[0,1,0],"fov_y_deg":42,"width":320,"height":240}
JSON
"$BIN" lab photograph low-scene2 --camera "$T/truth.json" --samples 1 --out "$T/photo.exr" >/dev/null
$PY "$TOOL" points "$T/truth.json" "$T/depth.json" depth
$PY "$TOOL" points "$T/truth.json" "$T/floor.json" floor

# Exact points: the camera back within 1e-6 m and 1e-4°, reprojection < 0.01 px.
RE='reprojection error [0-9.]+e-[0-9]+ px RMS|reprojection error 0\.00[0-9]* px RMS'
check solve-depth-fov ok "$RE" -- "$BIN" camera solve "$T/photo.exr" --points "$T/depth.json" --fov 42 --out "$T/s1.json"
check solve-depth-fov-camera ok "eye" -- $PY "$TOOL" compare "$T/truth.json" "$T/s1.json" 1e-6 1e-4 1e-6
check solve-floor-fov ok "coplanar.*$RE|IPPE" -- "$BIN" camera solve "$T/photo.exr" --points "$T/floor.json" --fov 42 --out "$T/s2.json"
check solve-floor-fov-camera ok "eye" -- $PY "$TOOL" compare "$T/truth.json" "$T/s2.json" 1e-6 1e-4 1e-6
check solve-floor-focal ok "$RE" -- "$BIN" camera solve "$T/photo.exr" --points "$T/floor.json" --out "$T/s3.json"
check solve-floor-focal-camera ok "eye" -- $PY "$TOOL" compare "$T/truth.json" "$T/s3.json" 1e-6 1e-4 1e-4
check solve-depth-focal-json ok '"reprojection_rms_px": ?[0-9.]+e-' -- \
  "$BIN" camera solve "$T/photo.exr" --points "$T/depth.json" --out "$T/s4.json" --json
check check-report ok "$RE" -- "$BIN" camera check "$T/photo.exr" --camera "$T/s1.json" --points "$T/depth.json"
check check-json ok '"reprojection_max_px"' -- "$BIN" camera check "$T/photo.exr" --camera "$T/truth.json" --points "$T/floor.json" --json

# A chessboard on the floor, rendered by OpenCV through the camera: found, and the camera within 1 cm and 0.3°.
cat > "$T/tb.json" <<'JSON'
{"format":"iblkit.camera/1","eye":[0.3,1.4,1.6],"target":[0,0,0],"up":[0,1,0],"fov_y_deg":50,"width":320,"height":240}
JSON
$PY "$TOOL" board "$T/tb.json" "$T/board.png" 9 6 0.08 -0.32,0,0.2 1,0,0 0,0,-1
check board-solve ok "reprojection error 0\.0[0-9]* px RMS" -- \
  "$BIN" camera solve "$T/board.png" --board checker:9x6:0.08 --board-origin -0.32,0,0.2 --fov 50 --out "$T/b1.json"
check board-solve-camera ok "eye" -- $PY "$TOOL" compare "$T/tb.json" "$T/b1.json" 0.01 0.3 1e-6
# The board turned by 180° on the floor (its dark first square at the far end): found and labelled from it.
$PY "$TOOL" board "$T/tb.json" "$T/turned.png" 9 6 0.08 0.32,0,-0.2 -1,0,0 0,0,1
check board-turned ok "54 board points, coplanar" -- "$BIN" camera solve "$T/turned.png" --board checker:9x6:0.08 \
  --board-origin 0.32,0,-0.2 --board-axes=-1,0,0,0,0,1 --fov 50 --out "$T/b2.json"
check board-turned-camera ok "eye" -- $PY "$TOOL" compare "$T/tb.json" "$T/b2.json" 0.01 0.3 1e-6

# A distorted lens: six photographs of a board calibrate it; it then solves a seventh view's points exactly.
L='"width":480,"height":360,"intrinsics":{"fx":400,"fy":401.5,"cx":244.25,"cy":178.5},"distortion":[-0.28,0.09,0.001,-0.0008,0]'
i=0
for e in "0,0.55,0.45:0,0,0" "0.3,0.5,0.4:0.12,0,0.1" "-0.3,0.6,0.45:-0.06,0,0" "0.1,0.6,-0.35:0.1,0,0.1" \
         "-0.25,0.45,0.55:0.1,0,-0.1" "0.3,0.62,-0.3:0,0,0.03"; do
  i=$((i+1))
  echo "{\"format\":\"iblkit.camera/1\",\"eye\":[${e%%:*}],\"target\":[${e##*:}],\"up\":[0,1,0],$L}" > "$T/v$i.json"
  $PY "$TOOL" board "$T/v$i.json" "$T/v$i.png" 9 6 0.06 -0.24,0,0.15 1,0,0 0,0,-1
done
check calibrate ok "reprojection error 0\.0[0-9]* px RMS \(calibrateCamera\)" -- \
  "$BIN" camera calibrate "$T"/v?.png --board checker:9x6:0.06 --board-origin -0.24,0,0.15 --out "$T/lens.json"
check calibrate-lens ok "eye" -- $PY "$TOOL" compare "$T/v1.json" "$T/lens.json" 0.003 0.2 2
echo "{\"format\":\"iblkit.camera/1\",\"eye\":[0.2,0.7,0.6],\"target\":[0,0,0],\"up\":[0,1,0],$L}" > "$T/v7.json"
$PY "$TOOL" points "$T/v7.json" "$T/v7pts.json" depth
check solve-distorted-exact-lens ok "$RE" -- \
  "$BIN" camera solve "$T/v1.png" --points "$T/v7pts.json" --intrinsics "$T/v7.json" --out "$T/d1.json"
check solve-distorted-camera ok "eye" -- $PY "$TOOL" compare "$T/v7.json" "$T/d1.json" 1e-6 1e-4 1e-6
check solve-calibrated-lens ok "reprojection" -- \
  "$BIN" camera solve "$T/v1.png" --points "$T/v7pts.json" --intrinsics "$T/lens.json" --out "$T/d2.json"
check solve-calibrated-camera ok "eye" -- $PY "$TOOL" compare "$T/v7.json" "$T/d2.json" 0.005 0.3 2
check distorted-file-keeps-lens ok '"distortion"' -- cat "$T/d1.json"

# composite through a distorted lens (CPU): the object lands where the lab photographs it through the same lens
# (its mask overlaps the truth's by > 0.95); the same intrinsics without distortion miss (< 0.9).
if "$BIN" --help | grep -q "^  composite"; then
  LENS='"eye":[0,1.3,2.2],"target":[0,0.3,0],"up":[0,1,0],"width":192,"height":144,"intrinsics":{"fx":176,"fy":176,"cx":96.6,"cy":71.6}'
  echo "{\"format\":\"iblkit.camera/1\",$LENS,\"distortion\":[-0.45,0.15,0.002,-0.001,0]}" > "$T/dist.json"
  echo "{\"format\":\"iblkit.camera/1\",$LENS}" > "$T/undist.json"
  OBJ=(--object blob --at -0.6,0.25,0.6 --object-size 0.3 --triangles 2000)
  "$BIN" lab photograph low-scene2 --camera "$T/dist.json" --samples 1 --out "$T/dphoto.exr" >/dev/null
  "$BIN" lab photograph low-scene2 --camera "$T/dist.json" --samples 2 "${OBJ[@]}" --mask "$T/dmask.exr" --out "$T/dtruth.exr" >/dev/null
  "$BIN" lab capture low-scene2 --fusion --probe 0,0.5,0 --size 16 --out "$T/fus" --quiet >/dev/null 2>&1
  for c in dist undist; do
    check composite-$c ok "composited" -- "$BIN" composite "$T/dphoto.exr" --camera "$T/$c.json" --backend cpu \
      --probes "$T/fus/probes.json" "${OBJ[@]}" --samples 4 --object-samples 4 --out "$T/c_$c.exr" --layers "$T/L_$c"
  done
  check composite-distorted-lines-up ok "mask overlap" -- $PY "$TOOL" overlap "$T/dmask.exr" "$T/L_dist/mask.exr" 0.95 1
  check composite-undistorted-misses ok "mask overlap" -- $PY "$TOOL" overlap "$T/dmask.exr" "$T/L_undist/mask.exr" 0 0.9
  check composite-gl-refuses fail "\-\-backend gl cannot render .*distortion.*use --backend cpu" -- "$BIN" composite \
    "$T/dphoto.exr" --camera "$T/dist.json" --backend gl --probes "$T/fus/probes.json" "${OBJ[@]}" --out "$T/bad_gl.exr"
  check composite-auto-cpu ok "" -- "$BIN" composite "$T/dphoto.exr" --camera "$T/dist.json" --backend auto \
    --probes "$T/fus/probes.json" "${OBJ[@]}" --samples 2 --object-samples 2 --out "$T/c_auto.exr"
  [ -e "$T/bad_gl.exr" ] && { echo "FAIL composite-gl-refuses wrote its output"; fail=$((fail+1)); }
fi

# Bad input: one line naming the option, nothing written.
$PY -c 'import json,sys; j=json.load(open(sys.argv[1])); j["points"]=j["points"][:5]; json.dump(j,open(sys.argv[2],"w"))' \
  "$T/depth.json" "$T/five.json"
check too-few-points fail "five.json.*at least 6" -- "$BIN" camera solve "$T/photo.exr" --points "$T/five.json" --fov 42 --out "$T/bad1.json"
sed 's/"pixel": \[/"pixel": [NaN, /' "$T/depth.json" > "$T/nan.json"
check nan-points fail "nan.json" -- "$BIN" camera solve "$T/photo.exr" --points "$T/nan.json" --fov 42 --out "$T/bad2.json"
check nan-fov fail "\-\-fov" -- "$BIN" camera solve "$T/photo.exr" --points "$T/depth.json" --fov nan --out "$T/bad3.json"
check no-board fail "\-\-board checker:9x6:0.08: no 9x6-corner chessboard found" -- \
  "$BIN" camera solve "$T/photo.exr" --board checker:9x6:0.08 --fov 42 --out "$T/bad4.json"
check charuco-bad-spec fail "\-\-board charuco:5x4:0.2:0.25: marker size" -- \
  "$BIN" camera solve "$T/photo.exr" --board charuco:5x4:0.2:0.25 --fov 42 --out "$T/bad8.json"
check charuco-not-found fail "no 5x4-square ChArUco board found|no aruco module" -- \
  "$BIN" camera solve "$T/board.png" --board charuco:5x4:0.08:0.06 --fov 50 --out "$T/bad9.json"
check symmetric-board fail "\-\-board checker:8x6" -- \
  "$BIN" camera solve "$T/board.png" --board checker:8x6:0.08 --fov 50 --out "$T/bad5.json"
check board-axes-backwards fail "\-\-board-axes" -- "$BIN" camera solve "$T/board.png" --board checker:9x6:0.08 \
  --board-origin -0.32,0,0.2 --board-axes 1,0,0,0,0,1 --fov 50 --out "$T/bad6.json"
$PY "$TOOL" points "$T/truth.json" "$T/moved.json" depth 60
check points-disagree fail "\-\-points .*disagree.*point 0" -- \
  "$BIN" camera solve "$T/photo.exr" --points "$T/moved.json" --fov 42 --out "$T/bad7.json"
echo '{"format":"iblkit.camera/1","eye":[0,1,-3],"target":[0,1,-6],"fov_y_deg":42,"width":320,"height":240}' > "$T/away.json"
check points-behind fail "\-\-points .*behind the camera" -- \
  "$BIN" camera check "$T/photo.exr" --camera "$T/away.json" --points "$T/depth.json"
check lens-size-mismatch fail "\-\-intrinsics .*480x360" -- \
  "$BIN" camera solve "$T/photo.exr" --points "$T/depth.json" --intrinsics "$T/lens.json" --out "$T/bad8.json"
check both-sources fail "either --points" -- \
  "$BIN" camera solve "$T/board.png" --points "$T/depth.json" --board checker:9x6:0.08 --out "$T/bad9.json"
check calibrate-too-few fail "at least 3" -- \
  "$BIN" camera calibrate "$T/v1.png" "$T/v2.png" --board checker:9x6:0.06 --out "$T/bad10.json"
written=$(ls "$T"/bad*.json 2>/dev/null | wc -l)
check nothing-written ok "^0$" -- echo "$written"

echo "cli_camera: $pass passed, $fail failed"
[ $fail -eq 0 ]
