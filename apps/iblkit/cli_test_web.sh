#!/usr/bin/env bash
# iblkit serve (the viewer's static server) and the three.js grid export, without a browser:
# what it serves, what it refuses, and the files ilf export-threejs writes.
set -euo pipefail
BIN="$1"
T=$(mktemp -d)
SERVER=
cleanup() { [[ -n "$SERVER" ]] && kill "$SERVER" 2>/dev/null; rm -rf "$T"; }
trap cleanup EXIT
fail() { echo "FAIL: $*"; exit 1; }

mkdir -p "$T/site/sub"
echo '<!doctype html><title>x</title>' > "$T/site/index.html"
echo 'export const a = 1;' > "$T/site/sub/m.js"
echo secret > "$T/outside.txt"
ln -s "$T/outside.txt" "$T/site/link.txt"

# Refusals: not a folder, not loopback.
"$BIN" serve "$T/nope" --port 0 --seconds 1 2>"$T/err" && fail "serve of a missing folder succeeded"
grep -q "not a folder" "$T/err" || fail "missing folder: $(cat "$T/err")"
"$BIN" serve "$T/site" --host 0.0.0.0 --port 0 --seconds 1 2>"$T/err" && fail "serve on 0.0.0.0 succeeded"
grep -q "loopback" "$T/err" || fail "non-loopback host: $(cat "$T/err")"

if ! command -v curl >/dev/null; then echo "SKIP (part): no curl; the served files are not fetched"; exit 0; fi
"$BIN" serve "$T/site" --port 0 --seconds 30 >"$T/out" &
SERVER=$!
for _ in $(seq 50); do grep -q "http://" "$T/out" && break; sleep 0.1; done
URL=$(grep -o 'http://[^ ]*' "$T/out") || fail "serve printed no address"
code() { curl -s --path-as-is -o "$T/body" -w '%{http_code} %{content_type}' "$URL$1"; }
[[ "$(code '')" == "200 text/html; charset=utf-8" ]] || fail "/: $(code '')"
[[ "$(code 'sub/m.js?v=1')" == "200 text/javascript" ]] || fail "module script: $(code 'sub/m.js?v=1')"
grep -q "export const a" "$T/body" || fail "module body"
[[ "$(code '../outside.txt' | cut -d' ' -f1)" == 404 ]] || fail ".. served"
[[ "$(code 'sub/%2e%2e/%2e%2e/outside.txt' | cut -d' ' -f1)" == 404 ]] || fail "encoded .. served"
[[ "$(code 'link.txt' | cut -d' ' -f1)" == 404 ]] || fail "a link out of the folder was served"
[[ "$(code 'missing.js' | cut -d' ' -f1)" == 404 ]] || fail "missing file not 404"
[[ "$(curl -s -o /dev/null -w '%{http_code}' -X POST "$URL")" == 405 ]] || fail "POST not refused"
kill "$SERVER"; wait "$SERVER" 2>/dev/null || true; SERVER=

# ilf export-threejs: the two files and the header's layout.
"$BIN" ilf synth --out "$T/seq" --probes 60 --size 16 >/dev/null
"$BIN" ilf build "$T/seq/sequence.json" --grid 4 --bands 5 --out "$T/g.shgrid" >/dev/null
"$BIN" --json ilf export-threejs "$T/g.shgrid" --out "$T/three" > "$T/exp.json"
grep -q '"bands_kept": 3' "$T/exp.json" || fail "export: $(cat "$T/exp.json")"
# 4×4×(7·(4+2)) texels × 4 floats × 4 bytes.
[[ $(stat -c %s "$T/three/grid_atlas.bin") == $((4 * 4 * 42 * 16)) ]] || fail "atlas size $(stat -c %s "$T/three/grid_atlas.bin")"
grep -q '"depth": 42' "$T/three/grid.json" || fail "header depth"
"$BIN" ilf export-threejs "$T/g.shgrid" --out "$T/three" --name ../x 2>"$T/err" && fail "a --name with a slash was accepted"
echo "cli_web: ok"
