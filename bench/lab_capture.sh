#!/usr/bin/env bash
# End-to-end capture benchmark of issue 4: 4397 mirror-ball probes of 250×250 pixels of low-scene1
# (Löw et al.'s first test scene), direct light only, 4 shadow rays per area-light hit, every frame
# streamed to disk as .exr, through the physical mirror-ball camera. Target: ≤ 300 s on 2 cores.
# Usage: bench/lab_capture.sh [IBLKIT_BINARY] [COUNT] [OUT_DIR]
set -euo pipefail
BIN=${1:-build/iblkit}
COUNT=${2:-4397}
OUT=${3:-$(mktemp -d)/lab_capture}
rm -rf "$OUT"
echo "cores: $(nproc), load before: $(cut -d' ' -f1-3 /proc/loadavg)"
/usr/bin/time -f "wall %e s, user %U s, sys %S s, max RSS %M KiB" \
  "$BIN" --quiet --json lab capture low-scene1 --random "$COUNT" --camera ball --size 250 \
  --area-samples 4 --bounces 0 --out "$OUT" > "$OUT.json"
python3 - "$OUT.json" "$COUNT" <<'PY'
import json, sys
r = json.load(open(sys.argv[1])); n = int(sys.argv[2])
print(f"{r['probes']} probes in {r['seconds']:.1f} s = {r['probes_per_second']:.1f} probes/s; "
      f"4397 probes extrapolate to {4397 / r['probes_per_second']:.0f} s (target 300 s)")
PY
du -sh "$OUT" | sed 's/^/disk: /'
