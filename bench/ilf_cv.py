#!/usr/bin/env python3
"""Issue 15 measurements against the lab's ground truth (run through bench/ilf_cv.sh).

  parallax  mirror-ball camera captures with parallax (`lab capture --camera ball --parallax`) at
            several ball radii; `ilf build` with and without the compensation (--no-parallax) at
            several grids, fixed kernel; relative L2 of the grid's SH (trilinear at random points of
            the volume) against `lab truth` there.
  crossval  ideal mirror balls; for each scene × probe count × grid × kernel (fixed ones and auto) the
            cross-validated error `ilf build` reports beside the true error (as above).
(Error against probe count and layout — random, parallel tracked lines, clusters — is bench/ilf_density.py.)
Everything is cached in WORK (delete WORK/<study>/*.json to re-measure). Writes WORK/<study>.md.
"""
import json, os, random, struct, subprocess, sys, time

BIN, WORK, STUDY = sys.argv[1], sys.argv[2], sys.argv[3]
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ilf_common import cached, cli, fmt3, log, rel_l2  # noqa: E402
run = cli(BIN)
env = os.environ.get
POINTS = int(env("POINTS", "40"))
SIZE, SAMPLES = int(env("SIZE", "48")), int(env("SAMPLES", "2"))
TRUTH = ["--size", "96", "--samples", "2", "--area-samples", "32"]
LOOK = "0,1,0"


class Grid:
    """An .shgrid read whole (pure Python), with SHGrid::coeffs_at's trilinear lookup."""

    def __init__(self, path):
        data = open(path, "rb").read()
        l1 = data.index(b"\n")
        l2 = data.index(b"\n", l1 + 1)
        h = json.loads(data[l1 + 1:l2])
        self.n = h["resolution"]
        self.lo, self.hi = h["min"], h["max"]
        self.K = h["bands"] ** 2
        self.v = struct.unpack_from("<%df" % (self.n[0] * self.n[1] * self.n[2] * self.K * 3), data, l2 + 1)

    def at(self, p):
        f, i0 = [], []
        for a in range(3):
            t = (p[a] - self.lo[a]) / (self.hi[a] - self.lo[a]) * (self.n[a] - 1)
            t = min(max(t, 0.0), self.n[a] - 1)
            i = min(int(t), self.n[a] - 2)
            i0.append(i)
            f.append(t - i)
        out = [0.0] * (self.K * 3)
        nx, ny = self.n[0], self.n[1]
        for c in range(8):
            w = 1.0
            idx = []
            for a in range(3):
                b = (c >> a) & 1
                w *= f[a] if b else 1 - f[a]
                idx.append(i0[a] + b)
            if w == 0:
                continue
            base = (((idx[2] * ny + idx[1]) * nx + idx[0]) * self.K) * 3
            for q in range(self.K * 3):
                out[q] += w * self.v[base + q]
        return out


def truth_points(scene, sdir, lo, hi, blind=None):
    """Exact SH (5 bands) at POINTS random points of the volume (cached, prefix-stable)."""
    path = os.path.join(sdir, "truth.json")
    rows = json.load(open(path)) if os.path.exists(path) else []
    rng = random.Random(77)
    pts = [[lo[a] + (hi[a] - lo[a]) * rng.random() for a in range(3)] for _ in range(POINTS)]
    for p in pts[len(rows):]:
        extra = ["--blind-cone", blind[0], "--blind-axis", blind[1]] if blind else []
        t = run("lab", "truth", scene, "--at", fmt3(p), "--bands", 5, *extra, *TRUTH)
        key = "sh_visible" if blind else "sh"
        rows.append({"p": p, "sh": [v for k in t[key]["coefficients"] for v in k]})
        json.dump(rows, open(path + ".tmp", "w"))
        os.replace(path + ".tmp", path)
    log(scene, "truth", len(rows), "points")
    return rows[:POINTS]


def true_error(grid_path, truth):
    g = Grid(grid_path)
    pairs = []
    for r in truth:
        pairs += list(zip(g.at(r["p"]), r["sh"]))
    return rel_l2(pairs)


def build(seq, out, *opts):
    t0 = time.time()
    rep = run("ilf", "build", seq, "--out", out, "--bands", 5, *opts)
    rep["wall"] = time.time() - t0
    return rep


def capture(scene, cap, count, extra, layout="random", seed=1):
    if os.path.exists(os.path.join(cap, "sequence.json")):
        return
    log(scene, "capture", cap)
    where = ["--random", str(count)] if layout == "random" else layout
    subprocess.check_call([BIN, "--quiet", "lab", "capture", scene, *where, "--mapping", "mirrorball", "--size", str(SIZE),
                           "--samples", str(SAMPLES), "--look", LOOK, "--half", "--seed", str(seed), *extra, "--out", cap],
                          stdout=subprocess.DEVNULL)


def vol(cap):
    s = json.load(open(os.path.join(cap, "sequence.json")))
    return s["volume"]["min"], s["volume"]["max"], len(s["probes"])


# ---------------------------------------------------------------------------------------------
def parallax():
    scene = env("SCENE", "low-scene1")
    radii = [float(v) for v in env("RADII", "0.02 0.05 0.1").split()]
    grids = [int(v) for v in env("GRIDS", "16 32 64").split()]
    probes = int(env("PROBES", "1500"))
    kernel = env("KERNEL", "3")
    sdir = os.path.join(WORK, "parallax", scene)
    os.makedirs(sdir, exist_ok=True)
    rows = []
    truth = None
    for r in radii:
        cap = os.path.join(sdir, "ball_r%g" % r)
        capture(scene, cap, probes, ["--camera", "ball", "--ball-radius", str(r), "--parallax"])
        lo, hi, _ = vol(cap)
        if truth is None:
            truth = truth_points(scene, sdir, lo, hi)
        for n in grids:
            for comp in (False, True):
                key = os.path.join(sdir, "r%g_g%d_%s.json" % (r, n, "with" if comp else "without"))
                def make():
                    out = os.path.join(cap, "g%d_%s.shgrid" % (n, "with" if comp else "without"))
                    rep = build(os.path.join(cap, "sequence.json"), out, "--grid", n, "--kernel", kernel, "--cv-folds", 0,
                                "--buckets", os.path.join(cap, "buckets"), *([] if comp else ["--no-parallax"]))
                    e = true_error(out, truth)
                    os.remove(out)
                    return {"radius": r, "grid": n, "compensated": comp, "true_error": e, "seconds": rep["wall"],
                            "ball_radius_used": rep["ball_radius"]}
                row = cached(key, make)
                log("parallax r", r, "grid", n, "comp", comp, "err %.4f" % row["true_error"])
                rows.append(row)
    lines = ["| ball radius | grid | rel. L2 SH, rays from the centre (--no-parallax) | rays from the ball (default) | change |",
             "| --- | --- | --- | --- | --- |"]
    for r in radii:
        for n in grids:
            a = [x for x in rows if x["radius"] == r and x["grid"] == n and not x["compensated"]][0]
            b = [x for x in rows if x["radius"] == r and x["grid"] == n and x["compensated"]][0]
            lines.append("| %g cm | %d³ | %.3f | %.3f | %+.0f%% |" % (r * 100, n, a["true_error"], b["true_error"],
                                                                   100 * (b["true_error"] / a["true_error"] - 1)))
    open(os.path.join(WORK, "parallax.md"), "w").write("\n".join(lines) + "\n")
    print("\n".join(lines))


# ---------------------------------------------------------------------------------------------
def crossval():
    scenes = env("SCENES", "low-scene1 low-scene2").split()
    densities = [int(v) for v in env("DENSITIES", "500 2000").split()]
    grids = [int(v) for v in env("GRIDS", "8 16 32 64").split()]
    kernels = env("KERNELS", "1.5 2 3 4 auto").split()
    rows = []
    for scene in scenes:
        sdir = os.path.join(WORK, "crossval", scene)
        os.makedirs(sdir, exist_ok=True)
        cap = os.path.join(sdir, "capture")
        capture(scene, cap, max(densities), ["--dead-angle", "4.2"])
        lo, hi, _ = vol(cap)
        truth = truth_points(scene, sdir, lo, hi, blind=("4.2", "0,-1,0"))
        seq = json.load(open(os.path.join(cap, "sequence.json")))
        for N in densities:
            sp = os.path.join(cap, "sequence_%d.json" % N)
            if not os.path.exists(sp):
                s = dict(seq)
                s["probes"] = seq["probes"][:N]
                json.dump(s, open(sp, "w"))
            for n in grids:
                for k in kernels:
                    key = os.path.join(sdir, "p%d_g%d_k%s.json" % (N, n, k))
                    def make():
                        out = os.path.join(cap, "g.shgrid")
                        rep = build(sp, out, "--grid", n, "--kernel", k, "--buckets", os.path.join(cap, "buckets_%d" % N))
                        e = true_error(out, truth)
                        return {"scene": scene, "probes": N, "grid": n, "kernel": k, "kernel_used": rep["kernel"],
                                "cv_error": rep["crossval"]["rel_error"], "true_error": e, "seconds": rep["wall"],
                                "t_choose": rep.get("choice", {}).get("seconds", 0), "t_total": rep["seconds"]["total"]}
                    row = cached(key, make)
                    log(scene, N, n, k, "cv %.4f true %.4f" % (row["cv_error"], row["true_error"]))
                    rows.append(row)
    lines = ["| scene | probes | grid | kernel | CV error | true error | build s |", "| --- | --- | --- | --- | --- | --- | --- |"]
    summary = ["| scene | probes | grid | best fixed kernel (true error) | auto: kernel chosen (true error) | auto vs best | CV's pick vs truth's pick |",
               "| --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        lines.append("| %s | %d | %d³ | %s%s | %.3f | %.3f | %.1f |" % (r["scene"], r["probes"], r["grid"], r["kernel"],
                     " → %g" % r["kernel_used"] if r["kernel"] == "auto" else "", r["cv_error"], r["true_error"], r["seconds"]))
    for scene in scenes:
        for N in densities:
            for n in grids:
                fixed = [r for r in rows if r["scene"] == scene and r["probes"] == N and r["grid"] == n and r["kernel"] != "auto"]
                auto = [r for r in rows if r["scene"] == scene and r["probes"] == N and r["grid"] == n and r["kernel"] == "auto"]
                if not fixed or not auto:
                    continue
                best = min(fixed, key=lambda r: r["true_error"])
                a = auto[0]
                cvpick = min(fixed, key=lambda r: r["cv_error"])
                summary.append("| %s | %d | %d³ | %s (%.3f) | %g (%.3f) | %+.1f%% | %s / %s |" % (
                    scene, N, n, best["kernel"], best["true_error"], a["kernel_used"], a["true_error"],
                    100 * (a["true_error"] / best["true_error"] - 1), cvpick["kernel"], best["kernel"]))
    # Rank correlation of CV and true error across all fixed-kernel rows per scene.
    corr = []
    for scene in scenes:
        f = [r for r in rows if r["scene"] == scene and r["kernel"] != "auto"]
        def ranks(v):
            o = sorted(range(len(v)), key=lambda i: v[i])
            rk = [0] * len(v)
            for i, j in enumerate(o):
                rk[j] = i
            return rk
        a, b = ranks([r["cv_error"] for r in f]), ranks([r["true_error"] for r in f])
        n = len(f)
        rho = 1 - 6 * sum((x - y) ** 2 for x, y in zip(a, b)) / (n * (n * n - 1)) if n > 2 else float("nan")
        corr.append("%s: Spearman ρ(CV, true) = %.2f over %d builds" % (scene, rho, n))
    text = "\n".join(lines) + "\n\n" + "\n".join(summary) + "\n\n" + "\n".join(corr) + "\n"
    open(os.path.join(WORK, "crossval.md"), "w").write(text)
    print(text)


{"parallax": parallax, "crossval": crossval}[STUDY]()
