#!/usr/bin/env bash
# The chain from a capture folder to the composite, measured against the lab's truth (docs/capture.md, "From the set
# to the composite"; rows in bench/RESULTS.md): `lab shoot low-scene2 … --backplate` (the ball's brackets from two
# sides, bracketed down until nothing saturates, a backplate with a board on the floor, the truth with the object;
# JPEG q95 or 16-bit TIFF), then `composite --capture` with the camera's curve the folder names, with the curve
# recovered from the ball's bracket (--recover-response), and for reference the same backplate composited with the
# lab's exact probe at the ball's centre and the exact camera (what the chain would reach with a perfect probe).
# Prints one line per case: camera error, reprojection, object / shadow / unchanged errors, wall time.
#
# Usage: bench/capture_chain.sh [BUILD/iblkit] [OUT]   (FORMATS="jpg tif dng": the sets to shoot (dng: raw files,
# linear, so no recovered curve; composites written as 16-bit TIFF); PLATE_SAMPLES=8: n×n rays per backplate pixel; TRUTH is
# the same photograph with the object, so its noise is the backplate's, but its path-traced grain is its own)
# BOUNCES=1: the lab's indirect bounces for the ball, the backplate and the truth (with one, the truth's object is not lit
# by the floor under it, so it sends none of that light into its shadow, which the compositor's object does).
# NOISE=1 also shoots the backplate and truth again with render seed 2 at the first one's exposure and prints the
# truth's own noise: what a composite that is right on average would score against this truth (the second seed's
# difference truth − backplate against the first's, over √2; the same classes of pixels; docs/capture.md).
set -eu
BIN=$(readlink -f "${1:-build/iblkit}")
OUT=${2:-/tmp/iblkit_capture_chain}
PS=${PLATE_SAMPLES:-8}
B=${BOUNCES:-1}
mkdir -p "$OUT"
summary() {  # the chain's JSON -> one line
  /usr/bin/python3 - "$1" "$2" "$3" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
e, c = j["errors"], j.get("camera", {})
cam = ""
if "eye_error_mm" in c:
    cam = "camera %.2f mm %.3f deg %.3f px, " % (c["eye_error_mm"], c["view_error_deg"], c["reprojection_rms_px"])
print("%s: %sobject %.1f %%, shadow %.1f %% of a %.0f %% signal, unchanged %.2f %%, %s s" % (
    sys.argv[2], cam, 100 * e["object"], 100 * e["shadow"], 100 * e["shadow_signal"], 100 * e["unchanged"],
    sys.argv[3]))
PY
}
for fmt in ${FORMATS:-jpg tif dng}; do
  out_ext=$fmt response=response.json modes="camera recovered"
  [ "$fmt" = dng ] && out_ext=tif response=linear modes=camera
  set_dir="$OUT/set_$fmt"
  rm -rf "$set_dir"
  t0=$(date +%s.%N)
  "$BIN" --quiet lab shoot low-scene2 --at 0,0.15,0 --two-sides --distance-radii 10 --width 384 --height 384 \
    --samples 4 --bracket 12 --until-unsaturated --ev-step 3 --bounces "$B" --noise --wb 1.1,1,0.8 --backplate \
    --plate-samples "$PS" --format "$fmt" --out "$set_dir" > /dev/null
  t1=$(date +%s.%N)
  echo "shoot ($fmt): $(printf '%.1f' "$(echo "$t1 - $t0" | bc)") s"
  for mode in $modes; do
    extra=()
    [ "$mode" = recovered ] && extra=(--recover-response)
    t0=$(date +%s.%N)
    "$BIN" --quiet --json composite --capture "$set_dir" --out "$set_dir/composite_$mode.$out_ext" "${extra[@]}" \
      > "$set_dir/chain_$mode.json"
    t1=$(date +%s.%N)
    summary "$set_dir/chain_$mode.json" "$fmt, $mode curve" "$(printf '%.1f' "$(echo "$t1 - $t0" | bc)")"
  done
  t0=$(date +%s.%N)
  (cd "$set_dir" && "$BIN" --quiet --json composite "backplate.$fmt" --camera camera_truth.json --light truth.exr \
    --at-probe 0,0.15,0 --proxy proxy.obj --at 0,0.161,0 --response "$response" --truth "truth.$fmt" \
    --out "exact.$out_ext" > exact.json)
  t1=$(date +%s.%N)
  summary "$set_dir/exact.json" "$fmt, the lab's exact probe and camera" "$(printf '%.1f' "$(echo "$t1 - $t0" | bc)")"
  [ "${NOISE:-0}" = 1 ] || continue
  exposure=$(/usr/bin/python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['backplate']['exposure_s'])" \
    "$set_dir/shoot.json")
  rm -rf "${set_dir}_seed2"
  "$BIN" --quiet lab shoot low-scene2 --at 0,0.15,0 --two-sides --distance-radii 10 --width 384 --height 384 \
    --samples 4 --bracket 12 --until-unsaturated --ev-step 3 --bounces "$B" --noise --wb 1.1,1,0.8 --backplate \
    --plate-samples "$PS" --format "$fmt" --seed 2 --plate-exposure "$exposure" --out "${set_dir}_seed2" > /dev/null
  /usr/bin/python3 - "$set_dir" "${set_dir}_seed2" "$fmt" <<'PY'
import json, os, sys
os.environ["OPENCV_IO_ENABLE_OPENEXR"] = "1"
import cv2, numpy as np
a, b, fmt = sys.argv[1:4]
resp = json.load(open(os.path.join(a, "response.json")))
curve = [np.asarray(c, dtype=np.float64) for c in resp["channels"]]
def linear(folder, name):  # code values through the camera's curve (iblkit.response/1), RGB
    im = cv2.imread(os.path.join(folder, name), cv2.IMREAD_UNCHANGED)[..., ::-1]
    code = im / (255.0 if im.dtype == np.uint8 else 65535.0)
    x = np.linspace(0, 1, len(curve[0]))
    return np.stack([np.interp(code[..., c], x, curve[c]) for c in range(3)], -1)
P1, T1 = linear(a, "backplate." + fmt), linear(a, "truth." + fmt)
P2, T2 = linear(b, "backplate." + fmt), linear(b, "truth." + fmt)
mask = cv2.imread(os.path.join(a, "truth_mask.png"), cv2.IMREAD_GRAYSCALE) > 127
lum = lambda x: x @ np.array([0.2125, 0.7154, 0.0721])
l1 = lambda x: np.abs(x).sum(-1)
box = lambda y: cv2.blur(y, (3, 3), borderType=cv2.BORDER_REPLICATE)  # augment/measure.cpp's 3×3 classification
yp, yt = box(lum(P1)), box(lum(T1))
shadow = ~mask & (yp - yt > 0.02 * yp)
unchanged = ~mask & ~shadow & ~(yt - yp > 0.02 * yp)
D1, D2, r2 = T1 - P1, T2 - P2, np.sqrt(2)
print("%s, the truth's own noise: object %.1f %%, shadow %.1f %%, unchanged %.2f %%" % (
    fmt, 100 * l1(T1 - T2)[mask].sum() / r2 / l1(T1)[mask].sum(), 100 * l1(D1 - D2)[shadow].sum() / r2 / l1(D1)[shadow].sum(),
    100 * l1(D1 - D2)[unchanged].sum() / r2 / l1(T1)[unchanged].sum()))
PY
done
