#!/usr/bin/env bash
# codyna sweep (issue 22, docs/parameter-studies.md), read back with h5py:
#   * the cart-pendulum's rod mass over 11 values with the model's LQR fixed: the file's
#     /closed_loop/poles_* equal eig(A - B K) of the stored A, B stacks and K to 1e-10, and its
#     /linear/A equals the linearize command's A of the same model with that mass (1e-12);
#   * a Monte Carlo of 200 samples run twice with one thread and once with two: every dataset and
#     attribute equal, variable by variable (and the CSVs equal);
#   * a variant that fails (mass -1) is recorded with status 1 and its reason, the others complete,
#     exit code 0;
#   * a study interrupted by SIGINT and started again writes the uninterrupted file, byte for byte;
#   * two --shard runs (one from SLURM_ARRAY_TASK_ID/COUNT) joined by sweep-merge: the single run's bytes;
#   * bad --vary, a missing --seed, and --out over the model exit 1 naming the option, writing nothing.
# Usage: sweep.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"; cd "$work"
fail() { echo "FAIL: $*"; exit 1; }
PY=/usr/bin/python3
model="$src/examples/cart_pendulum.json"

"$codyna" sweep "$model" --vary /bodies/1/mass=5:15:11 --out grid.h5 --csv grid.csv > grid.txt ||
  fail "the grid sweep exited non-zero"
grep -q "completed        11 of 11 (0 failed)" grid.txt || fail "summary: $(cat grid.txt)"
grep -q "stable           11 of 11 completed (100.0 %), closed loop" grid.txt || fail "summary: $(cat grid.txt)"
# the linearize command on the model with a rod of 13 kg (variant 8)
"$PY" -c "
import json; j = json.load(open('$model')); j['bodies'][1]['mass'] = 13.0; json.dump(j, open('m13.json', 'w'))"
"$codyna" linearize m13.json --out m13 > /dev/null

"$PY" - <<'PY'
import h5py, numpy as np, scipy.io
f = h5py.File("grid.h5", "r")
assert f.attrs["format"] == "codyna sweep", f.attrs["format"]
assert f.attrs["gain"] == "fixed" and f.attrs["design"] == "grid" and f.attrs["variants"] == 11
assert [s.decode() for s in f["parameters/fields"][:]] == ["/bodies/1/mass"]
m = f["parameters/values"][:]
assert m.shape == (11, 1) and np.allclose(m[:, 0], np.linspace(5, 15, 11), rtol=0, atol=1e-14), m
assert (f["status/code"][:] == 0).all()
A, B, K = f["linear/A"][:], f["linear/B"][:], f["closed_loop/K"][:]
assert A.shape == (11, 4, 4) and B.shape == (11, 4, 1) and K.shape == (1, 4) and f["linear/C"].shape == (11, 2, 4)
pr, pi = f["closed_loop/poles_real"][:], f["closed_loop/poles_imag"][:]
worst = 0
for i in range(11):
    e = np.linalg.eigvals(A[i] - B[i] @ K)
    e = e[np.lexsort((e.imag, e.real))]
    stored = pr[i] + 1j * pi[i]
    worst = max(worst, np.abs(stored - e).max())
    assert abs(f["closed_loop/max_real"][i] - e.real.max()) < 1e-10
assert worst < 1e-10, worst
assert (f["closed_loop/stable"][:] == 1).all()
lin = scipy.io.loadmat("m13/cart_pendulum.mat")
assert np.abs(A[8] - lin["A"]).max() <= 1e-12 * np.abs(lin["A"]).max(), (A[8], lin["A"])
print("grid: stored closed-loop poles vs eig(A - B K): %.1e" % worst)
PY

mc() { "$codyna" sweep "$model" --vary '/bodies/1/mass=normal(10,2)' --vary '/bodies/0/mass=uniform(15,25)' \
         --samples 200 --seed 2026 --threads "$1" --out "$2.h5" --csv "$2.csv" > "$2.txt"; }
mc 1 mc1; mc 1 mc1b; mc 2 mc2
cmp -s mc1.csv mc2.csv || fail "the CSVs of 1 and 2 threads differ"
"$PY" "$src/tests/cli/h5_equal.py" mc1.h5 mc1b.h5 mc2.h5 || fail "the Monte Carlo files differ (twice, 1 and 2 threads)"
"$PY" -c "
import h5py; f = h5py.File('mc1.h5', 'r')
assert f['parameters/values'].shape == (200, 2) and f.attrs['seed'] == 2026"

"$codyna" sweep "$model" --vary '/bodies/1/mass=[10,-1,12]' --out fail.h5 > fail.txt || fail "a failed variant stopped the study"
grep -q "completed        2 of 3 (1 failed)" fail.txt || fail "summary: $(cat fail.txt)"
grep -q "variant 1 (model error): .*/bodies/1/mass: expected a non-negative mass" fail.txt || fail "summary: $(cat fail.txt)"
"$PY" - <<'PY'
import h5py, numpy as np
f = h5py.File("fail.h5", "r")
assert list(f["status/code"][:]) == [0, 1, 0]
r = [s.decode() for s in f["status/reason"][:]]
assert r[0] == "" and "/bodies/1/mass" in r[1] and r[2] == "", r
assert np.isnan(f["linear/A"][1]).all() and not np.isnan(f["linear/A"][2]).any()
PY

# interrupted by SIGINT, then started again: the same bytes as an uninterrupted run
study=(sweep "$model" --vary '/bodies/1/mass=normal(10,2)' --samples 800 --seed 11 --simulate --threads 1 --quiet)
"$codyna" "${study[@]}" --out whole.h5 --csv whole.csv > /dev/null
"$codyna" "${study[@]}" --out cut.h5 --csv cut.csv > cut1.txt 2>&1 &
pid=$!
for _ in $(seq 400); do
  [ -f cut.h5.partial ] && [ "$(wc -l < cut.h5.partial)" -ge 20 ] && break
  sleep 0.05
done
kill -INT $pid
rc=0; wait $pid || rc=$?
[ $rc -ne 0 ] || fail "the study finished before it was interrupted (make it longer)"
[ ! -e cut.h5 ] || fail "an interrupted study left cut.h5"
done_before=$(( $(wc -l < cut.h5.partial) - 1 ))
"$codyna" "${study[@]}" --out cut.h5 --csv cut.csv > cut2.txt 2> cut2.err || fail "the restart failed: $(cat cut2.err)"
grep -q "codyna: note: resuming: [0-9]* of 800 variants were done (cut.h5.partial)" cut2.err || fail "no resume note: $(cat cut2.err)"
cmp -s cut.h5 whole.h5 || fail "the resumed cut.h5 differs from the uninterrupted whole.h5"
cmp -s cut.csv whole.csv || fail "the resumed cut.csv differs"
[ ! -e cut.h5.partial ] || fail "the journal was left behind"
echo "interrupted after $done_before of 800 variants, resumed: the same bytes"

# two shards (one through Slurm's variables) merged: the single run's bytes
"$codyna" "${study[@]:0:8}" --threads 2 --out whole2.h5 --csv whole2.csv > /dev/null
"$codyna" "${study[@]:0:8}" --shard 0/2 --out s0.sweep > /dev/null
SLURM_ARRAY_TASK_ID=1 SLURM_ARRAY_TASK_COUNT=2 "$codyna" "${study[@]:0:8}" --shard slurm --out s1.sweep > s1.txt
grep -q "shard            1/2: 400 of the 800 variants" s1.txt || fail "shard summary: $(cat s1.txt)"
"$codyna" sweep-merge s1.sweep s0.sweep --out merged.h5 --csv merged.csv > merged.txt || fail "sweep-merge failed"
cmp -s merged.h5 whole2.h5 || fail "the merged shards differ from the single run"
cmp -s merged.csv whole2.csv || fail "the merged CSV differs from the single run's"
rc=0; "$codyna" sweep-merge s0.sweep --out half.h5 > /dev/null 2> half.err || rc=$?
[ $rc -eq 1 ] && grep -q "variants 1, 3, 5" half.err || fail "a missing shard: exit $rc, $(cat half.err)"
[ ! -e half.h5 ] || fail "a refused merge wrote half.h5"
echo "two shards merged: the same bytes as one run"

refused() {  # refused OUTPUT_WORDS -- ARGS...
  local words="$1"; shift
  local rc=0
  "$codyna" sweep "$model" "$@" > out.txt 2> err.txt || rc=$?
  [ $rc -eq 1 ] || fail "for $*: exit code $rc, expected 1"
  grep -q -- "$words" err.txt || fail "for $*: expected \"$words\" in: $(cat err.txt)"
}
rm -f none.h5
refused "--vary /bodies/9/mass=1:2:3: the model file .* has no field /bodies/9/mass" --vary /bodies/9/mass=1:2:3 --out none.h5
refused "--vary /bodies/1/mass=1..3: expected a:b:n" --vary /bodies/1/mass=1..3 --out none.h5
refused "--seed: a random study" --vary '/bodies/1/mass=normal(10,1)' --samples 5 --out none.h5
refused "this is the input file" --vary /bodies/1/mass=1:2:3 --out "$model"
[ ! -e none.h5 ] || fail "a refused sweep wrote none.h5"
echo "sweep: ok"
