#!/usr/bin/env bash
# Accuracy of `iblkit composite` against `iblkit lab photograph` truth (docs/augment.md): for each scene,
# a photograph without and with the blob (path traced, one bounce more than the probes carry), then
# composites from one probe at the object, fused probes around it, an SH grid, and the two baselines
# (pasted without shadows; N median-cut lights only), each measured with --truth. Prints a Markdown
# table; leaves everything under $OUT (default /tmp/augment_accuracy).
# The truth is two photographs with the object (seeds 1 and 2, TRUTH_SAMPLES² rays per pixel each); the
# composites are measured against their mean, and the mean's own noise (from the two truths' spread,
# augment::measure_against) is the row "truth's own noise": the error a perfect composite would show.
# Usage: bench/augment_accuracy.sh BUILD/iblkit [WIDTHxHEIGHT] [TRUTH_SAMPLES]
set -eu
# PHOTO_ARGS / CAPTURE_ARGS / COMPOSITE_ARGS (environment): extra options of every photograph / capture /
# composite (default --match off: the lab's photographs and probes are radiance in one unit by construction, and
# the probes carry one bounce fewer, which the match would read as a +0.3-stop gain; the rows measure the
# compositor, docs/augment.md "Radiometric match" the match). By default the photographs carry two bounces and the probes one (the photograph reflects the
# light the probes see, and light that reaches the floor via the object has the bounces the composite gives it),
# and every probe texel is the mean of 4×4 rays (a camera's pixel integrates; one ray per texel misses or
# doubles small lamps and the sun).
BIN=$1; SIZE=${2:-160x120}; TS=${3:-32}; OUT=${OUT:-/tmp/augment_accuracy}
read -ra PA <<<"${PHOTO_ARGS---bounces 2}"; read -ra CA <<<"${CAPTURE_ARGS---bounces 1 --samples 4}"; read -ra XA <<<"${COMPOSITE_ARGS---match off}"
# KERNEL_SWEEP=1 adds a row for the SH grid built at each candidate kernel (1.5 … 4 cells), beside the kernel
# `ilf build --focus` chose for the object and the one the whole volume's cross-validation chose.
# BACKEND=gl|cpu (environment, default cpu): which compositor the rows measure (--backend); REUSE=1 keeps the
# photographs, captures and grids a previous run left under $OUT (the GL rows measured on the CPU rows' truths).
BACKEND=${BACKEND:-cpu}
W=${SIZE%x*}; H=${SIZE#*x}
mkdir -p "$OUT"
row() {  # row SCENE LABEL ARGS… : one composite, one table row
  local scene=$1 label=$2; shift 2
  local j
  local d="$OUT/$(basename "$scene" .json)"
  j=$("$BIN" composite "$d/photo.exr" "${CAM[@]}" "${OBJ[@]}" --truth "$d/truth.exr" --truth "$d/truth2.exr" --json --quiet \
      --backend "$BACKEND" --out "$d/comp_${BACKEND}_${label// /_}.exr" "${XA[@]}" "$@")
  python3 -c 'import json, sys
j = json.loads(sys.argv[3]); e = j["errors"]
print("| %s | %s | %.1f %% | %.1f %% | %.2f %% | %.1f s |" % (sys.argv[1], sys.argv[2], 100 * e["object"], 100 * e["shadow"], 100 * e["unchanged"], j["seconds"]))
if sys.argv[2] == "one probe":
  n = j["truth_noise"]
  print("| %s | truth\x27s own noise | %.1f %% | %.1f %% | %.2f %% | |" % (sys.argv[1], 100 * n["object"], 100 * n["shadow"], 100 * n["unchanged"]))' \
    "$scene" "$label" "$j"
}
scene_run() {  # scene_run SCENE AT EYE TARGET VOLUME FUSED_PROBES
  local scene=$1 at=$2; CAM=(--eye "$3" --target "$4" --fov 40); local vol=$5 fused=$6
  OBJ=(--object blob --at "$at" --object-size 0.3)
  local name; name=$(basename "$scene" .json); local d="$OUT/$name"; mkdir -p "$d"
  if [ "${REUSE:-0}" != 1 ] || [ ! -s "$d/grid.shgrid" ]; then
  "$BIN" lab photograph "$scene" "${CAM[@]}" --width "$W" --height "$H" --samples "$TS" "${PA[@]}" --out "$d/photo.exr" --quiet >/dev/null
  "$BIN" lab photograph "$scene" "${CAM[@]}" --width "$W" --height "$H" --samples "$TS" "${PA[@]}" "${OBJ[@]}" --mask "$d/mask.exr" \
    --out "$d/truth.exr" --quiet >/dev/null
  "$BIN" lab photograph "$scene" "${CAM[@]}" --width "$W" --height "$H" --samples "$TS" "${PA[@]}" "${OBJ[@]}" --seed 2 \
    --out "$d/truth2.exr" --quiet >/dev/null
  "$BIN" lab capture "$scene" --fusion --probe "$at" --size 128 "${CA[@]}" --out "$d/one" --quiet >/dev/null
  local probes=(); IFS=';' read -ra pts <<<"$fused"; for p in "${pts[@]}"; do probes+=(--probe "$p"); done
  "$BIN" lab capture "$scene" --fusion "${probes[@]}" --size 128 "${CA[@]}" --out "$d/fused" --quiet >/dev/null
  "$BIN" lab capture "$scene" --grid 6,6,6 --volume "$vol" --size 32 "${CA[@]}" --out "$d/seq" --quiet >/dev/null
  # The SH grid's kernel chosen for the object's neighbourhood (--focus: the centre and the object's radius), and
  # for comparison the whole volume's cross-validated choice.
  "$BIN" ilf build "$d/seq/sequence.json" --grid 6 --bands 5 --focus "$at,0.15" --json --out "$d/grid.shgrid" \
    >"$d/grid.json"
  "$BIN" ilf build "$d/seq/sequence.json" --grid 6 --bands 5 --json --out "$d/grid_volume.shgrid" >"$d/grid_volume.json"
  fi
  local kf kv
  kf=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["kernel"])' "$d/grid.json")
  kv=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["kernel"])' "$d/grid_volume.json")
  row "$scene" "one probe" --probes "$d/one/probes.json" --layers "$d/layers_$BACKEND"
  row "$scene" "fused probes" --probes "$d/fused/probes.json"
  row "$scene" "SH grid (kernel $kf cells, for the object)" --light "$d/grid.shgrid" --proxy "$d/one/proxy.obj"
  row "$scene" "SH grid (kernel $kv cells, for the volume)" --light "$d/grid_volume.shgrid" --proxy "$d/one/proxy.obj"
  if [ "${KERNEL_SWEEP:-0}" = 1 ]; then  # every candidate kernel, fixed: which one the object wanted
    for k in 1.5 2 2.5 3 4; do
      [ -s "$d/grid_k$k.shgrid" ] && [ "${REUSE:-0}" = 1 ] ||
        "$BIN" ilf build "$d/seq/sequence.json" --grid 6 --bands 5 --kernel "$k" --out "$d/grid_k$k.shgrid" --quiet >/dev/null
      row "$scene" "SH grid (kernel $k cells, fixed)" --light "$d/grid_k$k.shgrid" --proxy "$d/one/proxy.obj"
    done
  fi
  row "$scene" "pasted, no shadows" --probes "$d/one/probes.json" --no-shadows
  row "$scene" "16 median-cut lights" --probes "$d/one/probes.json" --median-cut 16
}
echo "| scene | light | object | shadow | unchanged | $BACKEND wall |"
echo "| --- | --- | --- | --- | --- | --- |"
SCENES=${SCENES:-low-scene2 t-corridor outdoor}
for sc in $SCENES; do
  case $sc in
    low-scene2) scene_run low-scene2 0.1,0.2,0.1 0,1.3,2.2 0,0.3,0 "-0.6,0.1,-0.6;0.6,1.3,0.6" \
                  "0.35,0.45,0.25;-0.1,0.45,0.05;0.3,0.45,-0.2;0.0,0.6,0.35" ;;
    t-corridor) scene_run t-corridor 0.3,0.2,-0.8 0,1.4,2.5 0.2,0.3,-0.8 "-0.8,0.1,-1.6;0.8,1.3,0.4" \
                  "0.6,0.6,-1.2;-0.6,0.6,-0.4;0.5,0.5,-0.3;-0.5,1.0,-1.5" ;;
    outdoor) scene_run "$(dirname "$0")/augment_outdoor.json" 0,0.2,0 0,1.3,2.2 0,0.3,0 "-1,0.1,-1;1,1.1,1" \
                  "0.5,0.4,0.5;-0.5,0.4,0.5;0.5,0.4,-0.5;-0.5,0.4,-0.5" ;;
  esac
done
