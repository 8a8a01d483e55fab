#!/usr/bin/env bash
# The simulation's initial state is kept apart from the operating point (issue 21):
#   * --initial pivot=0.6 on the pendulum starts the run at 0.6 rad (the first sample of
#     the coordinate, to 1e-9) while the operating point stays the upright equilibrium the
#     model's own state leads to (pi/2, to 1e-9, printed and stored in the results file);
#     the linear comparison starts from the same 0.6;
#   * a rate (--initial pivot_dot=0.5) is the first sample of v;
#   * on a closed loop (four-bar) the named coordinate is held exactly while the loops close
#     (the constraints hold at the first sample), and the operating point is the one found
#     without --initial, to the bit;
#   * --hold (and its older name --set) still holds the coordinate in the search: the pendulum
#     held at 0.6 has no equilibrium (nothing is free to hold it): exit code 2, no file;
#   * an unknown name in --initial or --hold is refused (exit code 1), named, with the list.
# Usage: initial_state_apart.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"; cd "$work"
fail() { echo "FAIL: $*"; exit 1; }
PY=/usr/bin/python3

"$codyna" simulate "$src/examples/pendulum.json" --initial pivot=0.6 --compare-linear --quiet --out big.h5 > big.txt 2> big.err ||
  fail "simulate --initial pivot=0.6: $(cat big.err)"
grep -Eq '^operating point  equilibrium \(residual [^)]*\): pivot = 1\.570796327, torque = 0$' big.txt || fail "operating point line: $(cat big.txt)"
grep -Eq '^initial state    pivot = 0\.6 ' big.txt || fail "initial state line: $(cat big.txt)"
"$PY" - <<'PY'
import h5py, json, math, sys
with h5py.File("big.h5", "r") as f:
    q, v, y, yl = f["q"][()], f["v"][()], f["y"][()], f["y_linear"][()]
    s = json.loads(f["provenance"].attrs["settings_json"])
op = s["operating_point_q"]["pivot"]
print(f"INITIAL_OK q(0) = {q[0, 0]!r}, y(0) = {y[0, 0]!r}, y_lin(0) = {yl[0, 0]!r}, operating point {s['operating_point']} pivot = {op!r}")
if abs(q[0, 0] - 0.6) > 1e-9: sys.exit(f"the run does not start at 0.6: {q[0, 0]}")
if abs(y[0, 0] - 0.6) > 1e-9 or abs(yl[0, 0] - 0.6) > 1e-9: sys.exit("the outputs (nonlinear, linear) do not start at 0.6")
if v[0, 0] != 0.0: sys.exit(f"the rate moved: {v[0, 0]}")
if s["operating_point"] != "equilibrium" or abs(op - math.pi / 2) > 1e-9: sys.exit(f"the operating point is not the upright equilibrium: {s}")
if s["initial_state"] != "study initial": sys.exit(f"settings: {s}")
# the PD loop brings the rod to the operating point from there
if abs(y[-1, 0] - math.pi / 2) > 1e-3: sys.exit(f"theta(end) = {y[-1, 0]}")
PY

# a rate
"$codyna" simulate "$src/examples/pendulum.json" --initial pivot_dot=0.5 --quiet --t-end 0.1 --out rate.h5 > /dev/null
"$PY" - <<'PY'
import h5py, sys
with h5py.File("rate.h5", "r") as f:
    q, v = f["q"][()], f["v"][()]
print(f"RATE_OK v(0) = {v[0, 0]!r}, q(0) = {q[0, 0]!r}")
if abs(v[0, 0] - 0.5) > 1e-12 or abs(q[0, 0] - 1.3962634015954636) > 1e-12: sys.exit("the rate was not set alone")
PY

# a closed loop: the four-bar's crank started at 1.3 rad, the loops closed around it
"$codyna" simulate "$src/examples/four_bar.json" --open-loop --compare-linear --t-end 0.1 --quiet --out fb_plain.h5 > /dev/null
"$codyna" simulate "$src/examples/four_bar.json" --initial pivot_A=1.3 --open-loop --compare-linear --t-end 0.1 --quiet --out fb_init.h5 > /dev/null
"$PY" - <<'PY'
import h5py, json, sys
def read(name):
    with h5py.File(name, "r") as f:
        return (f["q"][()], list(f["names/q"].asstr("utf-8")[()]), f["constraints/position_violation"][()],
                json.loads(f["provenance"].attrs["settings_json"]))
q, names, phi, s = read("fb_init.h5")
q1, _, _, s1 = read("fb_plain.h5")
i = names.index("pivot_A")
print(f"LOOP_OK pivot_A(0) = {q[0, i]!r}, |phi(0)| = {phi[0]:.3g}, operating point {s['operating_point_q']}")
if abs(q[0, i] - 1.3) > 1e-12: sys.exit("pivot_A was not held at 1.3 while the loop closed")
if phi[0] > 1e-10: sys.exit(f"the loop is not closed at the start: {phi[0]}")
if abs(q1[0, i] - 1.3) < 1e-3: sys.exit("the plain run should start elsewhere")
if s["operating_point_q"] != s1["operating_point_q"]: sys.exit(f"--initial moved the operating point: {s1['operating_point_q']} -> {s['operating_point_q']}")
PY

# --hold / --set still hold the coordinate in the search: no equilibrium at 0.6, nothing written
for flag in --hold --set; do
  rc=0
  "$codyna" simulate "$src/examples/pendulum.json" $flag pivot=0.6 --compare-linear --quiet --out held.h5 > held.txt 2> held.err || rc=$?
  [ "$rc" -eq 2 ] || fail "$flag pivot=0.6 exited $rc, expected 2: $(cat held.err)"
  grep -q "held: pivot" held.err || fail "$flag: $(cat held.err)"
  [ ! -e held.h5 ] || fail "$flag: a results file was written about an unconverged point"
done

# unknown names
for flag in --initial --hold; do
  rc=0
  "$codyna" simulate "$src/examples/pendulum.json" $flag pivto=0.6 --quiet --out bad.h5 > /dev/null 2> bad.err || rc=$?
  [ "$rc" -eq 1 ] || fail "$flag pivto=0.6 exited $rc, expected 1: $(cat bad.err)"
  grep -q 'unknown coordinate "pivto" (coordinates: pivot; rates: pivot_dot)' bad.err || fail "$flag: $(cat bad.err)"
  [ ! -e bad.h5 ] || fail "$flag: bad.h5 written"
done
rc=0
"$codyna" simulate "$src/examples/pendulum.json" --initial pivot --quiet --out bad.h5 > /dev/null 2> bad.err || rc=$?
[ "$rc" -eq 1 ] && grep -q -- "--initial pivot: expected NAME=VALUE" bad.err || fail "--initial pivot: $rc $(cat bad.err)"
# linearize takes --initial only along a trajectory
rc=0
"$codyna" linearize "$src/examples/pendulum.json" --initial pivot=0.6 --out lin > /dev/null 2> lin.err || rc=$?
[ "$rc" -eq 1 ] && grep -q -- "--trajectory only" lin.err || fail "linearize --initial: $rc $(cat lin.err)"
echo "initial_state_apart: all checks passed"
