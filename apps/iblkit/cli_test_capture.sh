#!/usr/bin/env bash
# End to end from a capture folder to the composite (CTest cli_capture; docs/capture.md "From the set to the
# composite"): `lab shoot --backplate` photographs low-scene2 — a chrome ball's brackets from two sides, a backplate
# with a board on the floor, the truth with the object — and `composite --capture` merges, unwarps, solves the camera
# from the board and composites into the JPEG; the camera must come back within 5 mm and 0.2° with a reprojection
# error under 0.5 px, the output keeps the backplate's format and Exif, and bad folders fail in one line, nothing
# written.
set -u
source "$(dirname "$0")/cli_check.sh" "$1"
if ! "$BIN" --help | grep -q "^  composite"; then echo "SKIP: no composite subcommand in this build"; exit 0; fi
if ! "$BIN" camera solve --help >/dev/null 2>&1; then echo "SKIP: this build has no iblkit camera (OpenCV)"; exit 0; fi

SHOOT=(lab shoot low-scene2 --at 0,0.15,0 --two-sides --distance-radii 10 --width 192 --height 192 --samples 2
  --bracket 12 --until-unsaturated --ev-step 3 --bounces 1 --noise --wb 1.1,1,0.8 --backplate --plate-samples 3)
check shoot ok "backplate 320x240 with a 7x4:0.1 board" -- "$BIN" "${SHOOT[@]}" --out "$T/set"
check manifest ok '"format": ?"iblkit.capture/1"' -- cat "$T/set/capture.json"
check chain ok "against truth.jpg: object" -- "$BIN" composite --capture "$T/set" --out "$T/set/composite.jpg" \
  --layers "$T/set/layers" --samples 32 --object-samples 256
"$BIN" --json composite --capture "$T/set" --out "$T/set/c2.jpg" --samples 32 --object-samples 256 2>/dev/null > "$T/chain.json"
check chain-camera ok "camera ok" -- /usr/bin/python3 - "$T/chain.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
c = j["camera"]
assert c["eye_error_mm"] < 5, c
assert c["view_error_deg"] < 0.2, c
assert c["reprojection_rms_px"] < 0.5, c
assert "Exif FocalLength" in c["lens"], c
assert j["match"]["applied"] and j["match"]["points"] > 1000, j["match"]
e = j["errors"]
assert e["object_pixels"] > 300 and e["shadow_pixels"] > 300, e
# The chain's measured figures (docs/capture.md): loose bounds that catch a broken step (a probe without its
# lamps scored 80 % on the object), not the targets.
assert e["object"] < 0.6 and e["shadow"] < 0.8 and e["unchanged"] < 0.05, e
print("camera ok", c["eye_error_mm"], c["view_error_deg"], e["object"], e["shadow"])
PY
check layers ok "probe_matched.exr" -- ls "$T/set/layers"
# Registration (docs/augment.md): a folder whose ball faced 40° elsewhere than it says; `--register yaw` finds the turn
# from the floor and walls both see and turns the probe back (a 40° error halves, here, to 4°: the spread must fall).
mkdir -p "$T/turned" && cp "$T/set/"* "$T/turned/" 2>/dev/null
/usr/bin/python3 - "$T/turned/capture.json" <<'PY'
import json, math, sys
j = json.load(open(sys.argv[1]))
f, a = j["ball"]["facing"], math.radians(40)
j["ball"]["facing"] = [math.cos(a) * f[0] + math.sin(a) * f[2], f[1], -math.sin(a) * f[0] + math.cos(a) * f[2]]
json.dump(j, open(sys.argv[1], "w"))
PY
"$BIN" --json composite --capture "$T/turned" --out "$T/turned/c.jpg" --samples 8 --object-samples 64 --register yaw \
  2>/dev/null > "$T/turned.json"
check register-yaw ok "turned back" -- /usr/bin/python3 - "$T/turned.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))["registration"]
# This set's ball is 192² at 2×2 rays: 4.1° off here (the bench's 384² set: 1.2°, the lab's exact probe 0.0°).
assert r["valid"] and r["applied"] and abs(r["yaw_deg"] + 40) < 6, r
assert r["spread_stops"] < 0.7 * r["spread_given_stops"], r
print("turned back", r["yaw_deg"])
PY
"$BIN" --json composite --capture "$T/turned" --out "$T/turned/p.jpg" --samples 8 --object-samples 64 --register pose \
  2>/dev/null > "$T/pose.json"
check register-pose ok "moved and turned" -- /usr/bin/python3 - "$T/pose.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))["registration"]
p = r["position"]
assert r["applied"] and p["applied"] and p["valid"] and abs(r["yaw_deg"] + 40) < 6, r
assert max(abs(v) for v in p["offset_m"]) <= 0.2 * 3 ** 0.5 + 1e-9 and p["spread_stops"] <= p["spread_given_stops"], p
print("moved and turned", p["offset_m"], r["yaw_deg"])
PY
check register-bad fail "\-\-register" -- "$BIN" composite --capture "$T/set" --out "$T/x9.jpg" --register north
# A ChArUco board (docs/camera.md): the lab prints OpenCV's board, the chain finds it by its markers, leaves out the
# corners it misread (a pool of light crosses the board) and meets the camera targets on a 640×480 plate.
if ! "$BIN" lab shoot low-scene2 --backplate --bracket 2 --board charuco:5x4:0.2:0.15 --width 32 --height 32 \
    --plate-width 64 --plate-height 48 --plate-samples 1 --out "$T/probe_charuco" 2>&1 | grep -q "no aruco module"; then
  "$BIN" --quiet lab shoot low-scene2 --at 0,0.15,0 --two-sides --distance-radii 10 --width 128 --height 128 --samples 1 \
    --bracket 12 --until-unsaturated --ev-step 3 --bounces 1 --noise --wb 1.1,1,0.8 --backplate --plate-samples 3 \
    --plate-width 640 --plate-height 480 --board charuco:5x4:0.2:0.15 --board-at -0.2,0,0.6 --out "$T/ch" > /dev/null
  "$BIN" --json composite --capture "$T/ch" --out "$T/ch/c.jpg" --samples 8 --object-samples 64 2>/dev/null > "$T/ch.json"
  check charuco-chain ok "charuco camera ok" -- /usr/bin/python3 - "$T/ch.json" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))["camera"]
assert c["board_corners"] >= 8, c
assert c["eye_error_mm"] < 5 and c["view_error_deg"] < 0.2 and c["reprojection_rms_px"] < 0.5, c
print("charuco camera ok", c["board_corners"], c["board_corners_dropped"], c["eye_error_mm"], c["view_error_deg"])
PY
else
  echo "SKIP charuco-chain: this build's OpenCV has no aruco module (libopencv-contrib-dev)"
fi
if command -v oiiotool > /dev/null; then
  check exif-kept ok "Exif:FocalLength" -- oiiotool --info -v "$T/set/composite.jpg"
else
  echo "SKIP exif-kept: oiiotool missing"
fi
# A folder whose board is not in the backplate, a missing manifest, a photograph and --capture together.
mkdir -p "$T/bad" && cp "$T/set/"* "$T/bad/" 2>/dev/null
sed -i 's/"checker:7x4:0.1"/"checker:9x6:0.1"/' "$T/bad/capture.json"
check board-not-found fail "backplate.jpg: no 9x6-corner chessboard" -- \
  "$BIN" composite --capture "$T/bad" --out "$T/bad/x1.jpg"
check no-manifest fail "nowhere: no such capture folder" -- "$BIN" composite --capture "$T/nowhere" --out "$T/x2.jpg"
check both fail "not both" -- "$BIN" composite "$T/set/backplate.jpg" --capture "$T/set" --out "$T/x3.jpg"
check backplate-no-bracket fail "--backplate: the ball needs its brackets" -- \
  "$BIN" lab shoot low-scene2 --backplate --out "$T/x5"
check backplate-symmetric-board fail "looks the same turned around" -- \
  "$BIN" lab shoot low-scene2 --backplate --bracket 3 --board 8x6:0.1 --out "$T/x6"
check nothing-written ok "^none$" -- sh -c "ls '$T' '$T/bad' | grep '^x[0-9]' || echo none"
# camera solve takes the lens from the backplate's Exif, and refuses a --fov that contradicts it.
O=$(/usr/bin/python3 -c "import json;print(','.join(map(str,json.load(open('$T/set/capture.json'))['board']['origin'])))")
check solve-exif ok "fixed \(Exif FocalLength" -- "$BIN" camera solve "$T/set/backplate.jpg" --board checker:7x4:0.1 \
  --board-origin "$O" --out "$T/cam.json"
check solve-exif-contradicts fail "drop --fov, or give --no-exif" -- "$BIN" camera solve "$T/set/backplate.jpg" \
  --board checker:7x4:0.1 --board-origin "$O" --fov 40 --out "$T/x4.json"

# The same set shot as raw files (DNG): the chain merges them linearly, reads the lens from their Exif, and writes
# the composite as a 16-bit linear TIFF; a raw composite is refused.
if [ -f "$(dirname "$BIN")/libiblkit_raw.so" ]; then
  check raw-shoot ok "8 dng frames|dng frames" -- "$BIN" "${SHOOT[@]}" --format dng --out "$T/raw"
  check raw-chain ok "response  linear \(raw files\)" -- "$BIN" composite --capture "$T/raw" --out "$T/raw/composite.tif" \
    --samples 32 --object-samples 256
  check raw-chain-lens ok "Exif FocalLength" -- "$BIN" composite --capture "$T/raw" --out "$T/raw/c2.jpg" \
    --samples 32 --object-samples 256
  if command -v iinfo > /dev/null; then
    check raw-composite-16bit ok "uint16 tiff" -- iinfo "$T/raw/composite.tif"
  fi
  check raw-out-refused fail "iblkit writes no raw files" -- "$BIN" composite --capture "$T/raw" --out "$T/raw/x7.dng"
  check raw-nothing-written ok "^none$" -- sh -c "ls '$T/raw' | grep '^x[0-9]' || echo none"
else
  echo "SKIP raw set: built without LibRaw (scripts/install-deps installs libraw-dev)"
fi

echo "cli_capture: $pass passed, $fail failed"
[ $fail -eq 0 ]
