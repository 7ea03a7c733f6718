#!/usr/bin/env bash
# End-to-end ILF benchmark at the paper's scale (Löw et al. 2009, Table 1): synthesises the closed-form
# light field of iblkit/ilf/analytic.h as 250×250 half-float mirror balls at random positions in a
# 1 m cube, then times `iblkit ilf build` (reading included) with /usr/bin/time for peak memory.
#   bench/ilf_e2e.sh [IBLKIT] [WORKDIR]      environment: PROBES (4397), GRID (64), DIRECTIONS (auto = pixel buckets)
set -euo pipefail
BIN=${1:-build/iblkit}
WORK=${2:-/tmp/iblkit_ilf_e2e}
PROBES=${PROBES:-4397}
GRID=${GRID:-64}
DIRECTIONS=${DIRECTIONS:-auto}
mkdir -p "$WORK"
if [ ! -f "$WORK/p$PROBES/sequence.json" ]; then
  echo "synthesising $PROBES probes of 250x250 into $WORK/p$PROBES …" >&2
  "$BIN" ilf synth --out "$WORK/p$PROBES" --probes "$PROBES" --size 250 --supersample 1 --quiet
fi
rm -rf "$WORK/p$PROBES/g.shgrid.buckets"  # time the sort too (a re-run would reuse the buckets)
/usr/bin/time -v "$BIN" ilf build "$WORK/p$PROBES/sequence.json" --grid "$GRID" --bands 5 --directions "$DIRECTIONS" \
  --out "$WORK/p$PROBES/g.shgrid" --quiet --json 2> "$WORK/time.txt" | tee "$WORK/report.json"
grep -E "Elapsed|Maximum resident" "$WORK/time.txt"
