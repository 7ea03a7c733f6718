"""Helpers the ILF measurement scripts share (bench/ilf_accuracy.py, bench/ilf_cv.py)."""
import json, math, os, subprocess, sys, time


def cli(binary):
    """run(*args): the iblkit binary's --json answer to one command."""
    def run(*args):
        return json.loads(subprocess.check_output([binary, "--quiet", "--json", *map(str, args)]))
    return run


def log(*a):
    print(time.strftime("%H:%M:%S"), *a, file=sys.stderr, flush=True)


def cached(path, make):
    """make()'s JSON value, kept in path (written atomically) for the next run."""
    if os.path.exists(path):
        return json.load(open(path))
    v = make()
    json.dump(v, open(path + ".tmp", "w"))
    os.replace(path + ".tmp", path)
    return v


def fmt3(p):
    return ",".join("%.9g" % v for v in p)


def rel_l2(pairs):
    """√(Σ (a − b)² / Σ b²) over (estimate, truth) pairs; NaN where the truth is zero."""
    num = den = 0.0
    for a, b in pairs:
        num += (a - b) ** 2
        den += b * b
    return math.sqrt(num / den) if den > 0 else float("nan")
