#!/usr/bin/env bash
# Hostile inputs, third pass (issue 32; CTest cli_hostile), the campaign's reproducers: readers refuse
# what is not a regular file (a device, a link to one, a FIFO, a folder) with one line and no read that
# runs for ever (§2); outputs replace links planted in their folder and never overwrite an input, not
# even through a hard link (§3); .shtree and JSON files that lie are refused (§4); an allocation that
# fails says what and which option to lower, and long work shows progress in a log (§6).
set -u
source "$(dirname "$0")/cli_check.sh" "$1"
[ -f "$PROBE" ] || { echo "cli_hostile: no blender-data probe: skipped"; exit 0; }
T10=(timeout 20)  # a reader that spins on a device would hang: 124 then counts as a failure below
hang() { local name="$1"; shift; local out rc; out=$("${T10[@]}" "$@" 2>&1); rc=$?
  if [ $rc -eq 124 ]; then echo "FAIL $name: still running after 20 s: $out"; fail=$((fail+1)); return 1; fi; return 0; }

# §2: not regular files.
mkfifo "$T/fifo.exr"
ln -s /dev/zero "$T/zero.exr"
mkdir -p "$T/folder.exr"
for f in /dev/zero /dev/urandom "$T/zero.exr" "$T/fifo.exr"; do
  hang "info $f" "$BIN" info "$f" && check "info $f" fail "not a regular file" -- "${T10[@]}" "$BIN" info "$f"
done
check info-folder fail "" -- "${T10[@]}" "$BIN" info "$T/folder.exr"
hang specular "$BIN" specular /dev/zero --out "$T/s.ktx2" && check specular-dev fail "is a character device, not a regular file" -- "${T10[@]}" "$BIN" specular /dev/zero --out "$T/s.ktx2"
check sh-specular-images fail "not a regular file" -- "${T10[@]}" "$BIN" sh "$T/zero.exr" --format gltf --specular-images "$T/spec"
check lights-dev fail "not a regular file" -- "${T10[@]}" "$BIN" lights /dev/urandom --count 4
check ilf-manifest-fifo fail "FIFO" -- "${T10[@]}" "$BIN" ilf build "$T/fifo.exr" --out "$T/g.shgrid"
check ilf-info-dev fail "not a regular file" -- "${T10[@]}" "$BIN" ilf info /dev/zero
check convert-dev fail "not a regular file" -- "${T10[@]}" "$BIN" convert /dev/zero "$T/c.exr" --mapping latlong

# §3: an output never writes through a link planted in its folder.
echo "outside" > "$T/outside.txt"
cp "$PROBE" "$T/probe.exr"
mkdir -p "$T/out"
ln -s "$T/outside.txt" "$T/out/p.exr"
check link-replaced ok "" -- "$BIN" convert "$T/probe.exr" "$T/out/p.exr" --mapping latlong --size 16
if [ "$(cat "$T/outside.txt")" = outside ] && [ ! -L "$T/out/p.exr" ] && [ -f "$T/out/p.exr" ]; then pass=$((pass+1)); else echo "FAIL link-replaced: wrote through the link"; fail=$((fail+1)); fi
if "$BIN" web --out "$T/w0" --probe "$T/probe.exr" >/dev/null 2>&1; then
  mkdir -p "$T/site/data" "$T/elsewhere"
  ln -s "$T/outside.txt" "$T/site/index.html"
  ln -s "$T/elsewhere" "$T/site/three"
  ln -s "$T/outside.txt" "$T/site/data/probe0.exr"
  check web-links ok "" -- "$BIN" web --out "$T/site" --probe "$T/probe.exr"
  if [ "$(cat "$T/outside.txt")" = outside ] && [ -z "$(ls -A "$T/elsewhere")" ] && [ ! -L "$T/site/index.html" ] && [ ! -L "$T/site/three" ]; then
    pass=$((pass+1)); else echo "FAIL web-links: wrote through a planted link ($(cat "$T/outside.txt"), $(ls "$T/elsewhere" | head -3))"; fail=$((fail+1)); fi
else
  echo "cli_hostile: no web viewer in this build: web's planted links not tried"
fi

# §3: no output is an input (the same device and inode): refused, the input untouched.
sum() { sha256sum "$1" | cut -d' ' -f1; }
before=$(sum "$T/probe.exr")
check specular-onto-input fail "is the same file as the input" -- "$BIN" specular "$T/probe.exr" --out "$T/probe.exr" --size 16
ln "$T/probe.exr" "$T/hard.exr"
check convert-onto-hard-link fail "same file" -- "$BIN" convert "$T/probe.exr" "$T/hard.exr" --mapping latlong --size 16
check sh-map-onto-input fail "same file" -- "$BIN" sh "$T/probe.exr" --irradiance-map "$T/probe.exr"
[ "$(sum "$T/probe.exr")" = "$before" ] && pass=$((pass+1)) || { echo "FAIL: the input probe was changed"; fail=$((fail+1)); }
"$BIN" --quiet ilf synth --out "$T/seq" --probes 30 --size 8 >/dev/null
"$BIN" --quiet ilf build "$T/seq/sequence.json" --grid 6 --kernel 3 --cv-folds 0 --out "$T/g.shgrid" >/dev/null
gsum=$(sum "$T/g.shgrid")
check adapt-onto-input fail "same file" -- "$BIN" ilf adapt "$T/g.shgrid" --tolerance 0.01 --out "$T/g.shgrid"
check build-two-outputs fail "name the same file" -- "$BIN" ilf build "$T/seq/sequence.json" --grid 4 --out "$T/e.shgrid" --error-grid "$T/e.shgrid"
[ "$(sum "$T/g.shgrid")" = "$gsum" ] && pass=$((pass+1)) || { echo "FAIL: ilf adapt changed its input"; fail=$((fail+1)); }
check adapt ok "" -- "$BIN" ilf adapt "$T/g.shgrid" --tolerance 0.01 --out "$T/t.shtree"
tsum=$(sum "$T/t.shtree")
check densify-onto-input fail "same file" -- "$BIN" ilf densify "$T/t.shtree" --out "$T/t.shtree"
[ "$(sum "$T/t.shtree")" = "$tsum" ] && pass=$((pass+1)) || { echo "FAIL: ilf densify changed its input"; fail=$((fail+1)); }
# An input named inside a file (the sequence's frames), not on the command line: the commit refuses.
f0="$T/seq/frames/000000.exr"; fsum=$(sum "$f0")
check frame-in-manifest fail "is an input of this command" -- "$BIN" ilf build "$T/seq/sequence.json" --grid 4 --out "$f0"
[ "$(sum "$f0")" = "$fsum" ] && pass=$((pass+1)) || { echo "FAIL: a frame named by the manifest was overwritten"; fail=$((fail+1)); }
if "$BIN" --help | grep -q "^  lab"; then
  CAM=(--eye 0,1.3,2.2 --target 0,0.3,0 --fov 40 --width 24 --height 18 --samples 1)
  check photo-mask-out fail "name the same file" -- "$BIN" lab photograph low-scene2 "${CAM[@]}" --object blob --at 0,0.2,0 --object-size 0.3 --triangles 500 --mask "$T/m.exr" --out "$T/m.exr"
  [ ! -e "$T/m.exr" ] && pass=$((pass+1)) || { echo "FAIL photo-mask-out: wrote $T/m.exr"; fail=$((fail+1)); }
  # composite --out naming its photograph, or a probe image named inside its probe set.
  "$BIN" --quiet lab photograph low-scene2 "${CAM[@]}" --out "$T/photo.exr" >/dev/null
  "$BIN" --quiet lab capture low-scene2 --fusion --probe 0,0.5,0 --size 16 --out "$T/fus" >/dev/null 2>&1
  COMP=("$BIN" --quiet composite "$T/photo.exr" --eye 0,1.3,2.2 --target 0,0.3,0 --fov 40 --probes "$T/fus/probes.json"
        --object blob --at 0,0.2,0 --object-size 0.3 --triangles 500 --samples 2 --object-samples 2)
  psum=$(sum "$T/photo.exr"); qsum=$(sum "$T/fus/probes/p0.exr")
  check composite-onto-photo fail "is the same file as the input" -- "${COMP[@]}" --out "$T/photo.exr"
  check composite-onto-probe fail "is an input of this command" -- "${COMP[@]}" --out "$T/fus/probes/p0.exr"
  [ "$(sum "$T/photo.exr")" = "$psum" ] && [ "$(sum "$T/fus/probes/p0.exr")" = "$qsum" ] && pass=$((pass+1)) \
    || { echo "FAIL composite: an input was changed"; fail=$((fail+1)); }
fi

# §4: a .shtree whose counts, bricks or length lie.
python3 - "$T/t.shtree" "$T" <<'PY'
import json, sys
src, T = sys.argv[1], sys.argv[2]
data = open(src, "rb").read()
l1 = data.index(b"\n") + 1
l2 = data.index(b"\n", l1) + 1
head = json.loads(data[l1:l2])
body = data[l2:]
def write(name, h, b):
    line = json.dumps(h, separators=(",", ":")).encode()
    line += b" " * (l2 - l1 - 1 - len(line)) + b"\n"
    assert len(line) == l2 - l1
    open(f"{T}/{name}", "wb").write(data[:l1] + line + b)
write("trailing.shtree", head, body + b"\0" * 64)
h = dict(head); h["bricks"] = list(head["bricks"]); i = max(k for k, n in enumerate(h["bricks"]) if n > 1) if any(n > 1 for n in h["bricks"]) else 0
h["bricks"][i] -= 1
write("short.shtree", h, body)
b = bytearray(body); b[-1] ^= 0x01  # a value of the last brick changed
write("changed.shtree", head, bytes(b))
PY
check shtree-trailing fail "bytes after the last brick" -- "$BIN" ilf info "$T/trailing.shtree"
check shtree-short-count fail "" -- "$BIN" ilf info "$T/short.shtree"
check shtree-changed fail "checksum" -- "$BIN" ilf info "$T/changed.shtree"
# A JSON integer beyond its type is refused, not read modulo 2^32 (a .shgrid header's "bands").
python3 - "$T/g.shgrid" "$T/wide.shgrid" <<'PY'
import sys
d = open(sys.argv[1], "rb").read()
l1 = d.index(b"\n") + 1; l2 = d.index(b"\n", l1) + 1
line = d[l1:l2 - 1].rstrip()
new = line.replace(b'"bands":5', b'"bands":4294967301')
assert new != line
open(sys.argv[2], "wb").write(d[:l1] + new + b" " * (l2 - l1 - 1 - len(new)) + b"\n" + d[l2:])
PY
check json-narrowing fail "4294967301 is not a whole number" -- "$BIN" ilf info "$T/wide.shgrid"
check shgrid-trailing-setup ok "" -- cp "$T/g.shgrid" "$T/g2.shgrid"
printf 'junk' >> "$T/g2.shgrid"
check shgrid-trailing fail "bytes after the data" -- "$BIN" ilf info "$T/g2.shgrid"

# §6: an allocation that fails names what and which option to lower. AddressSanitizer reserves terabytes of
# address space at start-up, so under `make test-sanitize` no address-space limit can be set: skipped there.
if ldd "$BIN" 2>/dev/null | grep -q libasan; then
  echo "skip out-of-memory: an AddressSanitizer build cannot run under ulimit -v"
else
out=$(bash -c 'ulimit -v 2000000; exec "$0" convert "$1" "$2" --mapping latlong --size 16384' "$BIN" "$PROBE" "$T/big.exr" 2>&1); rc=$?
if [ $rc -ne 0 ] && [ $rc -lt 128 ] && [ "$(wc -l <<<"$out")" = 1 ] && grep -q "out of memory" <<<"$out" && grep -q -- "--size 16384" <<<"$out"; then
  pass=$((pass+1)); else echo "FAIL out-of-memory: exit $rc: $out"; fail=$((fail+1)); fi
fi
# Progress in a log (stderr not a terminal): a line every few seconds (IBLKIT_PROGRESS_EVERY shortens it).
out=$(IBLKIT_PROGRESS_EVERY=0.01 "$BIN" convert "$PROBE" "$T/p2.exr" --mapping mirrorball --size 512 2>&1 >/dev/null)
grep -q "^iblkit: resample [0-9]*% " <<<"$out" && pass=$((pass+1)) || { echo "FAIL progress in a log: $out"; fail=$((fail+1)); }

echo "cli_hostile: $pass passed, $fail failed"
[ $fail -eq 0 ]
