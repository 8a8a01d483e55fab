#!/usr/bin/env bash
# A state that a motion input's realization shifts says so (issue 38): the CTMS bus with the road
# W among Plant/In exports X2_dot~ = X2_dot - (b2/m2) W, not the wheel's velocity.
#   * linearize prints the shifted state and what it is; the .m header lists it; the .mat holds
#     state_shift (F: b2/m2 = 46.9375 at X2_dot~, W, nothing else) and state_rate_shift (0);
#   * the way back is right: the wheel's velocity rebuilt as xi + F W has the transfer function
#     s X2(s)/W(s) of the wheel's (unshifted) position, to 1e-12, and xi alone does not;
#   * along a run: the road moved by a sine under the nonlinear bus started at its equilibrium,
#     and the exported linear model driven by the same W (scipy's lsim): xi + F W is the wheel's
#     velocity of the run (the bus is linear in its vertical motion: to the integrators' and the
#     input's interpolation error, 1e-4 of its peak), xi alone misses it by more than 5 %.
# Usage: shifted_states.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"; cd "$work"
fail() { echo "FAIL: $*"; exit 1; }
PY=/usr/bin/python3
model="$src/examples/bus_suspension.json"

"$codyna" linearize "$model" --out lin > lin.txt || fail "linearize: $(cat lin.txt)"
grep -q '^shifted state    X2_dot~ = X2_dot - 46.9375 W (motion inputs enter without their rates; the .mat holds state_shift)$' lin.txt ||
  fail "no shifted-state line: $(head -12 lin.txt)"
[ "$(grep -c '^shifted state' lin.txt)" -eq 1 ] || fail "more than one shifted state: $(grep '^shifted' lin.txt)"
grep -q '^%   X2_dot~ = X2_dot - 46.9375 W$' lin/bus_suspension.m || fail "the .m header does not say what X2_dot~ is"

"$codyna" simulate "$model" --inputs U --open-loop --initial operating-point \
  --disturbance '{"actuator": "W", "type": "sine", "amplitude": 0.01, "frequency": 1.5}' \
  --t-end 2 --output-step 0.001 --rtol 1e-10 --atol 1e-12 --quiet --out run.h5 > run.txt 2> run.err || fail "simulate: $(cat run.err)"

"$PY" - <<'PY'
import h5py, numpy as np, scipy.io, scipy.signal, sys
d = scipy.io.loadmat("lin/bus_suspension.mat")
names = [str(n[0]) for n in d["state_names"].ravel()]
A, B, F, F2 = d["A"], d["B"], d["state_shift"], d["state_rate_shift"]
if names != ["X1", "X2", "X1_dot", "X2_dot~"]: sys.exit(f"state names {names}")
i, w = names.index("X2_dot~"), 1  # W is the second input
expect = np.zeros_like(F); expect[i, w] = 15020 / 320
if np.abs(F - expect).max() > 1e-12 * 46.9375 or np.abs(F2).max() != 0: sys.exit(f"state_shift {F}, state_rate_shift {F2}")
# the transfer function of the rebuilt velocity against s times the position's
worst, off = 0.0, 0.0
for om in (0.3, 3.0, 30.0, 300.0):
    s = 1j * om
    g = np.linalg.solve(s * np.eye(4) - A, B[:, w])
    vel = g[i] + F[i, w]
    ref = s * g[names.index("X2")]
    worst = max(worst, abs(vel - ref) / abs(ref)); off = max(off, abs(g[i] - ref) / abs(ref))
if worst > 1e-12: sys.exit(f"xi + F W is not the wheel's velocity: {worst:.3g}")
if off < 1e-2: sys.exit(f"xi alone is already the velocity ({off:.3g}): the test shows nothing")
# along the run
with h5py.File("run.h5", "r") as f:
    t, v = f["time"][()], f["v"][()]
    vn = [s.decode() for s in f["names/v"][()]]
W = 0.01 * np.sin(2 * np.pi * 1.5 * t)
_, _, xi = scipy.signal.lsim((A, B[:, [w]], np.eye(4), np.zeros((4, 1))), W, t)
wheel = v[:, vn.index("X2_dot")]
peak = np.abs(wheel).max()
err = np.abs(xi[:, i] + F[i, w] * W - wheel).max()
miss = np.abs(xi[:, i] - wheel).max()
print(f"SHIFT_OK F = {F[i, w]}, transfer {worst:.2g}; along the run: rebuilt {err / peak:.2g} of the peak {peak:.3g} m/s, xi alone {miss / peak:.2g}")
if err > 1e-4 * peak: sys.exit(f"the rebuilt velocity misses the run's by {err:.3g} (peak {peak:.3g})")
if miss < 5e-2 * peak: sys.exit("xi alone is close to the velocity: the shift shows nothing here")
PY
echo "shifted states: OK"
