#!/usr/bin/env bash
# codyna freqresp (study/freqresp_job.hpp): the linear columns of its table are scipy's
# C (jwI - A)^-1 B + D of the plant codyna linearize exports at the same point, the nonlinear
# single-track car's gain and phase equal them at a small steer amplitude, the inverted
# cart-pendulum is measured in closed loop under its LQR, and bad input is refused naming the
# option (exit 1, nothing written).
# Usage: freqresp.sh CODYNA SOURCE_DIR WORK_DIR
set -uo pipefail
codyna="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"; cd "$work"
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
expect() {
  local code="$1" phrase="$2"; shift 3
  "$@" > out.txt 2> err.txt
  local rc=$?
  [ "$rc" -eq "$code" ] || fail "$* exited $rc, expected $code: $(cat err.txt)"
  grep -qF -- "$phrase" err.txt || fail "$*: stderr lacks \"$phrase\": $(cat err.txt)"
}
py=/usr/bin/python3
"$py" -c "import scipy.io, numpy" 2>/dev/null || { echo "skipped: scipy is missing"; exit 77; }

for model in single_track_car cart_pendulum; do
  "$codyna" linearize "$src/examples/$model.json" --out lin_$model > lin.txt 2> err.txt || fail "$model: linearize: $(cat err.txt)"
  "$codyna" freqresp "$src/examples/$model.json" --frequencies 0.3:30:7 --amplitude 1e-4 --csv $model.csv > out.txt 2> err.txt ||
    fail "$model: freqresp exit $?: $(cat err.txt)"
  grep -q "^largest gap" out.txt || fail "$model: no largest gap: $(cat out.txt)"
  "$py" - "$model.csv" lin_$model <<'PY' || fail "$model: the table differs from the exported plant's response"
import csv, glob, sys
import numpy as np, scipy.io
rows = list(csv.DictReader(open(sys.argv[1])))
mat = scipy.io.loadmat(glob.glob(sys.argv[2] + "/*.mat")[0])
A, B, C, D = (np.atleast_2d(mat[k]).astype(float) for k in "ABCD")
names = lambda key: [str(x[0]) if x.size else "" for x in mat[key].ravel()]
ins, outs = names("input_names"), names("output_names")
worst_lin = worst_nl = 0.0
for r in rows:
    w = float(r["w_rad_s"])
    H = C @ np.linalg.solve(1j * w * np.eye(A.shape[0]) - A, B) + D
    for i, y in enumerate(outs):
        for j, u in enumerate(ins):
            h = H[i, j]
            pre = "%s/%s_" % (y, u)
            mag_lin, ph_lin = float(r[pre + "magnitude_linear"]), float(r[pre + "phase_deg_linear"])
            lin = mag_lin * np.exp(1j * np.radians(ph_lin))
            nl = float(r[pre + "magnitude"]) * np.exp(1j * np.radians(float(r[pre + "phase_deg"])))
            worst_lin = max(worst_lin, abs(lin - h) / abs(h))
            worst_nl = max(worst_nl, abs(nl - h) / abs(h))
print(sys.argv[1], len(rows), "frequencies: linear columns vs scipy", worst_lin, "; nonlinear vs scipy", worst_nl)
sys.exit(0 if len(rows) == 7 and worst_lin < 1e-10 and worst_nl < 1e-4 else 1)
PY
done
grep -q "controller       the model file's lqr controller" out.txt || fail "cart_pendulum: not in closed loop: $(cat out.txt)"

# an unstable plant in open loop, bad frequencies and amplitudes, another file in the way
expect 1 "the plant is unstable about the operating point" -- "$codyna" freqresp "$src/examples/cart_pendulum.json" --frequencies 1 --open-loop
expect 1 "--frequencies -1: expected frequencies > 0 rad/s" -- "$codyna" freqresp "$src/examples/single_track_car.json" --frequencies=-1
expect 1 "--frequencies x: expected a number" -- "$codyna" freqresp "$src/examples/single_track_car.json" --frequencies 1:x:3
expect 1 "--amplitude 0: expected an amplitude other than 0" -- "$codyna" freqresp "$src/examples/single_track_car.json" --frequencies 1 --amplitude 0
echo mine > notes.csv
expect 1 "notes.csv" -- "$codyna" freqresp "$src/examples/single_track_car.json" --frequencies 1 --csv notes.csv
[ "$(cat notes.csv)" = mine ] || fail "notes.csv was replaced"
expect 1 "--hold pivot" -- "$codyna" freqresp "$src/examples/single_track_car.json" --frequencies 1 --hold pivot

[ "$fails" -eq 0 ] && echo "freqresp: all checks passed"
exit $((fails > 0))
