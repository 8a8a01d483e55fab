#!/usr/bin/env bash
# Regression tests for bad input and faults at the command line: a user's model is
# never overwritten, every number is checked where it enters, runs that would not end
# are refused before they start, divergence ends early, exit codes are 0, 1 or 2.
# Usage: bad_input.sh CODYNA SOURCE_DIR WORK_DIR
set -uo pipefail
codyna="$1"; src="$2"; work="$3"
umount "$work/full" 2> /dev/null || true
rm -rf "$work"; mkdir -p "$work"; cd "$work"
trap 'umount "$work/full" 2> /dev/null || true' EXIT
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

# expect CODE PHRASE -- command...: the exit code and a phrase of stderr
expect() {
  local code="$1" phrase="$2"; shift 3
  "$@" > out.txt 2> err.txt
  local rc=$?
  [ "$rc" -eq "$code" ] || fail "$* exited $rc, expected $code: $(cat err.txt)"
  grep -qF -- "$phrase" err.txt || fail "$*: stderr lacks \"$phrase\": $(cat err.txt)"
}

cp "$src/examples/pendulum.json" model.json
sum0=$(sha256sum model.json | cut -d' ' -f1)

# the model is never an output: directly, through a symlink, a hard link, as CSV, or as NAME.m
expect 1 "the input file" -- "$codyna" simulate model.json --out model.json --quiet
ln -s model.json link.h5
expect 1 "the input file" -- "$codyna" simulate model.json --out link.h5 --quiet
ln model.json hard.csv
expect 1 "the input file" -- "$codyna" simulate model.json --out r.h5 --csv hard.csv --quiet
cp model.json pendulum.m
expect 1 "the input file" -- "$codyna" linearize pendulum.m --out .
[ "$(sha256sum model.json | cut -d' ' -f1)" = "$sum0" ] || fail "model.json changed"
[ "$(sha256sum pendulum.m | cut -d' ' -f1)" = "$sum0" ] || fail "pendulum.m changed"
# a file codyna did not write is not replaced either
echo "my notes" > notes.csv
expect 1 "never replaces a file it did not write" -- "$codyna" simulate model.json --out r.h5 --csv notes.csv --quiet
[ "$(cat notes.csv)" = "my notes" ] || fail "notes.csv changed"
[ ! -e r.h5 ] || fail "r.h5 written although the run was refused"
expect 1 "the same file as --out" -- "$codyna" simulate model.json --out same.out --csv same.out --quiet

# numbers checked where they enter, with the flag named
for flag in "--t-end nan" "--t-end inf" "--t-end -5" "--rtol -1" "--rtol 2" "--atol nan" "--max-step -1" "--output-step 0"; do
  set -- $flag
  expect 1 "$1" -- "$codyna" simulate model.json --out r.h5 --quiet $flag
done
expect 1 "time=T" -- "$codyna" linearize model.json --out lin --operating-point time=inf
expect 1 "expected a finite number" -- "$codyna" linearize model.json --out lin --set pivot=inf
# a study value given on the command line is refused naming the flag and what was typed, not the model
# file's field (the file does not have it)
cart="$src/examples/cart_pendulum.json"
expect 1 "--r-weights: weight 1 is -1: expected a number > 0" -- "$codyna" linearize "$cart" --out lin --closed-loop --lqr --r-weights -1
expect 1 "--q-weights: expected 4 weights (one per state), got 2" -- "$codyna" linearize "$cart" --out lin --closed-loop --lqr --q-weights 1,2
expect 1 "--discrete: a sample time of 1e+300 s is too long for this plant" -- "$codyna" linearize "$cart" --out lin --discrete 1e300
expect 1 "--hold pivot: expected NAME=VALUE" -- "$codyna" linearize "$cart" --out lin --hold pivot
expect 1 "--hold cart: unknown coordinate" -- "$codyna" linearize "$cart" --out lin --hold cart=1
expect 1 "--target foo: output \"foo\" is not in Plant/Out" -- "$codyna" linearize "$cart" --out lin --target foo=1
expect 1 "--initial cart: unknown coordinate" -- "$codyna" simulate "$cart" --out r.h5 --quiet --initial cart=0.1
expect 1 "--r-weights: weight 1 is 0" -- "$codyna" simulate "$cart" --out r.h5 --quiet --lqr --r-weights 0
[ ! -e lin ] || fail "lin/ written although every linearization above was refused"
# runs that would not end are refused before they start, with the number and the flag that raises the bound
start=$(date +%s)
expect 1 "--max-samples" -- "$codyna" simulate model.json --out r.h5 --quiet --t-end 1e9
expect 1 "--max-samples" -- "$codyna" simulate model.json --out r.h5 --quiet --output-step 1e-12
expect 1 "1e9" -- "$codyna" simulate model.json --out r.h5 --quiet --integrator rk4 --max-step 1e-12
expect 1 "--max-step" -- "$codyna" simulate model.json --out r.h5 --quiet --integrator ida --max-step 1e-12
expect 1 "--trajectory-step" -- "$codyna" linearize model.json --out lin --trajectory 1e9
# alf's settings: each bad value refused with its flag; good ones used and said
held="$src/examples/four_bar_held.json"
expect 1 "--alf-penalty" -- "$codyna" simulate "$held" --out r.h5 --quiet --integrator alf --alf-penalty 0
expect 1 "--alf-iterations" -- "$codyna" simulate "$held" --out r.h5 --quiet --integrator alf --alf-iterations 0
expect 1 "--max-step" -- "$codyna" simulate "$held" --out r.h5 --quiet --integrator alf --alf-fixed-step --max-step 9 --t-end 1
[ ! -e r.h5 ] || fail "r.h5 written although the alf runs were refused"
"$codyna" simulate "$held" --out alf.h5 --quiet --integrator alf --alf-fixed-step --max-step 0.005 --alf-penalty 1e10 \
  --t-end 1 > alf.txt 2>&1 || fail "alf at fixed steps: $(cat alf.txt)"
grep -q "alf (fixed steps of 0.005 s, penalty 1e+10, at most 100 iterations a step, Newton at rtol" alf.txt ||
  fail "alf's settings not said: $(grep integrator alf.txt)"
grep -q ": 200 steps" alf.txt || fail "alf at 5 ms over 1 s: $(grep integrator alf.txt)"
[ $(( $(date +%s) - start )) -lt 20 ] || fail "refusing the runs took more than 20 s"

# a degenerate mechanism: refused clearly by simulate, never a crash
python3 - "$src/examples/pendulum.json" > fixed.json <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
m["joints"][0]["type"] = "fixed"
for k in ("axis", "q0", "v0"): m["joints"][0].pop(k, None)
m.pop("controller", None); m["actuators"] = []; m["sensors"] = []; m["plant"] = {"inputs": [], "outputs": []}
json.dump(m, sys.stdout)
PY
for integ in ida cvode-bdf rk4; do
  expect 1 "no degrees of freedom" -- "$codyna" simulate fixed.json --out f.h5 --quiet --integrator $integ
done
# a loop closed on a body that nothing moves (a welded plate pinned away from its place): the
# assembly has no coordinate to move; it crashed (an empty matrix decomposed) before 2026-11, and
# is refused before the assembly now
cat > welded_loop.json <<'JSON'
{"name": "welded_loop",
 "bodies": [{"name": "plate", "mass": 1, "inertia": [0.01, 0.01, 0.01]}],
 "joints": [{"name": "weld", "type": "fixed", "parent": "ground", "child": "plate"}],
 "constraints": [{"name": "pin", "type": "ball", "body_a": "ground", "point_a": [1, 0, 0], "body_b": "plate", "point_b": [0, 0, 0]}]}
JSON
expect 1 "/constraints/0: a loop closure needs a joint that moves" -- "$codyna" info welded_loop.json

# divergence ends the run early, with the reason and the partial result (exit 2)
python3 - "$src/examples/pendulum.json" > unstable.json <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
m["controller"]["kp"] = [[-1e9]]
m["controller"].pop("kd", None); m["controller"].pop("ki", None)
json.dump(m, sys.stdout)
PY
start=$(date +%s)
expect 2 "diverged" -- "$codyna" simulate unstable.json --out u.h5 --quiet --t-end 100
[ $(( $(date +%s) - start )) -lt 20 ] || fail "the diverging run took more than 20 s"
[ -s u.h5 ] || fail "no partial result after divergence"

# a sampled (LTI) controller with a tiny sample time is refused before the run, not spun through
python3 - "$src/examples/pendulum.json" > tinyts.json <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
m["controller"] = {"type": "lti", "Ac": [[0]], "Bc": [[1]], "Cc": [[1]], "Dc": [[-1]], "Ts": 1e-12, "operating_point": "equilibrium"}
json.dump(m, sys.stdout)
PY
start=$(date +%s)
expect 1 "sample time" -- "$codyna" simulate tinyts.json --out ts.h5 --quiet
expect 1 "max-samples" -- "$codyna" simulate tinyts.json --out ts.h5 --quiet
[ $(( $(date +%s) - start )) -lt 20 ] || fail "refusing a tiny sample time took more than 20 s"
[ ! -e ts.h5 ] || fail "a refused run wrote ts.h5"

# a model controller declared about an equilibrium that does not exist is refused, as linearize refuses it
python3 - "$src/examples/pendulum.json" > noeq.json <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
for e in m["effects"]:
    if e["type"] == "gravity": e["g"] = [0, 0, 0]
m["effects"].append({"name": "push", "type": "body_force", "body": m["bodies"][0]["name"], "force": [0, 0, 0], "torque": [0, 0, 5]})
m["controller"] = {"type": "lqr", "operating_point": "equilibrium"}
json.dump(m, sys.stdout)
PY
# (a search that does not converge is a failure of the work, exit code 2, and writes nothing)
expect 2 "equilibrium: not converged: the residual accelerations are" -- "$codyna" simulate noeq.json --out noeq.h5 --quiet
[ ! -e noeq.h5 ] || fail "noeq.h5 written about an equilibrium that was not found"
expect 2 "equilibrium: not converged: the residual accelerations are" -- "$codyna" linearize noeq.json --out lin
[ ! -e lin ] || fail "lin/ exported about an equilibrium that was not found"
# an empty Plant/In is said
python3 - "$src/examples/pendulum.json" > noin.json <<'PY'
import json, sys
m = json.load(open(sys.argv[1])); m["plant"]["inputs"] = []; m.pop("controller", None)
json.dump(m, sys.stdout)
PY
expect 0 "no Plant/In" -- "$codyna" linearize noin.json --out lin --operating-point initial

# exit codes: argument errors are 1, an unknown command is named with the list
expect 1 "unknown command \"frobnicate\"" -- "$codyna" frobnicate
expect 1 "commands: info, linearize, simulate" -- "$codyna" frobnicate
expect 1 "--no-such-flag" -- "$codyna" simulate model.json --out r.h5 --no-such-flag
expect 1 "model is required" -- "$codyna" simulate

# SIGTERM during a long run leaves no temporary file behind
"$codyna" simulate model.json --out long.h5 --csv long.csv --quiet --t-end 20000 --output-step 0.002 > /dev/null 2>&1 &
pid=$!
sleep 2
kill -TERM $pid 2>/dev/null
wait $pid 2>/dev/null
ls -a | grep -q "\.tmp-" && fail "temporary files left after SIGTERM: $(ls -a | grep tmp-)"

# model paths that are not model files: never a hang or a bad_alloc
mkfifo model.fifo
start=$(date +%s)
expect 1 "not a regular file" -- timeout 20 "$codyna" info model.fifo
expect 1 "not a regular file" -- timeout 20 "$codyna" info /dev/zero
expect 1 "is a directory" -- "$codyna" info .
[ $(( $(date +%s) - start )) -lt 10 ] || fail "refusing a FIFO or /dev/zero took too long"

# controller files whose K is not a real 2-D matrix say so (Octave writes them)
if command -v octave-cli > /dev/null; then
  octave-cli --no-gui --quiet --eval "K = [1+2i 3 4 5]; save('-v7','kc.mat','K'); K = sparse([1 2 3 4]); save('-v7','ks.mat','K'); K = ones(1,4,2); save('-v7','k3.mat','K');" > /dev/null 2>&1
  cp "$src/examples/cart_pendulum.json" cart.json
  expect 1 "K cannot be used (complex)" -- "$codyna" simulate cart.json --controller kc.mat --out k.h5 --quiet
  expect 1 "K cannot be used (sparse" -- "$codyna" simulate cart.json --controller ks.mat --out k.h5 --quiet
  expect 1 "K cannot be used (3-D" -- "$codyna" simulate cart.json --controller k3.mat --out k.h5 --quiet
  head -c 150 kc.mat > truncated.mat
  expect 1 "truncated or corrupt" -- "$codyna" simulate cart.json --controller truncated.mat --out k.h5 --quiet
else
  echo "bad_input: octave-cli not found, controller-file checks skipped"
fi

# a full disk: the error is reported, the old files are kept, no temporary is left, no crash
# (HDF5 once crashed at exit after a failed flush); needs a small tmpfs, so root
mkdir -p full
if [ "$(id -u)" -eq 0 ] && mount -t tmpfs -o size=64k tmpfs full 2> /dev/null; then
  "$codyna" linearize model.json --out full > /dev/null 2>&1 || fail "the first export into the small disk failed"
  old=$(sha256sum full/pendulum.mat | cut -d' ' -f1)
  dd if=/dev/zero of=full/filler bs=1k count=52 2> /dev/null
  expect 2 "full/pendulum.mat" -- "$codyna" linearize model.json --out full --mat-version 7.3
  grep -q "HDF5-DIAG" err.txt && fail "HDF5 printed its own diagnostics"
  [ "$(sha256sum full/pendulum.mat | cut -d' ' -f1)" = "$old" ] || fail "the old pendulum.mat changed on a full disk"
  rm -f full/filler; dd if=/dev/zero of=full/filler bs=1k count=40 2> /dev/null
  expect 2 "r.h5" -- "$codyna" simulate model.json --out full/r.h5 --quiet
  ls -a full | grep -q "\.tmp-" && fail "temporary files left on the full disk"
  umount full
else
  echo "bad_input: cannot mount a small tmpfs here (not root?), full-disk checks skipped"
fi

if [ "$fails" -eq 0 ]; then echo "bad_input: all checks passed"; else echo "bad_input: $fails failed"; exit 1; fi
