#!/usr/bin/env bash
# A failed steady-state search is an error (issue 21): exit code 2, a message that names the
# residual, the unknowns and what to free, and nothing exported or simulated about the point.
#   * tests/data/trim_underactuated.json: a rod tilted 0.3 rad on a cart, only the cart's force
#     in Plant/In. A trim holds both coordinates; the force cannot balance the rod. The
#     residual printed (and the coordinate it is largest on) equals the least-squares residual
#     computed here from the plant exported at the initial point (xdot0 and B: the accelerations
#     at u0 and their derivative in u), to 1e-5 relative (the message's 6 digits); before, the
#     trim was exported with its residual (exit 0).
#   * freeing the tilt (--trim-free tilt) gives the upright trim: tilt 0, push 0.
#   * simulate with --lqr or --compare-linear about that trim: exit 2, no results file.
#   * an equilibrium with the pendulum held at 1 rad and no free input: exit 2, the advice
#     names the input to free; with --free-input torque the torque is m g (l/2) cos(1).
# Usage: failed_steady_state.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"; cd "$work"
fail() { echo "FAIL: $*"; exit 1; }
PY=/usr/bin/python3
model="$src/tests/data/trim_underactuated.json"

rc=0
"$codyna" linearize "$model" --operating-point trim --out lin > lin.txt 2> lin.err || rc=$?
[ "$rc" -eq 2 ] || fail "linearize at the failed trim exited $rc, expected 2: $(cat lin.txt lin.err)"
cat lin.err
for phrase in "/analysis/operating_point: trim: not converged: the residual accelerations are " \
              "unknowns: free inputs push, free coordinates (none); held: slider, tilt" \
              "every Plant/In input is free already" "free a held coordinate: trim_free / --trim-free slider, tilt"; do
  grep -qF -- "$phrase" lin.err || fail "the message lacks \"$phrase\": $(cat lin.err)"
done
[ -z "$(ls -A lin 2> /dev/null)" ] || fail "files exported about the failed trim: $(ls -A lin)"

# the residual, computed independently from the plant at the initial point
"$codyna" linearize "$model" --operating-point initial --out init > /dev/null
"$PY" - <<'PY'
import re, numpy as np, scipy.io, sys
d = scipy.io.loadmat("init/trim_underactuated.mat")
names = [str(n[0]) for n in d["state_names"].ravel()]
xdot0, B = d["xdot0"].ravel(), d["B"]
acc = [i for i, n in enumerate(names) if n.endswith("_dot")]
a0, Bv = xdot0[acc], B[acc, :]                 # accelerations at u0 = 0, d(acc)/d(push)
du = np.linalg.lstsq(Bv, -a0, rcond=None)[0]
r = a0 + Bv @ du
expected = np.abs(r).max()
msg = open("lin.err").read()
printed = float(re.search(r"residual accelerations are ([0-9.eE+-]+)", msg).group(1))
worst = names[acc[int(np.argmax(np.abs(r)))]][:-len("_dot")]
print(f"RESIDUAL_OK printed {printed}, least squares from the export {expected:.9g} (largest on {worst}), push {du[0]:.6g} N")
if f"largest on {worst}: " not in msg: sys.exit(f"the message does not name {worst} as the largest residual")
if expected < 1e-3: sys.exit("the model does not make a failed trim")
if abs(printed - expected) > 1e-5 * expected: sys.exit(f"printed residual {printed} != {expected}")
PY

# freeing the tilt: the upright trim, exported
"$codyna" linearize "$model" --operating-point trim --trim-free tilt --out free > free.txt
"$PY" - <<'PY'
import numpy as np, scipy.io, sys
d = scipy.io.loadmat("free/trim_underactuated.mat")
names = [str(n[0]) for n in d["state_names"].ravel()]
x0, u0 = d["x0"].ravel(), d["u0"].ravel()
print(f"FREED_OK tilt = {x0[names.index('tilt')]:.3g}, push = {u0[0]:.3g}")
if abs(x0[names.index("tilt")]) > 1e-9 or abs(u0[0]) > 1e-9 or abs(x0[names.index("slider")]) > 1e-12:
    sys.exit(f"not the upright trim: x0 {x0}, u0 {u0}")
PY

# nothing simulated about the failed trim
for args in "--lqr" "--open-loop --compare-linear"; do
  rc=0
  "$codyna" simulate "$model" --operating-point trim $args --quiet --out run.h5 --csv run.csv > run.txt 2> run.err || rc=$?
  [ "$rc" -eq 2 ] || fail "simulate $args about the failed trim exited $rc, expected 2: $(cat run.err)"
  grep -qF "trim: not converged" run.err || fail "simulate $args: $(cat run.err)"
  [ -z "$(ls -A | grep -E '^run\.(h5|csv)|^\.run')" ] || fail "simulate $args wrote $(ls -A)"
done

# an equilibrium held where nothing can hold it, then with the input freed
rc=0
"$codyna" linearize "$src/examples/pendulum.json" --hold pivot=1 --out eq > eq.txt 2> eq.err || rc=$?
[ "$rc" -eq 2 ] || fail "the held equilibrium exited $rc, expected 2: $(cat eq.err)"
for phrase in "equilibrium: steady state: not found: the residual accelerations are 3.97" "largest on pivot" \
              "unknowns: free inputs (none), free coordinates (none); held: pivot" "free an input: free_inputs / --free-input torque"; do
  grep -qF -- "$phrase" eq.err || fail "the message lacks \"$phrase\": $(cat eq.err)"
done
[ ! -e eq ] || fail "the failed equilibrium exported $(ls -A eq)"
"$codyna" linearize "$src/examples/pendulum.json" --hold pivot=1 --free-input torque --out eq > /dev/null
"$PY" - <<'PY'
import math, scipy.io, sys
d = scipy.io.loadmat("eq/pendulum.mat")
u0, x0 = d["u0"].ravel()[0], d["x0"].ravel()[0]
expected = 10 * 9.81 * 1.0 * math.cos(1.0)
print(f"HELD_OK torque {u0!r} (m g l/2 cos 1 = {expected!r}), pivot {x0!r}")
if abs(u0 - expected) > 1e-9 or x0 != 1.0: sys.exit("wrong holding torque")
PY
# the quadrotor tilted 10 degrees (--hold fly.rx): its thrust cannot hold it in place; the trim's
# residual is the sideways acceleration g sin(10 deg) = 1.70349 on fly.y, exit 2, nothing written
rc=0
"$codyna" linearize "$src/tests/data/quadrotor.json" --operating-point trim --hold fly.rx=0.17453292519943295 --out tilt \
  > tilt.txt 2> tilt.err || rc=$?
[ "$rc" -eq 2 ] || fail "the tilted quadrotor's trim exited $rc, expected 2: $(cat tilt.txt tilt.err)"
[ ! -e tilt ] || fail "the failed trim wrote tilt/"
"$PY" - <<'PY'
import math, re, sys
err = open("tilt.err").read()
m = re.search(r"the residual accelerations are (\S+) after \d+ iterations \(tolerance 1e-08; largest on fly\.y: (\S+)\)", err)
if not m: sys.exit(f"message: {err}")
g = 9.81 * math.sin(math.radians(10))
if abs(float(m.group(1)) - g) > 1e-5 * g: sys.exit(f"residual {m.group(1)} != g sin(10 deg) = {g}")
print(f"TILT_OK the tilted quadrotor's trim fails with residual {m.group(1)} = g sin(10 deg) on fly.y, exit 2, nothing written")
PY
echo "failed_steady_state: all checks passed"
