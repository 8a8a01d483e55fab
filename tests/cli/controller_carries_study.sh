#!/usr/bin/env bash
# A controller carries its operating point: a K designed in Octave on a plant exported
# about a trim point (with a coordinate set), saved with the export's codyna_study and
# state_names, runs with no flag exactly as the run made with the flags; a K from
# another plant is refused with the reason.
# Usage: controller_carries_study.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"; cd "$work"
command -v octave-cli > /dev/null || { echo "octave-cli not found: skipped"; exit 77; }
fail() { echo "FAIL: $*"; exit 1; }
PY=/usr/bin/python3; [ -x "$PY" ] || PY=python3
cp "$src/examples/pendulum.json" model.json
python3 - model.json <<'PY'
import json, sys
m = json.load(open(sys.argv[1])); m.pop("controller", None)
json.dump(m, open(sys.argv[1], "w"), indent=1)
PY
"$codyna" linearize model.json --operating-point trim --set pivot=1.2 --out plant > /dev/null
octave-cli --no-gui --quiet --eval "run('plant/pendulum.m'); K = lqr(sys.a, sys.b, diag([100 1]), 1); save('-v7', 'K.mat', 'K', 'codyna_study', 'state_names'); save('-v7', 'K_plain.mat', 'K');" > octave.txt 2>&1 || true
[ -s K.mat ] && [ -s K_plain.mat ] || { cat octave.txt; fail "Octave did not save the controllers"; }
# with the study in the file: no flag
"$codyna" simulate model.json --controller K.mat --out carried.h5 --quiet --t-end 2 > carried.txt 2> carried.err || { cat carried.err; fail "simulate with K.mat"; }
grep -q "designed about the trim point" carried.err || fail "no note about the controller's operating point: $(cat carried.err)"
# the plain K with the flags repeated: the same run
"$codyna" simulate model.json --controller K_plain.mat --operating-point trim --set pivot=1.2 --out flags.h5 --quiet --t-end 2 > /dev/null
# the plain K without the flags: another (wrong) operating point, for contrast
"$codyna" simulate model.json --controller K_plain.mat --out wrong.h5 --quiet --t-end 2 > /dev/null 2>&1 || true
"$PY" - <<'PY'
import h5py, numpy as np, sys
def y(f):
    with h5py.File(f, "r") as h:
        return np.array(h["outputs"]) if "outputs" in h else np.array(h["y"])
a, b = y("carried.h5"), y("flags.h5")
d = float(np.max(np.abs(a - b)))
print(f"CARRIED_OK max |y_carried - y_flags| = {d:.3g}, theta(end) = {a[-1, 0]:.6f}")
if d > 1e-12: sys.exit("the run with the carried study differs from the run with the flags")
try:
    w = y("wrong.h5")
    if float(np.max(np.abs(w - a))) < 1e-6: sys.exit("the contrast run should differ (it uses another operating point)")
except OSError:
    pass
PY
# the steady-state search's knowns travel too: a four-bar crank held at 1.3 rad by its torque
# (--set pivot_A=1.3 --free-input crank_torque); the K saved with codyna_study runs with no flag
# exactly as with the flags
cp "$src/examples/four_bar.json" fourbar.json
"$codyna" linearize fourbar.json --operating-point equilibrium --set pivot_A=1.3 --free-input crank_torque --out fbplant > fb_lin.txt
grep -q "crank_torque = " fb_lin.txt || fail "no trim torque printed: $(cat fb_lin.txt)"
octave-cli --no-gui --quiet --eval "run('fbplant/four_bar.m'); K = lqr(sys.a, sys.b, eye(2), 1); save('-v7', 'Kfb.mat', 'K', 'codyna_study', 'state_names'); save('-v7', 'Kfb_plain.mat', 'K');" > octave_fb.txt 2>&1 || true
[ -s Kfb.mat ] || { cat octave_fb.txt; fail "Octave did not save the four-bar controller"; }
"$codyna" simulate fourbar.json --controller Kfb.mat --out fb_carried.h5 --quiet --t-end 1 > /dev/null 2> fb_carried.err || { cat fb_carried.err; fail "simulate with Kfb.mat"; }
"$codyna" simulate fourbar.json --controller Kfb_plain.mat --operating-point equilibrium --set pivot_A=1.3 --free-input crank_torque --out fb_flags.h5 --quiet --t-end 1 > /dev/null
"$PY" - <<'PY'
import h5py, numpy as np, sys
def y(f):
    with h5py.File(f, "r") as h:
        return np.array(h["outputs"]) if "outputs" in h else np.array(h["y"])
a, b = y("fb_carried.h5"), y("fb_flags.h5")
d = float(np.max(np.abs(a - b)))
print(f"FOURBAR_CARRIED_OK max |y_carried - y_flags| = {d:.3g}")
if d > 1e-12: sys.exit("the four-bar run with the carried study differs from the run with the flags")
PY
# a K from another plant (the cart-pendulum's states) is refused by name
cp "$src/examples/cart_pendulum.json" cart.json
"$codyna" linearize cart.json --out cartplant > /dev/null
octave-cli --no-gui --quiet --eval "run('cartplant/cart_pendulum.m'); K = [1 2]; save('-v7', 'Kcart.mat', 'K', 'state_names');" > /dev/null 2>&1 || true
if "$codyna" simulate model.json --controller Kcart.mat --operating-point trim --set pivot=1.2 --out x.h5 --quiet > /dev/null 2> other.err; then
  fail "a controller of another plant was accepted"
fi
grep -q "designed for state_names" other.err || fail "no reason given: $(cat other.err)"
echo "controller_carries_study: all checks passed"
