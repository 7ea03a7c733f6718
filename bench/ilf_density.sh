#!/usr/bin/env bash
# Issue 15 §3: ILF grid error against the lab's truth as a function of probe count and capture layout
# (random, a serpentine of parallel tracked lines, a few clusters), at several grid resolutions, with
# `ilf build`'s defaults (--kernel auto, 5-fold cross-validation): the true error beside the kernel
# auto chose and the cross-validated error it reports. See bench/ilf_density.py for the procedure.
#   bench/ilf_density.sh [IBLKIT] [WORKDIR]
#   environment: SCENES ("low-scene1 low-scene2"), COUNTS ("100 400 1600 6400 20000"),
#                LAYOUTS ("random path clusters"), GRIDS ("8 16 32 64"), MIN64 (6400: fewer probes are
#                not built at 64³), SIZE (32), SAMPLES (1), POINTS (64 truth points), CLUSTERS (6),
#                SPREAD (0.1 m), PATH_RATIO (4: line spacing / probe spacing along a line),
#                FLOOR (16 single frames against the truth), ERRVOL (1600: the count whose error
#                volumes are drawn), PLOT (WORKDIR/density.png; the error-volume slices go beside it)
# Needs /usr/bin/python3 with numpy and matplotlib (scripts/install-deps). Results: WORKDIR/density.md,
# WORKDIR/results.json and the plot; figures in bench/ilf_results.md ("Issue 15 §3").
set -euo pipefail
BIN=${1:-build/iblkit}
WORK=${2:-/tmp/iblkit_ilf_density}
PY=/usr/bin/python3
[ -x "$PY" ] || PY=python3
exec "$PY" "$(dirname "$0")/ilf_density.py" "$BIN" "$WORK"
