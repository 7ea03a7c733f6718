#!/usr/bin/env bash
# Every example runs as written (registered with CTest as cli_examples): the `build/iblkit …` lines of
# README.md's code blocks, then the `iblkit …` lines under "Example:"/"Examples:" of every --help (the
# top level, each subcommand, each member of a group), in that order, in one scratch folder where the
# files the examples name and do not make themselves are put first (probe.exr and forest.exr: 32-pixel
# lat-longs of Blender's forest; path.json; cam.json; room.obj and floor.obj: a box room and a floor at
# y = 0; grid.shgrid: an SH grid of low-scene2 over x, z in [-1, 1], y in [0.1, 1.5]; fusion/: a
# low-scene2 probe set at (0.1, 0.3, 0.1), what composite's examples composite into; ball/ and brackets/: lab
# shoot's chrome-ball photographs; photo.jpg, pts.json, b1..b4.jpg, lens.json: chessboards for camera's)
# and ../shared is
# the shared data. A failing example fails the test with its command and message. Skipped, with a message:
# `view` without --frames (an interactive window), examples that need OpenGL where it is absent, and
# those that read ../shared where it is absent. Each example may take IBLKIT_EXAMPLE_TIMEOUT seconds
# (default 120; make test-sanitize gives more).
set -u
source "$(dirname "$0")/cli_check.sh" "$1"
BIN=$(realpath "$BIN")
SRC=$(cd "$(dirname "$0")/../.." && pwd)
SHARED=${IBLKIT_SHARED:-$SRC/../shared}
W="$T/run"
mkdir -p "$W/build"
[ -d "$SHARED" ] && ln -s "$(cd "$SHARED" && pwd)" "$T/shared"
ln -s "$(cd "$(dirname "$BIN")" && pwd)/$(basename "$BIN")" "$W/build/iblkit"
cd "$W"

# ---- the files the examples name ------------------------------------------------------------------
"$BIN" --quiet convert "$PROBE" probe.exr --mapping latlong --size 32 >/dev/null
"$BIN" --quiet convert "$PROBE" forest.exr --mapping latlong --size 32 >/dev/null
cat > path.json <<'EOF'
{"format": "iblkit.path/1", "points": [{"position": [0, 1.5, 0], "time": 0}, {"position": [0, 1.5, 2], "time": 1},
 {"position": [0, 1.5, 4], "time": 2}]}
EOF
cat > cam.json <<'EOF'
{"format": "iblkit.camera/1", "eye": [0, 1.2, 1.8], "target": [0, 0.3, 0], "up": [0, 1, 0], "fov_y_deg": 40}
EOF
printf 'v -2 0 -2\nv 2 0 -2\nv 2 0 2\nv -2 0 2\nf 1 3 2\nf 1 4 3\n' > floor.obj
{ for v in "-2 0 -2" "2 0 -2" "2 0 2" "-2 0 2" "-2 3 -2" "2 3 -2" "2 3 2" "-2 3 2"; do echo "v $v"; done
  printf 'f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n'; } > room.obj
"$BIN" --quiet lab capture low-scene2 --grid 2,2,2 --volume "-1,0.1,-1;1,1.5,1" --mapping mirrorball --size 16 --out gridcap >/dev/null &&
  "$BIN" --quiet ilf build gridcap/sequence.json --grid 4 --bands 3 --out grid.shgrid >/dev/null || echo "FAIL setup: grid.shgrid"
"$BIN" --quiet lab capture low-scene2 --fusion --probe 0.1,0.3,0.1 --size 32 --out fusion >/dev/null || echo "FAIL setup: fusion/"
# ball/ and brackets/: what `lab shoot`'s examples write, which `probe from-ball`'s examples read (its --help comes first)
"$BIN" --quiet lab shoot low-scene1 --at 0,1,0 --distance-radii 8 --out ball >/dev/null || echo "FAIL setup: ball/"
"$BIN" --quiet lab shoot low-scene2 --two-sides --distance 2 --bracket 5 --ev-step 2 --noise --quality 95 --out brackets \
  >/dev/null || echo "FAIL setup: brackets/"
# window/: a ball in t-corridor seeing its bright panel, and the panel photographed from there (probe calibrate's)
"$BIN" --quiet lab shoot t-corridor --at 0,1.5,-1 --distance-radii 8 --width 256 --height 256 --truth-size 0 \
  --out window >/dev/null &&
  "$BIN" --quiet lab photograph t-corridor --eye 0,1.5,-1 --target 5.95,1.5,-1 --fov 40 --width 64 --height 64 \
    --out window/light.exr >/dev/null || echo "FAIL setup: window/"
# photo.jpg, pts.json, b1..b4.jpg (= board1..4.jpg) and lens.json: chessboards on the floor photographed by OpenCV
# (camera_test_tool.py, the peer of cli_camera) for `camera`'s examples; without python3-opencv they are skipped.
have_cv=no
if /usr/bin/python3 -c "import cv2, numpy" >/dev/null 2>&1; then
  have_cv=yes
  tool="$SRC/apps/iblkit/camera_test_tool.py"
  i=0
  for eye in "0,0.9,0.7" "0.4,0.8,0.6" "-0.4,0.9,0.5" "0.2,0.6,0.8" "-0.2,1.0,0.4"; do
    echo "{\"format\":\"iblkit.camera/1\",\"eye\":[$eye],\"target\":[0.1,0,-0.1],\"up\":[0,1,0],\"fov_y_deg\":40,\"width\":640,\"height\":480}" >"$T/c$i.json"
    i=$((i+1))
  done
  /usr/bin/python3 "$tool" board "$T/c0.json" photo.jpg 9 6 0.05 0,0,0 1,0,0 0,0,-1 &&
    /usr/bin/python3 "$tool" points "$T/c0.json" pts.json depth || echo "FAIL setup: photo.jpg, pts.json"
  for i in 1 2 3 4; do
    /usr/bin/python3 "$tool" board "$T/c$i.json" "b$i.jpg" 9 6 0.025 0,0,0 1,0,0 0,0,-1 && cp "b$i.jpg" "board$i.jpg" ||
      echo "FAIL setup: b$i.jpg"
  done
  "$BIN" --quiet camera calibrate b1.jpg b2.jpg b3.jpg b4.jpg --board checker:9x6:0.025 --out lens.json >/dev/null ||
    echo "FAIL setup: lens.json"
fi
have_gl=yes
"$BIN" --quiet render blob --light probe.exr --backend gl --size 16x16 --out "$T/gl.png" >/dev/null 2>&1 || have_gl=no

# run_example WHERE LINE: runs LINE (its program `iblkit` or `build/iblkit`) in $W.
declare -A seen
run_example() {
  local where="$1" line="$2" cmd out rc t0
  [ -n "${seen[$line]:-}" ] && return  # a group's --help and its member's show one example twice
  seen[$line]=1
  cmd=${line%%#*}  # a trailing comment
  case "$cmd" in
    *" serve "*)  # a server that runs until Ctrl-C (cli_test_web.sh starts and stops one)
      echo "skip ($where, a server until Ctrl-C): $line"; skip=$((skip+1)); return ;;
    *" view "*)
      if [[ "$cmd" != *--frames* ]]; then echo "skip ($where, interactive window): $line"; skip=$((skip+1)); return; fi ;;
  esac
  if [[ "$cmd" == *" camera "* && $have_cv = no ]]; then echo "skip ($where, no python3-opencv for its boards): $line"; skip=$((skip+1)); return; fi
  if [[ "$cmd" == *"--backend gl"* && $have_gl = no ]]; then echo "skip ($where, no OpenGL here): $line"; skip=$((skip+1)); return; fi
  if [[ "$cmd" == *"../shared/"* && ! -d "$T/shared" ]]; then echo "skip ($where, no $SHARED): $line"; skip=$((skip+1)); return; fi
  if [[ "$cmd" == xvfb-run* ]]; then
    if ! command -v xvfb-run >/dev/null; then echo "skip ($where, no xvfb-run): $line"; skip=$((skip+1)); return; fi
    cmd=${cmd/#xvfb-run -a iblkit /xvfb-run -a build\/iblkit }
  fi
  [[ "$cmd" == iblkit* ]] && cmd="build/$cmd"
  t0=$(date +%s.%N)
  out=$(eval "timeout ${IBLKIT_EXAMPLE_TIMEOUT:-120} $cmd" 2>&1); rc=$?
  printf '%6.2fs  %s\n' "$(echo "$(date +%s.%N) - $t0" | bc)" "$line"
  if [ $rc -ne 0 ]; then echo "FAIL ($where) exit $rc: $line"; echo "$out" | tail -3; fail=$((fail+1)); else pass=$((pass+1)); fi
}

# ---- README.md ------------------------------------------------------------------------------------
while IFS= read -r line; do
  run_example README "$line"
done < <(awk '/^```/{inb=!inb; next} inb' "$SRC/README.md" | grep -E '^(xvfb-run -a )?build/iblkit ')

# ---- every --help ---------------------------------------------------------------------------------
subcommands() { "$@" --help | awk '/^Subcommands:/{f=1;next} f&&/^[^ ]/{f=0} f&&NF{print $1}'; }
examples() { "$@" --help | sed -n '/^Examples\{0,1\}:/,$p' | grep -E '^  (xvfb-run -a )?iblkit ' | sed 's/^  //'; }
helps=("")
for sub in $(subcommands "$BIN"); do
  helps+=("$sub")
  for leaf in $(subcommands "$BIN" "$sub"); do helps+=("$sub $leaf"); done
done
for h in "${helps[@]}"; do
  # shellcheck disable=SC2086
  while IFS= read -r line; do
    run_example "iblkit $h --help" "$line"
  done < <(examples "$BIN" $h)
done

echo "cli_examples: $pass passed, $fail failed, $skip skipped"
[ $fail -eq 0 ]
