#!/usr/bin/env bash
# Strong scaling of the distributed ILF build (issue 18) at the paper's scale (Löw et al. 2009, scene 1:
# 4397 mirror balls of 250² → 64³, 25 coefficients; the input of bench/ilf_e2e.sh): the serial build,
# then `mpirun -np N` for each N of RANKS (oversubscribed beyond the cores), each from an empty bucket
# folder, with /usr/bin/time for the job's peak memory, and every grid compared with the serial one
# coefficient by coefficient. Writes WORKDIR/pPROBES/mpi_N.json (the build's --json report, with the
# per-phase times under "mpi") and prints one table row per run.
#   bench/ilf_mpi.sh [IBLKIT] [WORKDIR]      environment: PROBES (4397), GRID (64), RANKS ("1 2 3 4")
# Both builds use the fixed kernel 3 without cross-validation (--kernel 3 --cv-folds 0): under MPI the
# default kernel auto falls back to 3, and the serial default would add the cross-validation's passes.
set -euo pipefail
BIN=${1:-build/iblkit}
WORK=${2:-/tmp/iblkit_ilf_e2e}
PROBES=${PROBES:-4397}
GRID=${GRID:-64}
RANKS=${RANKS:-1 2 3 4}
D="$WORK/p$PROBES"
mkdir -p "$WORK"
if [ ! -f "$D/sequence.json" ]; then
  echo "synthesising $PROBES probes of 250x250 into $D …" >&2
  "$BIN" ilf synth --out "$D" --probes "$PROBES" --size 250 --supersample 1 --quiet
fi
MPIRUN=(mpirun --oversubscribe)
[ "$(id -u)" = 0 ] && MPIRUN=(env OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --oversubscribe)
if [ ! -f "$D/serial.json" ]; then
  rm -rf "$D/serial.buckets"
  /usr/bin/time -v "$BIN" --quiet --json ilf build "$D/sequence.json" --grid "$GRID" --bands 5 --kernel 3 --cv-folds 0 --out "$D/serial.shgrid" \
    --buckets "$D/serial.buckets" > "$D/serial.json" 2> "$D/serial.time"
fi
for n in $RANKS; do
  rm -rf "$D/mpi_$n.buckets"
  /usr/bin/time -v "${MPIRUN[@]}" -np "$n" "$BIN" --quiet --json ilf build "$D/sequence.json" --grid "$GRID" --bands 5 --kernel 3 --cv-folds 0 \
    --out "$D/mpi_$n.shgrid" --buckets "$D/mpi_$n.buckets" > "$D/mpi_$n.json" 2> "$D/mpi_$n.time"
  rm -rf "$D/mpi_$n.buckets"
done
python3 - "$D" $RANKS <<'PY'
import json, struct, sys, re
d, ranks = sys.argv[1], sys.argv[2:]
def grid(p):
    b = open(p, "rb").read()
    l1 = b.index(b"\n"); l2 = b.index(b"\n", l1 + 1)
    return struct.unpack("<%df" % ((len(b) - l2 - 1) // 4), b[l2 + 1:])
def wall(t):
    m = re.search(r"Elapsed \(wall clock\) time.*: (?:(\d+):)?(\d+):([\d.]+)", open(t).read())
    return (int(m.group(1) or 0) * 3600 + int(m.group(2)) * 60 + float(m.group(3)))
def rss(t):
    return int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", open(t).read()).group(1)) / 1024
ref = grid(d + "/serial.shgrid")
s = json.load(open(d + "/serial.json"))
print("| ranks | wall | read | exchange | project (repair) | SH products | reduce | write | sent per rank | peak RSS per rank | max rel. diff to serial |")
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
ss = s["seconds"]
print("| serial | %.0f s | sort %.1f s | — | %.1f s (%.1f s) | %.1f s | — | %.1f s | — | %.0f MB | — |" % (
    wall(d + "/serial.time"), ss["sort"], ss["project"], ss["repair"], ss["accumulate"], ss["write"], rss(d + "/serial.time")))
for n in ranks:
    j = json.load(open(d + "/mpi_%s.json" % n)); m = j["mpi"]; t = m["seconds"]
    g = grid(d + "/mpi_%s.shgrid" % n)
    worst = max((abs(a - b) / abs(a) for a, b in zip(ref, g) if a != 0), default=0.0)
    zeros = sum(1 for a, b in zip(ref, g) if a == 0 and b != 0)
    print("| %s | %.0f s | %.1f s | %.1f s | %.1f s (%.1f s) | %.1f s | %.2f s | %.2f s | %.0f MB | %.0f MB | %.2g%s |" % (
        n, wall(d + "/mpi_%s.time" % n), t["read"], t["exchange"], t["project"], t["repair"], t["accumulate"], t["reduce"],
        j["seconds"]["write"], m["bytes_sent"] / 1e6, m["peak_rss_bytes"] / 1e6, worst, "" if zeros == 0 else " (%d nonzero where serial is 0)" % zeros))
PY
