#!/usr/bin/env bash
# Start-up of the iblkit command (docs/startup.md, bench/RESULTS.md "Start-up"): `iblkit --version`,
# and `iblkit sh` against Filament's cmgen on the same 1024×512 probe, all timed in one hyperfine run.
# cmgen cannot read blender-data's DWAB-compressed EXRs, so both read the probe re-encoded as Radiance
# .hdr; `iblkit sh` on the EXR itself is timed too.
# Needs Debian's hyperfine and libfilament-tools (cmgen), which this script does not install:
#   apt-get install hyperfine libfilament-tools
# Usage: bench/startup.sh [BUILD_DIR] [PROBE.exr]
set -euo pipefail
BUILD=${1:-build}
EXR=${2:-/usr/share/blender/datafiles/studiolights/world/forest.exr}
BIN=$(realpath "$BUILD/iblkit")
for tool in hyperfine cmgen; do
  command -v "$tool" >/dev/null || { echo "startup.sh: needs $tool (apt-get install hyperfine libfilament-tools)" >&2; exit 1; }
done
[ -f "$EXR" ] || { echo "startup.sh: no probe $EXR (install blender-data)" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
HDR="$work/$(basename "${EXR%.*}").hdr"
"$BIN" -q convert "$EXR" "$HDR" >/dev/null
echo "executable: ldd lists $(ldd "$BIN" | wc -l) entries; probe $(basename "$HDR"): $("$BIN" info "$HDR" | awk '/^size/{sub(",", "", $4); print $2 "x" $4}')"
rss=$( { /usr/bin/time -f "%M" "$BIN" --version >/dev/null; } 2>&1 )
echo "iblkit --version: maximum resident set ${rss} kB"
cd "$work"  # cmgen writes nothing with these flags, but run it where it could
hyperfine -N --warmup 5 --runs "${RUNS:-40}" --export-markdown "$work/startup.md" \
  "$BIN --version" \
  "$BIN sh $HDR --format filament" \
  "cmgen --sh=3 --sh-shader $HDR" \
  "$BIN sh $EXR --format filament"
cat "$work/startup.md"
echo "Record the figures in bench/RESULTS.md with the date, the machine and its load (uptime: $(uptime | sed 's/.*average: //'))."
