#!/usr/bin/env bash
# A run that starts where the plant was linearized (issue 38): `--initial operating-point`.
#   * the bus suspension with an LQR on its actuator U (--inputs U: the road W stays still), designed about its static equilibrium: the first sample of
#     every state equals x0 of `codyna linearize` (its .mat) to 1e-12, and with nothing to disturb
#     it the body stays there (the model's own state, the unloaded springs, drops it by cm);
#   * the summary and the results file say where the run started;
#   * NAME=VALUE entries set coordinates on top of the point (a disturbed start), the others
#     stay x0's;
#   * a word that is neither a start nor NAME=VALUE is refused naming --initial and the choices.
# Usage: start_at_operating_point.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"; cd "$work"
fail() { echo "FAIL: $*"; exit 1; }
PY=/usr/bin/python3
model="$src/examples/bus_suspension.json"

"$codyna" linearize "$model" --inputs U --out lin > lin.txt || fail "linearize: $(cat lin.txt)"
"$codyna" simulate "$model" --inputs U --lqr --initial operating-point --t-end 0.5 --quiet --out op.h5 > op.txt 2> op.err ||
  fail "simulate --initial operating-point: $(cat op.err)"
grep -Eq '^start            at the equilibrium point \(x0 of the controller.s linearization\)$' op.txt || fail "start line: $(cat op.txt)"
"$codyna" simulate "$model" --inputs U --lqr --t-end 0.5 --quiet --out model.h5 > model.txt 2> model.err || fail "simulate: $(cat model.err)"
grep -q '^start ' model.txt && fail "a start line without --initial operating-point: $(cat model.txt)"
"$codyna" simulate "$model" --inputs U --lqr --initial operating-point --initial X1=0.05 --t-end 0.5 --quiet --out kick.h5 > kick.txt 2> kick.err ||
  fail "simulate --initial operating-point --initial X1=0.05: $(cat kick.err)"
grep -Eq '^start            at the equilibrium point with the initial coordinates set: X1 = 0\.05, X2 = -0\.05' kick.txt || fail "start line: $(cat kick.txt)"

"$PY" - <<'PY'
import h5py, json, numpy as np, scipy.io, sys
d = scipy.io.loadmat("lin/bus_suspension.mat")
names = [str(n[0]) for n in d["state_names"].ravel()]
x0 = d["x0"].ravel()
def run(path):
    with h5py.File(path, "r") as f:
        q, v = f["q"][()], f["v"][()]
        qn = [s.decode() for s in f["names/q"][()]]
        vn = [s.decode() for s in f["names/v"][()]]
        s = json.loads(f["provenance"].attrs["settings_json"])
    return q, v, (qn, vn), s
q, v, (qn, vn), s = run("op.h5")
if s["initial_state"] != "equilibrium": sys.exit(f"settings say {s['initial_state']}")
worst = 0.0
for k, n in enumerate(names):
    if n.endswith("_dot"):
        val = v[0, vn.index(n)]
    else:
        val = q[0, qn.index(n)]
    worst = max(worst, abs(val - x0[k]))
if worst > 1e-12: sys.exit(f"the first sample is {worst:.3g} from x0 (states {names}, x0 {x0})")
drift = np.abs(q[:, qn.index("X1")] - x0[names.index("X1")]).max()
if drift > 1e-6: sys.exit(f"the body moved {drift:.3g} m away from the equilibrium it started at")
qm, vm, _, sm = run("model.h5")
if sm["initial_state"] != "model": sys.exit(f"settings say {sm['initial_state']}")
drop = abs(qm[0, qn.index("X1")] - x0[names.index("X1")])
if drop < 1e-2: sys.exit(f"the model's own state is {drop:.3g} m from the equilibrium: the test shows nothing")
qk, vk, _, sk = run("kick.h5")
if sk["initial_state"] != "equilibrium + study initial": sys.exit(f"settings say {sk['initial_state']}")
if abs(qk[0, qn.index("X1")] - 0.05) > 1e-12: sys.exit(f"X1 starts at {qk[0, qn.index('X1')]}")
if abs(qk[0, qn.index("X2")] - x0[names.index("X2")]) > 1e-12: sys.exit("X2 left x0")
print(f"START_OK first sample {worst:.2g} from x0, drift {drift:.2g} m; the model's state {drop:.3g} m away")
PY

rc=0
"$codyna" simulate "$model" --inputs U --lqr --initial somewhere --quiet --out bad.h5 > bad.txt 2> bad.err || rc=$?
[ $rc -eq 1 ] || fail "--initial somewhere: exit $rc"
grep -q -- "--initial somewhere: expected NAME=VALUE, or where the run starts: model or operating-point" bad.err || fail "message: $(cat bad.err)"
[ ! -e bad.h5 ] || fail "a refused run wrote bad.h5"
echo "start at the operating point: OK"
