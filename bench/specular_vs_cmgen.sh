#!/bin/sh
# iblkit specular against Filament's cmgen --ibl-ld on the same file, same size and levels, side by
# side in one run on this machine (bench/RESULTS.md). cmgen cannot read blender-data's EXR
# compression, so both read an uncompressed copy written by iblkit convert (the lat-long, same
# pixels). REPS rounds; odd rounds run cmgen first, even rounds iblkit first; the minimum of each
# tool's wall times is the figure (the machine is shared: the load average is printed).
# Usage: bench/specular_vs_cmgen.sh [IBLKIT] [SIZE] [REPS]   (defaults: build/iblkit, 256, 3)
set -eu
IBLKIT=${1:-build/iblkit}
SIZE=${2:-256}
REPS=${3:-3}
PROBE=/usr/share/blender/datafiles/studiolights/world/forest.exr
command -v cmgen >/dev/null || { echo "cmgen absent (apt-get install libfilament-tools)"; exit 0; }
[ -f "$PROBE" ] || { echo "blender-data probe absent ($PROBE)"; exit 0; }
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
"$IBLKIT" -q convert "$PROBE" "$T/forest.exr" >/dev/null
now() { date +%s.%N; }
run_cmgen() { rm -rf "$T/cmgen"; cmgen --quiet --size="$SIZE" --format=exr --ibl-ld="$T/cmgen" "$T/forest.exr" >/dev/null 2>&1; }
run_iblkit() { rm -rf "$T/iblkit"; "$IBLKIT" -q specular "$T/forest.exr" --size "$SIZE" --roughness filament --frame filament --faces "$T/iblkit" >/dev/null; }
best_c=""; best_i=""
min() { if [ -z "$1" ]; then echo "$2"; else echo "if ($2 < $1) $2 else $1" | bc; fi; }
r=1
while [ "$r" -le "$REPS" ]; do
  if [ $((r % 2)) -eq 1 ]; then order="cmgen iblkit"; else order="iblkit cmgen"; fi
  for tool in $order; do
    t0=$(now); "run_$tool"; t1=$(now)
    dt=$(echo "$t1 - $t0" | bc)
    echo "round $r $tool $dt s"
    if [ "$tool" = cmgen ]; then best_c=$(min "$best_c" "$dt"); else best_i=$(min "$best_i" "$dt"); fi
  done
  r=$((r + 1))
done
levels_c=$(ls "$T/cmgen/forest" | grep -c _px)
levels_i=$(ls "$T/iblkit" | grep -c _px)
echo "size $SIZE, levels cmgen $levels_c / iblkit $levels_i, min of $REPS: cmgen --ibl-ld $best_c s, iblkit specular $best_i s, ratio iblkit/cmgen $(echo "scale=3; $best_i / $best_c" | bc) (nproc $(nproc), load $(cut -d' ' -f1-3 /proc/loadavg))"
