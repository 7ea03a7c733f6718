#!/usr/bin/env bash
# Löw et al. 2009, Fig. 9, with the lab in place of the photograph: a bunny-sized object on an
# 80 cm table in low-scene2, photographed by the lab (path traced in the scene's real emitters),
# beside renderings lit by SH grids of 8³, 16³, 32³ and 64³ built from a mirror-ball sequence of the
# same scene captured without the object and the table. Prints the error table and writes
# OUT/fig9_compare.png.
#   bench/fig9.sh BUILD_DIR/iblkit [OUT] [PROBES] [PROBE_SIZE]
set -euo pipefail
BIN=${1:?usage: fig9.sh path/to/iblkit [out-dir] [probes]}
OUT=${2:-fig9-out}
PROBES=${3:-4000}
SIZE=${4:-48}
SCENE="$(dirname "$0")/../examples/low-scene2.json"
mkdir -p "$OUT"
if [ ! -f "$OUT/seq/sequence.json" ]; then
  /usr/bin/time -f "capture: %e s wall, %M KB peak" "$BIN" lab capture "$SCENE" --random "$PROBES" --mapping mirrorball \
    --size "$SIZE" --samples 2 --out "$OUT/seq" --quiet
fi
lights=()
for g in 8 16 32 64; do
  [ -f "$OUT/g$g.shgrid" ] || /usr/bin/time -f "grid $g: %e s wall, %M KB peak" "$BIN" ilf build "$OUT/seq/sequence.json" \
    --grid $g --bands 5 --out "$OUT/g$g.shgrid" --quiet
  lights+=(--light "$OUT/g$g.shgrid")
done
"$BIN" render blob "${lights[@]}" --at 0,0.85,0 --object-size 0.35 --floor-size 0.8 --eye 0,1.45,1.5 --target 0,0.8,0 \
  --size 640x480 --truth "$SCENE" --truth-samples 6 --truth-bounces 1 --out "$OUT/fig9.png" --json > "$OUT/fig9.json"
python3 - "$OUT/fig9.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
print("| grid | object rel. L1 | median pixel rel. error | mean luminance render / truth | object + table rel. L1 |")
print("| --- | --- | --- | --- | --- |")
for r in j["renders"]:
    t = r["truth"]
    print(f'| {r["lighting"].split(",")[0].replace("SH grid ", "")} | {t["rel_l1_object"]:.3f} | {t["median_rel_object"]:.3f} | '
          f'{t["mean_luminance_render"]:.3f} / {t["mean_luminance_truth"]:.3f} | {t["rel_l1_object_and_floor"]:.3f} |')
print("pictures:", j["truth_pictures"])
PY
