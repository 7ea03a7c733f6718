#!/usr/bin/env python3
"""ILF accuracy against the lab's ground truth (issue 5, "Accuracy"; Löw et al. 2009 Figs. 9 and 11).

Run through bench/ilf_accuracy.sh, which documents the settings. For each scene:
  1. one capture of PROBES_MAX ideal mirror balls (SIZE², SAMPLES² sub-samples, 4.2° dead angle) at
     uniform random positions; a density of N probes is the first N of them (uniform too);
  2. the exact answers: `lab truth` SH (5 bands) at POINTS random grid points of each grid size
     (the same points for every density and repair), both of the whole sphere and without the
     dead-angle cone (`--blind-cone`: what any mirror-ball sequence can see), and the irradiance
     for the plane's normal at the PLANE_N² pixel centres of `ilf slice --plane P --size PLANE_N`
     (low-scene1: z = 0 facing the projector, normal −Z; low-scene2: y = 1 facing up);
  3. the truth's own noise floor: the truth settings against finer ones with another seed;
  4. `ilf build` for every density × grid × repair (buckets shared per density), the grid's SH read
     at the points straight from the .shgrid file, and its slice at the plane;
  5. results.json, table.md, and per scene a picture of the slices beside the truth (slices_SCENE.png)
     and a plot of the errors against resolution per density (errors_SCENE.png).
Everything is cached in WORK: a re-run only does what is missing.
"""
import json, math, os, random, struct, subprocess, sys, time, zlib

BIN, WORK = sys.argv[1], sys.argv[2]
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ilf_common import cached, cli, fmt3, log, rel_l2  # noqa: E402
run = cli(BIN)
env = os.environ.get
SCENES = env("SCENES", "low-scene1 low-scene2").split()
DENSITIES = [int(v) for v in env("DENSITIES", "500 2000 4397").split()]
GRIDS = [int(v) for v in env("GRIDS", "8 16 32 64").split()]
REPAIRS = env("REPAIRS", "mip pullpush none").split()
SIZE, SAMPLES = int(env("SIZE", "48")), int(env("SAMPLES", "2"))
POINTS = int(env("POINTS", "64"))
PLANE_N = int(env("PLANE_N", "20"))
# Irradiance plane per scene: axis, value, normal sign (−: `ilf slice --down`). PLANE ("z=0-") overrides.
PLANES = {"low-scene1": ("z", 0.0, -1), "low-scene2": ("y", 1.0, +1)}


def plane_of(scene):
    v = env("PLANE")
    if v:
        sign = -1 if v.endswith("-") else 1
        a, val = v.rstrip("+-").split("=")
        return (a, float(val), sign)
    return PLANES.get(scene, ("y", 1.0, +1))


def plane_tag(pl):
    return "%s%g%s" % (pl[0], pl[1], "-" if pl[2] < 0 else "+")


def plane_normal(pl):
    n = [0, 0, 0]
    n["xyz".index(pl[0])] = pl[2]
    return ",".join(map(str, n))
FLOOR_POINTS = int(env("FLOOR_POINTS", "6"))
DEAD = 4.2
LOOK = [float(v) for v in env("LOOK", "0,1,0").split(",")]       # the balls' +Z; the dead angle is around −LOOK
BLIND_AXIS = ",".join("%g" % -v for v in LOOK)
TRUTH_SH = ["--size", "128", "--samples", "4", "--area-samples", "64"]        # lab truth's defaults
TRUTH_PLANE = ["--size", "64", "--samples", "2", "--area-samples", "16"]      # irradiance only: cheaper
TRUTH_FINE = ["--size", "256", "--samples", "4", "--area-samples", "64", "--seed", "2"]
PROBES_MAX = max(DENSITIES)


def flat(sh):
    return [v for k in sh for v in k]


def read_shgrid_points(path, idx):
    """Coefficients (K lists of RGB) at grid indices idx [(i, j, k)] straight from the file."""
    with open(path, "rb") as f:
        head = f.read(4096)
        l1 = head.index(b"\n")
        l2 = head.index(b"\n", l1 + 1)
        h = json.loads(head[l1 + 1:l2])
        off = l2 + 1
        assert off % 64 == 0, "shgrid data offset %d is not a multiple of 64" % off
        nx, ny, nz = h["resolution"]
        K = h["bands"] ** 2
        out = []
        for (i, j, k) in idx:
            f.seek(off + (((k * ny + j) * nx + i) * K) * 3 * 4)
            v = struct.unpack("<%df" % (3 * K), f.read(12 * K))
            out.append([list(v[3 * q:3 * q + 3]) for q in range(K)])
        return out


def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        ch = 3 if kind == b"PF" else 1
        data = struct.unpack(("<" if scale < 0 else ">") + "%df" % (w * h * ch), f.read(w * h * ch * 4))
    rows = [[data[(y * w + x) * ch:(y * w + x) * ch + ch] for x in range(w)] for y in range(h)]
    return rows[::-1]  # PFM stores the bottom row first


def write_png(path, w, h, rgb):  # rgb: bytes-like of w*h*3
    raw = b"".join(b"\x00" + bytes(rgb[y * w * 3:(y + 1) * w * 3]) for y in range(h))
    def chunk(t, d):
        c = struct.pack(">I", len(d)) + t + d
        return c + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)
    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b"")
    open(path, "wb").write(png)


def srgb8(v):
    v = max(0.0, min(1.0, v))
    v = 12.92 * v if v <= 0.0031308 else 1.055 * v ** (1 / 2.4) - 0.055
    return int(round(255 * v))


# ---------------------------------------------------------------------------------------------
def plane_points(lo, hi, pl):
    """The pixel centres of `ilf slice` (image x along a1, image y down along a2), row by row."""
    axis = "xyz".index(pl[0])
    a1, a2 = (2 if axis == 0 else 0), (2 if axis == 1 else 1)
    pts = []
    for y in range(PLANE_N):
        for x in range(PLANE_N):
            p = [0.0, 0.0, 0.0]
            p[axis] = pl[1]
            p[a1] = lo[a1] + (hi[a1] - lo[a1]) * (x + 0.5) / PLANE_N
            p[a2] = hi[a2] - (hi[a2] - lo[a2]) * (y + 0.5) / PLANE_N
            pts.append(p)
    return pts


def grid_indices(n):
    rng = random.Random(1000 + n)
    return [(rng.randrange(n), rng.randrange(n), rng.randrange(n)) for _ in range(POINTS)]


def grid_pos(lo, hi, n, ijk):
    return [lo[a] + (hi[a] - lo[a]) * ijk[a] / (n - 1) for a in range(3)]


def scene_run(scene):
    sdir = os.path.join(WORK, scene)
    cap = os.path.join(sdir, "capture")
    os.makedirs(sdir, exist_ok=True)
    if not os.path.exists(os.path.join(cap, "sequence.json")):
        log(scene, "capture", PROBES_MAX)
        t0 = time.time()
        subprocess.check_call([BIN, "--quiet", "lab", "capture", scene, "--random", str(PROBES_MAX), "--mapping", "mirrorball",
                               "--size", str(SIZE), "--samples", str(SAMPLES), "--dead-angle", str(DEAD), "--look", ",".join(map(str, LOOK)), "--half", "--out", cap],
                              stdout=subprocess.DEVNULL)
        json.dump({"seconds": time.time() - t0}, open(os.path.join(sdir, "capture_time.json"), "w"))
    seq = json.load(open(os.path.join(cap, "sequence.json")))
    lo, hi = seq["volume"]["min"], seq["volume"]["max"]
    for N in DENSITIES:
        p = os.path.join(cap, "sequence_%d.json" % N)
        if not os.path.exists(p):
            s = dict(seq)
            s["probes"] = seq["probes"][:N]
            json.dump(s, open(p, "w"), indent=1)

    # Exact SH at the grid points of each grid (whole sphere and without the dead-angle cone). The
    # points of a grid are a prefix-stable random sequence: raising POINTS only adds truth evaluations.
    truth = {}
    for n in GRIDS:
        path = os.path.join(sdir, "truth_sh_%d.json" % n)
        rows = json.load(open(path)) if os.path.exists(path) else []
        want = grid_indices(n)
        if len(rows) < POINTS:
            for ijk in want[len(rows):]:
                p = grid_pos(lo, hi, n, ijk)
                t = run("lab", "truth", scene, "--at", fmt3(p), "--bands", 5, "--normal", "0,1,0", "--blind-cone", DEAD, "--blind-axis", BLIND_AXIS, *TRUTH_SH)
                rows.append({"ijk": list(ijk), "p": p, "sh": t["sh"]["coefficients"], "sh_visible": t["sh_visible"]["coefficients"],
                             "E": t["irradiance"][0]["irradiance"]})
            json.dump(rows, open(path + ".tmp", "w"))
            os.replace(path + ".tmp", path)
            log(scene, "SH truth", n, len(rows), "points")
        truth[str(n)] = rows[:POINTS]

    def plane_truth():
        rows = []
        for p in plane_points(lo, hi, pl):
            rows.append(run("lab", "truth", scene, "--at", fmt3(p), "--bands", 0, "--normal", plane_normal(pl), *TRUTH_PLANE)["irradiance"][0]["irradiance"])
        log(scene, "plane truth")
        return rows
    pl = plane_of(scene)
    ptruth = cached(os.path.join(sdir, "truth_plane_%s.json" % plane_tag(pl)), plane_truth)

    # The truth's noise floor: the settings above against finer maps, more sub-samples, another seed.
    def floor():
        sh_pairs, vis_pairs, e_pairs = [], [], []
        for r in truth[str(GRIDS[len(GRIDS) // 2])][:FLOOR_POINTS]:
            t = run("lab", "truth", scene, "--at", fmt3(r["p"]), "--bands", 5, "--normal", "0,1,0", "--blind-cone", DEAD, "--blind-axis", BLIND_AXIS, *TRUTH_FINE)
            sh_pairs += zip(flat(r["sh"]), flat(t["sh"]["coefficients"]))
            vis_pairs += zip(flat(r["sh_visible"]), flat(t["sh_visible"]["coefficients"]))
        pts = plane_points(lo, hi, pl)
        step = max(1, len(pts) // FLOOR_POINTS)
        for i in range(0, len(pts), step)[:FLOOR_POINTS]:
            t = run("lab", "truth", scene, "--at", fmt3(pts[i]), "--bands", 0, "--normal", plane_normal(pl), *TRUTH_FINE)
            e_pairs += zip(ptruth[i], t["irradiance"][0]["irradiance"])
        log(scene, "truth floor")
        return {"sh": rel_l2(sh_pairs), "sh_visible": rel_l2(vis_pairs), "plane_irradiance": rel_l2(e_pairs), "points": FLOOR_POINTS}
    tfloor = cached(os.path.join(sdir, "truth_floor_%s.json" % plane_tag(pl)), floor)

    results = []
    for N in DENSITIES:
        for n in GRIDS:
            for rep in REPAIRS:
                key = "p%d_g%d_%s" % (N, n, rep)
                def measure():
                    g = os.path.join(sdir, key + ".shgrid")
                    b = run("ilf", "build", os.path.join(cap, "sequence_%d.json" % N), "--grid", n, "--repair", rep, "--out", g,
                            "--buckets", os.path.join(sdir, "buckets_%d" % N))
                    rows = truth[str(n)]
                    got = read_shgrid_points(g, [tuple(r["ijk"]) for r in rows])
                    per = sorted(rel_l2(zip(flat(c), flat(r["sh_visible"]))) for c, r in zip(got, rows))
                    pfm = os.path.join(sdir, key + "_slice.pfm")
                    run("ilf", "slice", g, "--plane", "%s=%g" % pl[:2], "--size", PLANE_N, "--out", pfm, *(["--down"] if pl[2] < 0 else []))
                    img = read_pfm(pfm)
                    plane = [list(img[y][x]) for y in range(PLANE_N) for x in range(PLANE_N)]
                    if os.environ.get("KEEP_GRIDS") != "1":
                        os.remove(g)
                    os.remove(pfm)
                    return {"probes": N, "grid": n, "repair": rep, "points": POINTS, "plane_tag": plane_tag(pl),
                            "sh": rel_l2((a, b) for c, r in zip(got, rows) for a, b in zip(flat(c), flat(r["sh"]))),
                            "sh_visible": rel_l2((a, b) for c, r in zip(got, rows) for a, b in zip(flat(c), flat(r["sh_visible"]))),
                            "sh_visible_median": per[len(per) // 2], "sh_visible_max": per[-1],
                            "plane_irradiance": rel_l2((a, b) for e, t in zip(plane, ptruth) for a, b in zip(e, t)),
                            "uncovered": b["fraction_uncovered"], "build_s": b["seconds"]["total"], "plane": plane}
                path = os.path.join(sdir, key + ".json")
                if os.path.exists(path) and (json.load(open(path)).get("points"), json.load(open(path)).get("plane_tag")) != (POINTS, plane_tag(pl)):
                    os.remove(path)  # measured at another number of points
                res = cached(path, measure)
                log(scene, key, "SH %.3f vis %.3f E %.3f" % (res["sh"], res["sh_visible"], res["plane_irradiance"]))
                results.append(res)
    pictures(scene, sdir, ptruth, results)
    return {"scene": scene, "plane": plane_tag(pl), "floor": tfloor, "results": results,
            "capture_s": json.load(open(os.path.join(sdir, "capture_time.json")))["seconds"]
            if os.path.exists(os.path.join(sdir, "capture_time.json")) else None}


# ---------------------------------------------------------------------------------------------
# Pictures. Slices: rows = densities, columns = truth, then the grids (repair PICTURE_REPAIR), each
# PLANE_N² irradiance values shown as ZOOM×ZOOM blocks, one exposure per scene (the truth's 98th
# percentile luminance maps to 0.9 before sRGB encoding), 4-pixel white gutters.
ZOOM, GUT = 8, 4


def pictures(scene, sdir, ptruth, results):
    rep = os.environ.get("PICTURE_REPAIR", REPAIRS[0])
    lum = sorted(0.2125 * e[0] + 0.7154 * e[1] + 0.0721 * e[2] for e in ptruth)
    scale = 0.9 / max(lum[int(0.98 * (len(lum) - 1))], 1e-9)
    tile = PLANE_N * ZOOM
    cols, rows = 1 + len(GRIDS), len(DENSITIES)
    W, H = cols * tile + (cols + 1) * GUT, rows * tile + (rows + 1) * GUT
    buf = bytearray([255]) * (W * H * 3)

    def put(ci, ri, vals):
        x0, y0 = GUT + ci * (tile + GUT), GUT + ri * (tile + GUT)
        for py in range(PLANE_N):
            for px in range(PLANE_N):
                c = bytes(srgb8(v * scale) for v in vals[py * PLANE_N + px])
                for yy in range(ZOOM):
                    o = ((y0 + py * ZOOM + yy) * W + x0 + px * ZOOM) * 3
                    buf[o:o + 3 * ZOOM] = c * ZOOM

    by = {(r["probes"], r["grid"], r["repair"]): r for r in results}
    for ri, N in enumerate(DENSITIES):
        put(0, ri, ptruth)
        for ci, n in enumerate(GRIDS):
            put(ci + 1, ri, by[(N, n, rep)]["plane"])
    write_png(os.path.join(WORK, "slices_%s.png" % scene), W, H, buf)

    # Error plot: x = log2(grid resolution), y = relative error 0..YMAX; per density one colour;
    # solid = SH error (visible truth) of repair `rep`, dotted = plane irradiance error.
    PW, PH, M = 480, 320, 30
    ymax = float(os.environ.get("PLOT_YMAX", "0.6"))
    img = bytearray([255]) * (PW * PH * 3)
    def px(x, y, c):
        if 0 <= x < PW and 0 <= y < PH:
            o = (y * PW + x) * 3
            img[o:o + 3] = bytes(c)
    def X(n):
        return int(M + (PW - 2 * M) * (math.log2(n) - math.log2(GRIDS[0])) / max(1e-9, math.log2(GRIDS[-1]) - math.log2(GRIDS[0])))
    def Y(v):
        return int(PH - M - (PH - 2 * M) * min(v, ymax) / ymax)
    for k in range(0, 7):  # horizontal lines every ymax/6
        for x in range(M, PW - M):
            px(x, Y(ymax * k / 6), (220, 220, 220) if k else (0, 0, 0))
    for n in GRIDS:
        for y in range(M, PH - M):
            px(X(n), y, (220, 220, 220))
    for y in range(M, PH - M):
        px(M, y, (0, 0, 0))
    colours = [(230, 90, 20), (30, 110, 220), (20, 160, 60), (150, 40, 170)]
    def line(p0, p1, c, dotted):
        steps = max(abs(p1[0] - p0[0]), abs(p1[1] - p0[1]), 1)
        for s in range(steps + 1):
            if dotted and (s // 4) % 2:
                continue
            x = round(p0[0] + (p1[0] - p0[0]) * s / steps)
            y = round(p0[1] + (p1[1] - p0[1]) * s / steps)
            for dx in (0, 1):
                for dy in (0, 1):
                    px(x + dx, y + dy, c)
    for di, N in enumerate(DENSITIES):
        c = colours[di % len(colours)]
        for field, dotted in (("sh_visible", False), ("plane_irradiance", True)):
            pts = [(X(n), Y(by[(N, n, rep)][field])) for n in GRIDS]
            for a, b in zip(pts, pts[1:]):
                line(a, b, c, dotted)
            for (x, y) in pts:
                for dx in range(-3, 4):
                    for dy in range(-3, 4):
                        px(x + dx, y + dy, c)
    write_png(os.path.join(WORK, "errors_%s.png" % scene), PW, PH, img)


def table(allres):
    """One row per scene × density × grid; the repairs side by side (they coincide where nothing is uncovered)."""
    reps = REPAIRS
    out = ["| scene (plane) | probes | grid | uncovered | rel. L2 SH, visible sphere (%s) | median / worst point (%s) "
           "| rel. L2 irradiance on the plane (%s) | build s (%s) |" % (" / ".join(reps), reps[0], " / ".join(reps), reps[0]),
           "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for s in allres:
        by = {(r["probes"], r["grid"], r["repair"]): r for r in s["results"]}
        for N in DENSITIES:
            for n in GRIDS:
                rr = [by[(N, n, rep)] for rep in reps]
                def cells(field):
                    vals = [r[field] for r in rr]
                    best = min(vals)
                    return " / ".join(("**%.3f**" if v == best and len(set("%.3f" % x for x in vals)) > 1 else "%.3f") % v for v in vals)
                out.append("| %s (%s) | %d | %d³ | %.2f%% | %s | %.3f / %.2f | %s | %.1f |" % (
                    s["scene"], s["plane"], N, n, 100 * rr[0]["uncovered"], cells("sh_visible"), rr[0]["sh_visible_median"],
                    rr[0]["sh_visible_max"], cells("plane_irradiance"), rr[0]["build_s"]))
    out.append("")
    out.append("| scene | SH whole sphere = visible? (max difference over all rows) | truth floor: SH (%s vs %s) | plane irradiance (%s vs %s) | capture s |" % (
        " ".join(TRUTH_SH), " ".join(TRUTH_FINE), " ".join(TRUTH_PLANE), " ".join(TRUTH_FINE)))
    out.append("| --- | --- | --- | --- | --- |")
    for s in allres:
        f = s["floor"]
        dmax = max(abs(r["sh"] - r["sh_visible"]) for r in s["results"])
        out.append("| %s | %.4f | %.4f (%d points) | %.4f | %s |" % (s["scene"], dmax, f["sh_visible"], f["points"], f["plane_irradiance"],
                                                               "%.0f" % s["capture_s"] if s["capture_s"] else "—"))
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    os.makedirs(WORK, exist_ok=True)
    allres = [scene_run(s) for s in SCENES]
    json.dump(allres, open(os.path.join(WORK, "results.json"), "w"))
    t = table(allres)
    open(os.path.join(WORK, "table.md"), "w").write(t)
    print(t)
