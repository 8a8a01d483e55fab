#!/usr/bin/env bash
# codyna import (issue 20): MuJoCo's own humanoid (libmujoco-samples) imported with its armature
# (rotor inertia, as the joints' armature) and linearized at once, then with --ignore armature; a URDF imported and linearized;
# the refusals (no file, a malformed file, an output over the input or over a file codyna did
# not write, an unknown --ignore kind) with exit code 1 and the input left as it was.
# usage: import_models.sh CODYNA SOURCE_DIR WORK_DIR
set -uo pipefail
codyna="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"; cd "$work"
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

# expect CODE PHRASE -- command...: the exit code and a phrase of stdout + stderr
expect() {
  local code="$1" phrase="$2"; shift 3
  "$@" > out.txt 2> err.txt
  local rc=$?
  [ "$rc" -eq "$code" ] || fail "$* exited $rc, expected $code: $(cat err.txt)"
  grep -qF -- "$phrase" out.txt err.txt || fail "$*: output lacks \"$phrase\": $(cat out.txt err.txt)"
}

data="$src/tests/data/import"
humanoid=/usr/share/mujoco/model/humanoid/humanoid.xml
if "$codyna" import "$data/double_pendulum.urdf" --out probe.json > /dev/null 2> probe.txt ||
   ! grep -q "built without" probe.txt; then :; else
  echo "import_models: this codyna was built without urdfdom; skipped"; exit 77
fi

# URDF: imported, every joint an actuator and an output, linearized about the hanging rest
expect 0 "wrote dp.json: 2 bodies, 2 joints, DOF 2" -- "$codyna" import "$data/double_pendulum.urdf" --out dp.json
grep -qF "every actuator as Plant/In (2), every joint coordinate as Plant/Out (2)" out.txt || fail "URDF plant line: $(cat out.txt)"
expect 0 "A (4 x 4)" -- "$codyna" linearize dp.json --operating-point initial --out lin_dp
[ -f lin_dp/double_pendulum.mat ] || fail "lin_dp/double_pendulum.mat not written"

if [ -f "$humanoid" ] && ! "$codyna" import "$humanoid" --out probe.json 2>&1 | grep -q "built without"; then
  cp "$humanoid" humanoid.xml
  sum0=$(sha256sum humanoid.xml | cut -d' ' -f1)
  # the armature (rotor inertia) is the joints' armature: the issue's command as it is
  expect 0 "wrote h.json: 25 bodies, 25 joints, DOF 27 (nq 28, nv 27), 21 Plant/In, 27 Plant/Out" -- \
    "$codyna" import humanoid.xml --ignore contacts --out h.json
  grep -qF "21 joint armatures (rotor inertia) -> joint armature" out.txt || fail "no armature mapped line: $(cat out.txt)"
  grep -qF "contacts (ignored): contacts are not modelled" out.txt || fail "no contacts line: $(cat out.txt)"
  grep -qF "limits: joint limits" out.txt || fail "no limits line: $(cat out.txt)"
  [ "$(grep -c '"armature": 0.01' h.json)" -eq 21 ] || fail "h.json does not hold 21 armatures of 0.01: $(grep -c armature h.json)"
  expect 0 "A (54 x 54)" -- "$codyna" linearize h.json --operating-point initial --out lin_arm
  # --ignore armature leaves it out, and says so once
  expect 0 "wrote h.json: 25 bodies, 25 joints, DOF 27 (nq 28, nv 27), 21 Plant/In, 27 Plant/Out" -- \
    "$codyna" import humanoid.xml --ignore armature,contacts --out h.json
  grep -qF "armature (changes the dynamics; ignored by --ignore armature): rotor inertia (armature) left out as --ignore armature asks: abdomen_z 0.01" out.txt ||
    fail "no armature line: $(cat out.txt)"
  ! grep -qF '"armature"' h.json || fail "h.json holds an armature although --ignore armature"
  expect 0 "DOF          27" -- "$codyna" info h.json
  expect 0 "A (54 x 54)" -- "$codyna" linearize h.json --operating-point initial --out lin
  [ -f lin/Humanoid.mat ] && [ -f lin/Humanoid.m ] || fail "lin/Humanoid.mat, .m not written: $(ls lin)"
  # an output over the input (directly or through a link) is refused; so is a file codyna did not write
  expect 1 "the input file" -- "$codyna" import humanoid.xml --ignore armature --out humanoid.xml
  ln -s humanoid.xml link.json
  expect 1 "the input file" -- "$codyna" import humanoid.xml --ignore armature --out link.json
  echo "my notes" > notes.json
  expect 1 "is not a codyna model file" -- "$codyna" import humanoid.xml --ignore armature --out notes.json
  [ "$(cat notes.json)" = "my notes" ] || fail "notes.json changed"
  [ "$(sha256sum humanoid.xml | cut -d' ' -f1)" = "$sum0" ] || fail "humanoid.xml changed"
  # a model file codyna wrote may be written again
  expect 0 "wrote h.json" -- "$codyna" import humanoid.xml --ignore armature --out h.json
else
  echo "import_models: $humanoid missing or no MJCF import in this build; humanoid checks skipped"
fi

# refusals, exit code 1
expect 1 "nothing.xml: cannot open file" -- "$codyna" import nothing.xml --out x.json
expect 1 "bad.urdf: not a valid URDF" -- "$codyna" import "$data/bad.urdf" --out x.json
expect 1 "--ignore contact: unknown kind" -- "$codyna" import "$data/double_pendulum.urdf" --ignore contact --out x.json
echo '{"not": "a model"}' > plain.txt
expect 1 "neither MJCF" -- "$codyna" import plain.txt --out x.json
if "$codyna" import "$data/four_bar_connect.xml" --out fb.json > /dev/null 2>&1; then
  expect 1 "MuJoCo cannot read it" -- "$codyna" import "$data/bad.xml" --out x.json
  grep -qF "line 6" err.txt || fail "the MJCF error does not name the line: $(cat err.txt)"
  expect 0 "DOF          1" -- "$codyna" info fb.json
fi
[ ! -e x.json ] || fail "x.json written by a refused import"

if [ "$fails" -eq 0 ]; then echo "import_models: all checks passed"; else echo "import_models: $fails failed"; exit 1; fi
