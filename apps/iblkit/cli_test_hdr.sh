#!/usr/bin/env bash
# End-to-end checks of `iblkit hdr` (CTest cli_hdr): a bracket shot through the sensor model (hdr bracket),
# merged from its Exif exposures and from --exposures, the curve written and reused, the report, and the
# bad brackets of issue 29 (one image, no spread, no exposure, different sizes, all saturated): one line,
# nothing written.
set -u
source "$(dirname "$0")/cli_check.sh" "$1"
[ -f "$PROBE" ] || { echo "SKIP: blender-data probe missing"; exit 0; }

check bracket ok "wrote .*/b-4.jpg" -- \
  "$BIN" hdr bracket "$PROBE" -o "$T/b" --response camera --full-well 30000 --read-noise 3e-4 --exposures 1/64,1/16,1/4,1,4
check merge-exif ok "dynamic range +[0-9.]+ stops" -- "$BIN" hdr merge "$T"/b-?.jpg --out "$T/m.exr" --response-out "$T/c.json"
check merge-wrote ok "m.exr" -- ls "$T"
check curve-file ok '"format":"iblkit.response/1"' -- cat "$T/c.json"
check merge-reuse ok "response debevec" -- "$BIN" hdr merge "$T"/b-?.jpg --out "$T/m2.exr" --response "$T/c.json" --no-align
check merge-json ok '"exposure_source": ?"ev"' -- \
  "$BIN" --json hdr merge "$T"/b-?.jpg --out "$T/m3.exr" --exposures ev:0,2,4,6,8 --method robertson
check merge-grey-card ok '"gains"' -- \
  "$BIN" --json hdr merge "$T"/b-?.jpg --out "$T/m4.exr" --grey-card 10,300,20,20 --reflectance 0.18
check one-image fail "b-0.jpg: one photograph only" -- "$BIN" hdr merge "$T/b-0.jpg" --out "$T/x1.exr"
check no-spread fail "no exposure spread" -- "$BIN" hdr merge "$T/b-0.jpg" "$T/b-0.jpg" --out "$T/x2.exr"
check wrong-count fail "--exposures gives 3 values for 2" -- \
  "$BIN" hdr merge "$T/b-0.jpg" "$T/b-1.jpg" --exposures 1,2,3 --out "$T/x3.exr"
"$BIN" hdr bracket "$PROBE" -o "$T/p" --format png --exposures 1/8,1/2 > /dev/null
check no-exif fail "p-0.png: no exposure time .*--exposures" -- "$BIN" hdr merge "$T/p-0.png" "$T/p-1.png" --out "$T/x4.exr"
check png-exposures ok "wrote" -- "$BIN" hdr merge "$T/p-0.png" "$T/p-1.png" --exposures 1/8,1/2 --response srgb --out "$T/x5.exr"
if command -v oiiotool > /dev/null; then
  for t in 1 4; do
    oiiotool --pattern constant:color=1,1,1 64x32 3 -d uint8 --attrib:type=float ExposureTime $t -o "$T/s-$t.jpg"
  done
  check all-saturated fail "s-1.jpg: even the darkest photograph is saturated" -- \
    "$BIN" hdr merge "$T/s-1.jpg" "$T/s-4.jpg" --out "$T/x6.exr"
else
  echo "SKIP all-saturated: oiiotool missing"
fi
"$BIN" hdr bracket "$PROBE" -o "$T/t16" --format tif --bits 16 --response camera --exposures 1/16,1/2,4 > /dev/null
check curve-too-shallow fail "t16-0.tif: a 16-bit photograph, but the curve .*c.json has 256 code values" -- \
  "$BIN" hdr merge "$T"/t16-?.tif --exposures 1/16,1/2,4 --response "$T/c.json" --out "$T/x8.exr"
check nothing-written ok "^none$" -- sh -c "ls '$T' | grep '^x[0-468]' || echo none"
check bad-grey-card fail "grey-card" -- "$BIN" hdr merge "$T"/b-?.jpg --out "$T/x7.exr" --grey-card 1,2,3

# A chrome ball's bracket on a tripod (the lab shoots without a shift): a mostly dark room of a few large flat areas,
# the longest frame 70 % saturated, where Ward's pyramid once landed a step off (shift 1,1) at a coarse level; every
# shift must come back 0,0.
if "$BIN" --help | grep -q "^  lab"; then
  "$BIN" --quiet lab shoot low-scene2 --at 0,0.15,0 --distance-radii 10 --width 384 --height 384 --samples 4 \
    --bracket 12 --until-unsaturated --ev-step 3 --bounces 1 --noise --wb 1.1,1,0.8 --out "$T/ball" > /dev/null
  "$BIN" --json hdr merge "$T"/ball/view0_e*.jpg --out "$T/ball.exr" > "$T/ball.json"
  check tripod-shifts ok "8 frames, all 0,0" -- /usr/bin/python3 -c "
import json, sys
f = json.load(open(sys.argv[1]))['frames']
bad = [(x['file'], x['shift']) for x in f if x['shift'] != [0, 0]]
print('%d frames, all 0,0' % len(f) if not bad else bad)" "$T/ball.json"
fi

# Raw brackets (LibRaw, the raw plugin): the lab's DNGs merge linearly with their levels reported; a curve is
# refused; a raw file LibRaw cannot read, or one cut short, fails naming it; nothing written.
if [ -f "$(dirname "$BIN")/libiblkit_raw.so" ]; then
  check raw-bracket ok "wrote .*/r-2.dng" -- "$BIN" hdr bracket "$PROBE" -o "$T/r" --format dng --exposures 1/16,1/2,4
  check raw-merge ok "raw +RGGB black 512 white 16383" -- "$BIN" hdr merge "$T"/r-?.dng --out "$T/mr.exr"
  check raw-merge-json ok '"response": ?"linear"' -- "$BIN" --json hdr merge "$T"/r-?.dng --out "$T/mr2.exr"
  check raw-curve fail "r-0.dng: a raw file is linear .*drop --response srgb" -- \
    "$BIN" hdr merge "$T"/r-?.dng --response srgb --out "$T/y1.exr"
  echo "not a raw file" > "$T/junk.nef"
  check raw-junk fail "junk.nef: not a raw file LibRaw can read" -- "$BIN" hdr merge "$T/junk.nef" "$T/r-1.dng" --out "$T/y2.exr"
  head -c 300000 "$T/r-1.dng" > "$T/cut.dng"
  check raw-cut fail "cut.dng: corrupt or truncated raw data" -- "$BIN" hdr merge "$T/r-0.dng" "$T/cut.dng" --out "$T/y3.exr"
  check raw-mixed fail "b-0.jpg: a developed photograph, but .*r-0.dng is a raw file" -- \
    "$BIN" hdr merge "$T/r-0.dng" "$T/b-0.jpg" --out "$T/y4.exr"
  check raw-nothing-written ok "^none$" -- sh -c "ls '$T' | grep '^y[0-9]' || echo none"
else
  echo "SKIP raw brackets: built without LibRaw (scripts/install-deps installs libraw-dev)"
fi

echo "cli_hdr: $pass passed, $fail failed"
[ $fail -eq 0 ]
