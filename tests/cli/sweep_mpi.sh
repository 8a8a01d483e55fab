#!/usr/bin/env bash
# codyna sweep under mpirun (OpenMPI; docs/parameter-studies.md, "MPI"), read back with h5py:
#   * the cart-pendulum's rod mass over 11 values with --simulate, on 2 and 3 ranks (11 = 4+4+3,
#     uneven), and a Monte Carlo of 200 samples on 2 and 3 ranks (67+67+66): every dataset and
#     attribute equal to the single-process run's, variable by variable, and the HDF5, CSV and MAT
#     files equal byte for byte;
#   * a study every rank refuses (a bad --vary) exits 1 with the error said once, no hang; one
#     rank failing alone (mpirun's MPMD form gives it another --vary) is named by rank 0, exit 1,
#     nothing written; ranks given different studies (another seed) are refused when joined;
#   * --shard under mpirun is refused, and so is sweep-merge (N processes would write one file);
#   * a study interrupted under mpirun resumes from its ranks' journals (OUT.partial.<k>of<N>) when
#     started again on N ranks, to the uninterrupted run's bytes; on other N it is refused.
# A codyna built without MPI: started as one of 2 MPI processes (OMPI_COMM_WORLD_SIZE=2) it must
# refuse, writing nothing; then the test is skipped (exit 77), saying so.
# Environment: as root, OpenMPI needs OMPI_ALLOW_RUN_AS_ROOT(_CONFIRM); in containers its shared
# memory transport's single-copy mechanism (CMA) may be forbidden: btl_vader_single_copy_mechanism
# none. Under AddressSanitizer, OpenMPI's own allocations live until exit and are reported from
# unloaded plugins (no names to suppress): the mpirun runs alone have detect_leaks=0; the
# single-process runs of the same binary are still leak-checked.
# Usage: sweep_mpi.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"; cd "$work"
fail() { echo "FAIL: $*"; exit 1; }
PY=/usr/bin/python3
model="$src/examples/cart_pendulum.json"

if ! "$codyna" sweep --help | tr '\n' ' ' | grep -q "mpirun -np N codyna sweep"; then
  fail "codyna sweep --help does not mention MPI"
fi
if "$codyna" sweep --help | tr '\n' ' ' | grep -q "built without MPI"; then
  rc=0
  OMPI_COMM_WORLD_SIZE=2 "$codyna" sweep "$model" --vary /bodies/1/mass=5:15:3 --out no.h5 > /dev/null 2> no.err || rc=$?
  [ $rc -eq 1 ] && grep -q "built without MPI" no.err || fail "without MPI, under a launcher of 2: exit $rc, $(cat no.err)"
  [ ! -e no.h5 ] || fail "a refused run wrote no.h5"
  echo "SKIP: this codyna was built without MPI (it refuses to run under mpirun, checked); nothing more to test"
  exit 77
fi
command -v mpirun > /dev/null || fail "codyna was built with MPI but mpirun is not installed (Debian: openmpi-bin)"

if [ "$(id -u)" -eq 0 ]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
export OMPI_MCA_btl_vader_single_copy_mechanism=none
mpi() {  # mpi NP ARGS...
  local np="$1"; shift
  ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" timeout 120 mpirun --oversubscribe -np "$np" "$codyna" "$@"
}

grid=(sweep "$model" --vary /bodies/1/mass=5:15:11 --simulate --quiet)
mc=(sweep "$model" --vary '/bodies/1/mass=normal(10,2)' --vary '/bodies/0/mass=uniform(15,25)' --samples 200 --seed 2026 --quiet)
"$codyna" "${grid[@]}" --threads 1 --out grid1.h5 --csv grid1.csv --mat grid1/g.mat > grid1.txt
"$codyna" "${mc[@]}" --threads 1 --out mc1.h5 --csv mc1.csv > mc1.txt
for np in 2 3; do
  mpi $np "${grid[@]}" --out grid$np.h5 --csv grid$np.csv --mat grid$np/g.mat > grid$np.txt 2> grid$np.err ||
    fail "mpirun -np $np, the grid: $(cat grid$np.err)"
  mpi $np "${mc[@]}" --out mc$np.h5 --csv mc$np.csv > mc$np.txt 2> mc$np.err || fail "mpirun -np $np, the Monte Carlo: $(cat mc$np.err)"
  sed "s/grid$np/grid1/g" grid$np.txt | cmp -s - grid1.txt || fail "-np $np: the printed summary differs: $(cat grid$np.txt)"
  [ ! -e grid$np.h5.partial ] || fail "-np $np left a journal"
done

for study in grid mc; do
  "$PY" "$src/tests/cli/h5_equal.py" $study"1.h5" $study"2.h5" $study"3.h5" || fail "$study: the files of 1, 2 and 3 ranks differ"
done
"$PY" -c "
import h5py
g, m = h5py.File('grid1.h5', 'r'), h5py.File('mc1.h5', 'r')
assert g.attrs['variants'] == 11 and (g['status/code'][:] == 0).all() and (g['simulation/status'][:] == 0).all()
assert g['simulation/overshoot'].shape == (11, 2)
assert m.attrs['variants'] == 200 and (m['status/code'][:] == 0).all()"
for np in 2 3; do
  for f in grid$np.h5 grid$np.csv grid$np/g.mat grid$np/g.m mc$np.h5 mc$np.csv; do
    cmp -s "$f" "${f/$np/1}" || fail "$f differs from the single-process ${f/$np/1}"
  done
done
echo "mpirun -np 2 and 3: the single-process files, byte for byte"

# every rank refuses: said once, exit 1, nothing written
rc=0; mpi 2 sweep "$model" --vary /bodies/1/mass=1..3 --out bad.h5 > bad.txt 2> bad.err || rc=$?
[ $rc -ne 0 ] || fail "a bad --vary under mpirun exited 0"
[ "$(grep -c "codyna: error: --vary /bodies/1/mass=1..3: expected a:b:n" bad.err)" -eq 1 ] || fail "the error, once: $(cat bad.err)"
[ ! -e bad.h5 ] || fail "a refused study wrote bad.h5"
# one rank fails on its own (mpirun's MPMD form: rank 1 is given a field the model lacks): rank 0,
# done with its slice, is not left waiting; it names rank 1's error, writes nothing, exit 1
rc=0
ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" timeout 120 mpirun --oversubscribe -np 1 "$codyna" "${mc[@]}" \
  --out part.h5 : -np 1 "$codyna" sweep "$model" --vary /bodies/9/mass=1:2:3 --out part.h5 > part.txt 2> part.err || rc=$?
[ $rc -eq 1 ] || fail "a rank that failed: exit $rc, $(cat part.err)"
grep -q "codyna: error: rank 1 of 2: --vary /bodies/9/mass=1:2:3: the model file .* has no field /bodies/9/mass" part.err &&
  grep -q "codyna: error: 1 of 2 ranks failed; no results written" part.err || fail "a rank that failed: $(cat part.err)"
[ ! -e part.h5 ] && [ ! -e part.h5.partial ] || fail "a study with a failed rank wrote part.h5"
# ranks given different studies (another seed on rank 1): refused when joined, naming the ranks
rc=0
ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" timeout 120 mpirun --oversubscribe -np 1 "$codyna" "${mc[@]}" \
  --out mixed.h5 : -np 1 "$codyna" "${mc[@]/2026/2027}" --out mixed.h5 > mixed.txt 2> mixed.err || rc=$?
[ $rc -eq 1 ] && grep -q "codyna: error: rank 1: a shard of another study than rank 0" mixed.err || fail "mixed studies: exit $rc, $(cat mixed.err)"
[ ! -e mixed.h5 ] && [ ! -e mixed.h5.partial ] || fail "mixed studies wrote mixed.h5"
rc=0; mpi 2 sweep "$model" --vary /bodies/1/mass=5:15:3 --shard 0/2 --out s.sweep > /dev/null 2> shard.err || rc=$?
[ $rc -ne 0 ] && grep -q "under mpirun the ranks share the variants already" shard.err || fail "--shard under mpirun: $(cat shard.err)"
rc=0; mpi 2 sweep-merge whatever.sweep --out m.h5 > /dev/null 2> merge.err || rc=$?
[ $rc -ne 0 ] && grep -q "sweep-merge: started as one of 2 processes by an MPI launcher" merge.err || fail "sweep-merge under mpirun: $(cat merge.err)"
# interrupted under mpirun (its ranks killed, as a job killed at its time limit or a node lost), then
# started again: on another number of ranks it is refused, naming a rank's journal; on as many
# ranks it resumes and writes the uninterrupted run's bytes, leaving no journal behind
study=(sweep "$model" --vary /bodies/1/mass=5:15:80 --vary '/solver/t_end=[20]' --simulate --quiet)  # about 1 s on 2 ranks
"$codyna" "${study[@]}" --threads 1 --out whole.h5 --csv whole.csv > /dev/null
ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" timeout 120 mpirun --oversubscribe -np 2 "$codyna" "${study[@]}" \
  --out cut.h5 --csv cut.csv > cut1.txt 2>&1 &
pid=$!
lines() { [ -f "$1" ] && wc -l < "$1" || echo 0; }
for _ in $(seq 3000); do
  [ "$(lines cut.h5.partial.0of2)" -ge 8 ] && [ "$(lines cut.h5.partial.1of2)" -ge 8 ] && break
  sleep 0.01
done
pkill -KILL -f "^$codyna sweep .*--out cut.h5" || true  # the ranks (their command lines start with codyna), not mpirun
rc=0; wait $pid || rc=$?
[ $rc -ne 0 ] || fail "the MPI study finished before it was interrupted (make it longer)"
[ ! -e cut.h5 ] || fail "an interrupted MPI study left cut.h5"
done0=$(( $(lines cut.h5.partial.0of2) - 2 )); done1=$(( $(lines cut.h5.partial.1of2) - 2 ))
[ $done0 -ge 6 ] && [ $done1 -ge 6 ] || fail "the ranks' journals hold $done0 and $done1 variants"
rc=0; mpi 3 "${study[@]}" --out cut.h5 --csv cut.csv > cut3.txt 2> cut3.err || rc=$?
[ $rc -eq 1 ] && grep -q "cut.h5.partial.[01]of2: the journal of rank [01] of an interrupted run on 2 ranks: start it again with mpirun -np 2" cut3.err ||
  fail "resumed on 3 ranks: exit $rc, $(cat cut3.err)"
[ ! -e cut.h5 ] || fail "a refused resume wrote cut.h5"
mpi 2 "${study[@]}" --out cut.h5 --csv cut.csv > cut2.txt 2> cut2.err || fail "the MPI restart failed: $(cat cut2.err)"
grep -q "codyna: note: resuming: [0-9]* of the 40 variants of slice 0/2 were done (cut.h5.partial.0of2)" cut2.err ||
  fail "no resume note: $(cat cut2.err)"
cmp -s cut.h5 whole.h5 || fail "the resumed cut.h5 differs from the uninterrupted single-process whole.h5"
cmp -s cut.csv whole.csv || fail "the resumed cut.csv differs"
ls cut.h5.partial* > /dev/null 2>&1 && fail "journals left behind: $(ls cut.h5.partial*)"
echo "mpirun -np 2 interrupted after $done0 + $done1 of 80 variants, refused on 3 ranks, resumed on 2: the same bytes"
echo "sweep mpi: ok"
