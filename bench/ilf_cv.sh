#!/usr/bin/env bash
# Issue 15's measurements against the lab's ground truth; see bench/ilf_cv.py for what each study does.
#   bench/ilf_cv.sh IBLKIT WORKDIR parallax|crossval
#   environment: POINTS (40 truth points), SIZE (48), SAMPLES (2);
#     parallax: SCENE (low-scene1), RADII ("0.02 0.05 0.1"), GRIDS ("16 32 64"), PROBES (1500), KERNEL (3)
#     crossval: SCENES ("low-scene1 low-scene2"), DENSITIES ("500 2000"), GRIDS ("8 16 32 64"), KERNELS ("1.5 2 3 4 auto")
# Needs python3 only. Results: WORKDIR/parallax.md, WORKDIR/crossval.md; figures in bench/ilf_results.md.
set -euo pipefail
exec python3 "$(dirname "$0")/ilf_cv.py" "${1:-build/iblkit}" "${2:-/tmp/iblkit_ilf_cv}" "${3:-crossval}"
