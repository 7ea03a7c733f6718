#!/usr/bin/env bash
# assemble-page.sh OUT: installs the pinned npm packages (npm ci, once per package-lock.json) and
# writes the viewer's folder OUT: viewer/* and the three.js files of three-files.txt under OUT/three/.
# Everything the page needs at run time is in OUT; nothing is fetched when it runs. Without npm or
# without the registry it says so and writes nothing (the browser tests then skip).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
out="$1"
trap 'touch "$out.stamp"' EXIT  # the build step's output, also when it skips
stamp="$here/node_modules/.iblkit-lock"
if [[ ! -f "$stamp" ]] || ! cmp -s "$stamp" "$here/package-lock.json"; then
  if ! command -v npm >/dev/null; then echo "web: npm not found; the web viewer and its tests are skipped" >&2; exit 0; fi
  if ! (cd "$here" && PUPPETEER_SKIP_DOWNLOAD=1 npm ci --no-audit --no-fund --loglevel=error >&2); then
    echo "web: npm ci failed (no registry?); the web viewer and its tests are skipped" >&2
    exit 0
  fi
  cp "$here/package-lock.json" "$stamp"
fi
rm -rf "$out.tmp" && mkdir -p "$out.tmp/three"
cp -r "$here/viewer/." "$out.tmp/"
grep -v '^#' "$here/three-files.txt" | while read -r f; do
  [[ -z "$f" ]] && continue
  mkdir -p "$out.tmp/three/$(dirname "$f")"
  cp "$here/node_modules/three/$f" "$out.tmp/three/$f"
done
cp "$here/node_modules/three/LICENSE" "$out.tmp/three/LICENSE"
rm -rf "$out" && mv "$out.tmp" "$out"
