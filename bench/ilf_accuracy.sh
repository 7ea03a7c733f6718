#!/usr/bin/env bash
# ILF accuracy against the lab's ground truth (issue 5, "Accuracy"; Löw et al. 2009, Figs. 9 and 11):
# for each scene, one capture of the largest density of ideal mirror balls (SIZE², SAMPLES×SAMPLES
# sub-samples per pixel, 4.2° dead angle, uniform random positions; a smaller density is the first N
# probes of it), SH grids at every resolution with every repair, and against `iblkit lab truth`:
#   - relative L2 of the grid's SH (25 coefficients × RGB) at POINTS random grid points per
#     resolution, against the exact SH of the whole sphere and of the sphere without the dead-angle
#     cone (what any mirror-ball sequence can see; `lab truth --blind-cone`);
#   - relative L2 of the irradiance on a plane at PLANE_N² points (the pixel centres of `ilf slice
#     --size PLANE_N`): low-scene1 z = 0 for the normal −Z (facing its projector), low-scene2 y = 1, +Y;
#   - the truth's own noise floor (its settings against finer maps with another seed).
# Writes WORKDIR/table.md, results.json, slices_SCENE.png (rows: densities; columns: truth, then the
# grids, repair PICTURE_REPAIR) and errors_SCENE.png (SH error solid, plane irradiance dotted, one
# colour per density, x = log2 resolution). Everything is cached in WORKDIR: a re-run redoes only
# what is missing (delete WORKDIR/SCENE/*.json to re-measure).
#   bench/ilf_accuracy.sh [IBLKIT] [WORKDIR]
#   environment: SCENES ("low-scene1 low-scene2"), DENSITIES ("500 2000 4397"), GRIDS ("8 16 32 64"),
#                REPAIRS ("mip pullpush none"), SIZE (48), SAMPLES (2), POINTS (64),
#                PLANE ("z=0-" style, default per scene), PLANE_N (20), FLOOR_POINTS (6), PICTURE_REPAIR (first of REPAIRS), PLOT_YMAX (0.6),
#                LOOK ("0,1,0": the balls look up, so that their dead angle and their coarse rim, where a
#                48² ball's outer pixel ring spans ~30°, face the floor and not a lamp; see docs/ilf.md)
# Needs python3 only. On the shared 2-core dev machine (load 4–6) the default sweep took ≈ 19 min with
# the captures and bucket files of an earlier run reused; a first run adds ≈ 30 s of capture per scene
# and the bucket sorts (a 20-point run from scratch took 16 min). Figures: bench/ilf_results.md.
set -euo pipefail
BIN=${1:-build/iblkit}
WORK=${2:-/tmp/iblkit_ilf_accuracy}
exec python3 "$(dirname "$0")/ilf_accuracy.py" "$BIN" "$WORK"
