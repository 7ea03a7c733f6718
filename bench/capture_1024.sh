#!/usr/bin/env bash
# The chain of issue 29 at 1024² photographs, timed: `lab shoot` of a chrome ball in low-scene2 from two sides (five
# JPEG q95 frames 3 EV apart each, bracketed down until nothing saturates: 8 a side here; noise), then the user's part — `hdr merge` of each side (the camera's curve named,
# and again recovering it), `probe from-ball` of both into one lat-long probe, `sh` and `lights` (16, median cut) —
# each a separate process as a user runs them, wall clock of the whole user part (best of 3). Target (issue 29): under
# 5 s on 2 cores. Also prints the probe's irradiance error against the lab's probe at the ball (2000 normals, mean
# relative luminance after one global scale, `iblkit eval`-free: numpy on the two lat-longs).
# Usage: bench/capture_1024.sh [BUILD/iblkit] [OUT]   (/usr/bin/python3 with numpy and cv2)
set -eu
BIN=$(readlink -f "${1:-build/iblkit}")
OUT=${2:-/tmp/iblkit_capture_1024}
rm -rf "$OUT"
mkdir -p "$OUT"
cd "$OUT"
t0=$(date +%s.%N)
"$BIN" --quiet lab shoot low-scene2 --at 0,0.15,0 --two-sides --distance-radii 10 --width 1024 --height 1024 \
  --samples 1 --bracket 12 --until-unsaturated --ev-step 3 --noise --truth-size 128 --out set > /dev/null
echo "shoot (the lab's camera, not the user's chain): $(echo "$(date +%s.%N) - $t0" | bc) s"
circle() {  # the silhouette the lab wrote, as --ball takes it
  /usr/bin/python3 -c "import json;b=json.load(open('set/shoot.json'))['views'][$1]['ball'];print(','.join(map(str,b)))"
}
B0=$(circle 0)
B1=$(circle 1)
D=$(/usr/bin/python3 -c "import json;print(json.load(open('set/shoot.json'))['views'][0]['distance_radii'])")
chain() {  # $1: extra hdr merge options
  "$BIN" --quiet hdr merge set/view0_e*.jpg --out v0.exr --no-align $1 > /dev/null
  "$BIN" --quiet hdr merge set/view1_e*.jpg --out v1.exr --no-align $1 > /dev/null
  "$BIN" --quiet probe from-ball v0.exr v1.exr --ball "$B0" --ball "$B1" --distance "$D" --angle 90 --size 256 \
    --out probe.exr > /dev/null
  "$BIN" --quiet sh probe.exr > sh.txt
  "$BIN" --quiet lights probe.exr --count 16 --out lights.json > /dev/null
}
for mode in named recovered; do
  opts="--response set/response.json"
  [ "$mode" = recovered ] && opts=""
  best=1000000000
  for rep in 1 2 3; do
    t0=$(date +%s.%N)
    chain "$opts"
    t=$(echo "$(date +%s.%N) - $t0" | bc)
    best=$(echo "if ($t < $best) $t else $best" | bc)
  done
  err=$(/usr/bin/python3 - <<'PY'
import os
os.environ["OPENCV_IO_ENABLE_OPENEXR"] = "1"
import cv2, numpy as np
def latlong(p):
    img = cv2.imread(p, cv2.IMREAD_UNCHANGED)[:, :, :3][:, :, ::-1].astype(np.float64)
    return img
def irradiance(img, normals):
    h, w, _ = img.shape
    th = (np.arange(h) + 0.5) / h * np.pi
    ph = (np.arange(w) + 0.5) / w * 2 * np.pi
    st = np.sin(th)[:, None]
    # iblkit's lat-long: +Y up, u = 0.5 + atan2(x, -z) / 2pi (docs/conventions.md)
    dx = (st * np.sin(ph[None, :] - np.pi))
    dy = np.repeat(np.cos(th)[:, None], w, 1)
    dz = -(st * np.cos(ph[None, :] - np.pi))
    d = np.stack([dx, dy, dz], -1).reshape(-1, 3)
    dw = (np.repeat(st, w, 1) * (np.pi / h) * (2 * np.pi / w)).reshape(-1)
    L = img.reshape(-1, 3)
    c = np.clip(normals @ d.T, 0, None) * dw[None, :]
    return c @ L
rng = np.random.default_rng(1)
n = rng.normal(size=(2000, 3)); n /= np.linalg.norm(n, axis=1, keepdims=True)
lum = np.array([0.2126, 0.7152, 0.0722])
a = irradiance(latlong("probe.exr"), n) @ lum
b = irradiance(latlong("set/truth.exr"), n) @ lum
s = np.median(b / a)
print(f"{100 * np.mean(np.abs(s * a / b - 1)):.2f}")
PY
)
  echo "user chain at 1024² ($mode curve): $(printf '%.2f' "$best") s (best of 3), irradiance error $err %"
done
