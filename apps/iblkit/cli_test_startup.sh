#!/usr/bin/env bash
# End-to-end checks of start-up (CTest cli_startup, docs/startup.md): the iblkit executable links
# none of the heavy libraries; alone, without its plugins, it still lists every subcommand and runs
# the light ones on EXR, RGBE and PNG; a command that needs a missing plugin says which in one line;
# plugins are found from any folder and through a symbolic link.
set -u
source "$(dirname "$0")/cli_check.sh" "$1"
ok() { pass=$((pass+1)); }
bad() { echo "FAIL $1"; fail=$((fail+1)); }

heavy_re="OpenImageIO|embree|assimp|openvdb|libGL|libEGL|epoxy|glfw|opencv|avcodec|gdal"
# A sanitizer build links Embree into the executable on purpose (CMakeLists.txt: its TLS must be static
# for LeakSanitizer); every other heavy library stays out there too.
if ldd "$BIN" | grep -q libasan; then heavy_re="OpenImageIO|assimp|openvdb|libGL|libEGL|epoxy|glfw|opencv|avcodec|gdal"; fi
heavy=$(ldd "$BIN" | grep -iE "$heavy_re" || true)
if [ -z "$heavy" ]; then ok; else bad "the executable links heavy libraries: $heavy"; fi

# The executable alone, in a folder without plugins.
mkdir -p "$T/alone"
cp "$BIN" "$T/alone/iblkit"
A="$T/alone/iblkit"
check alone-version ok "^iblkit [0-9]" -- "$A" --version
if diff <("$BIN" --help) <("$A" --help) >/dev/null; then ok; else bad "--help differs without the plugins"; fi
if [ -f "$PROBE" ]; then
  check alone-sh ok "L00" -- "$A" sh "$PROBE" --format filament
  if diff <("$BIN" sh "$PROBE" --format filament) <("$A" sh "$PROBE" --format filament) >/dev/null; then ok; else bad "sh differs without the plugins"; fi
  check alone-convert-hdr ok "" -- "$A" convert "$PROBE" "$T/p.hdr" --size 64
  check alone-info-hdr ok "hdr" -- "$A" info "$T/p.hdr"
  check alone-preview-png ok "wrote" -- "$A" preview "$T/p.hdr" "$T/p.png"
  check alone-jpeg-needs-oiio fail "libiblkit_oiio.so" -- "$A" preview "$T/p.hdr" "$T/p.jpg"
  check alone-read-png-needs-oiio fail "libiblkit_oiio.so" -- "$A" info "$T/p.png"
else
  echo "no blender-data probe: the probe checks are skipped"; skip=$((skip+1))
fi
# The ILF (in the executable) writes OpenVDB through its plugin.
check ilf-synth ok "" -- "$BIN" --quiet ilf synth --out "$T/seq" --probes 40 --size 16
out=$("$BIN" --quiet ilf build "$T/seq/sequence.json" --grid 4 --out "$T/g.shgrid" --vdb "$T/g.vdb" 2>&1); rc=$?
if { [ $rc -eq 0 ] && [ -s "$T/g.vdb" ]; } || { [ $rc -ne 0 ] && grep -q "no OpenVDB" <<<"$out"; }; then ok; else bad "ilf build --vdb: rc $rc: $out"; fi
check alone-vdb-needs-plugin fail "libiblkit_vdb.so|no OpenVDB" -- "$A" --quiet ilf build "$T/seq/sequence.json" --grid 4 --out "$T/g2.shgrid" --vdb "$T/g2.vdb"
if "$BIN" --help | grep -q "^  render"; then
  check alone-render-needs-plugin fail "libiblkit_geometry.so: plugin not found" -- "$A" render --help
  # From another folder, and through a symbolic link: the plugins are found beside the real file.
  check other-cwd ok "Example" -- bash -c "cd '$T' && '$BIN' render --help"
  ln -s "$BIN" "$T/link"
  check symlink ok "Example" -- "$T/link" lab capture --help
fi
echo "$pass passed, $fail failed, $skip skipped"
[ $fail -eq 0 ]
