#!/usr/bin/python3
"""HDR merge against exact truth, iblkit beside OpenCV and pfstools on the same brackets (issue 29 §1).

A radiance image (blender-data forest.exr, 1024x512) is photographed through iblkit's sensor model
(`iblkit hdr bracket`: camera-like response with toe and shoulder, shot noise 30000 e-, read noise
3e-4 of full scale, 5 exposures 2 EV apart, 8-bit JPEG q95, Exif exposure times). Each tool then merges
the JPEGs recovering the response itself:
  iblkit:   iblkit hdr merge (Debevec & Malik, iblkit's sampling and smoothness)
  OpenCV:   cv2.createCalibrateDebevec().process + cv2.createMergeDebevec().process (python3-opencv)
  pfstools: pfsinhdrgen | pfshdrcalibrate (its default, Robertson) | pfsoutexr
Error: median relative error over pixels and channels well exposed (true exposure in [0.05, 0.95]) in at
least one frame, after the one global scale a bracket cannot observe (geometric mean of truth/merged over
those pixels), the same for every tool. Time: wall clock of the whole command (reading, recovery, merge,
writing), best of 3. Usage: /usr/bin/python3 bench/hdr_merge_vs_peers.py BUILD/iblkit [--out DIR] (Debian python3-opencv, numpy)
"""
import argparse, os, shutil, subprocess, sys, tempfile, time

import numpy as np

os.environ.setdefault("OPENCV_IO_ENABLE_OPENEXR", "1")
import cv2  # noqa: E402

PROBE = "/usr/share/blender/datafiles/studiolights/world/forest.exr"
TIMES = ["1/64", "1/16", "1/4", "1", "4"]


def read_exr(path):
    img = cv2.imread(path, cv2.IMREAD_ANYCOLOR | cv2.IMREAD_ANYDEPTH | cv2.IMREAD_UNCHANGED)
    if img is None:
        sys.exit(f"cannot read {path}")
    return img[:, :, :3][:, :, ::-1].astype(np.float64)  # BGR -> RGB


def timed(cmd, reps=3, **kw):
    best = 1e9
    for _ in range(reps):
        t = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, **kw)
        best = min(best, time.perf_counter() - t)
    return best


def error(merged, truth, mask):
    # The scale: the median of truth / merged (robust: a raw mosaic's demosaiced noise floor reads 0 in places,
    # where a geometric mean would be dominated by the zeros).
    r = truth[mask] / np.maximum(merged[mask], 1e-30)
    s = float(np.median(r))
    return float(np.median(np.abs(s * merged[mask] / truth[mask] - 1))), float(s)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("iblkit")
    ap.add_argument("--out", default=None)
    ap.add_argument("--linear-raw", action="store_true", help="with --format dng: LinearRaw DNGs (no mosaic)")
    ap.add_argument("--format", default="jpg", choices=["jpg", "png", "dng"],
                    help="jpg: q95; png: lossless 8-bit; dng: 14-bit raw mosaics (iblkit only: OpenCV's calibration "
                    "takes 8-bit images and neither peer reads DNG)")
    a = ap.parse_args()
    d = a.out or tempfile.mkdtemp(prefix="hdrbench-")
    os.makedirs(d, exist_ok=True)
    subprocess.run([a.iblkit, "hdr", "bracket", PROBE, "-o", f"{d}/b", "--response", "camera", "--full-well",
                    "30000", "--read-noise", "3e-4", "--quality", "95", "--format", a.format,
                    "--exposures", ",".join(TIMES)] + (["--linear-raw"] if a.linear_raw else []),
                   check=True, stdout=subprocess.DEVNULL)
    files = [f"{d}/b-{j}.{a.format}" for j in range(len(TIMES))]
    secs = [eval(t) for t in TIMES]  # noqa: S307 (our own constants)
    truth = read_exr(PROBE)
    X = np.stack([truth * t for t in secs])
    mask = np.any((X >= 0.05) & (X <= 0.95), axis=0) & (truth > 0)
    rows = []
    # iblkit
    t = timed([a.iblkit, "-q", "hdr", "merge", *files, "--out", f"{d}/iblkit.exr", "--float", "--exposures",
               ",".join(TIMES)])
    rows.append((f"iblkit hdr merge ({'linear raw' if a.format == 'dng' else 'Debevec'})",
                 *error(read_exr(f"{d}/iblkit.exr"), truth, mask), t))
    if a.format == "dng":
        report(rows, files, a.format, mask)
        return
    # OpenCV
    ocv = f"""
import os, sys, cv2, numpy as np
os.environ["OPENCV_IO_ENABLE_OPENEXR"] = "1"
files = {files!r}; secs = np.array({secs!r}, dtype=np.float32)
imgs = [cv2.imread(f) for f in files]
resp = cv2.createCalibrateDebevec().process(imgs, secs)
hdr = cv2.createMergeDebevec().process(imgs, secs, resp)
np.save("{d}/opencv.npy", hdr[:, :, ::-1])
"""
    t = timed([sys.executable, "-c", ocv], env=dict(os.environ, OPENCV_IO_ENABLE_OPENEXR="1"))
    rows.append(("OpenCV CalibrateDebevec+MergeDebevec", *error(np.load(f"{d}/opencv.npy").astype(np.float64),
                                                                truth, mask), t))
    # pfstools
    if shutil.which("pfsinhdrgen") and shutil.which("pfshdrcalibrate"):
        with open(f"{d}/bracket.hdrgen", "w") as f:
            for fn, s in zip(files, secs):
                f.write(f"{fn} {1.0 / s:g} 1 100 0\n")
        cmd = f"pfsinhdrgen {d}/bracket.hdrgen | pfshdrcalibrate | pfsoutexr {d}/pfs.exr"
        t = timed(["sh", "-c", cmd])
        rows.append(("pfstools pfshdrcalibrate (Robertson)", *error(read_exr(f"{d}/pfs.exr"), truth, mask), t))
    else:
        print("SKIP pfstools: pfsinhdrgen/pfshdrcalibrate missing")
    report(rows, files, a.format, mask)


def report(rows, files, fmt, mask):
    kind = {"jpg": "JPEG q95", "png": "PNG", "dng": "DNG (14-bit raw)"}[fmt]
    print(f"bracket: {len(files)} {kind} 1024x512, 2 EV apart; {int(mask.sum())} well-exposed channel values")
    print(f"{'tool':40s} {'median rel. error':>18s} {'scale':>8s} {'time s':>8s}")
    for name, e, s, t in rows:
        print(f"{name:40s} {100 * e:17.2f}% {s:8.4f} {t:8.3f}")


if __name__ == "__main__":
    main()
