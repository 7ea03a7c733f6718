#!/usr/bin/env bash
# Issue 19's crash list, kept (CTest cli_robust): every input that once aborted inside Embree,
# segfaulted in the SH grid lookup or ran out of memory now fails with a one-line message.
set -u
source "$(dirname "$0")/cli_check.sh" "$1"
BIN=$(realpath "$BIN"); cd "$T"

# The issue's setup, smaller where the size does not matter.
"$BIN" lab capture low-scene2 --grid 2,2,2 --mapping mirrorball --size 16 --out cap >/dev/null 2>&1 &&
  "$BIN" ilf build cap/sequence.json --grid 4 --bands 3 --out room.shgrid >/dev/null 2>&1 || { echo "FAIL setup ilf"; exit 1; }
"$BIN" lab capture t-corridor --fusion --probe 0,1.5,-1 --probe 0,1.5,5 --size 16 --out tc >/dev/null 2>&1 || { echo "FAIL setup fusion"; exit 1; }
"$BIN" nearfield simulate flashlight --grid 3x3 --resolution 16 --out nf/nf.json >/dev/null 2>&1 || { echo "FAIL setup nearfield"; exit 1; }

# Non-finite or huge coordinates (Embree's ray.valid() abort).
for v in nan inf 1e30; do
  check "probe-$v" fail "--probe|probe position" -- "$BIN" lab capture low-scene2 --probe "$v,1,0" --size 8 --out c
  check "truth-$v" fail "--at|ground-truth position" -- "$BIN" lab truth low-scene2 --at "$v,1,0" --size 8
  check "random-volume-$v" fail "volume" -- "$BIN" lab capture low-scene2 --random 3 --volume "$v,0,0;1,1,1" --size 8 --out c
  check "grid-volume-$v" fail "volume" -- "$BIN" lab capture low-scene2 --grid 2,2,2 --volume "0,0,0;$v,1,1" --size 8 --out c
  check "path-$v" fail "--path|path point 2" -- "$BIN" lab capture low-scene2 --path "0,1,0;$v,1,1" --size 8 --out c
  check "fuse-at-$v" fail "--at|the point" -- "$BIN" fuse tc/probes.json --at "$v,1.5,1" --out f.exr
  check "fuse-eval-$v" fail "--at|evaluation point" -- "$BIN" fuse eval tc/probes.json --scene t-corridor --at "$v,1.5,1" --out ev
  check "render-eye-$v" fail "--eye|camera eye" -- "$BIN" render blob --light room.shgrid --eye "$v,1,1" --truth low-scene2 --size 16x12 --out r.png
  check "nearfield-eye-$v" fail "--eye|camera eye" -- "$BIN" nearfield render nf/nf.json --eye "$v,0,0" --out n.png
  check "nearfield-at-$v" fail "--at|luminaire position" -- "$BIN" nearfield render nf/nf.json --at "$v,0,0" --out n.png
  check "ilf-query-$v" fail "--at|not finite" -- "$BIN" ilf query room.shgrid --at "$v,1,0"
  check "ilf-slice-$v" fail "--plane" -- "$BIN" ilf slice room.shgrid --plane "y=$v" --out s.png
done
check render-eye-1e30-gl fail "camera eye" -- "$BIN" render blob --light room.shgrid --eye 1e30,1,1 --size 16x12 --out r.png
printf '[[0,1.5,0],[1e30,1.5,1]]' > path.json
printf '[[0,1.5,0],[0,1.5,1]]' > path2.json
check path-file-1e30 fail "point 2" -- "$BIN" fuse tc/probes.json --path path.json --out pf
python3 - <<'PY'
import json
j = json.load(open("tc/probes.json")); j["probes"][1]["position"] = [1e30, 1.5, 5]
json.dump(j, open("tc/far.json", "w"))
PY
check probe-set-1e30 fail 'probes\[1\]: field "position"' -- "$BIN" fuse tc/far.json --at 0,1.5,1 --out f.exr

# The SH grid: a header with min/max ±1e308, and one that declares 200³ points in a 256-byte file.
python3 - <<'PY'
import json
def mk(name, hdr, nbytes):
    h = "IBLKIT-SHGRID 1\n" + json.dumps(dict(hdr, dtype="float32", layout="z,y,x,coefficient,channel"))
    total = ((len(h) + 1 + 63) // 64) * 64
    open(name, "wb").write((h + " " * (total - len(h) - 1) + "\n").encode() + b"\0" * nbytes)
mk("huge.shgrid", dict(bands=1, resolution=[2, 2, 2], min=[-1e308] * 3, max=[1e308] * 3), 96)
mk("big.shgrid", dict(bands=5, resolution=[200, 200, 200], min=[0, 0, 0], max=[1, 1, 1]), 128)
PY
check shgrid-1e308-info fail '"min", "max"' -- "$BIN" ilf info huge.shgrid
check shgrid-1e308-query fail '"min", "max"' -- "$BIN" ilf query huge.shgrid --at 0,0,0
check shgrid-declared-size fail "truncated: the header declares 200x200x200" -- "$BIN" ilf info big.shgrid

# Sizes bounded before allocation.
check capture-grid-huge fail "exceeds the 1e\+06.*choose fewer grid points" -- "$BIN" lab capture low-scene2 --grid 100000,100000,100000 --out c
check capture-random-huge fail "exceeds the 1e\+06.*random probe count" -- "$BIN" lab capture low-scene2 --random 1000000000 --out c
printf '{"format":"iblkit.scene/1","name":"t","surfaces":[{"type":"sphere","name":"s","center":[0,1,0],"radius":0.5,"rings":100000,"segments":100000}]}' > bigsphere.json
check sphere-rings-huge fail "surfaces\[0\]: a sphere of 100000 rings.*choose fewer rings" -- "$BIN" lab capture bigsphere.json --probe 0,1,0 --size 8 --out c
printf '{"format":"iblkit.scene/1","name":"t","surfaces":[{"type":"sphere","name":"s","center":[0,1,0],"radius":0.5,"rings":1e20}]}' > bigsphere2.json
check sphere-rings-1e20 fail "surfaces\[0\]\.rings: expected a whole number" -- "$BIN" lab capture bigsphere2.json --probe 0,1,0 --size 8 --out c

# Values that once passed and should not.
cp "$T/tc/probes/p0.exr" same.exr
check convert-onto-input fail "is the same file as the input" -- "$BIN" convert same.exr ./same.exr --mapping mirrorball --size 16
cmp -s same.exr "$T/tc/probes/p0.exr" || { echo "FAIL convert-onto-input: the input changed"; fail=$((fail + 1)); }
check convert-size-16384 fail "would allocate .* GB.*choose a smaller --size" -- "$BIN" convert "$T/tc/probes/p0.exr" x.exr --mapping hcross --size 16384
check ilf-kernel-1e9 fail "kernel.*would allocate.*kernel_cells" -- "$BIN" ilf build cap/sequence.json --grid 4 --bands 3 --kernel 1e9 --out k.shgrid
check preview-exposure-nan fail "exposure" -- "$BIN" preview tc/probes/p0.exr p.png --exposure nan
for v in nan -1; do
  check "lights-min-separation-$v" fail "minimum separation" -- "$BIN" lights tc/probes/p0.exr --min-separation "$v" --out l.json
  check "ilf-subsample-$v" fail "subsample: threshold" -- "$BIN" ilf build cap/sequence.json --grid 4 --bands 3 --subsample "$v" --out k.shgrid
  check "fuse-tau-$v" fail "time constant" -- "$BIN" fuse tc/probes.json --path "$T/path2.json" --tau "$v" --out pf
  check "render-albedo-$v" fail "albedo" -- "$BIN" render blob --light tc/probes/p0.exr --albedo "$v,0.5,0.5" --backend cpu --size 16x12 --out r.png
done
check fuse-lights-huge ok "warning: --lights 1000000: .* gives only" -- "$BIN" fuse tc/probes.json --at 0,1.5,1 --lights 1000000 --out f.exr
printf '{"format":"iblkit.sh/1","bands":0,"coefficients":[]}' > sh0.json
check sh-bands-0 fail '"bands" must be in 1' -- "$BIN" render blob --light sh0.json --backend cpu --size 16x12 --out r.png
python3 - <<'PY'
import struct
def pfm(name, w, h, vals):
    open(name, "wb").write(f"PF\n{w} {h}\n-1.0\n".encode() + struct.pack("<%df" % len(vals), *vals))
v = [1.0] * 24; v[4] = 3e38
pfm("huge.pfm", 4, 2, v)
pfm("ball1.pfm", 1, 1, [1.0] * 3)
PY
check pixel-3e38 fail "pixel \(1, 1\) channel 1 is above 1e20" -- "$BIN" lights huge.pfm --out l.json
check mirror-ball-1x1 ok "12.566" -- "$BIN" info ball1.pfm --in-mapping mirrorball

# Messages: one line naming the file, the field and the value; never nlohmann's raw text; hints name
# the flags the command has.
nojson() { ! grep -q "json.exception" <<<"$("$@" 2>&1)"; }
printf '[1,2]' > arr.json
check msg-lighting-array fail "arr.json: expected a JSON object" -- "$BIN" render blob --light arr.json --backend cpu --size 16x12 --out r.png
printf '{"format":"iblkit.sequence/1","mapping":3,"probes":[]}' > seqmap.json
check msg-sequence-mapping fail 'seqmap.json: field "mapping" must be a string, got 3' -- "$BIN" ilf build seqmap.json --out q.shgrid
python3 - <<'PY'
import json
j = json.load(open("tc/probes.json")); j["dead_angle_deg"] = "a"; json.dump(j, open("tc/dead.json", "w"))
j = json.load(open("tc/probes.json")); j["probes"][0]["position"] = [0, 1, "a"]; json.dump(j, open("tc/pos.json", "w"))
PY
check msg-probes-dead-angle fail 'dead.json: field "dead_angle_deg" must be a number, got "a"' -- "$BIN" fuse tc/dead.json --at 0,1.5,1 --out f.exr
check msg-probes-position fail 'pos.json: probes\[0\]: field "position"' -- "$BIN" fuse tc/pos.json --at 0,1.5,1 --out f.exr
printf '{"format":"iblkit.lights/1","method":7,"lights":[]}' > lm.json
check msg-lights-method fail 'lm.json: field "method" must be a string' -- "$BIN" render blob --light lm.json --backend cpu --size 16x12 --out r.png
printf '{"format":"iblkit.lights/1","lights":[{"direction":[0,1,0],"irradiance":[1,1,1],"solid_angle":"x"}]}' > ls.json
check msg-lights-solid-angle fail 'ls.json: lights\[0\]: field "solid_angle" must be a number' -- "$BIN" render blob --light ls.json --backend cpu --size 16x12 --out r.png
printf '{"format":"iblkit.sh/1","bands":1}' > shc.json
check msg-sh-coefficients fail 'shc.json: "coefficients" must be an array' -- "$BIN" render blob --light shc.json --backend cpu --size 16x12 --out r.png
printf '{"format":"iblkit.scene/1","name":"t","volume":{"min":[-1,0,-1],"max":[1,2,1]}}' > nosurf.json
check msg-scene-prefix fail '^iblkit: error: [^ ]*nosurf.json: surfaces: missing' -- "$BIN" lab capture nosurf.json --probe 0,1,0 --size 8 --out c
printf '{"format":"iblkit.scene/1","name":"t","proxy":3,"surfaces":[]}' > sproxy.json
check msg-scene-proxy fail 'sproxy.json: proxy: expected a file name' -- "$BIN" lab capture sproxy.json --probe 0,1,0 --size 8 --out c
check msg-sanitize-hint fail "; --sanitize replaces such values" -- "$BIN" info huge.pfm
check msg-unknown-subcommand fail "unknown subcommand 'bogus' of iblkit \(see iblkit --help\)" -- "$BIN" bogus
check msg-unknown-group-subcommand fail "unknown subcommand 'bogus' of iblkit lab" -- "$BIN" lab bogus
for f in arr.json seqmap.json tc/dead.json lm.json ls.json shc.json sproxy.json; do
  if nojson "$BIN" render blob --light "$f" --backend cpu --size 16x12 --out r.png && nojson "$BIN" ilf build "$f" --out q.shgrid &&
     nojson "$BIN" fuse "$f" --at 0,1.5,1 --out f.exr && nojson "$BIN" lab capture "$f" --probe 0,1,0 --size 8 --out c; then
    pass=$((pass+1))
  else echo "FAIL msg-raw-json $f: a message shows nlohmann's raw text"; fail=$((fail+1)); fi
done

# Near-field manifests: messages name the file, the field and the value.
nfedit() { python3 -c "import json,sys; j=json.load(open('nf/nf.json')); exec(sys.argv[1]); json.dump(j, open('nf/bad.json','w'))" "$1"; }
if command -v python3 >/dev/null; then
  nfedit 'j["spacing"]="wide"';         check msg-nf-spacing fail 'bad.json: field "spacing" must be a number, got "wide"' -- "$BIN" nearfield info nf/bad.json
  nfedit 'j["grid"]=[4294967299,1]';   check msg-nf-grid fail 'bad.json: field "grid": 4294967299x1 out of range' -- "$BIN" nearfield info nf/bad.json
  nfedit 'j["measurements"][1]["i"]=0.5'; check msg-nf-i fail 'bad.json: measurements\[1\]: field "i" must be a whole number, got 0.5' -- "$BIN" nearfield info nf/bad.json
  nfedit 'del j["measurements"][2]["positive"]'; check msg-nf-image fail 'bad.json: measurements\[2\]: field "positive" is missing' -- "$BIN" nearfield info nf/bad.json
else
  skip=$((skip+1))
fi

# The README's Fig. 9 example (the camera looks at --at; only the frame size is made smaller here;
# cli_examples runs every example as written).
mkdir -p ex && cd ex
check readme-fig9 ok "object relative L1" -- "$BIN" render blob --light ../room.shgrid --at 0,0.85,0 --object-size 0.35 --truth low-scene2 --size 160x120 --out fig9.png
cd ..

echo "$pass passed, $fail failed, $skip skipped"
[ $fail -eq 0 ]
