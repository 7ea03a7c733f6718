#!/bin/sh
# CTest ktx2_parse: `iblkit specular` KTX2 files (a cube map and the DFG table) read by the ktx-parse
# npm package (web/test/check_ktx2.mjs). Skips (exit 77) where node or web/node_modules/ktx-parse is
# absent (cd web && npm ci installs it). KTX_PARSE_NODE_MODULES overrides the node_modules folder.
# Usage: ktx2_parse_test.sh IBLKIT_EXECUTABLE
set -eu
IBLKIT=$1
HERE=$(cd "$(dirname "$0")" && pwd)
NM=${KTX_PARSE_NODE_MODULES:-$HERE/../node_modules}
PROBE=/usr/share/blender/datafiles/studiolights/world/forest.exr
if ! command -v node >/dev/null 2>&1; then echo "SKIP: node is absent"; exit 77; fi
if [ ! -d "$NM/ktx-parse" ]; then echo "SKIP: $NM/ktx-parse is absent (cd web && npm ci)"; exit 77; fi
if [ ! -f "$PROBE" ]; then echo "SKIP: blender-data probes absent"; exit 77; fi
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
"$IBLKIT" -q specular "$PROBE" --size 64 --out "$T/env.ktx2" --irradiance "$T/irr.ktx2" --irradiance-size 8 --dfg "$T/dfg.ktx2" --dfg-size 32 >/dev/null
node "$HERE/check_ktx2.mjs" "$T/env.ktx2" --faces 6 --size 64 --levels 3 --node-modules "$NM"
node "$HERE/check_ktx2.mjs" "$T/irr.ktx2" --faces 6 --size 8 --levels 1 --node-modules "$NM"
node "$HERE/check_ktx2.mjs" "$T/dfg.ktx2" --faces 1 --size 32 --levels 1 --format 83 --node-modules "$NM"
