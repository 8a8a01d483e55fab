#!/usr/bin/env bash
# codyna export-mjcf (issue 20): examples written as MJCF (MuJoCo loads each before it is written,
# where codyna has MuJoCo), a URDF imported and exported back, and the refusals with exit code 1 and
# nothing written: an element without an MJCF equivalent (a bushing), the model file itself as the
# output (also through a link), a file codyna did not write, a missing or malformed model file.
# usage: export_mjcf.sh CODYNA SOURCE_DIR WORK_DIR
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
  [ "$rc" -eq "$code" ] || fail "$* exited $rc, expected $code: $(cat out.txt err.txt)"
  grep -qF -- "$phrase" out.txt err.txt || fail "$*: output lacks \"$phrase\": $(cat out.txt err.txt)"
}

cp "$src/examples/cart_pendulum.json" "$src/examples/four_bar.json" "$src/examples/heavy_top.json" .
expect 0 "wrote cp.xml: 2 bodies, 2 joints, 1 actuators, 0 equalities" -- "$codyna" export-mjcf cart_pendulum.json --out cp.xml
head -n 1 cp.xml | grep -qF "<!-- MJCF written by codyna" || fail "cp.xml's first line: $(head -n 1 cp.xml)"
grep -qF '<joint name="cart_slider" type="slide"' cp.xml || fail "no slide joint in cp.xml: $(cat cp.xml)"
# again: a file codyna wrote is replaced
expect 0 "wrote cp.xml" -- "$codyna" export-mjcf cart_pendulum.json --out cp.xml
expect 0 "1 loop closures -> connect equalities" -- "$codyna" export-mjcf four_bar.json --out fb.xml
expect 0 "the initial state (q0, v0, u0) -> keyframe initial" -- "$codyna" export-mjcf heavy_top.json --out top.xml

# a URDF imported, then exported back
if "$codyna" import "$src/tests/data/import/arm7.urdf" --out arm7.json > /dev/null 2> probe.txt; then
  expect 0 "wrote arm7.xml: 9 bodies, 7 joints, 7 actuators" -- "$codyna" export-mjcf arm7.json --out arm7.xml
elif ! grep -q "built without" probe.txt; then
  fail "arm7.urdf not imported: $(cat probe.txt)"
fi

# refusals: exit 1, the reason named, nothing written, the inputs as they were
sum0=$(sha256sum cart_pendulum.json | cut -d' ' -f1)
expect 1 "this is the input file" -- "$codyna" export-mjcf cart_pendulum.json --out cart_pendulum.json
ln -s cart_pendulum.json link.xml
expect 1 "this is the input file" -- "$codyna" export-mjcf cart_pendulum.json --out link.xml
[ "$(sha256sum cart_pendulum.json | cut -d' ' -f1)" = "$sum0" ] || fail "cart_pendulum.json changed"
echo '<mujoco model="mine"/>' > mine.xml
expect 1 "is not an MJCF export written by codyna" -- "$codyna" export-mjcf cart_pendulum.json --out mine.xml
grep -qF 'model="mine"' mine.xml || fail "mine.xml was replaced"
/usr/bin/python3 - <<'PY'
import json
m = json.load(open("cart_pendulum.json"))
m["effects"].append({"name": "mount", "type": "bushing", "body_a": "cart", "body_b": "rod",
                     "translational_stiffness": [100, 100, 100]})
json.dump(m, open("bushing.json", "w"), indent=1)
PY
expect 1 "bushing mount: a 6-component spring-damper between two frames has no MJCF equivalent" -- \
  "$codyna" export-mjcf bushing.json --out bushing.xml
[ ! -e bushing.xml ] || fail "bushing.xml written although the export was refused"
ls -a | grep -q "tmp" && fail "a temporary file was left: $(ls -a)"
expect 1 "no_such.json" -- "$codyna" export-mjcf no_such.json --out x.xml
echo '{"codyna_model": 1, "bodies": [' > broken.json
expect 1 "broken.json" -- "$codyna" export-mjcf broken.json --out broken.xml
[ ! -e broken.xml ] || fail "broken.xml written"

[ "$fails" -eq 0 ] && echo "export_mjcf: all checks passed"
exit "$fails"
