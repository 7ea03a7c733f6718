#!/usr/bin/env bash
# End-to-end checks that outputs are written whole or not at all (registered with CTest as
# cli_atomic; a few seconds; docs/formats.md "How every output is written"): a failing `convert`
# (bad input, invalid target, a write that fails half way) leaves no file at its output path and
# keeps the file that was there; an `ilf build` killed by SIGTERM mid-run leaves no file at --out,
# keeps the previous grid and leaves no temporary file; `sh --format gltf --specular-images` that
# fails half way leaves none of its PNGs.
set -u
source "$(dirname "$0")/cli_check.sh" "$1"

# no_temp NAME DIR: counts a failure when DIR holds a temporary file (*.tmp-*).
no_temp() {
  local left
  left=$(find "$2" -name '*.tmp-*' 2>/dev/null)
  if [ -n "$left" ]; then echo "FAIL $1: temporary files left: $left"; fail=$((fail+1)); else pass=$((pass+1)); fi
}
# absent NAME FILE / same NAME FILE COPY: the output is not there / is byte for byte the previous one.
absent() { if [ -e "$2" ]; then echo "FAIL $1: $2 exists"; fail=$((fail+1)); else pass=$((pass+1)); fi; }
same() { if cmp -s "$2" "$3"; then pass=$((pass+1)); else echo "FAIL $1: $2 changed"; fail=$((fail+1)); fi; }

# ---- convert -------------------------------------------------------------------------------------
check convert-missing-input fail "nothere.exr: no such file" -- "$BIN" convert "$T/nothere.exr" "$T/c/out.exr" --size 8
printf 'not an image at all\n' > "$T/notes.exr"
mkdir -p "$T/c"
check convert-corrupt-input fail "notes.exr" -- "$BIN" convert "$T/notes.exr" "$T/c/out.exr" --size 8
check convert-no-folder fail "" -- "$BIN" convert "$T/notes.exr" "$T/nofolder/out.exr" --size 8
absent convert-nothing-written "$T/c/out.exr"
no_temp convert-bad-input "$T"

if [ -f "$PROBE" ]; then
  check convert-previous ok "wrote" -- "$BIN" convert "$PROBE" "$T/c/prev.exr" --size 32
  cp "$T/c/prev.exr" "$T/prev_copy.exr"
  check convert-bad-extension fail "no image writer" -- "$BIN" convert "$PROBE" "$T/c/out.xyz" --size 8
  absent convert-bad-extension-nothing "$T/c/out.xyz"
  check convert-bad-mapping fail "unknown mapping" -- "$BIN" convert "$PROBE" "$T/c/prev.exr" --mapping sphere
  same convert-bad-mapping-keeps "$T/c/prev.exr" "$T/prev_copy.exr"
  check convert-bad-input-keeps-run fail "no such file" -- "$BIN" convert "$T/nothere.exr" "$T/c/prev.exr"
  same convert-bad-input-keeps "$T/c/prev.exr" "$T/prev_copy.exr"
  # The target is a folder: the rename fails, the folder stays as it was.
  mkdir -p "$T/c/dir.exr"
  check convert-onto-folder fail "dir.exr" -- "$BIN" convert "$PROBE" "$T/c/dir.exr" --size 16
  [ -d "$T/c/dir.exr" ] && [ -z "$(ls -A "$T/c/dir.exr")" ] && pass=$((pass+1)) || { echo "FAIL convert-onto-folder: folder changed"; fail=$((fail+1)); }
  # A write that fails half way: a 64 KiB file-size limit (SIGXFSZ ignored, so write() fails with
  # EFBIG instead of killing the process) against a 512-pixel lat-long EXR of several MB.
  check convert-write-fails fail "prev.exr" -- bash -c "trap '' XFSZ; ulimit -f 64; exec \"$BIN\" convert \"$PROBE\" \"$T/c/prev.exr\" --size 512"
  same convert-write-fails-keeps "$T/c/prev.exr" "$T/prev_copy.exr"
  check convert-write-fails-new fail "new.exr" -- bash -c "trap '' XFSZ; ulimit -f 64; exec \"$BIN\" convert \"$PROBE\" \"$T/c/new.exr\" --size 512"
  absent convert-write-fails-nothing "$T/c/new.exr"
  no_temp convert-write-fails-temp "$T"
else
  skip=$((skip+1))
fi

# ---- ilf build killed by SIGTERM -----------------------------------------------------------------
check ilf-capture ok "" -- "$BIN" --quiet lab capture low-scene2 --random 40 --mapping mirrorball --size 64 --out "$T/cap"
# kill_build NAME OUT: starts `ilf build` into OUT, sends SIGTERM 0.1 s after it starts sorting (its
# bucket folder appears; the resampling that follows takes seconds) and checks that it died of the signal.
kill_build() {
  local name="$1" out="$2" pid rc i
  rm -rf "$out.buckets"
  "$BIN" --quiet ilf build "$T/cap/sequence.json" --grid 32 --out "$out" >/dev/null 2>&1 &
  pid=$!
  for i in $(seq 1 400); do [ -d "$out.buckets" ] && break; sleep 0.02; done
  sleep 0.1
  kill -TERM $pid 2>/dev/null
  wait $pid; rc=$?
  if [ $rc -eq 143 ]; then pass=$((pass+1)); else echo "FAIL $name: exit $rc, expected 143 (killed by SIGTERM mid-run)"; fail=$((fail+1)); fi
}
mkdir -p "$T/ilf"
kill_build ilf-killed "$T/ilf/new.shgrid"
absent ilf-killed-no-output "$T/ilf/new.shgrid"
no_temp ilf-killed-no-temp "$T/ilf"
# With a grid from an earlier run at --out: killed, the earlier grid is intact.
check ilf-previous ok "wrote" -- "$BIN" ilf build "$T/cap/sequence.json" --grid 4 --out "$T/ilf/prev.shgrid"
cp "$T/ilf/prev.shgrid" "$T/prev_copy.shgrid"
kill_build ilf-killed-over-previous "$T/ilf/prev.shgrid"
same ilf-killed-keeps-previous "$T/ilf/prev.shgrid" "$T/prev_copy.shgrid"
no_temp ilf-killed-over-previous-no-temp "$T/ilf"
# A re-run after the kill succeeds (it reuses the buckets only where their sort had finished).
check ilf-after-kill ok "wrote" -- "$BIN" ilf build "$T/cap/sequence.json" --grid 4 --out "$T/ilf/new.shgrid"

# ---- sh --format gltf --specular-images: 18 RGBD PNGs and the glTF, or (a face unwritable half way)
# nothing at all: the PNGs written before the failure go again, the earlier glTF stays.
if [ -f "$PROBE" ]; then
  mkdir -p "$T/g"
  check gltf-faces ok "wrote" -- "$BIN" specular "$PROBE" --size 64 --faces "$T/g/spec"
  check gltf-ibl ok "18 RGBD PNGs" -- "$BIN" sh "$PROBE" --format gltf --specular-images "$T/g/spec/m{level}_{face}.exr" --out "$T/g/ibl.gltf"
  n=$(ls "$T/g" | grep -c '^ibl_m[0-2]_[pn][xyz]\.png$')
  if [ "$n" = 18 ]; then pass=$((pass+1)); else echo "FAIL gltf-ibl-pngs: $n of 18"; fail=$((fail+1)); fi
  cp "$T/g/ibl.gltf" "$T/ibl_copy.gltf"
  mkdir -p "$T/g2" && mkdir "$T/g2/new_m1_py.png"
  check gltf-ibl-unwritable fail "new_m1_py.png" -- "$BIN" sh "$PROBE" --format gltf --specular-images "$T/g/spec/m{level}_{face}.exr" --out "$T/g2/new.gltf"
  left=$(ls "$T/g2" | grep -v '^new_m1_py.png$')
  if [ -z "$left" ]; then pass=$((pass+1)); else echo "FAIL gltf-ibl-rollback: left $left"; fail=$((fail+1)); fi
  rm "$T/g/spec/m1_nz.exr"
  check gltf-ibl-missing-face fail "m1_nz.exr is missing" -- "$BIN" sh "$PROBE" --format gltf --specular-images "$T/g/spec/m{level}_{face}.exr" --out "$T/g/ibl.gltf"
  same gltf-ibl-keeps-previous "$T/g/ibl.gltf" "$T/ibl_copy.gltf"
  no_temp gltf-ibl-no-temp "$T/g"
fi

echo "cli_atomic: $pass passed, $fail failed, $skip skipped"
[ $fail -eq 0 ]
