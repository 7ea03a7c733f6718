#!/usr/bin/env bash
# End-to-end checks of `iblkit fuse` (CTest cli_fusion): a lab probe set of the T corridor fused at a
# point, along a path, its depth traced and cached, and every bad-input class failing with a short
# message (or warning) and a non-zero exit code, never a crash. A few seconds.
set -u
source "$(dirname "$0")/cli_check.sh" "$1"
exists() { if [ -s "$1" ]; then pass=$((pass+1)); else echo "FAIL missing $1"; fail=$((fail+1)); fi; }

check help ok "--no-visibility" -- "$BIN" fuse --help
check capture ok "captured 2 probes" -- "$BIN" --quiet lab capture t-corridor --fusion --probe 0,1.5,-1 --probe 0,1.5,5 --size 32 --out "$T/tc"
check at ok "100.0% fused" -- "$BIN" fuse "$T/tc/probes.json" --at 0,1.5,1 --size 32 --lights 8 --out "$T/at/local.exr"
for f in local.exr local_depth.exr local_coverage.exr local_sh.json local_lights.json local.png; do exists "$T/at/$f"; done
check lights-localised ok '"position"' -- cat "$T/at/local_lights.json"
check lights-origin ok '"origin"' -- cat "$T/at/local_lights.json"
check cube ok "256×192 hcross" -- "$BIN" fuse "$T/tc/probes.json" --at 0,1.5,1 --mapping hcross --size 64 --blend angle --no-visibility --out "$T/cube.exr"
check json ok '"fused": 1' -- "$BIN" --json fuse "$T/tc/probes.json" --at 0,1.5,3 --size 16 --blend nearest --out "$T/j.exr"
printf '[[0,1.5,6],[0,1.5,5],[0,1.5,4],[0,1.5,3],[0,1.5,2]]' > "$T/path.json"
check path ok "shadow lights' jump" -- "$BIN" fuse "$T/tc/probes.json" --path "$T/path.json" --size 16 --lights 4 --out "$T/path"
exists "$T/path/frames/0004.exr"; exists "$T/path/lights/0004.json"; exists "$T/path/path_summary.json"; exists "$T/path/path.png"
check path-ids ok '"id"' -- cat "$T/path/lights/0002.json"
# Depth: traced beside the probe when the manifest names none, then read from the cache.
sed 's/"depth": *"[^"]*",//' "$T/tc/probes.json" > "$T/tc/nodepth.json"
check depth-traced ok "traced" -- "$BIN" fuse depth "$T/tc/nodepth.json"
exists "$T/tc/probes/p0_proxydepth.exr"
check depth-cached ok "cache" -- "$BIN" fuse depth "$T/tc/nodepth.json"
check eval ok "footprint \| on" -- "$BIN" fuse eval "$T/tc/probes.json" --scene t-corridor --at -2,1.5,-1 --size 16 --samples 1 --truth-samples 1 --area-samples 2 --out "$T/eval"

# Bad input.
check no-point fail "exactly one of --at and --path" -- "$BIN" fuse "$T/tc/probes.json" --out "$T/x.exr"
check point-in-wall fail "inside geometry or outside the proxy" -- "$BIN" fuse "$T/tc/probes.json" --at 0,1.5,12 --out "$T/x.exr"
check bad-blend fail "unknown blend" -- "$BIN" fuse "$T/tc/probes.json" --at 0,1.5,1 --blend median --out "$T/x.exr"
check missing-set fail "none.json: no such file" -- "$BIN" fuse "$T/none.json" --at 0,1.5,1 --out "$T/x.exr"
printf '{"format":"iblkit.probes/1","proxy":"proxy.obj","probes":[{"image":"probes/p0.exr","position":[0,1.5,-1]},{"image":"probes/p1.exr","position":[0,1.5,14]}]}' > "$T/tc/outside.json"
check probe-outside fail "probe 1.*outside the proxy" -- "$BIN" fuse "$T/tc/outside.json" --at 0,1.5,1 --out "$T/x.exr"
cp "$T/tc/probes.json" "$T/tc/mismatch.json"
"$BIN" --quiet lab capture t-corridor --fusion --probe 0,1.5,-1 --size 16 --out "$T/small" >/dev/null
cp "$T/small/probes/p0_depth.exr" "$T/tc/probes/small_depth.exr"
sed -i 's#probes/p0_depth.exr#probes/small_depth.exr#' "$T/tc/mismatch.json"
check depth-size fail "must match" -- "$BIN" fuse "$T/tc/mismatch.json" --at 0,1.5,1 --out "$T/x.exr"
# An open proxy (the stem's end wall removed): a warning and a coverage report, not a black map.
head -n 200 "$T/tc/proxy.obj" | grep -v '^f' > "$T/tc/open.obj"
grep '^f' "$T/tc/proxy.obj" | head -n -2 >> "$T/tc/open.obj"
sed 's#"proxy.obj"#"open.obj"#' "$T/tc/nodepth.json" > "$T/tc/open.json"
check open-proxy ok "not closed" -- "$BIN" fuse "$T/tc/open.json" --at 0,1.5,3 --size 16 --out "$T/open.exr"
check open-coverage ok "left the proxy" -- "$BIN" fuse "$T/tc/open.json" --at 0,1.5,3 --size 16 --out "$T/open.exr"

echo "cli_fusion: $pass passed, $fail failed"
[ $fail -eq 0 ]
