#!/usr/bin/env bash
# End-to-end checks of `iblkit nearfield` (CTest cli_nearfield): simulate, info, irradiance against
# the exact luminaire, render with --exact, fig3, an IES file, and bad input failing with one line.
set -u
source "$(dirname "$0")/cli_check.sh" "$1"

check simulate ok "simulated bikelight-9x7 \(63 filter positions" -- "$BIN" nearfield simulate bikelight --grid 9x7 --resolution 48 --out "$T/bike/bike.json"
check simulate-5x5 ok "25 filter positions" -- "$BIN" nearfield simulate flashlight --grid 5x5 --spacing 0.0075 --resolution 32 --out "$T/mag/mag.json"
check info ok "9x7 filter positions" -- "$BIN" nearfield info "$T/bike/bike.json"
check info-json ok '"worst_shift_invariance_error_2d"' -- "$BIN" --json nearfield info "$T/bike/bike.json"
check irradiance ok "near_field_error +vs exact" -- "$BIN" nearfield irradiance "$T/bike/bike.json" --plane z=0.3 --size 32 --out "$T/irr.exr"
[ -f "$T/irr.exr" ] && [ -f "$T/irr_compare.png" ] && pass=$((pass+1)) || { echo "FAIL irradiance files"; fail=$((fail+1)); }
check render ok "near field vs exact" -- "$BIN" nearfield render "$T/bike/bike.json" --scene crypt --size 32 --exact auto --out "$T/view.png"
[ -f "$T/view.png" ] && [ -f "$T/view_compare.png" ] && pass=$((pass+1)) || { echo "FAIL render files"; fail=$((fail+1)); }
check fig3 ok "peaks at 8.0" -- "$BIN" nearfield fig3 --out "$T/fig3.png"
cat > "$T/cos.ies" <<'IES'
IESNA:LM-63-2002
[TEST] cosine lobe
TILT=NONE
1 -1 1 3 1 1 2 0 0 0
1 1 10
0 45 90
0
100 70.71 0
IES
check render-ies ok "1 spotlight" -- "$BIN" nearfield render --ies "$T/cos.ies" --scene crypt --size 24 --out "$T/ies.png"

# Bad input.
check missing-manifest fail "nothere.json: no such file" -- "$BIN" nearfield info "$T/nothere.json"
check bad-grid fail "--grid" -- "$BIN" nearfield simulate bikelight --grid 9by7 --out "$T/x.json"
check bad-luminaire fail "unknown luminaire" -- "$BIN" nearfield simulate torch --out "$T/x.json"
check bad-plane fail "--plane" -- "$BIN" nearfield irradiance "$T/bike/bike.json" --plane y=2 --out "$T/x.exr"
sed 's/"filter_width": [0-9.e-]*/"filter_width": 0.03/' "$T/bike/bike.json" > "$T/bike/width.json"
check width-mismatch fail "does not match the biquadratic basis" -- "$BIN" nearfield info "$T/bike/width.json"
python3 - "$T/bike/bike.json" "$T/bike/cut.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1])); j["measurements"] = [m for m in j["measurements"] if not (m["i"] == 4 and m["j"] == 3)]
json.dump(j, open(sys.argv[2], "w"))
PY
check missing-position fail "\(4, 3\) of the 9x7 grid has no measurement" -- "$BIN" nearfield info "$T/bike/cut.json"
"$BIN" convert "$T/bike/bike_images/ij_0_0_pos.exr" "$T/bike/bike_images/small.exr" --mapping latlong --size 8 >/dev/null 2>&1
python3 - "$T/bike/bike.json" "$T/bike/size.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1])); j["measurements"][5]["positive"] = "bike_images/small.exr"
json.dump(j, open(sys.argv[2], "w"))
PY
check size-mismatch fail "is 16x8x3, the first is 48x48x3" -- "$BIN" nearfield info "$T/bike/size.json"
printf 'not an ies file\n' > "$T/bad.ies"
check bad-ies fail "no TILT= line" -- "$BIN" nearfield render --ies "$T/bad.ies" --out "$T/x.png"
check no-source fail "DATASET or --ies" -- "$BIN" nearfield render --out "$T/x.png"

echo "cli_nearfield: $pass passed, $fail failed"
[ $fail -eq 0 ]
