#!/usr/bin/env bash
# Validates `iblkit lights --gltf` output with the Khronos glTF validator (npm package gltf-validator,
# its node API validateBytes). Usage: bench/check_gltf.sh BUILD/iblkit [VALIDATOR_DIR]
#   VALIDATOR_DIR: a folder with node_modules/gltf-validator (default /tmp; `cd /tmp && npm install
#   gltf-validator` puts it there). Exits 0 when every file has 0 errors and 0 warnings, 77 (skip)
#   when node or the validator is missing, 1 otherwise. Prints the validator's counts per file.
set -u
BIN="$1"
VDIR="${2:-/tmp}"
PROBE=/usr/share/blender/datafiles/studiolights/world/forest.exr
command -v node >/dev/null || { echo "SKIP: node not installed"; exit 77; }
[ -d "$VDIR/node_modules/gltf-validator" ] || { echo "SKIP: no $VDIR/node_modules/gltf-validator (cd $VDIR && npm install gltf-validator)"; exit 77; }
[ -f "$PROBE" ] || { echo "SKIP: blender-data probe missing"; exit 77; }
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
# One light, a typical set, a set whose colours hit the [0,1] bounds, and the optimiser's output.
"$BIN" lights "$PROBE" --method median-cut --count 1 --gltf "$T/mc1.gltf" --quiet >/dev/null || exit 1
"$BIN" lights "$PROBE" --method median-cut --count 16 --gltf "$T/mc16.gltf" --quiet >/dev/null || exit 1
"$BIN" lights "$PROBE" --method variance-cut --count 64 --gltf "$T/vc64.gltf" --lux-per-unit 1000 --quiet >/dev/null || exit 1
"$BIN" lights "$PROBE" --method optimize --count 8 --normals-level 4 --gltf "$T/opt8.gltf" --quiet >/dev/null || exit 1
cat > "$T/validate.js" <<'JS'
const fs = require('fs');
const validator = require(process.argv[2] + '/node_modules/gltf-validator');
let bad = 0;
(async () => {
  for (const f of process.argv.slice(3)) {
    const r = await validator.validateBytes(new Uint8Array(fs.readFileSync(f)), {uri: f, maxIssues: 100});
    const i = r.issues;
    console.log(`${f.split('/').pop()}: validator ${r.validatorVersion}: ${i.numErrors} errors, ${i.numWarnings} warnings, ` +
                `${i.numInfos} infos, ${i.numHints} hints`);
    for (const m of i.messages) console.log(`  [${m.severity}] ${m.code} ${m.pointer || ''}: ${m.message}`);
    if (i.numErrors > 0 || i.numWarnings > 0) bad++;
  }
  process.exit(bad ? 1 : 0);
})();
JS
node "$T/validate.js" "$VDIR" "$T"/*.gltf
