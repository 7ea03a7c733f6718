#!/usr/bin/env bash
# The near-field CPU reference benchmark of issue 7: the simulated 9×7 bike-light dataset (128² images)
# lighting the crypt at 400×400 with one shadow ray per spotlight (63 per pixel). Prints the render
# time of each run (reading the dataset and building the E' textures reported apart). Target ≤ 10 s
# on the 2-core dev machine. Usage: bench/nearfield_render.sh [BUILD_DIR] [RUNS]
set -eu
BIN="${1:-build}/iblkit"
RUNS="${2:-5}"
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
"$BIN" --quiet nearfield simulate bikelight --grid 9x7 --resolution 128 --out "$T/bike.json" >/dev/null
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
for r in $(seq "$RUNS"); do
  "$BIN" --json --quiet nearfield render "$T/bike.json" --scene crypt --size 400 --out "$T/view.png" |
    python3 -c "import json,sys; j=json.load(sys.stdin); print(f\"run $r: render {j['render_seconds']:.3f} s, setup {j['setup_seconds']:.3f} s, {j['spotlights']} spotlights, shadows {j['shadows']}\")"
done
"$BIN" --json --quiet nearfield render "$T/bike.json" --scene crypt --size 400 --no-shadows --out "$T/view_ns.png" |
  python3 -c "import json,sys; j=json.load(sys.stdin); print(f\"no shadows: render {j['render_seconds']:.3f} s\")"
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
