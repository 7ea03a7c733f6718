#!/usr/bin/env bash
# End-to-end checks of the CLI as a new user meets it (registered with CTest as cli_smoke):
# --help everywhere, the main commands on a real probe, and every bad-input class failing with a
# one-line message and a non-zero exit code, never a crash.
set -u
source "$(dirname "$0")/cli_check.sh" "$1"

check help ok "Subcommands" -- "$BIN" --help
subcommands() { "$@" --help | awk '/^Subcommands:/{f=1;next} f&&/^[^ ]/{f=0} f&&NF{print $1}'; }  # up to "Examples:"
for sub in $(subcommands "$BIN"); do
  nested=$(subcommands "$BIN" "$sub")
  if [ -z "$nested" ]; then
    check "help-$sub" ok "Example" -- "$BIN" "$sub" --help
  else  # a group (lab, ilf): every member shows an example
    for leaf in $nested; do check "help-$sub-$leaf" ok "Example" -- "$BIN" "$sub" "$leaf" --help; done
  fi
done
check no-subcommand fail "" -- "$BIN"
check unknown-subcommand fail "" -- "$BIN" frobnicate
check missing-file fail "nothere.exr: no such file" -- "$BIN" info "$T/nothere.exr"
printf 'not an image at all\n' > "$T/notes.exr"
check corrupt-image fail "notes.exr" -- "$BIN" info "$T/notes.exr"
check folder-not-image fail "folder" -- "$BIN" preview "$T" "$T/x.png"

if [ -f "$PROBE" ]; then
  check info ok "latlong" -- "$BIN" info "$PROBE"
  check info-json ok '"mapping": "latlong"' -- "$BIN" --json info "$PROBE"
  check convert ok "power out/in" -- "$BIN" convert "$PROBE" "$T/cross.exr" --mapping hcross --size 64
  check convert-back ok "" -- "$BIN" convert "$T/cross.exr" "$T/ll.exr" --mapping latlong --size 64
  check convert-faces ok "" -- "$BIN" convert "$PROBE" "$T/faces" --mapping cubestrip --size 32 --faces
  check read-faces ok "hcross" -- "$BIN" info "$T/faces"
  check bad-mapping fail "unknown mapping 'sphere'" -- "$BIN" convert "$PROBE" "$T/x.exr" --mapping sphere
  check bad-in-mapping fail "aspect" -- "$BIN" info "$PROBE" --in-mapping mirrorball
  check bad-size fail "" -- "$BIN" convert "$PROBE" "$T/x.exr" --size 0
  check bad-extension fail "no image writer" -- "$BIN" convert "$PROBE" "$T/x.xyz" --size 8
  check preview ok "wrote" -- "$BIN" preview "$PROBE" "$T/p.png"
  check demo-mappings ok "contact sheet" -- "$BIN" demo --out "$T/demo" --only mappings
  check demo-unknown-step fail "no demo step 'nope'" -- "$BIN" demo --out "$T/demo" --only nope
  check lab-capture ok "" -- "$BIN" lab capture low-scene1 --probe 0,1,0 --size 16 --out "$T/lab"
  check render-cpu ok "CPU time" -- "$BIN" render blob --light "$PROBE" --backend cpu --size 64x48 --triangles 2000 --out "$T/r.png"
  check lights ok "" -- "$BIN" lights "$PROBE" --method median-cut --count 8 --out "$T/l.json" --overlay "$T/l.png"
  check render-lights ok "8 directional lights" -- "$BIN" render blob --light "$T/l.json" --backend cpu --size 64x48 --triangles 2000 --out "$T/rl.png"
  check lights-zero fail "" -- "$BIN" lights "$PROBE" --count 0
  check eval-small ok "" -- "$BIN" eval "$PROBE" --methods median-cut,variance-cut --counts 1,4 --normals-level 2 --out "$T/ev"
  check render-mesh-file ok "CPU time" -- "$BIN" render "$(dirname "$0")/../../examples/crypt.obj" --light "$PROBE" --backend cpu --size 64x48 --out "$T/rm.png"
  check render-missing-mesh fail "nothere.obj" -- "$BIN" render "$T/nothere.obj" --light "$PROBE" --backend cpu --out "$T/rm.png"
  check render-bad-size fail "--size" -- "$BIN" render blob --light "$PROBE" --size 64by48 --out "$T/r.png"
  printf '{"format":"iblkit.lights/1","lights":[{"direction":[0,1,0]}]}' > "$T/bad_lights.json"
  check render-bad-lights fail "irradiance" -- "$BIN" render blob --light "$T/bad_lights.json" --backend cpu --out "$T/r.png"
  [ -s "$T/demo/contact_sheet.png" ] && pass=$((pass+1)) || { echo "FAIL demo wrote no contact sheet"; fail=$((fail+1)); }
else
  skip=$((skip+1))
fi

echo "$pass passed, $fail failed, $skip skipped"
[ $fail -eq 0 ]
