#!/usr/bin/env bash
# The plant selection and the study's signals from the command line, for one run (issue 21):
#   * --inputs/--outputs give the same A, B, C, D, names and offsets, bit for bit, as the model
#     file edited to that selection (and the file itself is left as it was);
#   * --disable-effect gravity gives what the file with "disabled_effects": ["gravity"] gives;
#   * --disturbance ACTUATOR=VALUE@TIME (a gust on the quadrotor held by an LQR) (the step shorthand) and the same as a JSON object give
#     the same run as the file's analysis.disturbances, with /u_disturbance recorded;
#     --reference likewise;
#   * unknown names and bad signals are refused (exit code 1) naming the flag and the field.
# Usage: plant_flags.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"; cd "$work"
fail() { echo "FAIL: $*"; exit 1; }
PY=/usr/bin/python3
quad="$src/tests/data/quadrotor.json"
before=$(sha256sum "$quad")

# the edited files, written by Python from the original
"$PY" - "$quad" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
m["plant"] = {"inputs": ["rotor_3", "rotor_1"], "outputs": ["heading", "z"]}
json.dump(m, open("edited.json", "w"), indent=1)
m["analysis"]["disabled_effects"] = ["gravity"]
json.dump(m, open("no_gravity.json", "w"), indent=1)
m = json.load(open(sys.argv[1]))
m["analysis"].update({"controller": "lqr",
                      "disturbances": [{"actuator": "gust", "type": "step", "time": 0.2, "value": 0.5}],
                      "references": [{"output": "z", "type": "step", "time": 0.1, "value": 0.3}]})
json.dump(m, open("signals.json", "w"), indent=1)
PY
"$codyna" linearize "$quad" --inputs rotor_3,rotor_1 --outputs heading,z --out flags > /dev/null || fail "linearize --inputs --outputs"
"$codyna" linearize edited.json --out edited > /dev/null || fail "linearize edited.json"
"$codyna" linearize "$quad" --inputs rotor_3,rotor_1 --outputs heading,z --disable-effect gravity --out flags_ng > /dev/null || fail "--disable-effect"
"$codyna" linearize no_gravity.json --out edited_ng > /dev/null || fail "linearize no_gravity.json"
[ "$before" = "$(sha256sum "$quad")" ] || fail "the model file changed"
"$PY" - <<'PY'
import sys, scipy.io
import numpy as np
for a, b in (("flags/quadrotor.mat", "edited/quadrotor.mat"), ("flags_ng/quadrotor.mat", "edited_ng/quadrotor.mat")):
    x, y = scipy.io.loadmat(a), scipy.io.loadmat(b)
    for k in ("A", "B", "C", "D", "x0", "u0", "y0", "xdot0"):
        if x[k].shape != y[k].shape or not np.array_equal(x[k], y[k]): sys.exit(f"{a}: {k} differs from {b}")
    for k in ("input_names", "output_names", "state_names"):
        if [str(n[0]) for n in x[k].ravel()] != [str(n[0]) for n in y[k].ravel()]: sys.exit(f"{a}: {k} differs")
x = scipy.io.loadmat("flags/quadrotor.mat")
names = [str(n[0]) for n in x["input_names"].ravel()], [str(n[0]) for n in x["output_names"].ravel()]
if names != (["rotor_3", "rotor_1"], ["heading", "z"]): sys.exit(f"selection {names}")
g = scipy.io.loadmat("flags_ng/quadrotor.mat")
if np.array_equal(g["A"], x["A"]): sys.exit("--disable-effect gravity changed nothing")
print("SELECTION_OK B", x["B"].shape, "bit for bit as the edited file; gravity off likewise")
PY

# signals: the shorthand, the JSON form and the file give one run
common=(--t-end 0.6 --output-step 0.01 --quiet)
"$codyna" simulate signals.json "${common[@]}" --out file.h5 > /dev/null 2> file.err || fail "signals.json: $(cat file.err)"
"$codyna" simulate "$quad" --lqr --disturbance gust=0.5@0.2 --reference z=0.3@0.1 "${common[@]}" --out short.h5 > /dev/null 2> short.err || fail "shorthand: $(cat short.err)"
"$codyna" simulate "$quad" --lqr --disturbance '{"actuator": "gust", "type": "step", "time": 0.2, "value": 0.5}' \
  --reference '{"output": "z", "type": "step", "time": 0.1, "value": 0.3}' "${common[@]}" --out json.h5 > /dev/null 2> json.err || fail "JSON: $(cat json.err)"
"$PY" - <<'PY'
import sys, h5py
import numpy as np
runs = {n: h5py.File(n + ".h5", "r") for n in ("file", "short", "json")}
for n in ("short", "json"):
    for k in ("time", "q", "v", "u", "y", "u_disturbance", "y_reference"):
        if not np.array_equal(runs[n][k][()], runs["file"][k][()]): sys.exit(f"{n}: /{k} differs from the file's run")
f = runs["file"]
d = f["u_disturbance"][()]
names = [x.decode() if isinstance(x, bytes) else x for x in f["names/inputs"][()]]
col = names.index("gust")
t = f["time"][()]
if not (d[t < 0.2 - 1e-9, col] == 0).all() or not np.allclose(d[t > 0.2 + 1e-9, col], 0.5): sys.exit("the gust is not the step")
z = f["y"][()][:, [x.decode() if isinstance(x, bytes) else x for x in f["names/outputs"][()]].index("z")]
print(f"SIGNALS_OK shorthand, JSON and file runs equal bit for bit; z(end) = {z[-1]:.4f} (from 1 toward the reference 0.3)")
PY

# refusals name the flag
expect() {  # expect RC TEXT -- command...
  local want="$1" text="$2"; shift 2
  local rc=0
  "$@" > /dev/null 2> err.txt || rc=$?
  [ "$rc" -eq "$want" ] || fail "exit $rc (expected $want) for $*: $(cat err.txt)"
  grep -qF -- "$text" err.txt || fail "message for $*: $(cat err.txt)"
}
expect 1 '--inputs: no actuator named "rotor_9" (actuators: rotor_1, rotor_2, rotor_3, rotor_4, yaw, gust)' "$codyna" linearize "$quad" --inputs rotor_9 --out bad
expect 1 '--outputs: no sensor named "alt" (sensors: x, y, z, heading)' "$codyna" simulate "$quad" --outputs alt --out bad.h5
expect 1 '--disable-effect: no effect named "gravit" (effects: gravity)' "$codyna" simulate "$quad" --disable-effect gravit --out bad.h5
expect 1 '--disturbance yaw=abc: expected a finite number for the value' "$codyna" simulate "$quad" --disturbance yaw=abc --out bad.h5
expect 1 '--disturbance: /analysis/disturbances/0/amplitude: expected a number' "$codyna" simulate "$quad" --disturbance '{"actuator": "yaw", "type": "sine", "amplitude": "x"}' --out bad.h5
expect 1 '--reference z: expected NAME=VALUE[@TIME]' "$codyna" simulate "$quad" --reference z --out bad.h5
[ ! -e bad.h5 ] && [ ! -e bad ] || fail "a refused run wrote output"
echo "REFUSALS_OK"
