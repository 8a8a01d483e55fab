#!/usr/bin/env bash
# codyna simulate on the paper's examples with the controllers their model
# files declare (paper 4.1: PD on the joint torque; 4.2: LQR on the cart
# force), checked from the results file with h5py; CSV written; open loop
# falls over; bad input gives exit code 1 and no results file.
# usage: simulate_examples.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*"; exit 1; }
PY=/usr/bin/python3; [ -x "$PY" ] || PY=python3

"$codyna" simulate "$src/examples/pendulum.json" --quiet --out "$work/pendulum.h5" --csv "$work/pendulum.csv" > "$work/p.txt"
grep -q "controller from the model file: PD" "$work/p.txt" || { cat "$work/p.txt"; fail "model controller not used"; }
"$codyna" simulate "$src/examples/cart_pendulum.json" --quiet --t-end 8 --compare-linear --out "$work/cart.h5" > "$work/c.txt"
grep -q "within 1 % throughout" "$work/c.txt" || { cat "$work/c.txt"; fail "linear comparison missing"; }
"$codyna" simulate "$src/examples/pendulum.json" --open-loop --quiet --t-end 2 --out "$work/open.h5" > /dev/null
head -1 "$work/pendulum.csv" | grep -q '^t,pivot,pivot_dot,torque,theta' || fail "CSV header: $(head -1 "$work/pendulum.csv")"
# the header docs/simulation.md shows is the one written (with --compare-linear)
"$codyna" simulate "$src/examples/pendulum.json" --quiet --compare-linear --out "$work/pl.h5" --csv "$work/pl.csv" > /dev/null
grep -qxF "$(head -1 "$work/pl.csv")" "$src/docs/simulation.md" || fail "docs/simulation.md does not show the CSV header $(head -1 "$work/pl.csv")"

"$PY" - "$work" <<'PY'
import sys, math
import h5py, numpy as np
work = sys.argv[1]
def load(name):
    with h5py.File(f"{work}/{name}", "r") as f:
        names = [s.decode() if isinstance(s, bytes) else s for s in np.array(f["names/outputs"]).tolist()]
        return np.array(f["time"]), np.array(f["y"]), np.array(f["u"]), names
t, y, u, names = load("pendulum.h5")
theta = y[:, names.index("theta")]
assert abs(theta[0] - math.radians(80)) < 1e-12
late = t >= 3.0
assert np.max(np.abs(theta[late] - math.pi / 2)) < math.radians(0.5), np.max(np.abs(theta[late] - math.pi / 2))
assert np.max(np.abs(u)) < 40.0, np.max(np.abs(u))  # bounded: the initial P action is 218.1 * 10 deg = 38.1 N m
t, y, u, names = load("cart.h5")
th = y[:, names.index("theta")]
assert np.max(np.abs(th[t >= 5.0])) < math.radians(0.5)
t, y, u, names = load("open.h5")
assert y[-1, 0] < math.radians(0), y[-1, 0]  # without control the rod falls past horizontal
print("SIMULATE_OK")
PY

rc=0
"$codyna" simulate "$src/examples/pendulum.json" --integrator euler --quiet --out "$work/bad.h5" 2> "$work/err.txt" > /dev/null || rc=$?
[ "$rc" -eq 1 ] || fail "unknown integrator: exit code $rc"
grep -q 'unknown integrator "euler"' "$work/err.txt" || fail "message: $(cat "$work/err.txt")"
rc=0
"$codyna" simulate "$src/examples/pendulum.json" --quiet --out "$work/no/such/dir/r.h5" 2> "$work/err.txt" > /dev/null || rc=$?
[ "$rc" -eq 1 ] || fail "missing output directory: exit code $rc"
grep -q "does not exist" "$work/err.txt" || fail "message: $(cat "$work/err.txt")"
[ ! -e "$work/bad.h5" ] || fail "a failed run left a results file"
echo "simulate_examples: all checks passed"
