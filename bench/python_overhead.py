#!/usr/bin/env python3
"""Python overhead over the C++ call (issue 17): the module's call against bench/python_bench.cpp's
(iblkit_bench --benchmark_filter=BM_PyRef), same inputs, alternating rounds, min and median of each;
and two threads projecting at once against one (the GIL is released).

usage: PYTHONPATH=BUILD/python python3 bench/python_overhead.py BUILD [ROUNDS]
Prints the rows for bench/RESULTS.md. Needs blender-data (forest.exr)."""
import json
import os
import statistics
import subprocess
import sys
import tempfile
import threading
import time

import numpy

import iblkit
from iblkit import ilf

BUILD = sys.argv[1] if len(sys.argv) > 1 else "build"
ROUNDS = int(sys.argv[2]) if len(sys.argv) > 2 else 5
FOREST = "/usr/share/blender/datafiles/studiolights/world/forest.exr"


def timed(fn, reps):
    out = []
    for _ in range(reps):
        t0 = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t0)
    return out


def cpp_times(env):
    r = subprocess.run([os.path.join(BUILD, "iblkit_bench"), "--benchmark_filter=BM_PyRef", "--benchmark_format=json",
                        "--benchmark_min_time=0.5"], capture_output=True, text=True, env=env, check=True)
    return {b["name"].split("/")[0]: b["real_time"] / 1e3 for b in json.loads(r.stdout)["benchmarks"]}  # ms -> s


def main():
    work = tempfile.mkdtemp(prefix="iblkit-pybench-")
    seq = os.path.join(work, "seq")
    subprocess.run([os.path.join(BUILD, "iblkit"), "--quiet", "ilf", "synth", "--out", seq, "--probes", "200", "--size", "64"], check=True)
    seq = os.path.join(seq, "sequence.json")
    buckets = os.path.join(work, "buckets")
    env = dict(os.environ, IBLKIT_PYBENCH_SEQ=seq, IBLKIT_PYBENCH_BUCKETS=buckets)
    img = iblkit.read_image(FOREST)
    assert img.shape == (512, 1024, 3)
    ilf.build(seq, grid=16, bands=5, work_dir=buckets)  # sorts the buckets once; every later build reuses them

    # Per round: the C++ benchmark's mean time per call (Google Benchmark, ≥ 0.5 s of calls) and the
    # Python call's mean over a batch, run one after the other (which first alternates by round); min
    # and median over the rounds.
    py = {"BM_PyRef_ShProject": [], "BM_PyRef_MedianCut64": [], "BM_PyRef_IlfBuild": []}
    cpp = {k: [] for k in py}
    batch = {"BM_PyRef_ShProject": (lambda: iblkit.sh_project(img, 3), 400),
             "BM_PyRef_MedianCut64": (lambda: iblkit.lights(img, "median-cut", 64), 50),
             "BM_PyRef_IlfBuild": (lambda: ilf.build(seq, grid=16, bands=5, work_dir=buckets), 3)}
    def cpp_round():
        for k, v in cpp_times(env).items():
            cpp[k].append(v)

    def py_round():
        for k, (fn, reps) in batch.items():
            py[k].append(statistics.fmean(timed(fn, reps)))

    for r in range(ROUNDS):  # the order alternates, so that neither side always runs first
        for step in ((cpp_round, py_round) if r % 2 == 0 else (py_round, cpp_round)):
            step()

    load = os.getloadavg()[0]
    what = {"BM_PyRef_ShProject": ("`sh_project(img, 3)`, 1024×512 forest.exr (float32 array read in place)",
                                   "`sh::project(env, 3)`"),
            "BM_PyRef_MedianCut64": ("`lights(img, \"median-cut\", 64)`, 1024×512 forest.exr (array from `read_image`, lent without a copy)",
                                     "`lights::extract`, median-cut 64"),
            "BM_PyRef_IlfBuild": ("`ilf.build(path, grid=16, bands=5)`: 200 mirror balls of 64² (`iblkit ilf synth`) → 16³ × 25 coefficients, buckets reused",
                                  "`read_sequence` + `build_shgrid`")}
    for k, (pyw, cw) in what.items():
        pm, cm = statistics.median(py[k]), statistics.median(cpp[k])
        print(f"| {time.strftime('%Y-%m-%d')} | 2-core VM (this sandbox), load {load:.1f} | {pyw} | {min(py[k]) * 1e3:.3f} ms min · "
              f"{pm * 1e3:.3f} ms median | {cw}: {min(cpp[k]) * 1e3:.3f} · {cm * 1e3:.3f} ms | {100 * (pm / cm - 1):+.1f} % (median) |")

    # The binding's fixed cost per call, bounded from above: the whole call on a 16×8 image (argument
    # conversion, the GIL's release and re-acquisition, the result's wrapping, and the library's work on
    # 128 pixels), against the paper-scale call's time.
    tiny = numpy.ones((8, 16, 3), numpy.float32)
    for name, fn, ref in (("sh_project(tiny, 3)", lambda: iblkit.sh_project(tiny, 3), "BM_PyRef_ShProject"),
                          ("lights(tiny, \"median-cut\", 4)", lambda: iblkit.lights(tiny, "median-cut", 4), "BM_PyRef_MedianCut64")):
        per = min(statistics.fmean(timed(fn, 5000)) for _ in range(3))
        print(f"| {time.strftime('%Y-%m-%d')} | 2-core VM (this sandbox) | whole call `{name}` on a 16×8 image: an upper bound of the "
              f"binding's fixed cost per call | {per * 1e6:.1f} µs (min of 3 means of 5000) | paper-scale call, C++ median "
              f"{statistics.median(cpp[ref]) * 1e3:.3f} ms | ≤ {100 * per / statistics.median(cpp[ref]):.2f} % |")

    # Two threads projecting at once vs one, each call on one thread (set_threads(1)). Each thread runs a
    # batch of calls, so that the thread start and the GIL hand-over (Python's switch interval is 5 ms,
    # longer than one call) are amortised; with the GIL held the two batches take ≥ 2× one batch.
    iblkit.set_threads(1)
    calls = 25

    def batch_of_calls():
        for _ in range(calls):
            iblkit.sh_project(img, 5)

    one, two = [], []
    for _ in range(9):
        t0 = time.perf_counter()
        batch_of_calls()
        one.append(time.perf_counter() - t0)
        ts = [threading.Thread(target=batch_of_calls) for _ in range(2)]
        t0 = time.perf_counter()
        for t in ts:
            t.start()
        for t in ts:
            t.join()
        two.append(time.perf_counter() - t0)
    iblkit.set_threads(0)
    load = os.getloadavg()[0]
    print(f"| {time.strftime('%Y-%m-%d')} | 2-core VM (this sandbox), load {load:.1f} | two Python threads, each projecting 1024×512 to 5 bands "
          f"{calls} times, at once vs one thread's {calls} (set_threads(1): one core per call) | two: {min(two) * 1e3:.1f} ms min · "
          f"{statistics.median(two) * 1e3:.1f} ms median | one: {min(one) * 1e3:.1f} ms min · {statistics.median(one) * 1e3:.1f} ms median "
          f"(GIL held: ≥ 2×) | {min(two) / min(one):.2f}× (min) · {statistics.median(two) / statistics.median(one):.2f}× (median) |")
    subprocess.run(["rm", "-rf", work])


if __name__ == "__main__":
    main()
