#!/usr/bin/env python3
"""A building-scale ILF capture built on MPI (issue 18): the lab's four-room storey
(examples/building.json, 20 x 10 m) captured with 51 520 ideal mirror balls of 16² (a regular
80 x 14 x 46 grid over the 19 x 1 x 9 m volume that misses the walls, balls looking up, half floats),
built serially and with `mpirun -np N` for N in RANKS, and each grid's SH compared with
`lab truth` (SH without the balls' dead-angle cone, as bench/ilf_accuracy.py does) at POINTS random
grid points. Prints a table row per build and writes WORKDIR/building_results.json.

Usage: bench/ilf_mpi_building.py IBLKIT WORKDIR   environment: RANKS ("2 4"), GRID ("77,5,37"), POINTS (48)
"""
import json, math, os, random, struct, subprocess, sys, time

BIN, WORK = sys.argv[1], sys.argv[2]
env = os.environ.get
RANKS = env("RANKS", "2 4").split()
GRID = [int(v) for v in env("GRID", "77,5,37").split(",")]
POINTS = int(env("POINTS", "48"))
SCENE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples", "building.json")
CAP = os.path.join(WORK, "building")
DEAD = 4.2
MPIRUN = ["mpirun", "--oversubscribe"]
ENV = dict(os.environ)
if os.getuid() == 0:
    ENV.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")


def run(args, **kw):
    return subprocess.run(args, check=True, capture_output=True, text=True, env=ENV, **kw).stdout


def read_grid(path):
    b = open(path, "rb").read()
    l1 = b.index(b"\n"); l2 = b.index(b"\n", l1 + 1)
    h = json.loads(b[l1 + 1:l2])
    return h, struct.unpack("<%df" % ((len(b) - l2 - 1) // 4), b[l2 + 1:])


def rel_l2(pairs):
    num = sum((a - b) ** 2 for a, b in pairs); den = sum(b * b for a, b in pairs)
    return math.sqrt(num / den)


os.makedirs(WORK, exist_ok=True)
if not os.path.exists(os.path.join(CAP, "sequence.json")):
    t0 = time.time()
    run([BIN, "--quiet", "lab", "capture", SCENE, "--grid", "80,14,46", "--mapping", "mirrorball", "--size", "16", "--samples", "1",
         "--dead-angle", str(DEAD), "--look", "0,1,0", "--half", "--out", CAP])
    print("capture: %.0f s" % (time.time() - t0))
seq = os.path.join(CAP, "sequence.json")
nprobes = len(json.load(open(seq))["probes"])
builds = {}
common = ["ilf", "build", seq, "--grid", ",".join(map(str, GRID)), "--bands", "5", "--kernel", "3", "--cv-folds", "0", "--skip-bad"]
for name, pre in [("serial", [])] + [("mpi_%s" % n, MPIRUN + ["-np", n]) for n in RANKS]:
    out = os.path.join(WORK, "building_%s.shgrid" % name)
    t0 = time.time()
    rep = json.loads(run(pre + [BIN, "--quiet", "--json"] + common + ["--out", out, "--buckets", out + ".buckets"]))
    builds[name] = {"wall": time.time() - t0, "report": rep, "path": out}
    subprocess.run(["rm", "-rf", out + ".buckets"])

h, ref = read_grid(builds["serial"]["path"])
nx, ny, nz = h["resolution"]; K = h["bands"] ** 2; lo, hi = h["min"], h["max"]
rng = random.Random(18)
idx = [(rng.randrange(nx), rng.randrange(ny), rng.randrange(nz)) for _ in range(POINTS)]
truth_path = os.path.join(WORK, "building_truth_%d_%d_%d_%d.json" % (nx, ny, nz, POINTS))
if os.path.exists(truth_path):
    truth = json.load(open(truth_path))
else:
    truth = []
    for (i, j, k) in idx:
        p = [lo[0] + (hi[0] - lo[0]) * i / (nx - 1), lo[1] + (hi[1] - lo[1]) * j / (ny - 1), lo[2] + (hi[2] - lo[2]) * k / (nz - 1)]
        t = json.loads(run([BIN, "--quiet", "--json", "lab", "truth", SCENE, "--at", ",".join("%.9g" % v for v in p), "--bands", "5",
                            "--blind-cone", str(DEAD), "--blind-axis", "0,-1,0", "--size", "128", "--samples", "4", "--area-samples", "64"]))
        truth.append([v for c in t["sh_visible"]["coefficients"] for v in c])
    json.dump(truth, open(truth_path, "w"))

def at(g, ijk):
    i, j, k = ijk
    o = (((k * ny + j) * nx + i) * K) * 3
    return g[o:o + 3 * K]

rows = {}
print("| build | probes used | wall | read | exchange | project (repair) | SH | reduce | SH rel. L2 vs truth (%d points) | max rel. diff to serial |" % POINTS)
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
for name, b in builds.items():
    _, g = read_grid(b["path"])
    err = rel_l2([(a, t) for ijk, tr in zip(idx, truth) for a, t in zip(at(g, ijk), tr)])
    worst = max((abs(x - y) / abs(x) for x, y in zip(ref, g) if x != 0), default=0.0)
    r = b["report"]; s = r["seconds"]; m = r.get("mpi")
    if m:
        t = m["seconds"]
        cells = (t["read"], t["exchange"], t["project"], t["repair"], t["accumulate"], "%.2f s" % t["reduce"])
    else:
        cells = (s["sort"], float("nan"), s["project"], s["repair"], s["accumulate"], "—")
    print("| %s | %d of %d | %.0f s | %.1f s | %.1f s | %.1f s (%.1f s) | %.1f s | %s | %.4f | %.2g |" % (
        name, r["probes_used"], nprobes, b["wall"], cells[0], cells[1], cells[2], cells[3], cells[4], cells[5], err, worst))
    rows[name] = {"wall": b["wall"], "sh_rel_l2": err, "max_rel_diff_to_serial": worst, "report": r}
json.dump(rows, open(os.path.join(WORK, "building_results.json"), "w"), indent=1)
