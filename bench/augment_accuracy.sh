#!/usr/bin/env bash
# Accuracy of `iblkit composite` against `iblkit lab photograph` truth (docs/augment.md): for each scene,
# a photograph without and with the blob (path traced, one bounce more than the probes carry), then
# composites from one probe at the object, fused probes around it, an SH grid, and the two baselines
# (pasted without shadows; N median-cut lights only), each measured with --truth. Prints a Markdown
# table; leaves everything under $OUT (default /tmp/augment_accuracy).
# Usage: bench/augment_accuracy.sh BUILD/iblkit [WIDTHxHEIGHT] [TRUTH_SAMPLES]
set -eu
# PHOTO_ARGS / CAPTURE_ARGS (environment): extra options of every photograph / capture (e.g. more area samples).
# BACKEND=gl|cpu (environment, default cpu): which compositor the rows measure (--backend); REUSE=1 keeps the
# photographs, captures and grids a previous run left under $OUT (the GL rows measured on the CPU rows' truths).
BIN=$1; SIZE=${2:-320x240}; TS=${3:-8}; OUT=${OUT:-/tmp/augment_accuracy}
read -ra PA <<<"${PHOTO_ARGS:-}"; read -ra CA <<<"${CAPTURE_ARGS:-}"; BACKEND=${BACKEND:-cpu}
W=${SIZE%x*}; H=${SIZE#*x}
mkdir -p "$OUT"
row() {  # row SCENE LABEL ARGS… : one composite, one table row
  local scene=$1 label=$2; shift 2
  local j
  local d="$OUT/$(basename "$scene" .json)"
  j=$("$BIN" composite "$d/photo.exr" "${CAM[@]}" "${OBJ[@]}" --truth "$d/truth.exr" --json --quiet --backend "$BACKEND" \
      --out "$d/comp_${BACKEND}_${label// /_}.exr" "$@")
  python3 -c 'import json, sys
j = json.loads(sys.argv[3]); e = j["errors"]
print("| %s | %s | %.1f %% | %.1f %% | %.2f %% | %.1f s |" % (sys.argv[1], sys.argv[2], 100 * e["object"], 100 * e["shadow"], 100 * e["unchanged"], j["seconds"]))' \
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
  "$BIN" lab capture "$scene" --fusion --probe "$at" --size 128 "${CA[@]}" --out "$d/one" --quiet >/dev/null
  local probes=(); IFS=';' read -ra pts <<<"$fused"; for p in "${pts[@]}"; do probes+=(--probe "$p"); done
  "$BIN" lab capture "$scene" --fusion "${probes[@]}" --size 128 "${CA[@]}" --out "$d/fused" --quiet >/dev/null
  "$BIN" lab capture "$scene" --grid 6,6,6 --volume "$vol" --size 32 "${CA[@]}" --out "$d/seq" --quiet >/dev/null
  "$BIN" ilf build "$d/seq/sequence.json" --grid 6 --bands 5 --out "$d/grid.shgrid" --quiet >/dev/null
  fi
  row "$scene" "one probe" --probes "$d/one/probes.json" --layers "$d/layers_$BACKEND"
  row "$scene" "fused probes" --probes "$d/fused/probes.json"
  row "$scene" "SH grid" --light "$d/grid.shgrid" --proxy "$d/one/proxy.obj"
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
