#!/usr/bin/env python3
"""Adaptive SH grids against dense ones: bytes against error (issue 15 §4, docs/ilf.md "Adaptive storage").

Per case (lab captures of low-scene2 and low-scene1, and the building-scale capture of bench/ilf_mpi_building.py):
  1. dense grids built at several resolutions (`ilf build --kernel W --cv-folds 0`, W = 3 cells, the
     direction buckets sorted once and reused), the finest the "64³-class" grid (≈ 64³ points), which
     is also built with the kernel that 3 cells of a coarser grid span (W in its own cells: smooth at
     the scale the probes resolve, fine where they resolve more);
  2. `ilf adapt` of some of them (ADAPT per case) at several tolerances and brick sizes;
  3. each grid's SH (5 bands) against `lab truth` (the SH without the balls' dead-angle cone, as
     bench/ilf_accuracy.py takes it) at POINTS random points of the volume, relative L2 over all
     coefficients; dense grids looked up in numpy (checked against `ilf query --points`), adaptive
     ones with `ilf query --points` (their own lookup);
  4. a table: file bytes, error, bytes relative to the 64³-class grid; the smallest adaptive grid whose
     error is within 1 % of the better 64³-class grid's, and its ratio; the smallest dense grid too.
Truths, captures and builds are cached in WORKDIR. Writes WORKDIR/adaptive_results.json.

Usage: bench/ilf_adaptive.py IBLKIT WORKDIR [CASE ...]   (cases: lab (low-scene2), lab1 (low-scene1), building; default all)
environment: POINTS (320), TOLS ("0.02 0.05 0.1 0.2 0.3 0.5"), BRICKS ("4 8"),
             BUILDING_SEQ (default /tmp/mpi_e2e/building/sequence.json; captured into WORKDIR when absent)
"""
import json, os, random, subprocess, sys, time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ilf_common import cached, cli, fmt3, log  # noqa: E402

BIN, WORK = sys.argv[1], os.path.abspath(sys.argv[2])
CASES_RUN = sys.argv[3:] or ["lab", "lab1", "building"]
env = os.environ.get
POINTS = int(env("POINTS", "320"))
TOLS = [float(v) for v in env("TOLS", "0.02 0.05 0.1 0.2 0.3 0.5").split()]
BRICKS = [int(v) for v in env("BRICKS", "4 8").split()]
EXAMPLES = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples")
DEAD = 4.2
TRUTH = ["--size", "64", "--samples", "2", "--area-samples", "16"]  # 0.6 % from lab truth's defaults (measured, docs/ilf.md)
run = cli(BIN)

CASES = {
    # 12³ balls of 32² over low-scene2's (and low-scene1's) 1 m cube.
    "lab": dict(scene="low-scene2", capture=["--grid", "12,12,12", "--mapping", "mirrorball", "--size", "32"],
                dense=["8,8,8@3", "16,16,16@3", "32,32,32@3", "64,64,64@3", "64,64,64@12"], adapt=["64,64,64@12"], keep_out=None),
    "lab1": dict(scene="low-scene1", capture=["--grid", "12,12,12", "--mapping", "mirrorball", "--size", "32"],
                 dense=["8,8,8@3", "16,16,16@3", "32,32,32@3", "64,64,64@3", "64,64,64@12"], adapt=["64,64,64@12"], keep_out=None),
    # 51 520 balls of 16² over the four-room storey (bench/ilf_mpi_building.py); 220×12×105 ≈ 64³ points,
    # also with wider kernels (8.6 cells: 3 cells of 77×5×37).
    "building": dict(scene=os.path.join(EXAMPLES, "building.json"), seq=env("BUILDING_SEQ", "/tmp/mpi_e2e/building/sequence.json"),
                     capture=["--grid", "80,14,46", "--mapping", "mirrorball", "--size", "16", "--samples", "1"],
                     dense=["39,3,19@3", "77,5,37@3", "153,9,73@3", "220,12,105@3", "220,12,105@4.5", "220,12,105@8.6"],
                     adapt=["220,12,105@3", "220,12,105@4.5", "153,9,73@3"], keep_out=0.2),
}


def read_shgrid(path):
    """(header, array [nz, ny, nx, K·3]) of an .shgrid."""
    with open(path, "rb") as f:
        b = f.read()
    l1 = b.index(b"\n"); l2 = b.index(b"\n", l1 + 1)
    h = json.loads(b[l1 + 1:l2])
    nx, ny, nz = h["resolution"]; K = h["bands"] ** 2
    a = np.frombuffer(b, dtype="<f4", offset=l2 + 1, count=nx * ny * nz * K * 3).reshape(nz, ny, nx, K * 3)
    return h, a


def trilinear(h, a, pts):
    """SHGrid::coeffs_at at pts [N, 3] (clamped), as float64 [N, K·3]."""
    lo, hi, n = np.array(h["min"]), np.array(h["max"]), np.array(h["resolution"])
    f = np.clip((pts - lo) / (hi - lo) * (n - 1), 0, n - 1)
    i0 = np.minimum(f.astype(int), n - 2)
    t = f - i0
    out = np.zeros((len(pts), a.shape[3]))
    for c in range(8):
        d = np.array([c & 1, (c >> 1) & 1, c >> 2])
        w = np.prod(np.where(d == 1, t, 1 - t), axis=1)
        idx = i0 + d
        out += w[:, None] * a[idx[:, 2], idx[:, 1], idx[:, 0]].astype(np.float64)
    return out


def rel_l2(est, truth):
    return float(np.sqrt(np.sum((est - truth) ** 2) / np.sum(truth ** 2)))


def points(volume, keep_out, n, seed):
    """n uniform random points of the volume; with keep_out, none within keep_out m of the walls x = 0, z = 0."""
    rng = random.Random(seed)
    lo, hi = volume["min"], volume["max"]
    out = []
    while len(out) < n:
        p = [lo[a] + (hi[a] - lo[a]) * rng.random() for a in range(3)]
        if keep_out and (abs(p[0]) < keep_out or abs(p[2]) < keep_out):
            continue
        out.append(p)
    return out


def case(name):
    c = CASES[name]
    d = os.path.join(WORK, name)
    os.makedirs(d, exist_ok=True)
    seq = c.get("seq")
    if not seq or not os.path.exists(seq):
        seq = os.path.join(d, "capture", "sequence.json")
        if not os.path.exists(seq):
            log(name, "capture")
            subprocess.check_call([BIN, "--quiet", "lab", "capture", c["scene"], *c["capture"], "--dead-angle", str(DEAD), "--look", "0,1,0",
                                   "--half", "--out", os.path.dirname(seq)], stdout=subprocess.DEVNULL)
    manifest = json.load(open(seq))
    volume = manifest["volume"]
    probes = len(manifest["probes"])
    pts = points(volume, c["keep_out"], POINTS, 15)

    def truth():
        rows = []
        for i, p in enumerate(pts):
            t = run("lab", "truth", c["scene"], "--at", fmt3(p), "--bands", 5, "--blind-cone", DEAD, "--blind-axis", "0,-1,0", *TRUTH)
            rows.append([v for k in t["sh_visible"]["coefficients"] for v in k])
            if i % 40 == 39:
                log(name, "truth", i + 1, "of", len(pts))
        return rows
    T = np.array(cached(os.path.join(d, "truth_%d.json" % POINTS), truth))
    P = np.array(pts)
    pts_file = os.path.join(d, "points_%d.json" % POINTS)
    json.dump(pts, open(pts_file, "w"))

    def query(grid):  # the grid's own lookup (SHGrid or AdaptiveGrid) at every point
        return np.array([[x for k in c for x in k] for c in run("ilf", "query", grid, "--points", pts_file)["coefficients"]])

    rows, dense, checked = [], {}, None
    for spec in c["dense"]:
        res, kernel = spec.split("@")
        out = os.path.join(d, "dense_%s_k%s.shgrid" % (res.replace(",", "x"), kernel))
        def build():
            t0 = time.time()
            rep = run("ilf", "build", seq, "--grid", res, "--bands", 5, "--kernel", kernel, "--cv-folds", 0, "--skip-bad", "--out", out,
                      "--buckets", os.path.join(d, "buckets"))
            return {"wall": time.time() - t0, "total": rep["seconds"]["total"], "probes_used": rep["probes_used"]}
        meta = out + ".build.json"
        if not (os.path.exists(out) and os.path.exists(meta)):
            json.dump(build(), open(meta, "w"))
        b = json.load(open(meta))
        h, a = read_shgrid(out)
        est = trilinear(h, a, P)
        if checked is None:  # numpy's trilinear against the library's
            checked = float(np.max(np.abs(query(out) - est)) / np.max(np.abs(est)))
        err = rel_l2(est, T)
        dense[spec] = {"path": out, "bytes": os.path.getsize(out), "error": err, "build_s": b["total"]}
        rows.append({"grid": "dense %s, kernel %s cells" % (res.replace(",", "×"), kernel), "points": int(np.prod(h["resolution"])),
                     "bytes": os.path.getsize(out), "error": err, "seconds": b["total"]})
        log(name, "dense", spec, "error %.4f" % err)
    big = [k for k in c["dense"] if k.split("@")[0] == c["dense"][-1].split("@")[0]]
    ref_spec = min(big, key=lambda k: dense[k]["error"])  # the better 64³-class grid
    ref = dense[ref_spec]
    for src, brick, tol in [(a, b, t) for a in c["adapt"] for b in BRICKS for t in TOLS]:
        fine = dense[src]
        res, kernel = src.split("@")
        tree = os.path.join(d, "tree_%s_k%s_b%d_t%g.shtree" % (res.replace(",", "x"), kernel, brick, tol))
        rep = run("ilf", "adapt", fine["path"], "--tolerance", tol, "--brick", brick, "--out", tree)
        est = query(tree)
        err = rel_l2(est, T)
        os.remove(tree)
        rows.append({"grid": "adaptive of %s k%s, brick %d³, tolerance %g" % (res.replace(",", "×"), kernel, brick, tol),
                     "points": rep["stored_points"], "bytes": rep["bytes"],
                     "error": err, "seconds": rep["seconds"], "max_point_error": rep["max_point_error"], "rel_l2_to_fine": rep["rel_l2_to_fine"],
                     "brick": brick, "tolerance": tol})
        log(name, "adaptive", src, brick, tol, "error %.4f" % err, "bytes %.3g" % rep["bytes"])
    for r in rows:
        r["ratio"] = r["bytes"] / ref["bytes"]
    ok = [r for r in rows if r["grid"].startswith("adaptive") and r["error"] <= 1.01 * ref["error"]]
    best = min(ok, key=lambda r: r["bytes"]) if ok else None
    dense_ok = [r for r in rows if r["grid"].startswith("dense") and r["error"] <= 1.01 * ref["error"]]
    best_dense = min((r for r in rows if r["grid"].startswith("dense")), key=lambda r: r["error"])
    ok2 = [r for r in rows if r["grid"].startswith("adaptive") and r["error"] <= 1.01 * best_dense["error"]]
    return {"probes": probes, "volume": volume, "points": POINTS, "reference": ref_spec, "reference_error": ref["error"], "rows": rows,
            "best_adaptive": best,
            "smallest_dense_within_1pct": min(dense_ok, key=lambda r: r["bytes"]) if dense_ok else None,
            "numpy_vs_query_max_rel": checked, "best_dense": best_dense,
            "adaptive_within_1pct_of_best_dense": min(ok2, key=lambda r: r["bytes"]) if ok2 else None}


results = {}
for name in CASES_RUN:
    results[name] = case(name)
    r = results[name]
    print("\n### %s (%d probes; error: SH relative L2 against lab truth at %d random points)\n" % (name, r["probes"], r["points"]))
    print("| grid | stored points | bytes | bytes / 64³-class | SH rel. L2 vs truth | adapt or build s |")
    print("| --- | --- | --- | --- | --- | --- |")
    for row in r["rows"]:
        print("| %s | %d | %.3g | %.3f | %.4f | %.1f |" % (row["grid"], row["points"], row["bytes"], row["ratio"], row["error"], row["seconds"]))
    b = r["best_adaptive"]
    print("\nsmallest adaptive grid within 1 %% of the 64³-class grid's error: %s" % (
        "%s, %.3g bytes = %.3f of it (error %.4f vs %.4f, %s)" % (b["grid"], b["bytes"], b["ratio"], b["error"], r["reference_error"], r["reference"])
        if b else "none"))
    s = r["smallest_dense_within_1pct"]
    print("smallest dense grid within 1 %%: %s" % ("%s (%.3f of the bytes)" % (s["grid"], s["ratio"]) if s else "none"))
    bd, a2 = r["best_dense"], r["adaptive_within_1pct_of_best_dense"]
    print("most accurate dense grid: %s (error %.4f, %.3g bytes); smallest adaptive within 1 %% of it: %s" % (
        bd["grid"], bd["error"], bd["bytes"], "%s, %.3g bytes = %.3f of it" % (a2["grid"], a2["bytes"], a2["bytes"] / bd["bytes"]) if a2 else "none"))
    print("numpy trilinear vs `ilf query --points` on a dense grid: max difference %.2g of the largest coefficient" % r["numpy_vs_query_max_rel"])
json.dump(results, open(os.path.join(WORK, "adaptive_results.json"), "w"), indent=1)
