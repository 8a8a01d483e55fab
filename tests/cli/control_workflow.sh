#!/usr/bin/env bash
# The control engineer's workflow from the command line: references read from CSV and .mat
# files (bad files: exit code 1, a message naming the file, the column or variable and what
# was expected), a disturbance on an actuator that is not Plant/In, PID anti-windup from the
# model file, and --lqr on a spherical pendulum whose yaw no input moves (refused, naming
# the yaw, unless --lqr-controllable-part; then the tilt is stabilized).
# usage: control_workflow.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*"; exit 1; }
PY=/usr/bin/python3; [ -x "$PY" ] || PY=python3

# expect_error EXIT_CODE PHRASE COMMAND...: the command fails with that code and says PHRASE
expect_error() {
  local code=$1 phrase=$2; shift 2
  set +e
  "$@" > "$work/out.txt" 2>&1
  local rc=$?
  set -e
  [ $rc -eq "$code" ] || { cat "$work/out.txt"; fail "exit code $rc, expected $code: $*"; }
  grep -qF -- "$phrase" "$work/out.txt" || { cat "$work/out.txt"; fail "no \"$phrase\" in the message of: $*"; }
}

# end value of an output in simulate's summary
end_of() { sed -n "s/^output $2 *start *[^ ]* *end *\([^ ]*\) .*/\1/p" "$1"; }

# ---- references from files: a PI loop on a spring-mass (a linear plant)
slider() {  # slider REFERENCE_FILE [extra analysis fields]
  cat <<JSON
{"codyna_model": 1, "name": "slider",
 "bodies": [{"name": "block", "mass": 2, "inertia": [0.1, 0.1, 0.1]}],
 "joints": [{"name": "x", "type": "prismatic", "parent": "ground", "child": "block", "axis": [1, 0, 0]}],
 "effects": [{"name": "spring", "type": "joint_spring_damper", "joint": "x", "stiffness": 3, "damping": 0.5}],
 "actuators": [{"name": "force", "type": "joint_force", "joint": "x", "unit": "N", "min": -8, "max": 8},
               {"name": "push", "type": "joint_force", "joint": "x", "unit": "N"}],
 "sensors": [{"name": "pos", "type": "joint_position", "joint": "x", "unit": "m"}],
 "plant": {"inputs": ["force"], "outputs": ["pos"]},
 "controller": {"type": "pid", "kp": [[19]], "ki": [[12]], "kd": [[11.5]], "operating_point": "initial"},
 "solver": {"integrator": "cvode-bdf", "rtol": 1e-9, "atol": 1e-11, "t_end": 14, "output_step": 0.01},
 "analysis": {"operating_point": "initial", "references": [{"output": "pos", "type": "file", "file": "$1"}]${2:-}}}
JSON
}
mkdir -p "$work/ref"
printf 't,pos\n0,0\n1,0\n3,0.2\n4,0.1\n' > "$work/ref/ramp.csv"
slider ramp.csv > "$work/ref/csv.json"
"$codyna" simulate "$work/ref/csv.json" --quiet --out "$work/ref/csv.h5" --csv "$work/ref/csv_run.csv" > "$work/ref/csv.txt" 2>&1 \
  || { cat "$work/ref/csv.txt"; fail "simulate with a CSV reference"; }
y_end=$(end_of "$work/ref/csv.txt" pos)
"$PY" -c "import sys; y=float('$y_end'); assert abs(y - 0.1) < 1e-4, y" || fail "the CSV reference's end value 0.1 not reached: $y_end"
# the same reference from a .mat (t and value written by Octave when it is there, else skipped)
if command -v octave-cli > /dev/null; then
  (cd "$work/ref" && octave-cli --no-gui --quiet --eval "t = [0 1 3 4]; value = [0; 0; 0.2; 0.1]; save('-v7', 'ramp.mat', 't', 'value'); t = [0 1 3]; save('-v7', 'short.mat', 't', 'value'); y = value; t = [0 1 3 4]; save('-v7', 'novalue.mat', 't', 'y'); printf('MAT_OK\n');" > octave.txt 2>&1) || true
  grep -q MAT_OK "$work/ref/octave.txt" || { cat "$work/ref/octave.txt"; fail "octave could not write the .mat signals"; }
  slider ramp.mat > "$work/ref/mat.json"
  "$codyna" simulate "$work/ref/mat.json" --quiet --out "$work/ref/mat.h5" --csv "$work/ref/mat_run.csv" > "$work/ref/mat.txt" 2>&1 \
    || { cat "$work/ref/mat.txt"; fail "simulate with a .mat reference"; }
  cmp -s <(cut -d, -f1-3 "$work/ref/csv_run.csv") <(cut -d, -f1-3 "$work/ref/mat_run.csv") || fail "the .mat reference's run differs from the CSV's"
  slider short.mat > "$work/ref/short.json"
  expect_error 1 "short.mat: t has 3 entries but value has 4: expected one value per time" \
    "$codyna" simulate "$work/ref/short.json" --quiet --out "$work/ref/x.h5"
  slider novalue.mat > "$work/ref/novalue.json"
  expect_error 1 "novalue.mat: no variable value: a signal .mat holds the vectors t and value" \
    "$codyna" simulate "$work/ref/novalue.json" --quiet --out "$work/ref/x.h5"
else
  echo "octave-cli not installed: the .mat reference part skipped"
fi
printf 't,pos\n0,0\n1,zero\n' > "$work/ref/bad.csv"
slider bad.csv > "$work/ref/bad.json"
expect_error 1 "/analysis/references/0/file: $work/ref/bad.csv: row 2 (line 3), column pos: expected a number, got \"zero\"" \
  "$codyna" simulate "$work/ref/bad.json" --quiet --out "$work/ref/x.h5"
expect_error 1 "/analysis/references/0/file: $work/ref/bad.csv: row 2 (line 3), column pos: expected a number, got \"zero\"" \
  "$codyna" linearize "$work/ref/bad.json" --closed-loop --out "$work/ref/lin_bad"
slider missing.csv > "$work/ref/missing.json"
expect_error 1 "missing.csv: no such file" "$codyna" simulate "$work/ref/missing.json" --quiet --out "$work/ref/x.h5"
[ ! -e "$work/ref/x.h5" ] || fail "a results file was written for a bad reference"

# ---- a constant push on the block (not Plant/In): the PI loop brings it back, the force cancels it
slider ramp.csv ', "disturbances": [{"actuator": "push", "type": "step", "time": 5, "value": 0.5}]' > "$work/ref/push.json"
"$codyna" simulate "$work/ref/push.json" --quiet --t-end 20 --out "$work/ref/push.h5" --csv "$work/ref/push.csv" > "$work/ref/push.txt" 2>&1 \
  || { cat "$work/ref/push.txt"; fail "simulate with a disturbance"; }
"$PY" - "$work/ref/push.csv" <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
h = rows[0]; last = [float(x) for x in rows[-1]]
col = lambda name: h.index(next(c for c in h if c == name or c.startswith(name + " ")))
y, force, push = last[col("pos")], last[col("force")], last[col("push")]
# steady state: y = r = 0.1, k y = force + push  ->  force = 0.3 - 0.5
assert abs(y - 0.1) < 1e-5, y
assert abs(push - 0.5) == 0, push
assert abs(force - (3 * 0.1 - 0.5)) < 1e-4, force
print(f"DISTURBANCE_OK y {y:.8f} force {force:.8f} push {push}")
PY

# ---- a 2 N push on the cart of the cart-pendulum (LQR upright): the linear comparison, through
# the push's own B column, follows the nonlinear run (the gap is RK4's and the nonlinearity's)
"$PY" - "$src/examples/cart_pendulum.json" "$work/cart_push.json" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
m["actuators"].append({"name": "push", "type": "body_force", "body": "cart", "point": [0, 0, 0],
                       "direction": [1, 0, 0], "frame": "world", "unit": "N"})
m["joints"][1]["q0"] = 0.0
m["analysis"] = {"operating_point": "equilibrium", "controller": "lqr", "q_weights": [10, 100, 1, 1], "r_weights": [0.01],
                 "compare_linear": True, "disturbances": [{"actuator": "push", "type": "step", "time": 0.5, "value": 2}]}
m["solver"].update({"t_end": 8, "rtol": 1e-10, "atol": 1e-12})
json.dump(m, open(sys.argv[2], "w"), indent=1)
PY
"$codyna" simulate "$work/cart_push.json" --quiet --out "$work/cart_push.h5" > "$work/cart_push.txt" 2>&1 \
  || { cat "$work/cart_push.txt"; fail "simulate the cart with a push"; }
"$PY" - "$work/cart_push.txt" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
for out in ("h", "theta"):
    m = re.search(r"^  " + out + r" +max \|y - y_lin\| (\S+) \((\S+) % of its excursion\); within 1 % throughout", text, re.M)
    assert m, text
    assert float(m.group(2)) < 0.05, (out, m.group(2))  # below 5e-4 of the excursion (measured 3.5e-5, 2.0e-4)
    print(f"CART_PUSH_OK {out}: max |y - y_lin| {m.group(1)} ({m.group(2)} % of its excursion)")
PY

# ---- anti-windup from the model file: a 1 m step against a 4 N limit (3 N hold the block there);
# the unlimited loop overshoots 0.129 m by itself, windup makes it 0.23 m (tests/core/controller_test.cpp)
for aw in none back_calculation conditional; do
  extra=''
  [ $aw = none ] || extra=", \"anti_windup\": \"$aw\""
  [ $aw = back_calculation ] && extra="$extra, \"tracking_time\": 0.2"
  slider ramp.csv "$extra" | sed -e 's/"type": "file", "file": "ramp.csv"/"type": "step", "time": 0, "value": 1/' \
    -e 's/"min": -8, "max": 8/"min": -4, "max": 4/' > "$work/ref/aw_$aw.json"
  "$codyna" simulate "$work/ref/aw_$aw.json" --quiet --t-end 15 --out "$work/ref/aw_$aw.h5" --csv "$work/ref/aw_$aw.csv" > "$work/ref/aw_$aw.txt" 2>&1 \
    || { cat "$work/ref/aw_$aw.txt"; fail "simulate with anti_windup $aw"; }
done
grep -q "anti-windup by back-calculation (tracking time 0.2 s)" "$work/ref/aw_back_calculation.txt" || { cat "$work/ref/aw_back_calculation.txt"; fail "controller description"; }
"$PY" - "$work/ref" <<'PY'
import csv, sys
def overshoot(path):
    rows = list(csv.reader(open(path))); h = rows[0]
    i = h.index(next(c for c in h if c == "pos" or c.startswith("pos ")))
    return max(float(r[i]) for r in rows[1:]) - 1
o = {aw: overshoot(f"{sys.argv[1]}/aw_{aw}.csv") for aw in ("none", "back_calculation", "conditional")}
print("ANTI_WINDUP overshoot " + ", ".join(f"{k} {v:.4f} m" for k, v in o.items()))
assert abs(o["none"] - 0.2296) < 2e-3, o
assert o["back_calculation"] < 1e-4 and abs(o["conditional"] - 0.0462) < 2e-3, o
PY

# ---- LQR on the controllable part of a spherical pendulum
sp="$src/tests/data/spherical_pendulum.json"
expect_error 1 "not stabilizable: the Plant/In inputs cannot move lambda = 0 (ball.wz)" \
  "$codyna" simulate "$sp" --lqr --quiet --out "$work/sp.h5"
grep -qF -- "--lqr-controllable-part" "$work/out.txt" || fail "the refusal does not say how to design on the controllable part"
grep -qF "(ball.wz)" "$work/out.txt" || { cat "$work/out.txt"; fail "the refusal does not name the yaw rate ball.wz"; }
"$codyna" simulate "$sp" --lqr --lqr-controllable-part --quiet --out "$work/sp.h5" > "$work/sp.txt" 2> "$work/sp.err" \
  || { cat "$work/sp.txt" "$work/sp.err"; fail "simulate --lqr --lqr-controllable-part"; }
grep -qF "codyna: note: lqr on the controllable part (4 of 6 states): the Plant/In inputs cannot move lambda = 0 (ball.wz); these poles stay where they are" "$work/sp.err" \
  || { cat "$work/sp.err"; fail "no note on the controllable part"; }
grep -qF "(ball.wz)" "$work/sp.err" || { cat "$work/sp.err"; fail "no note naming the yaw rate ball.wz"; }
x_end=$(end_of "$work/sp.txt" tip_x) y_end=$(end_of "$work/sp.txt" tip_y)
"$PY" -c "x=float('$x_end'); y=float('$y_end'); assert abs(x) < 1e-4 and abs(y) < 1e-4, (x, y); print(f'SPHERICAL_OK tip at the end ({x:.2g}, {y:.2g}) m')" \
  || { cat "$work/sp.txt"; fail "the tilt is not stabilized"; }
# the same design as a linear closed loop: four tilt poles moved, the yaw's two left at 0
"$codyna" linearize "$sp" --lqr --lqr-controllable-part --closed-loop --out "$work/sp_cl" > "$work/sp_cl.txt" 2> "$work/sp_cl.err" \
  || { cat "$work/sp_cl.txt" "$work/sp_cl.err"; fail "linearize --lqr --lqr-controllable-part --closed-loop"; }
[ -s "$work/sp_cl/spherical_pendulum_cl.mat" ] || fail "spherical_pendulum_cl.mat not written"
grep -qF "lqr on the controllable part (4 of 6 states)" "$work/sp_cl.err" || { cat "$work/sp_cl.err"; fail "no note from linearize"; }
"$PY" - "$work/sp_cl.txt" <<'PY'
import re, sys
text = open(sys.argv[1]).read().split("closed loop ", 1)[1]
# the yaw's double zero is one row ("1-2   0 (x2) ... -"), the four moved poles one row each
zero = re.search(r"^1-(\d+)\s+0 \(x(\d+)\)\s+0\s+0\s+-\s", text, re.M)
assert zero and zero.group(1) == zero.group(2) == "2", text
re_parts = [float(m.group(1)) for m in re.finditer(r"^\d+\s+(\S+) [+-] \S+j", text, re.M)]
assert len(re_parts) == 4 and all(x < -0.5 for x in re_parts), re_parts
print("SPHERICAL_CL_OK a double zero and real parts", re_parts)
PY
expect_error 1 "--closed-loop: not along a --trajectory (one operating point)" "$codyna" linearize "$sp" --lqr --lqr-controllable-part --closed-loop --trajectory 1 --out "$work/sp_x"
expect_error 1 "--lqr: a controller is used by --closed-loop only (add it)" "$codyna" linearize "$sp" --lqr --out "$work/sp_x"
expect_error 1 "--controller and --lqr: choose one" "$codyna" linearize "$sp" --lqr --controller K.mat --closed-loop --out "$work/sp_x"
expect_error 1 "--lqr-controllable-part: goes with --lqr" "$codyna" simulate "$sp" --lqr-controllable-part --quiet --out "$work/sp2.h5"
echo "control workflow: OK"
