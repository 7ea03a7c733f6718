#!/bin/sh
# iblkit specular against Filament's cmgen --ibl-ld on the same file, same size and levels, one run
# on this machine (bench/RESULTS.md). cmgen cannot read blender-data's EXR compression, so both read
# an uncompressed copy written by iblkit convert --mapping latlong (same pixels, resampled 1:1).
# Usage: bench/specular_vs_cmgen.sh [IBLKIT] [SIZE]   (defaults: build/iblkit, 256)
set -eu
IBLKIT=${1:-build/iblkit}
SIZE=${2:-256}
PROBE=/usr/share/blender/datafiles/studiolights/world/forest.exr
command -v cmgen >/dev/null || { echo "cmgen absent (apt-get install libfilament-tools)"; exit 0; }
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
"$IBLKIT" -q convert "$PROBE" "$T/forest.exr" >/dev/null
t0=$(date +%s.%N)
cmgen --quiet --size="$SIZE" --format=exr --ibl-ld="$T/cmgen" "$T/forest.exr" >/dev/null 2>&1
t1=$(date +%s.%N)
"$IBLKIT" -q specular "$T/forest.exr" --size "$SIZE" --roughness filament --frame filament --faces "$T/iblkit" >/dev/null
t2=$(date +%s.%N)
echo "size $SIZE, $(ls "$T/cmgen/forest" | grep -c _px) levels: cmgen --ibl-ld $(echo "$t1 - $t0" | bc) s, iblkit specular $(echo "$t2 - $t1" | bc) s (nproc $(nproc))"
