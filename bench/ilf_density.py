#!/usr/bin/env python3
"""Issue 15 §3: how the probes' number and layout limit an ILF grid (Löw et al. 2009, §6 future work).

Run through bench/ilf_density.sh, which documents the settings. For each scene:
  1. captures of ideal mirror balls (SIZE², SAMPLES² sub-samples, 4.2° dead angle, looking up) in
     three layouts over the scene's capture volume:
       random    `lab capture --random N` (uniform; a tracked hand-held capture),
       path      `lab capture --path P --count N`: a serpentine of parallel lines along x, the lines
                 PATH_RATIO× farther apart (across y and z) than the probes along them (the paper's
                 translation-stage capture: dense along a line, sparse across),
       clusters  `lab capture --random N --clusters CLUSTERS --cluster-spread SPREAD` (a few spots);
     random and clusters are captured once at the largest count and the smaller counts are prefixes
     of it (both layouts are prefix-stable: lab::random_positions, lab::cluster_positions); a path is
     captured per count (a prefix of a serpentine covers part of the volume);
  2. the exact SH (5 bands, without the dead-angle cone) at POINTS uniform random points of the
     volume (`lab truth`), the same points for every build;
  3. `ilf build --bands 5 --grid n` with the defaults (`--kernel auto`, 5-fold cross-validation) for
     every layout × count × grid (64³ only from MIN64 probes up): the kernel it chose, the
     cross-validated error it reports, and the true error = relative L2 of the grid's SH (trilinear,
     as SHGrid::coeffs_at) against the truth at the points;
  4. the frames' own floor: FLOOR single probes of the random capture, each built alone on a 2³ grid
     (every point then holds that probe's SH through the builder's buckets), against the truth there;
  5. what the error volume shows: per layout, ERRVOL probes built at 16³ with --error-grid, its slice
     through the middle of the volume (`ilf slice`) as a PNG beside PLOT;
  6. WORK/density.md (the tables), WORK/results.json, and the plot PLOT.
Everything is cached in WORK (delete WORK/SCENE/*.json to re-measure).
"""
import json, math, os, random, resource, subprocess, sys, time

import numpy as np

BIN, WORK = sys.argv[1], sys.argv[2]
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ilf_common import cached, cli, fmt3, log  # noqa: E402
run = cli(BIN)
env = os.environ.get
SCENES = env("SCENES", "low-scene1 low-scene2").split()
COUNTS = [int(v) for v in env("COUNTS", "100 400 1600 6400 20000").split()]
LAYOUTS = env("LAYOUTS", "random path clusters").split()
GRIDS = [int(v) for v in env("GRIDS", "8 16 32 64").split()]
MIN64 = int(env("MIN64", "6400"))
SIZE, SAMPLES = int(env("SIZE", "32")), int(env("SAMPLES", "1"))
POINTS = int(env("POINTS", "64"))
CLUSTERS, SPREAD = int(env("CLUSTERS", "6")), float(env("SPREAD", "0.1"))
PATH_RATIO = float(env("PATH_RATIO", "4"))
FLOOR = int(env("FLOOR", "16"))
ERRVOL = int(env("ERRVOL", "1600"))
PLOT = env("PLOT", os.path.join(WORK, "density.png"))
DEAD, LOOK, BLIND_AXIS = 4.2, "0,1,0", "0,-1,0"
TRUTH = ["--size", "96", "--samples", "2", "--area-samples", "32"]


# ---------------------------------------------------------------------------------------------
def serpentine(lo, hi, n, ratio):
    """A boustrophedon of parallel lines along x through the box, Ly planes (y) × Lz lines (z) at
    spacing s, whose arc length spreads n probes at ≈ s/ratio: the line count that fits best."""
    ext = [hi[a] - lo[a] for a in range(3)]
    best = None
    for L in range(2, 400):
        s = max(ext[1], ext[2]) / (L - 1)
        ly, lz = max(2, round(ext[1] / s) + 1), max(2, round(ext[2] / s) + 1)
        length = ly * lz * ext[0] + (lz - 1) * ly * ext[2] / (lz - 1) + (ly - 1) * ext[1] / (ly - 1)
        along = length / max(n - 1, 1)
        score = abs(math.log(along / (s / ratio)))
        if best is None or score < best[0]:
            best = (score, ly, lz, s, along)
    _, ly, lz, s, along = best
    pts, line = [], 0
    for j in range(ly):
        y = lo[1] + ext[1] * j / (ly - 1)
        ks = range(lz) if j % 2 == 0 else range(lz - 1, -1, -1)
        for k in ks:
            z = lo[2] + ext[2] * k / (lz - 1)
            xa, xb = (lo[0], hi[0]) if line % 2 == 0 else (hi[0], lo[0])
            pts += [[xa, y, z], [xb, y, z]]
            line += 1
    return pts, {"planes": ly, "lines_per_plane": lz, "line_spacing": s, "probe_spacing": along}


def capture(scene, cap, where, seed=1):
    if os.path.exists(os.path.join(cap, "sequence.json")):
        return
    log(scene, "capture", cap)
    t0, c0 = time.time(), resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.check_call([BIN, "--quiet", "lab", "capture", scene, *where, "--mapping", "mirrorball", "--size", str(SIZE),
                           "--samples", str(SAMPLES), "--dead-angle", str(DEAD), "--look", LOOK, "--half", "--seed", str(seed),
                           "--out", cap], stdout=subprocess.DEVNULL)
    c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    json.dump({"seconds": time.time() - t0, "cpu_s": c1.ru_utime + c1.ru_stime - c0.ru_utime - c0.ru_stime},
              open(os.path.join(cap, "capture_time.json"), "w"))


def prefix(cap, n):
    sp = os.path.join(cap, "sequence_%d.json" % n)
    if not os.path.exists(sp):
        seq = json.load(open(os.path.join(cap, "sequence.json")))
        assert len(seq["probes"]) >= n
        s = dict(seq)
        s["probes"] = seq["probes"][:n]
        json.dump(s, open(sp + ".tmp", "w"))
        os.replace(sp + ".tmp", sp)
    return sp


def sequences(scene, sdir, lo, hi):
    """{(layout, count): (sequence path, bucket folder, layout notes)}."""
    out = {}
    for layout in LAYOUTS:
        if layout in ("random", "clusters"):
            cap = os.path.join(sdir, layout)
            where = ["--random", str(max(COUNTS))] + (["--clusters", str(CLUSTERS), "--cluster-spread", str(SPREAD)]
                                                       if layout == "clusters" else [])
            capture(scene, cap, where)
            for n in COUNTS:
                out[(layout, n)] = (prefix(cap, n), os.path.join(cap, "buckets_%d" % n), {})
        elif layout == "path":
            for n in COUNTS:
                poly, info = serpentine(lo, hi, n, PATH_RATIO)
                cap = os.path.join(sdir, "path_%d" % n)
                capture(scene, cap, ["--path", ";".join(fmt3(p) for p in poly), "--count", str(n)])
                out[(layout, n)] = (os.path.join(cap, "sequence.json"), os.path.join(cap, "buckets"), info)
        else:
            raise SystemExit("unknown layout " + layout)
    return out


# ---------------------------------------------------------------------------------------------
def truth_points(scene, sdir, lo, hi):
    """Exact SH (5 bands, without the dead-angle cone) at POINTS random points (cached, prefix-stable)."""
    path = os.path.join(sdir, "truth.json")
    rows = json.load(open(path)) if os.path.exists(path) else []
    rng = random.Random(77)
    pts = [[lo[a] + (hi[a] - lo[a]) * rng.random() for a in range(3)] for _ in range(POINTS)]
    for p in pts[len(rows):]:
        t = run("lab", "truth", scene, "--at", fmt3(p), "--bands", 5, "--blind-cone", DEAD, "--blind-axis", BLIND_AXIS, *TRUTH)
        rows.append({"p": p, "sh": [v for k in t["sh_visible"]["coefficients"] for v in k]})
        json.dump(rows, open(path + ".tmp", "w"))
        os.replace(path + ".tmp", path)
    log(scene, "truth", len(rows), "points")
    return rows[:POINTS]


def grid_at(path, pts):
    """The .shgrid's SH at points (trilinear, clamped to the volume, as SHGrid::coeffs_at)."""
    data = open(path, "rb").read()
    l1 = data.index(b"\n")
    l2 = data.index(b"\n", l1 + 1)
    h = json.loads(data[l1 + 1:l2])
    nx, ny, nz = h["resolution"]
    K = h["bands"] ** 2
    v = np.frombuffer(data, dtype="<f4", count=nx * ny * nz * K * 3, offset=l2 + 1).reshape(nz, ny, nx, K * 3)
    lo, hi, n = np.array(h["min"]), np.array(h["max"]), np.array([nx, ny, nz])
    out = []
    for p in pts:
        t = np.clip((np.array(p) - lo) / (hi - lo) * (n - 1), 0, n - 1)
        i = np.minimum(t.astype(int), n - 2)
        f = t - i
        acc = np.zeros(K * 3)
        for c in range(8):
            b = [(c >> a) & 1 for a in range(3)]
            w = np.prod([f[a] if b[a] else 1 - f[a] for a in range(3)])
            if w:
                acc += w * v[i[2] + b[2], i[1] + b[1], i[0] + b[0]]
        out.append(acc)
    return np.array(out)


def cpu_children():
    u = resource.getrusage(resource.RUSAGE_CHILDREN)
    return u.ru_utime + u.ru_stime


def measure(seq, buckets, n, truth):
    t0, c0 = time.time(), cpu_children()
    out = seq + ".g%d.shgrid" % n
    rep = run("ilf", "build", seq, "--out", out, "--bands", 5, "--grid", n, "--buckets", buckets)
    wall, cpu = time.time() - t0, cpu_children() - c0
    est = grid_at(out, [r["p"] for r in truth])
    os.remove(out)
    tr = np.array([r["sh"] for r in truth])
    per = np.sqrt(((est - tr) ** 2).sum(1) / (tr ** 2).sum(1))
    cv = rep["crossval"]
    return {"true_error": float(math.sqrt(((est - tr) ** 2).sum() / (tr ** 2).sum())), "true_median": float(np.median(per)),
            "kernel": rep["kernel"], "cv_error": cv["rel_error"], "cv_median": cv["median_probe_error"],
            "cv_regions": [r["rel_error"] for r in cv["regions"]], "trials": rep.get("choice", {}).get("trials", []),
            "uncovered": rep["fraction_uncovered"], "build_s": wall, "cpu_s": cpu, "stages": rep["seconds"],
            "buckets_reused": rep.get("buckets_reused"), "probes": rep.get("probes", n)}


def frame_floor(scene, sdir, cap):
    """The error of single frames: a one-probe sequence built on a 2³ grid (every point holds that
    probe's SH through the builder's own buckets) against the truth at the probe (FLOOR probes: the
    first of the random capture)."""
    def make():
        seq = json.load(open(os.path.join(cap, "sequence.json")))
        rows = []
        for k in range(FLOOR):
            s = dict(seq)
            s["probes"] = seq["probes"][k:k + 1]
            sp = os.path.join(cap, "one_%d.json" % k)
            json.dump(s, open(sp, "w"))
            g = sp + ".shgrid"
            run("ilf", "build", sp, "--out", g, "--bands", 5, "--grid", 2, "--kernel", 3, "--cv-folds", 0)
            p = seq["probes"][k]["position"]
            est = grid_at(g, [p])[0]
            os.remove(g)
            t = run("lab", "truth", scene, "--at", fmt3(p), "--bands", 5, "--blind-cone", DEAD, "--blind-axis", BLIND_AXIS, *TRUTH)
            tr = np.array([v for c in t["sh_visible"]["coefficients"] for v in c])
            rows.append({"p": p, "num": float(((est - tr) ** 2).sum()), "den": float((tr ** 2).sum())})
        return rows
    rows = cached(os.path.join(sdir, "floor_%d.json" % FLOOR), make)
    per = sorted(math.sqrt(r["num"] / r["den"]) for r in rows)
    return {"probes": len(rows), "rel_l2": math.sqrt(sum(r["num"] for r in rows) / sum(r["den"] for r in rows)),
            "median": per[len(per) // 2], "max": per[-1]}


def scene_run(scene):
    sdir = os.path.join(WORK, scene)
    os.makedirs(sdir, exist_ok=True)
    # The scene's capture volume (every layout spans it): the manifest of a one-probe capture.
    probe_cap = os.path.join(sdir, "volume_probe")
    capture(scene, probe_cap, ["--random", "1"])
    v = json.load(open(os.path.join(probe_cap, "sequence.json")))["volume"]
    lo, hi = v["min"], v["max"]
    seqs = sequences(scene, sdir, lo, hi)
    truth = truth_points(scene, sdir, lo, hi)
    rows = []
    for layout in LAYOUTS:
        for N in COUNTS:
            seq, buckets, info = seqs[(layout, N)]
            for n in GRIDS:
                if n >= 64 and N < MIN64:
                    continue
                key = os.path.join(sdir, "%s_p%d_g%d.json" % (layout, N, n))
                r = cached(key, lambda: measure(seq, buckets, n, truth))
                r.update({"scene": scene, "layout": layout, "count": N, "grid": n, "path": info})
                log(scene, layout, N, "%d³" % n, "kernel %g cv %.3f true %.3f (%.1f s)" % (r["kernel"], r["cv_error"], r["true_error"], r["build_s"]))
                rows.append(r)
    floor = frame_floor(scene, sdir, os.path.join(sdir, "random")) if "random" in LAYOUTS else None
    # What the error volume (`ilf build --error-grid`) shows of each layout: its slice through the
    # middle of the volume, ERRVOL probes at 16³, as `ilf slice` draws it (PLOT's folder).
    errvol = {}
    if ERRVOL in COUNTS:
        for layout in LAYOUTS:
            seq, buckets, _ = seqs[(layout, ERRVOL)]
            png = os.path.join(os.path.dirname(PLOT) or ".", "ilf_density_errvol_%s_%s.png" % (scene.replace("-", "_"), layout))
            def make():
                ev = seq + ".err.shgrid"
                g = seq + ".ev.shgrid"
                run("ilf", "build", seq, "--out", g, "--bands", 5, "--grid", 16, "--buckets", buckets, "--error-grid", ev)
                mid = 0.5 * (lo[1] + hi[1])
                r = run("ilf", "slice", ev, "--plane", "y=%g" % mid, "--size", 128, "--out", png)
                os.remove(g)
                os.remove(ev)
                return {"png": png, "plane": "y=%g" % mid, "mean": r["mean_rel_error"], "max": r["max_rel_error"]}
            key = os.path.join(sdir, "errvol_%s_%d.json" % (layout, ERRVOL))
            if os.path.exists(key) and not os.path.exists(json.load(open(key))["png"]):
                os.remove(key)
            errvol[layout] = cached(key, make)
    caps = {}
    for d in sorted(os.listdir(sdir)):
        f = os.path.join(sdir, d, "capture_time.json")
        if os.path.exists(f) and d != "volume_probe":
            caps[d] = json.load(open(f))
    return {"scene": scene, "volume": [lo, hi], "rows": rows, "capture": caps, "floor": floor, "errvol": errvol}


# ---------------------------------------------------------------------------------------------
def tables(allres):
    out = []
    head = "| scene | layout | probes | " + " | ".join("%d³: true / CV (kernel)" % n for n in GRIDS) + " |"
    out += [head, "| --- | --- | --- | " + " | ".join("---" for _ in GRIDS) + " |"]
    for s in allres:
        by = {(r["layout"], r["count"], r["grid"]): r for r in s["rows"]}
        for layout in LAYOUTS:
            for N in COUNTS:
                cells = []
                for n in GRIDS:
                    r = by.get((layout, N, n))
                    cells.append("—" if r is None else "%.3f / %.3f (%g)" % (r["true_error"], r["cv_error"], r["kernel"]))
                out.append("| %s | %s | %d | %s |" % (s["scene"], layout, N, " | ".join(cells)))
    out.append("")
    # The best grid per layout and count, by the truth and by cross-validation.
    out += ["| scene | layout | probes | best grid by truth (true error) | grid CV picks (its true error) | 20 000-probe-class best for comparison |",
            "| --- | --- | --- | --- | --- | --- |"]
    for s in allres:
        for layout in LAYOUTS:
            top = None
            for N in reversed(COUNTS):
                rr = [r for r in s["rows"] if r["layout"] == layout and r["count"] == N]
                if not rr:
                    continue
                bt = min(rr, key=lambda r: r["true_error"])
                bc = min(rr, key=lambda r: r["cv_error"])
                if top is None:
                    top = bt
                out.append("| %s | %s | %d | %d³ (%.3f) | %d³ (%.3f) | %d³ (%.3f) |" % (
                    s["scene"], layout, N, bt["grid"], bt["true_error"], bc["grid"], bc["true_error"], top["grid"], top["true_error"]))
    out.append("")
    # Where more probes stop helping: per layout and grid, the fewest probes within 5 % of the least
    # true error over all counts, as probes per m³ and per grid cell.
    out += ["| scene | layout | " + " | ".join("%d³: fewest probes within 5 %% of its best (best error) — per m³, per cell" % n for n in GRIDS) + " |",
            "| --- | --- | " + " | ".join("---" for _ in GRIDS) + " |"]
    for s in allres:
        vol = math.prod(s["volume"][1][a] - s["volume"][0][a] for a in range(3))
        for layout in LAYOUTS:
            cells = []
            for n in GRIDS:
                rr = sorted((r for r in s["rows"] if r["layout"] == layout and r["grid"] == n), key=lambda r: r["count"])
                if not rr:
                    cells.append("—")
                    continue
                best = min(r["true_error"] for r in rr)
                first = next(r for r in rr if r["true_error"] <= 1.05 * best)
                cells.append("%d (%.3f) — %.0f, %.2f" % (first["count"], best, first["count"] / vol, first["count"] / (n - 1) ** 3))
            out.append("| %s | %s | %s |" % (s["scene"], layout, " | ".join(cells)))
    out.append("")
    # Coverage: what `ilf build` reports as uncovered (grid point × bucket pairs no ray reached, repaired).
    out += ["| scene | layout | probes | " + " | ".join("%d³ uncovered" % n for n in GRIDS) + " |",
            "| --- | --- | --- | " + " | ".join("---" for _ in GRIDS) + " |"]
    for s in allres:
        by = {(r["layout"], r["count"], r["grid"]): r for r in s["rows"]}
        for layout in LAYOUTS:
            for N in COUNTS:
                out.append("| %s | %s | %d | %s |" % (s["scene"], layout, N, " | ".join(
                    "—" if (layout, N, n) not in by else "%.1f %%" % (100 * by[(layout, N, n)]["uncovered"]) for n in GRIDS)))
    out.append("")
    # Paths: the serpentine's geometry per count.
    out += ["| scene | layout | error volume (%d probes, 16³) on its middle plane: mean / max relative error | picture |" % ERRVOL, "| --- | --- | --- | --- |"]
    for s in allres:
        for layout, e in s.get("errvol", {}).items():
            out.append("| %s | %s | %.3f / %.3f (%s) | %s |" % (s["scene"], layout, e["mean"], e["max"], e["plane"], os.path.basename(e["png"])))
    out.append("")
    out += ["| probes | path: planes × lines per plane | line spacing | probe spacing along a line |", "| --- | --- | --- | --- |"]
    s = allres[0]
    for N in COUNTS:
        rr = [r for r in s["rows"] if r["layout"] == "path" and r["count"] == N]
        if rr:
            i = rr[0]["path"]
            out.append("| %d | %d × %d | %.3f m | %.3f m |" % (N, i["planes"], i["lines_per_plane"], i["line_spacing"], i["probe_spacing"]))
    out.append("")
    out += ["| scene | one frame against the truth at its position: rel. L2 of all / median / worst (probes) | captures: wall s (CPU s) | builds: wall s (CPU s) |",
            "| --- | --- | --- | --- |"]
    for s in allres:
        f = s["floor"]
        cap = ", ".join("%s %.0f (%s)" % (k, v["seconds"], "%.0f" % v["cpu_s"] if "cpu_s" in v else "—") for k, v in s["capture"].items())
        bw = sum(r["build_s"] for r in s["rows"])
        timed = [r for r in s["rows"] if "cpu_s" in r]  # rows cached before CPU time was recorded have none
        bc = "%.0f" % sum(r["cpu_s"] for r in timed) + ("" if len(timed) == len(s["rows"]) else " over %d of %d builds" % (len(timed), len(s["rows"])))
        out.append("| %s | %s | %s | %.0f (%s) |" % (s["scene"], "%.3f / %.3f / %.3f (%d)" % (f["rel_l2"], f["median"], f["max"], f["probes"]) if f else "—",
                                                       cap, bw, bc))
    return "\n".join(out) + "\n"


def plot(allres):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    colours = {"random": "tab:blue", "path": "tab:orange", "clusters": "tab:green"}
    fig, axes = plt.subplots(len(allres), len(GRIDS), figsize=(3.2 * len(GRIDS), 3.0 * len(allres)), sharex=True, sharey=True,
                             squeeze=False)
    for si, s in enumerate(allres):
        for gi, n in enumerate(GRIDS):
            ax = axes[si][gi]
            for layout in LAYOUTS:
                rr = sorted((r for r in s["rows"] if r["layout"] == layout and r["grid"] == n), key=lambda r: r["count"])
                if not rr:
                    continue
                x = [r["count"] for r in rr]
                ax.plot(x, [r["true_error"] for r in rr], "-o", color=colours.get(layout), ms=3, label=layout + " (true)")
                ax.plot(x, [r["cv_error"] for r in rr], "--", color=colours.get(layout), lw=1, label=layout + " (CV)")
            if s.get("floor"):
                ax.axhline(s["floor"]["rel_l2"], ls=":", color="grey", lw=1, label="one frame at its own position")
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.grid(True, which="both", alpha=0.3)
            ax.set_title("%s, %d³" % (s["scene"], n), fontsize=9)
            if si == len(allres) - 1:
                ax.set_xlabel("probes in the 1 m³ volume")
            if gi == 0:
                ax.set_ylabel("rel. L2 of the SH")
    axes[0][-1].legend(fontsize=6, loc="upper left")
    fig.suptitle("ILF grid error against probe count and layout (solid: against the lab's truth; dashed: cross-validated; "
                 "dotted: one %d² frame's own error)" % SIZE, fontsize=9)
    fig.tight_layout()
    fig.savefig(PLOT, dpi=110)


if __name__ == "__main__":
    os.makedirs(WORK, exist_ok=True)
    allres = [scene_run(s) for s in SCENES]
    json.dump(allres, open(os.path.join(WORK, "results.json"), "w"))
    t = tables(allres)
    open(os.path.join(WORK, "density.md"), "w").write(t)
    print(t)
    plot(allres)
    log("plot", PLOT)
