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
    # Python call's mean over a batch, run one after the other; min and median over the rounds.
    py = {"BM_PyRef_ShProject": [], "BM_PyRef_MedianCut64": [], "BM_PyRef_IlfBuild": []}
    cpp = {k: [] for k in py}
    batch = {"BM_PyRef_ShProject": (lambda: iblkit.sh_project(img, 3), 400),
             "BM_PyRef_MedianCut64": (lambda: iblkit.lights(img, "median-cut", 64), 50),
             "BM_PyRef_IlfBuild": (lambda: ilf.build(seq, grid=16, bands=5, work_dir=buckets), 3)}
    for _ in range(ROUNDS):
        for k, v in cpp_times(env).items():
            cpp[k].append(v)
        for k, (fn, reps) in batch.items():
            py[k].append(statistics.fmean(timed(fn, reps)))

    # Two threads projecting at once vs one, each call on one thread (set_threads(1)). The wall-time
    # ratio needs two free cores; on a shared machine it shows the cores' share, so the overlap of the
    # two calls is measured too: with the GIL held they could not overlap at all.
    iblkit.set_threads(1)
    one = timed(lambda: iblkit.sh_project(img, 5), 40)
    spans = []

    def call():
        t0 = time.perf_counter()
        iblkit.sh_project(img, 5)
        spans.append((t0, time.perf_counter()))

    two, overlap = [], []
    for _ in range(40):
        spans.clear()
        ts = [threading.Thread(target=call) for _ in range(2)]
        t0 = time.perf_counter()
        for t in ts:
            t.start()
        for t in ts:
            t.join()
        two.append(time.perf_counter() - t0)
        (a0, a1), (b0, b1) = spans
        overlap.append(max(0.0, min(a1, b1) - max(a0, b0)) / min(a1 - a0, b1 - b0))
    iblkit.set_threads(0)
    load = os.getloadavg()[0]
    print(f"| 2026-12-01 | 2-core VM (this sandbox), load {load:.1f} | two Python threads each projecting 1024×512 to 5 bands at once "
          f"vs one (set_threads(1): one core per call) | two: {min(two) * 1e3:.2f} ms min · {statistics.median(two) * 1e3:.2f} ms median; "
          f"the two calls overlap {100 * statistics.median(overlap):.0f} % of the shorter (median) | one: {min(one) * 1e3:.2f} ms min · "
          f"{statistics.median(one) * 1e3:.2f} ms median; GIL held: ≥ 2× and 0 % overlap | "
          f"{min(two) / min(one):.2f}× (min) · {statistics.median(two) / statistics.median(one):.2f}× (median) |")
    subprocess.run(["rm", "-rf", work])


if __name__ == "__main__":
    main()
