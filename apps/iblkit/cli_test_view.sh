#!/usr/bin/env bash
# End-to-end checks of `iblkit view` (CTest cli_view): it fails cleanly without a display, and under
# Xvfb it opens a window, renders an orbit of frames through the GL renderer and the window's own
# framebuffer, and writes a screenshot that shows the object.
set -u
source "$(dirname "$0")/cli_check.sh" "$1"
ok() { pass=$((pass+1)); }
bad() { echo "FAIL $1"; fail=$((fail+1)); }

if ! "$BIN" --help | grep -q "^  view"; then
  echo "iblkit was built without the viewer (GLFW or GL missing): skipped"; exit 0
fi
out=$(env -u DISPLAY -u WAYLAND_DISPLAY "$BIN" view blob --light "$PROBE" --frames 1 2>&1); rc=$?
if [ $rc -ne 0 ] && [ $rc -lt 128 ] && grep -q "no display" <<<"$out"; then ok; else bad "no-display: rc $rc: $out"; fi
out=$("$BIN" view blob --light "$T/missing.exr" --frames 1 2>&1); rc=$?
if [ $rc -ne 0 ] && [ $rc -lt 128 ] && grep -q "missing.exr" <<<"$out"; then ok; else bad "missing-light: rc $rc: $out"; fi

# --error-grid (an error volume of ilf build) is read and checked before a window opens.
"$BIN" --quiet lab capture low-scene2 --random 40 --mapping mirrorball --size 16 --out "$T/cap" >/dev/null &&
  "$BIN" --quiet ilf build "$T/cap/sequence.json" --grid 6 --bands 3 --out "$T/g.shgrid" --error-grid "$T/err.shgrid" >/dev/null ||
  bad "error-grid setup"
out=$("$BIN" view blob --light "$T/g.shgrid" --error-grid "$T/g.shgrid" --frames 1 2>&1); rc=$?
if [ $rc -ne 0 ] && [ $rc -lt 128 ] && grep -q "not a cross-validated error volume" <<<"$out"; then ok; else bad "error-grid of radiance: rc $rc: $out"; fi

if command -v xvfb-run >/dev/null && [ -f "$PROBE" ]; then
  # The error slice through the object (at y = 1), 80 px wide in a 240-px window, drawn top left: its
  # figures are `ilf slice`'s for the same plane and width, and its pixels are ilf slice's PNG but for
  # the 13 of the white cross that marks the object.
  out=$(xvfb-run -a "$BIN" --json view blob --light "$T/g.shgrid" --error-grid "$T/err.shgrid" --at 0,1,0 --object-size 0.3 --frames 2 \
        --size 240x180 --screenshot "$T/err_shot.png" 2>&1); rc=$?
  ref=$("$BIN" --quiet --json ilf slice "$T/err.shgrid" --plane y=1 --size 80 --out "$T/err_slice.png" 2>&1)
  mean() { grep -o '"mean_rel_error": *[0-9.e+-]*' <<<"$1" | grep -o '[0-9.e+-]*$'; }
  if [ $rc -eq 0 ] && grep -q '"plane": *"y=1"' <<<"$out" && [ -n "$(mean "$out")" ] && [ "$(mean "$out")" = "$(mean "$ref")" ]; then ok
  else bad "error-slice figures: rc $rc: $out / $ref"; fi
  if command -v oiiotool >/dev/null && [ -s "$T/err_shot.png" ]; then
    if oiiotool "$T/err_shot.png" --cut 80x80+8+8 -o "$T/err_cut.png" && \
       oiiotool "$T/err_cut.png" "$T/err_slice.png" --fail 0.004 --failpercent 0.25 --diff >/dev/null 2>&1; then ok
    else bad "error-slice pixels differ from ilf slice's: $(oiiotool "$T/err_cut.png" "$T/err_slice.png" --diff 2>&1 | tail -3)"; fi
  fi
  out=$(xvfb-run -a "$BIN" view blob --light "$PROBE" --light "$PROBE" --frames 4 --size 160x120 --triangles 5000 \
        --screenshot "$T/shot.png" --json 2>&1); rc=$?
  if [ $rc -eq 0 ] && grep -q '"frames": *4' <<<"$out" && [ -s "$T/shot.png" ]; then ok; else bad "xvfb-orbit: rc $rc: $out"; fi
  # The screenshot is the window's back buffer: the object (bright) in the middle, the sky (black) on top.
  if command -v oiiotool >/dev/null && [ -s "$T/shot.png" ]; then
    mid=$(oiiotool "$T/shot.png" --cut 20x20+70+60 --printstats 2>/dev/null | awk '/Stats Avg/{print $3}')
    top=$(oiiotool "$T/shot.png" --cut 160x6+0+0 --printstats 2>/dev/null | awk '/Stats Avg/{print $3}')
    if awk -v m="$mid" -v t="$top" 'BEGIN{exit !(m > 0.2 && t < 0.05)}'; then ok; else bad "screenshot content: centre $mid, top $top"; fi
  fi
else
  echo "no xvfb-run or no blender-data probe: the windowed checks are skipped"; skip=$((skip+1))
fi
echo "$pass passed, $fail failed, $skip skipped"
[ $fail -eq 0 ]
