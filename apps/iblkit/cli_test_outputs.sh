#!/usr/bin/env bash
# Commands with several outputs keep all or none of them (registered with CTest as cli_outputs; a few
# seconds; docs/cli.md "Outputs"): a command that fails after writing one output removes it, puts back
# the file it replaced, and removes the folders it made; every command makes the missing folders of its
# outputs; two --light inputs with one stem write two files; the ILF bucket cache is where the README
# says and --drop-buckets removes it. An output "inside" a plain file ($T/file/…) cannot be written,
# even by root.
set -u
source "$(dirname "$0")/cli_check.sh" "$1"

absent() { if [ -e "$2" ]; then echo "FAIL $1: $2 exists"; fail=$((fail+1)); else pass=$((pass+1)); fi; }
present() { if [ -e "$2" ]; then pass=$((pass+1)); else echo "FAIL $1: $2 missing"; fail=$((fail+1)); fi; }
same() { if cmp -s "$2" "$3"; then pass=$((pass+1)); else echo "FAIL $1: $2 changed"; fail=$((fail+1)); fi; }
# clean NAME DIR: DIR holds no temporary (*.tmp-*) or kept (*.bak-*) file.
clean() {
  local left
  left=$(find "$2" -name '*.tmp-*' -o -name '*.bak-*' 2>/dev/null)
  if [ -n "$left" ]; then echo "FAIL $1: left behind: $left"; fail=$((fail+1)); else pass=$((pass+1)); fi
}
echo "a plain file" > "$T/file"
BAD="$T/file/sub"

if [ -f "$PROBE" ]; then
  "$BIN" --quiet convert "$PROBE" "$T/p.exr" --mapping latlong --size 32 >/dev/null
  # lights: --out written, then --gltf fails → no l.json, and a previous l.json is put back.
  check lights-gltf-fails fail "x.gltf: cannot write" -- "$BIN" lights "$T/p.exr" --count 4 --out "$T/a/l.json" --gltf "$BAD/x.gltf"
  absent lights-no-json "$T/a/l.json"
  absent lights-no-folder "$T/a"
  echo '{"previous": true}' > "$T/l.json"; cp "$T/l.json" "$T/l_copy.json"
  check lights-gltf-fails-over-previous fail "x.gltf" -- "$BIN" lights "$T/p.exr" --count 4 --out "$T/l.json" --overlay "$T/o.png" --gltf "$BAD/x.gltf"
  same lights-previous-back "$T/l.json" "$T/l_copy.json"
  absent lights-no-overlay "$T/o.png"
  check lights-ok ok "wrote" -- "$BIN" lights "$T/p.exr" --count 4 --out "$T/l.json" --gltf "$T/g/x.gltf"
  present lights-gltf-folder-made "$T/g/x.gltf"
  # sh: --out then --irradiance-map fails.
  check sh-map-fails fail "i.exr: cannot write" -- "$BIN" sh "$T/p.exr" --out "$T/s.json" --irradiance-map "$BAD/i.exr"
  absent sh-no-json "$T/s.json"
  # render: two --light files, the second unreadable: the first frame goes again.
  check render-second-light-fails fail "nothere.json" -- "$BIN" render blob --light "$T/p.exr" --light "$T/nothere.json" --backend cpu --size 32x24 --out "$T/r/f.png"
  absent render-no-first-frame "$T/r"
  # render: two --light inputs with one stem write two frames.
  mkdir -p "$T/x" "$T/y"; cp "$T/p.exr" "$T/x/probe.exr"; cp "$T/p.exr" "$T/y/probe.exr"
  check render-same-stem ok "" -- "$BIN" render blob --light "$T/x/probe.exr" --light "$T/y/probe.exr" --backend cpu --size 32x24 --out "$T/f.png"
  present render-same-stem-1 "$T/f_probe_1.png"
  present render-same-stem-2 "$T/f_probe_2.png"
  absent render-same-stem-no-shared "$T/f_probe.png"
  check render-same-file-twice ok "" -- "$BIN" --json render blob --light "$T/x/probe.exr" --light "$T/x/probe.exr" --backend cpu --size 32x24 --out "$T/t.exr"
  present render-same-file-twice-2 "$T/t_probe_2.exr"
  # convert: missing folders of the output are made (the one rule), and unmade when it fails.
  check convert-makes-folders ok "wrote" -- "$BIN" convert "$T/p.exr" "$T/n1/n2/c.exr" --size 8
  present convert-folder "$T/n1/n2/c.exr"
  check convert-fails-unmakes fail "" -- "$BIN" convert "$T/p.exr" "$T/m1/m2/c.xyz" --size 8
  absent convert-fails-no-folder "$T/m1"
else
  skip=$((skip+1))
fi

# lab capture: frames written, then the manifest cannot be (a folder in its place): no frames stay.
mkdir -p "$T/cap/sequence.json"
check capture-manifest-fails fail "sequence.json" -- "$BIN" --quiet lab capture low-scene2 --grid 2,1,1 --mapping mirrorball --size 16 --out "$T/cap"
absent capture-no-frames "$T/cap/frames"
rmdir "$T/cap/sequence.json"
check capture ok "" -- "$BIN" --quiet lab capture low-scene2 --grid 2,2,2 --mapping mirrorball --size 16 --out "$T/cap"
# ilf build: missing folders made like every command's; the bucket cache OUT.buckets beside it,
# reused by a re-run, removed by --drop-buckets.
check ilf-makes-folders ok "wrote" -- "$BIN" ilf build "$T/cap/sequence.json" --grid 2 --bands 2 --out "$T/new/dir/g.shgrid"
present ilf-buckets-beside "$T/new/dir/g.shgrid.buckets"
check ilf-reuses ok "reused" -- "$BIN" ilf build "$T/cap/sequence.json" --grid 2 --bands 2 --out "$T/new/dir/g.shgrid"
check ilf-drop-buckets ok "wrote" -- "$BIN" ilf build "$T/cap/sequence.json" --grid 2 --bands 2 --out "$T/new/dir/g.shgrid" --drop-buckets
absent ilf-buckets-dropped "$T/new/dir/g.shgrid.buckets"
present ilf-grid-kept "$T/new/dir/g.shgrid"
check ilf-bad-folder fail "g.shgrid" -- "$BIN" ilf build "$T/cap/sequence.json" --grid 2 --out "$BAD/g.shgrid"
clean no-leftovers "$T"

echo "cli_outputs: $pass passed, $fail failed, $skip skipped"
[ $fail -eq 0 ]
