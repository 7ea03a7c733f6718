#!/usr/bin/env bash
# Fusion accuracy (issue 6): lab probe sets of t-corridor and partition-room, fused at points off the
# probes with every blend, visibility on and off, against the lab's exact local radiance maps.
# Usage: bench/fusion_accuracy.sh path/to/iblkit [OUT]   (about a minute on 2 cores)
set -euo pipefail
B=${1:?usage: $0 path/to/iblkit [OUT]}
OUT=${2:-fusion-accuracy}
HERE=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$OUT"
# T corridor: probes along the crossbar and down the stem; points in the crossbar, the junction and the stem.
"$B" --quiet lab capture t-corridor --fusion --size 128 --samples 2 --out "$OUT/tc" \
  --probe -3,1.5,-1 --probe 0,1.5,-1 --probe 3,1.5,-1 --probe 0,1.5,4 >/dev/null
"$B" --quiet fuse eval "$OUT/tc/probes.json" --scene t-corridor --size 64 --samples 4 --out "$OUT/tc_eval" \
  --at -2,1.5,-1.5 --at 1.5,1.2,-0.6 --at 0,1.5,2 --at 0.5,1.0,6.5 --view 1,0,0
# Fig. 7.8: two probes, the junction and the stem, seen from the crossbar looking down the bright arm.
"$B" --quiet lab capture t-corridor --fusion --size 128 --samples 2 --out "$OUT/tc2" --probe 0,1.5,-1 --probe 0,1.5,5 >/dev/null
"$B" --quiet fuse eval "$OUT/tc2/probes.json" --scene t-corridor --size 64 --samples 4 --out "$OUT/fig78" \
  --at -2,1.5,-1 --view 1,0,0
# Partition room: a probe on each side of the partition, one in the gap, one in a corner.
"$B" --quiet lab capture "$HERE/examples/partition-room.json" --fusion --size 128 --samples 2 --out "$OUT/pr" \
  --probe -2,1.2,0 --probe 2,1.2,0 --probe 0,1.5,1.5 --probe -3,1.5,-1.2 >/dev/null
"$B" --quiet fuse eval "$OUT/pr/probes.json" --scene "$HERE/examples/partition-room.json" --size 64 --samples 4 \
  --out "$OUT/pr_eval" --at -1,1.0,-1 --at 1.2,1.0,-1.2 --at -3,1.5,1 --at 0.8,1.3,1.6 --view 1,0,0.3
