#!/usr/bin/env bash
# codyna maneuver (study/maneuver_job.hpp): the constant-radius points are the steady turns codyna
# linearize finds at the same radius and speed (its printed steer, 6 digits), the step steer's
# yaw-rate gain is the handling number codyna linearize prints, files are written and read back,
# and bad input is refused naming the flag or the field, exit 1.
# Usage: maneuver.sh CODYNA SOURCE_DIR WORK_DIR
set -uo pipefail
codyna="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"; cd "$work"
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
expect() {
  local code="$1" phrase="$2"; shift 2
  "$@" > out.txt 2> err.txt
  local rc=$?
  [ "$rc" -eq "$code" ] || fail "$* exited $rc, expected $code: $(cat err.txt)"
  grep -qF -- "$phrase" err.txt || fail "$*: stderr lacks \"$phrase\": $(cat err.txt)"
}
py=/usr/bin/python3
car="$src/examples/single_track_car.json"
driver="$src/tests/data/single_track_car_driver.json"

# constant radius: each point's steer is codyna linearize's at that radius and speed
"$codyna" maneuver "$car" --type constant-radius --radius 120 --speed-min 10 --speed-max 30 --points 3 \
  --free-input steer,drive --csv cr.csv > out.txt 2> err.txt || fail "constant radius: exit $?: $(cat err.txt)"
grep -q "understeer gradient at the lowest a_y" out.txt || fail "constant radius: $(cat out.txt)"
while IFS=, read -r speed ay steer rest; do
  [ "$speed" = speed ] && continue
  "$codyna" linearize "$car" --radius 120 --speed "$speed" --free-input steer,drive --out lin > lin.txt 2>&1 ||
    fail "linearize at $speed: $(cat lin.txt)"
  lin=$(sed -n 's/^ *steer = \([-0-9.e+]*\).*/\1/p' lin.txt | head -1)
  $py -c "import sys; a, b = float('$steer'), float('$lin'); sys.exit(0 if abs(a - b) <= 1e-5 * abs(b) else 1)" ||
    fail "constant radius at $speed m/s: steer $steer, linearize $lin"
done < cr.csv
[ "$(wc -l < cr.csv)" -eq 4 ] || fail "cr.csv: $(cat cr.csv)"

# step steer: the yaw-rate gain at a small steer is the handling number (7.03443 1/s at 30 m/s)
"$codyna" maneuver "$car" --type step-steer --steer 0.001 --out step.h5 --csv step.csv > out.txt 2> err.txt ||
  fail "step steer: exit $?: $(cat err.txt)"
gain=$(awk '/^yaw rate/{y=1} y && /steady-state gain/{print $3; exit}' out.txt)
$py -c "import sys; sys.exit(0 if abs(float('$gain') - 7.03443) < 1e-3 * 7.03443 else 1)" || fail "step steer gain $gain: $(cat out.txt)"
[ -s step.h5 ] && [ -s step.csv ] || fail "step steer: no files"
grep -q "wrote step.h5" out.txt || fail "step steer: $(cat out.txt)"

# sine with dwell on the single-track car (linear tires: it never spins)
"$codyna" maneuver "$car" --type sine-with-dwell --steer 0.02 > out.txt 2> err.txt || fail "sine with dwell: exit $?: $(cat err.txt)"
grep -q "yaw-rate ratio at 1.00 s" out.txt || fail "sine with dwell: $(cat out.txt)"

# the lane change driven by the driver of the model file
"$codyna" maneuver "$driver" --type double-lane-change --speed 22.2 --preview 6 > out.txt 2> err.txt || fail "lane change: exit $?: $(cat err.txt)"
grep -q "cones            none hit" out.txt || fail "lane change: $(cat out.txt)"
# a car whose file has no position sensors: the maneuver measures the chassis and says so
"$codyna" maneuver "$car" --type double-lane-change --speed 22.2 > out.txt 2> err.txt || fail "lane change, no sensors: exit $?: $(cat err.txt)"
grep -q 'sensors the maneuver added, the model having none of those names: "x"' err.txt || fail "lane change, no sensors: $(cat err.txt)"
grep -q "^path error       max" out.txt || fail "lane change, no sensors: $(cat out.txt)"

# bad input: named, exit 1, nothing written
expect 1 '--type: unknown maneuver "slalom"' "$codyna" maneuver "$car" --type slalom --csv bad.csv
[ -e bad.csv ] && fail "bad.csv written"
expect 1 '--preview: expected a number > 0, got -1' "$codyna" maneuver "$driver" --type double-lane-change --preview -1
expect 1 '--drive: the driver needs the actuator "throttle", which the model does not have (actuators: steer, drive)' \
  "$codyna" maneuver "$car" --type double-lane-change --drive throttle
expect 1 '--yaw: the driver needs the sensor "heading", which the model does not have' "$codyna" maneuver "$driver" --type double-lane-change --yaw heading
expect 1 '--radius: the constant-radius maneuver needs a radius' "$codyna" maneuver "$car" --type constant-radius
expect 1 '--radius: expected a radius other than 0' "$codyna" maneuver "$car" --type constant-radius --radius 0
sed 's/"preview": 15/"preview": -1/' "$driver" > neg.json
expect 1 'neg.json: /controller/preview: expected a number > 0, got number -1' "$codyna" maneuver neg.json --type double-lane-change

# the sedan: two constant-radius points on 1000 m, each codyna linearize's steer at its speed
"$codyna" maneuver "$src/examples/sedan.json" --type constant-radius --radius 1000 --speed-min 25 --speed-max 26 \
  --points 2 --csv sedan_cr.csv > out.txt 2> err.txt || fail "sedan constant radius: exit $?: $(cat err.txt)"
while IFS=, read -r speed ay steer rest; do
  [ "$speed" = speed ] && continue
  "$codyna" linearize "$src/examples/sedan.json" --radius 1000 --speed "$speed" --out lin > lin.txt 2>&1 ||
    fail "sedan linearize at $speed: $(cat lin.txt)"
  lin=$(sed -n 's/^ *steer = \([-0-9.e+]*\).*/\1/p' lin.txt | head -1)
  $py -c "import sys; a, b = float('$steer'), float('$lin'); sys.exit(0 if abs(a - b) <= 1e-5 * abs(b) else 1)" ||
    fail "sedan constant radius at $speed m/s: steer $steer, linearize $lin"
done < sedan_cr.csv

# the sedan with its yaw-rate controller: a swept sine refuses it (nothing written), --friction is
# checked, and the refusal of a controller on the steer names the field
esc="$src/examples/sedan_esc.json"
expect 1 '--open-loop: the model file has a pid controller' "$codyna" maneuver "$esc" --type swept-sine --csv esc.csv
[ -e esc.csv ] && fail "esc.csv written"
expect 1 '--friction: expected a number > 0, got -0.5' "$codyna" maneuver "$esc" --type step-steer --friction -0.5
$py - "$esc" "$src/examples" <<'PY' || fail "esc_steer.json not written"
import json, sys
m = json.load(open(sys.argv[1]))
m["plant"]["inputs"] = ["steer", "brake_fr"]
for e in m["effects"]:
    if "file" in e:
        e["file"] = sys.argv[2] + "/" + e["file"]
json.dump(m, open("esc_steer.json", "w"))
PY
expect 1 'esc_steer.json: /plant/inputs: the maneuver drives the steer "steer"' "$codyna" maneuver esc_steer.json --type step-steer

[ "$fails" -eq 0 ] && echo "maneuver: all passed"
exit $((fails > 0))
