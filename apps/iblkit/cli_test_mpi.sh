#!/usr/bin/env bash
# End-to-end faults of the distributed ILF build (issue 18; CTest cli_mpi, seconds): a rank killed
# mid-build ends the whole job through mpirun (no hang) and leaves no grid and no temporary file; the
# re-run reuses the buckets the killed run had finished and gives the grid of an undisturbed run;
# rank 0 prints one report; `--mpi` without mpirun runs as a job of one rank; the cross-validated
# error, kernel and --error-grid under mpirun are the serial build's. Skips without mpirun or
# without the MPI plugin. Open MPI refuses root unless told: the allowance is given to mpirun here only.
set -u
source "$(dirname "$0")/cli_check.sh" "$1"
if ! command -v mpirun >/dev/null 2>&1; then echo "cli_mpi: mpirun is absent (install openmpi-bin): skipped"; exit 0; fi
if [ ! -f "$(dirname "$(readlink -f "$BIN")")/libiblkit_mpi.so" ]; then echo "cli_mpi: this build has no MPI plugin: skipped"; exit 0; fi
MPIRUN=(env OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --oversubscribe)

"$BIN" --quiet ilf synth --out "$T/seq" --probes 300 --size 32 --supersample 1 >/dev/null || { echo "FAIL synth"; exit 1; }
S="$T/seq/sequence.json"
ARGS=(--grid 24 --directions pixel --buckets "$T/b")

# An undisturbed run: one report, from rank 0.
check run ok "ranks     2:" -- timeout 300 "${MPIRUN[@]}" -np 2 "$BIN" ilf build "$S" "${ARGS[@]}" --out "$T/ref.shgrid"
n=$(timeout 300 "${MPIRUN[@]}" -np 2 "$BIN" ilf build "$S" "${ARGS[@]}" --out "$T/ref2.shgrid" | grep -c "^wrote ")
if [ "$n" = 1 ]; then pass=$((pass+1)); else echo "FAIL one-report: $n reports"; fail=$((fail+1)); fi

# Kill rank 1 while it cross-validates or projects (the buckets reused from above make the sort instant).
timeout 300 "${MPIRUN[@]}" -np 2 "$BIN" --quiet ilf build "$S" "${ARGS[@]}" --out "$T/killed.shgrid" >"$T/killed.log" 2>&1 &
job=$!
victim=""
for _ in $(seq 1 200); do
  # the ranks are the iblkit children of this mpirun
  for p in $(pgrep -P "$job"; for c in $(pgrep -P "$job"); do pgrep -P "$c"; done); do
    if [ "$(cat /proc/$p/comm 2>/dev/null)" = iblkit ] && grep -q "^OMPI_COMM_WORLD_RANK=1$" <(tr '\0' '\n' < /proc/$p/environ 2>/dev/null); then victim=$p; fi
  done
  [ -n "$victim" ] && break
  sleep 0.05
done
sleep 0.3
if [ -n "$victim" ] && kill -0 "$victim" 2>/dev/null; then
  kill -9 "$victim"
  wait $job; rc=$?
  if [ $rc -ne 0 ] && [ $rc -ne 124 ]; then pass=$((pass+1)); else echo "FAIL kill: mpirun exit $rc (124 = hung): $(cat "$T/killed.log")"; fail=$((fail+1)); fi
  if ! ls -a "$T" | grep -qE "^killed\.(shgrid|tmp-)"; then pass=$((pass+1)); else echo "FAIL kill: a grid or temporary file was left: $(ls -a "$T")"; fail=$((fail+1)); fi
  grep -qiE "killed|signal 9|exited on signal" "$T/killed.log" && pass=$((pass+1)) || { echo "FAIL kill: mpirun did not say a rank died: $(cat "$T/killed.log")"; fail=$((fail+1)); }
else
  wait $job
  echo "FAIL kill: rank 1 was not found running (the build was too quick to interrupt)"; fail=$((fail+1))
fi
# The re-run reuses the finished buckets and gives the undisturbed grid.
check rerun-reuses ok "reused" -- timeout 300 "${MPIRUN[@]}" -np 2 "$BIN" ilf build "$S" "${ARGS[@]}" --out "$T/again.shgrid"
if cmp -s "$T/ref.shgrid" "$T/again.shgrid"; then pass=$((pass+1)); else echo "FAIL rerun: the grid differs from the undisturbed run's"; fail=$((fail+1)); fi

# --mpi without mpirun: a job of one rank (MPI's singleton start), the serial build's grid.
check singleton ok "ranks     1:" -- env OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 timeout 120 "$BIN" ilf build "$S" --grid 8 --kernel 3 --mpi --out "$T/one.shgrid" --buckets "$T/b1"
check serial ok "" -- "$BIN" --quiet ilf build "$S" --grid 8 --kernel 3 --out "$T/serial.shgrid" --buckets "$T/b0"
if cmp -s "$T/one.shgrid" "$T/serial.shgrid"; then pass=$((pass+1)); else echo "FAIL singleton: its grid differs from the serial build's"; fail=$((fail+1)); fi

# The cross-validation under mpirun, as the serial build's: the CLI's default (--kernel auto, 5 folds)
# with --error-grid on 3 ranks prints the serial cv error and chosen kernel, and writes the serial
# error volume (its slice's mean and max to 1e-6).
"$BIN" --quiet ilf synth --out "$T/cv" --probes 120 --size 24 --supersample 1 >/dev/null || { echo "FAIL synth cv"; exit 1; }
CV=("$T/cv/sequence.json" --grid 8)
timeout 120 "${MPIRUN[@]}" -np 3 "$BIN" ilf build "${CV[@]}" --out "$T/cv3.shgrid" --error-grid "$T/cv3.err.shgrid" --buckets "$T/cvb3" >"$T/cv3.log" 2>&1 \
  && grep -q "^wrote $T/cv3.err.shgrid" "$T/cv3.log" && pass=$((pass+1)) || { echo "FAIL cv-mpi: $(cat "$T/cv3.log")"; fail=$((fail+1)); }
"$BIN" ilf build "${CV[@]}" --out "$T/cv0.shgrid" --error-grid "$T/cv0.err.shgrid" --buckets "$T/cvb0" >"$T/cv0.log" 2>&1 || echo "serial build failed: $(cat "$T/cv0.log")"
m=$(grep -E "^(cv error|kernel) " "$T/cv3.log"); s=$(grep -E "^(cv error|kernel) " "$T/cv0.log")
# the kernel line says how long the choice took: compare up to its timing
if [ -n "$s" ] && [ "$(sed 's/ in [0-9.]*s//' <<<"$m")" = "$(sed 's/ in [0-9.]*s//' <<<"$s")" ]; then pass=$((pass+1)); else echo "FAIL cv-same: mpi \"$m\" serial \"$s\""; fail=$((fail+1)); fi
echo "cv under mpirun: $m"
slice() { "$BIN" --quiet --json ilf slice "$1" --plane y=0.5 --size 16 --out "$T/slice.exr" | tr -d ' \n' | grep -oE '"(max|mean)_rel_error":[-0-9.e+]+' | cut -d: -f2; }
a=($(slice "$T/cv3.err.shgrid")); b=($(slice "$T/cv0.err.shgrid"))
if [ ${#a[@]} = 2 ] && [ ${#b[@]} = 2 ] && awk -v a0="${a[0]}" -v a1="${a[1]}" -v b0="${b[0]}" -v b1="${b[1]}" \
     'function d(x, y) { return (x > y ? x - y : y - x) <= 1e-6 * (y > 0 ? y : -y) } BEGIN { exit !(b0 > 0 && d(a0, b0) && d(a1, b1)) }'; then
  pass=$((pass+1)); else echo "FAIL cv-error-grid: mpi ${a[*]}, serial ${b[*]}"; fail=$((fail+1)); fi

# Ranks that disagree (issue 32 §5): started with different options, every rank ends within seconds
# with one line naming the option, non-zero, no hang, no grid written.
disagree() {  # NAME PATTERN -- OPTIONS-OF-RANK-0 -- OPTIONS-OF-RANK-1
  local name="$1" pat="$2"; shift 3
  local a=() b=()
  while [ "$1" != -- ]; do a+=("$1"); shift; done; shift
  b=("$@")
  local out rc
  out=$(timeout 60 "${MPIRUN[@]}" -np 1 "$BIN" --quiet ilf build --out "$T/dis.shgrid" --buckets "$T/db" "${a[@]}" : \
        -np 1 "$BIN" --quiet ilf build --out "$T/dis.shgrid" --buckets "$T/db" "${b[@]}" 2>&1); rc=$?
  local lines; lines=$(grep -c "^iblkit: error:" <<<"$out")
  if [ $rc -ne 0 ] && [ $rc -ne 124 ] && [ "$lines" = 1 ] && grep -qE -- "$pat" <<<"$out" && [ ! -e "$T/dis.shgrid" ]; then
    pass=$((pass+1)); else echo "FAIL $name: exit $rc, $lines error lines: $out"; fail=$((fail+1)); fi
}
disagree grid "disagree on --grid: rank 0 has 8, rank 1 has 6" -- "$S" --grid 8 -- "$S" --grid 6
disagree bands "disagree on --bands" -- "$S" --grid 6 --bands 3 -- "$S" --grid 6 --bands 4
disagree directions "disagree on --directions" -- "$S" --grid 6 --directions pixel -- "$S" --grid 6 --directions 8
disagree kernel "disagree on --kernel" -- "$S" --grid 6 --kernel 2 -- "$S" --grid 6 --kernel 3
disagree sequence "disagree on sequence" -- "$T/cv/sequence.json" --grid 6 -- "$S" --grid 6
# The same command line over two different sequences (each rank in its own folder): the build's own
# description (the sequence's fingerprint) differs.
mkdir -p "$T/wa" "$T/wb"
"$BIN" --quiet ilf synth --out "$T/wa/s" --probes 20 --size 8 >/dev/null && "$BIN" --quiet ilf synth --out "$T/wb/s" --probes 21 --size 8 >/dev/null
out=$(cd "$T" && timeout 60 "${MPIRUN[@]}" -np 1 -wdir "$T/wa" "$BIN" --quiet ilf build s/sequence.json --grid 4 --out g.shgrid : \
      -np 1 -wdir "$T/wb" "$BIN" --quiet ilf build s/sequence.json --grid 4 --out g.shgrid 2>&1); rc=$?
if [ $rc -ne 0 ] && [ $rc -ne 124 ] && [ "$(grep -c '^iblkit: error:' <<<"$out")" = 1 ] && grep -q "disagree on sequence: rank 0 has s/sequence.json (20 probes" <<<"$out"; then
  pass=$((pass+1)); else echo "FAIL sequence-content: exit $rc: $out"; fail=$((fail+1)); fi
# A rank that is not iblkit: an MPI program that never comes to the handshake (named after
# --mpi-timeout), and a program without MPI (MPI_Init itself waits: said so after the timeout).
if command -v mpicc >/dev/null 2>&1; then
  printf '#include <mpi.h>\n#include <unistd.h>\nint main(int c, char** v) { MPI_Init(&c, &v); sleep(120); MPI_Finalize(); return 0; }\n' > "$T/other.c"
  if mpicc -o "$T/other" "$T/other.c" 2>/dev/null; then
    t0=$(date +%s)
    out=$(timeout 60 "${MPIRUN[@]}" -np 1 "$BIN" --quiet ilf build "$S" --grid 4 --out "$T/o.shgrid" --buckets "$T/ob" --mpi-timeout 3 : -np 1 "$T/other" 2>&1); rc=$?
    took=$(( $(date +%s) - t0 ))
    if [ $rc -ne 0 ] && [ $rc -ne 124 ] && [ $took -lt 30 ] && grep -q "^iblkit: error: rank 1 of this MPI job of 2 did not take part within --mpi-timeout 3 s" <<<"$out"; then
      pass=$((pass+1)); else echo "FAIL not-iblkit: exit $rc after $took s: $out"; fail=$((fail+1)); fi
  fi
else
  echo "cli_mpi: no mpicc: the rank that runs another MPI program is not tried"
fi
out=$(timeout 60 "${MPIRUN[@]}" -np 1 "$BIN" --quiet ilf build "$S" --grid 4 --out "$T/o.shgrid" --buckets "$T/ob" --mpi-timeout 3 : -np 1 sleep 100 2>&1); rc=$?
if [ $rc -ne 0 ] && [ $rc -ne 124 ] && grep -q "^iblkit: error: MPI_Init did not complete within --mpi-timeout 3 s" <<<"$out"; then
  pass=$((pass+1)); else echo "FAIL not-mpi: exit $rc: $out"; fail=$((fail+1)); fi

echo "cli_mpi: $pass passed, $fail failed"
[ $fail -eq 0 ]
