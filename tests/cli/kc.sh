#!/usr/bin/env bash
# codyna kc (the suspension K&C rig, study/kc_job.hpp) on the sedan's double-wishbone corner: the
# table and the CSV agree, the design point's kingpin inclination is the balls' closed form, the
# printed bump steer is the table's slope at design; the bushing corner complies under Fy; bad
# input is refused naming the option (exit 1), an unreachable travel exits 2, nothing written.
# Usage: kc.sh CODYNA SOURCE_DIR WORK_DIR
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
cp "$src/examples/kc_double_wishbone.json" corner.json
cp "$src/tests/data/kc_double_wishbone_bushing.json" bushing.json

"$codyna" kc corner.json --travel=-0.08:0.08:9 --steer-range=-0.02:0.02:5 --csv kc.csv > out.txt 2> err.txt \
  || fail "kc: exit $?: $(cat err.txt)"
grep -q "wrote kc.csv" out.txt || fail "no 'wrote kc.csv': $(cat out.txt)"
grep -q "kingpin 6.5198 deg" out.txt || fail "design kingpin: $(cat out.txt)"
$py - kc.csv out.txt <<'PY' || fail "the CSV and the printed gradients disagree"
import csv, math, re, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert len(rows) == 14, len(rows)
travel = [r for r in rows if r['sweep'] == 'travel']
steer = [r for r in rows if r['sweep'] == 'steer']
assert len(travel) == 9 and len(steer) == 5
design = travel[4]
assert float(design['travel_m']) == 0.0
assert abs(float(design['kingpin_deg']) - math.degrees(math.atan(0.04 / 0.35))) < 1e-9, design['kingpin_deg']
assert abs(float(design['toe_deg'])) < 1e-9 and abs(float(design['camber_deg'])) < 1e-9
text = open(sys.argv[2]).read()
bump = float(re.search(r'bump steer\s+(\S+) deg/m', text).group(1))
slope = (float(travel[5]['toe_deg']) - float(travel[3]['toe_deg'])) / 0.04
assert abs(bump - slope) < 0.02 * abs(bump), (bump, slope)
# the wheel centre follows the prescribed travel exactly
for r in travel:
    assert abs(float(r['wheel_z_m']) - (float(design['wheel_z_m']) + float(r['travel_m']))) < 1e-12, r
# the rack to the left: the left wheel toes in
assert float(steer[4]['toe_deg']) > 5, steer[4]
PY
# codyna's own K&C CSV may be replaced
"$codyna" kc corner.json --csv kc.csv > /dev/null 2>&1 || fail "a K&C CSV codyna wrote could not be replaced"

# the bushing corner: lateral-force compliance steer and camber, not zero
"$codyna" kc bushing.json --fy=-2000:2000:3 > out.txt 2> err.txt || fail "bushing: exit $?: $(cat err.txt)"
$py - out.txt <<'PY' || fail "the bushing corner does not comply: $(cat out.txt)"
import re, sys
text = open(sys.argv[1]).read()
m = re.search(r'Fy compliance steer\s+(\S+) deg/kN\s+camber\s+(\S+) deg/kN', text)
assert m and abs(float(m.group(1))) > 1e-3 and abs(float(m.group(2))) > 1e-3, m
PY

# the sedan's front axle (the chassis held on its free joint) rolled: the left wheel at +phi is the right one at -phi
"$codyna" kc "$src/examples/sedan.json" --wheel tire_fl --wheel tire_fr --roll=-4:4:5 --csv axle.csv > out.txt 2> err.txt \
  || fail "axle: exit $?: $(cat err.txt)"
grep -q "axle roll centre" out.txt || fail "no axle roll centre: $(cat out.txt)"
$py - axle.csv <<'PY' || fail "the sedan's axle is not symmetric in roll"
import csv, sys
rows = [r for r in csv.DictReader(open(sys.argv[1])) if r['sweep'] == 'roll']
assert len(rows) == 10, len(rows)
at = {(r['wheel'], float(r['roll_deg'])): r for r in rows}
for phi in (-4, -2, 0, 2, 4):
    l, r = at[('wheel_fl', phi)], at[('wheel_fr', -phi)]
    for k in ('camber_deg', 'toe_deg', 'track_change_m'):
        assert abs(float(l[k]) - float(r[k])) < 1e-9, (phi, k, l[k], r[k])
assert abs(float(at[('wheel_fl', 4)]['camber_deg'])) > 0.1
PY

# bad input: named, exit 1, nothing written
expect 1 "--wheel nope: no body or tire element of that name" "$codyna" kc corner.json --wheel nope --csv bad.csv
expect 1 "--travel 0.05:-0.05:5: expected MIN < MAX" "$codyna" kc corner.json --travel=0.05:-0.05:5 --csv bad.csv
expect 1 "--travel -0.05:0.05:1: expected a point count N from 2 to 10000" "$codyna" kc corner.json --travel=-0.05:0.05:1 --csv bad.csv
expect 1 "--fy 1:2: expected MIN:MAX:N" "$codyna" kc corner.json --fy 1:2 --csv bad.csv
expect 1 "--steer nope: no motion input of that name (motion inputs: rack)" "$codyna" kc corner.json --steer nope --csv bad.csv
expect 1 "--radius: expected a wheel radius > 0 m" "$codyna" kc corner.json --radius=-1 --csv bad.csv
expect 1 "corner.json" "$codyna" kc corner.json --csv corner.json
expect 1 "--roll: rolls an axle: give its two wheels" "$codyna" kc corner.json --roll=-2:2:3 --csv bad.csv
expect 2 "--travel 0.6: the suspension cannot reach it" "$codyna" kc corner.json --travel 0:0.6:3 --csv bad.csv
[ -e bad.csv ] && fail "bad.csv written on error"
cmp -s corner.json "$src/examples/kc_double_wishbone.json" || fail "the model file was changed"
echo "{" > broken.json
expect 1 "broken.json" "$codyna" kc broken.json --csv bad.csv
[ -e bad.csv ] && fail "bad.csv written on error"

[ "$fails" -eq 0 ] && echo "kc: all checks passed"
exit $((fails > 0))
