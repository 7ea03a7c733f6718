#!/usr/bin/env bash
# ILF accuracy against the lab's ground truth (issue 5, "Accuracy"): captures SCENE with PROBES
# ideal mirror balls of SIZE² at random positions in its volume, builds SH grids at 8³, 16³, 32³ with
# each repair, and compares the grid's coefficients at POINTS random grid points per resolution with
# `iblkit lab truth` there (relative L2 over points × 25 coefficients × RGB), plus the irradiance
# for the normal +Y at the same points.
#   bench/ilf_accuracy.sh [IBLKIT] [WORKDIR]   environment: SCENE (low-scene2), PROBES (1000), SIZE (64), SAMPLES (2: n×n per pixel),
#                                              GRIDS ("8 16 32"), POINTS (16), REPAIRS ("mip pullpush")
set -euo pipefail
BIN=${1:-build/iblkit}
WORK=${2:-/tmp/iblkit_ilf_accuracy}
SCENE=${SCENE:-low-scene2}
PROBES=${PROBES:-1000}
SIZE=${SIZE:-64}
SAMPLES=${SAMPLES:-2}
GRIDS=${GRIDS:-8 16 32}
POINTS=${POINTS:-16}
REPAIRS=${REPAIRS:-mip pullpush}
CAP="$WORK/$SCENE-p$PROBES-s$SIZE-x$SAMPLES"
mkdir -p "$WORK"
if [ ! -f "$CAP/sequence.json" ]; then
  "$BIN" --quiet lab capture "$SCENE" --random "$PROBES" --mapping mirrorball --size "$SIZE" --samples "$SAMPLES" \
    --dead-angle 4.2 --half --out "$CAP" > /dev/null
fi
python3 - "$BIN" "$CAP" "$SCENE" "$POINTS" "$GRIDS" "$REPAIRS" <<'PY'
import json, math, random, subprocess, sys, os
bin_, cap, scene, npts, grids, repairs = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4]), sys.argv[5].split(), sys.argv[6].split()
def run(*a):
    return json.loads(subprocess.check_output([bin_, "--quiet", "--json", *a]))
seq = json.load(open(os.path.join(cap, "sequence.json")))
lo, hi = seq["volume"]["min"], seq["volume"]["max"]
rng = random.Random(7)
truth_cache = {}
def truth(p):
    key = tuple(round(v, 9) for v in p)
    if key not in truth_cache:
        d = os.path.join(cap, "truth_%d" % len(truth_cache))
        run("lab", "truth", scene, "--at", ",".join("%.9g" % v for v in p), "--bands", "5", "--normal", "0,1,0", "--out", d)
        sh = json.load(open(os.path.join(d, "sh.json")))["coefficients"]
        tj = json.load(open(os.path.join(d, "truth.json")))
        truth_cache[key] = (sh, tj)
    return truth_cache[key]
print("| scene | probes | grid | repair | rel. L2 SH (%d pts) | median point rel. SH error | rel. irradiance error (+Y) | uncovered | build s |" % npts)
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
for n in grids:
    n = int(n)
    pts = [[lo[a] + (hi[a] - lo[a]) * rng.randrange(n) / (n - 1) for a in range(3)] for _ in range(npts)]
    for rep in repairs:
        out = os.path.join(cap, "g%d_%s.shgrid" % (n, rep))
        r = run("ilf", "build", os.path.join(cap, "sequence.json"), "--grid", str(n), "--repair", rep, "--out", out,
                "--buckets", os.path.join(cap, "buckets"))
        num = den = en = ed = 0.0
        per = []
        for p in pts:
            pn = pd = 0.0
            sh, tj = truth(p)
            q = run("ilf", "query", out, "--at", ",".join("%.9g" % v for v in p), "--normal", "0,1,0")
            for k in range(25):
                for c in range(3):
                    pn += (q["coefficients"][k][c] - sh[k][c]) ** 2
                    pd += sh[k][c] ** 2
            num += pn; den += pd; per.append(math.sqrt(pn / pd))
            E = tj["irradiance"][0]["irradiance"]
            for c in range(3):
                en += (q["irradiance"][c] - E[c]) ** 2
                ed += E[c] ** 2
        per.sort()
        print("| %s | %d | %d³ | %s | %.4f | %.4f | %.4f | %.4f | %.1f |" % (scene, len(seq["probes"]), n, rep, math.sqrt(num / den), per[len(per) // 2],
              math.sqrt(en / ed), r["fraction_uncovered"], r["seconds"]["total"]))
PY
