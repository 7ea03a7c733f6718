#!/usr/bin/env python3
"""The cost model of the distributed ILF build (docs/ilf.md "Cost model"), calibrated on this machine's
measurements (bench/ilf_mpi.sh: the serial build and mpirun -np N at the paper's scale; bench/
ilf_mpi_building.py: the building capture's serial build), checked against the measured runs, and
its weak/strong-scaling prediction for 1e5 and 1e6 probes of 250² on 16, 64 and 256 ranks.

Per rank, with P probes, S samples per frame, N ranks, G grid points, B buckets, K coefficients:
  read      P·S/N / rho_read                      (decode + scatter, per core)
  exchange  6·P·S/N·(N-1)/N / beta + 6·P·S/N / disk   (all-to-all; the received samples to scratch)
  project   (a·P·S + b·G·B)/N                     (splats per ray, bilinear reads per grid point and bucket)
  SH        6·G·B·K/N / F                         (float GEMM, per core)
  reduce    24·G·K·ceil(log2 N) / beta_r          (binomial tree of double partial sums)
  write     12·G·K / disk                         (rank 0)
Calibration: rho_read, F and the exchange's shared-memory beta from the 2-rank run (one core per rank);
a and b from the two serial builds (paper scale: projection dominated by grid reads; building scale:
by splats), per core = measured seconds × cores in use.

Usage: bench/ilf_mpi_model.py P4397_DIR BUILDING_RESULTS_JSON
"""
import json, math, sys

d, bres = sys.argv[1], sys.argv[2]
CORES = 2
serial = json.load(open(d + "/serial.json"))
runs = {}
for n in (2, 3, 4):
    try:
        runs[n] = json.load(open(d + "/mpi_%d.json" % n))
    except FileNotFoundError:
        pass
b = json.load(open(bres))["serial"]["report"]

P, S, B = serial["probes_used"], serial["samples"] / serial["probes_used"], serial["buckets"]
G, K = 64 ** 3, 25
Pb, Sb, Bb = b["probes_used"], b["samples"] / b["probes_used"], b["buckets"]
Gb = 77 * 5 * 37
# a, b: serial projection seconds × cores = a·P·S + b·G·B (two builds, two unknowns).
tp, tpb = serial["seconds"]["project"] * CORES, b["seconds"]["project"] * CORES
det = (P * S) * (Gb * Bb) - (Pb * Sb) * (G * B)
a = (tp * Gb * Bb - tpb * G * B) / det
bb = ((P * S) * tpb - (Pb * Sb) * tp) / det
m2 = runs[2]["mpi"]["seconds"]
rho_read = (P * S / 2) / m2["read"]
F = 6 * G * B * K / 2 / m2["accumulate"]
beta_shm = (6 * P * S / 2 * 0.5) / max(m2["exchange"], 1e-9)
print("calibration: rho_read %.3g samples/s/core, a %.3g s/ray, b %.3g s/(point·bucket), F %.3g flop/s/core, shared-memory exchange %.3g B/s" %
      (rho_read, a, bb, F, beta_shm))


def model(P, S, B, G, K, N, cores_per_rank, beta, beta_r, disk, alpha=5e-6, chunk=912):
    c = cores_per_rank
    t = {}
    t["read"] = P * S / N / (rho_read * c)
    rounds = math.ceil(P / N / chunk)
    t["exchange"] = (6 * P * S / N * (N - 1) / N / beta + rounds * N * alpha + 6 * P * S / N / disk) if N > 1 else 6 * P * S / disk
    t["project"] = (a * P * S + bb * G * B) / N / c
    t["sh"] = 6 * G * B * K / N / (F * c)
    t["reduce"] = 24 * G * K * math.ceil(math.log2(N)) / beta_r if N > 1 else 0.0
    t["write"] = 12 * G * K / disk
    t["total"] = sum(t.values())
    return t

print()
print("| ranks (here: 2 cores) | phase | model | measured |")
print("| --- | --- | --- | --- |")
for n, r in sorted(runs.items()):
    m = model(P, S, B, G, K, n, CORES / n, beta_shm, beta_shm, 1e9)
    t = r["mpi"]["seconds"]
    for ph, key in [("read", "read"), ("exchange", "exchange"), ("project", "project"), ("sh", "accumulate"), ("reduce", "reduce")]:
        print("| %d | %s | %.1f s | %.1f s |" % (n, ph, m[ph], t[key]))
    print("| %d | total | %.0f s | %.0f s |" % (n, m["total"], r["seconds"]["total"]))

print()
print("Predictions (one core per rank, all-to-all 1 GB/s per rank, reduce 5 GB/s, scratch 1 GB/s, 250² balls, 64³, 25 coefficients):")
print("| probes | ranks | read | exchange | project | SH | reduce | total | sent per rank | scratch per rank |")
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
for PP in (1e5, 1e6):
    for N in (16, 64, 256):
        m = model(PP, S, B, G, K, N, 1, 1e9, 5e9, 1e9)
        print("| %.0e | %d | %.0f s | %.0f s | %.0f s | %.0f s | %.2f s | %.0f s (%.1f h) | %.2g GB | %.2g GB |" % (
            PP, N, m["read"], m["exchange"], m["project"], m["sh"], m["reduce"], m["total"], m["total"] / 3600,
            6 * PP * S / N * (N - 1) / N / 1e9, 6 * PP * S / N / 1e9))
