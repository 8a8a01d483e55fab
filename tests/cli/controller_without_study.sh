#!/usr/bin/env bash
# A controller file states its point (issue 21):
#   * a K saved without codyna_study: the run says which operating point it applies the
#     controller about (each coordinate and input, the equilibrium pivot = pi/2 to 1e-9) and
#     how to carry the design point (save ... codyna_study);
#   * a K saved with codyna_study: a held coordinate (--hold / --set) that its point does not
#     hold is refused (exit 1) with the reason and the way out (--initial); one it holds at the
#     same value is accepted; --initial is accepted and the run starts there.
# Usage: controller_without_study.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"; cd "$work"
fail() { echo "FAIL: $*"; exit 1; }
PY=/usr/bin/python3
cp "$src/examples/pendulum.json" model.json
"$PY" - model.json <<'PY'
import json, sys
m = json.load(open(sys.argv[1])); m.pop("controller", None)
json.dump(m, open(sys.argv[1], "w"), indent=1)
PY
"$codyna" linearize model.json --out plant > /dev/null
"$codyna" linearize model.json --operating-point trim --hold pivot=1.2 --out trimplant > /dev/null
"$PY" - <<'PY'
import numpy as np, scipy.io, scipy.linalg
for src, out in (("plant/pendulum.mat", "K"), ("trimplant/pendulum.mat", "Ktrim")):
    d = scipy.io.loadmat(src)
    A, B = d["A"], d["B"]
    P = scipy.linalg.solve_continuous_are(A, B, np.diag([100.0, 1.0]), np.eye(1))
    K = B.T @ P
    scipy.io.savemat(out + "_plain.mat", {"K": K})
    study = str(d["codyna_study"][0])
    scipy.io.savemat(out + "_study.mat", {"K": K, "codyna_study": study})
PY

# without codyna_study: the point is said, with how to carry it
"$codyna" simulate model.json --controller K_plain.mat --t-end 0.5 --quiet --out plain.h5 > plain.txt 2> plain.err ||
  fail "simulate with K_plain.mat: $(cat plain.err)"
grep -qF "K_plain.mat carries no codyna_study: the controller is applied about this study's equilibrium point (pivot = " plain.err ||
  fail "no note on the point: $(cat plain.err)"
grep -qF "save('-v7', 'K.mat', 'K', 'codyna_study', 'state_names')" plain.err || fail "no advice to carry the point: $(cat plain.err)"
"$PY" - <<'PY'
import math, re, sys
m = re.search(r"equilibrium point \(pivot = ([0-9.eE+-]+), torque = ([0-9.eE+-]+)\)", open("plain.err").read())
pivot, torque = float(m.group(1)), float(m.group(2))
print(f"NOTE_OK pivot = {pivot!r}, torque = {torque!r}")
if abs(pivot - math.pi / 2) > 1e-9 or torque != 0: sys.exit("the note's point is not the upright equilibrium")
PY
# with codyna_study: no such note
"$codyna" simulate model.json --controller K_study.mat --t-end 0.5 --quiet --out study.h5 > /dev/null 2> study.err
grep -q "carries no codyna_study" study.err && fail "the note on a controller that carries its study"
grep -q "designed about the equilibrium point" study.err || fail "no note on the carried point: $(cat study.err)"

# held coordinates against the carried study
for hold in "--hold pivot=1.2" "--set pivot=1.2" "--hold pivto=1"; do
  rc=0
  "$codyna" simulate model.json --controller K_study.mat $hold --t-end 0.5 --quiet --out held.h5 > /dev/null 2> held.err || rc=$?
  [ "$rc" -eq 1 ] || fail "$hold with a carried study exited $rc, expected 1: $(cat held.err)"
  name=${hold#* }; name=${name%%=*}
  grep -qF "K_study.mat: the controller carries the operating point it was designed about (codyna_study: equilibrium, held: none), and the held coordinate $name = " held.err ||
    fail "$hold: $(cat held.err)"
  grep -qF "is not one of them" held.err && grep -qF -- "--initial $name=VALUE" held.err || fail "$hold: no reason: $(cat held.err)"
  [ ! -e held.h5 ] || fail "$hold: held.h5 written"
done
rc=0
"$codyna" simulate model.json --controller Ktrim_study.mat --hold pivot=1.3 --t-end 0.5 --quiet --out held.h5 > /dev/null 2> held.err || rc=$?
[ "$rc" -eq 1 ] && grep -qF "(codyna_study: trim, held: pivot = 1.2" held.err && grep -qF "is held there at another value" held.err ||
  fail "--hold pivot=1.3 against a trim at 1.2: $rc $(cat held.err)"
"$codyna" simulate model.json --controller Ktrim_study.mat --hold pivot=1.2 --initial pivot=1.0 --t-end 0.5 --quiet --out same.h5 > same.txt 2> same.err ||
  fail "--hold pivot=1.2 with the trim's own value: $(cat same.err)"
"$PY" - <<'PY'
import h5py, json, sys
with h5py.File("same.h5", "r") as f:
    q = f["q"][()]
    s = json.loads(f["provenance"].attrs["settings_json"])
print(f"CARRIED_OK q(0) = {q[0, 0]!r}, operating point {s['operating_point']} {s['operating_point_q']}")
if q[0, 0] != 1.0 or s["operating_point"] != "trim" or s["operating_point_q"]["pivot"] != 1.2: sys.exit("wrong start or point")
PY
echo "controller_without_study: all checks passed"
