#!/usr/bin/env bash
# codyna tire (the tire test rig, study/tire_job.hpp): the CSV's values are MFeval 4.0's on its own
# grid (tests/data/tires/mfeval, 1e-9 relative), a model's tire element is evaluated with its law,
# the Fiala closed form holds, and bad input is refused naming the option, exit 1, nothing written.
# Usage: tire_rig.sh CODYNA SOURCE_DIR WORK_DIR
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
tires="$src/tests/data/tires"

# MFeval's combined-slip grid: loads 0.5, 1, 1.5 FNOMIN (the default), kappa and alpha in
# linspace(-0.3, 0.3, 13), gamma 0 and 0.05, Vx 16.7 m/s
for name in MagicFormula61_Paramerters PacejkaBook_Defaults MagicFormula52_Paramerters MagicFormula62_Paramerters; do
  "$codyna" tire --tir "$tires/$name.tir" --kappa=-0.3:0.3:13 --alpha=-0.3:0.3:13 --gamma 0,0.05 --speed 16.7 \
    --out "$name.csv" > out.txt 2> err.txt || fail "$name: exit $?: $(cat err.txt)"
  grep -q "points   1014" out.txt || fail "$name: $(cat out.txt)"
  $py - "$name.csv" "$tires/mfeval/$name.csv" <<'PY' || fail "$name: differs from MFeval"
import csv, sys
ours = list(csv.DictReader(open(sys.argv[1])))
ref = [list(map(float, r)) for r in csv.reader(open(sys.argv[2])) if r and not r[0].startswith(('#', 'F'))]
key = lambda fz, k, a, g: (round(fz, 6), round(k, 9), round(a, 9), round(g, 9))
table = {key(float(r['Fz']), float(r['kappa']), float(r['alpha']), float(r['gamma'])): r for r in ours}
worst = 0.0
for fz, k, a, g, vx, fx, fy, mz, mx, my, kxk, kya, re in ref:
    r = table[key(fz, k, a, g)]
    for ours_v, ref_v in ((r['Fx'], fx), (r['Fy'], fy), (r['Mz'], mz), (r['Mx'], mx), (r['My'], my),
                          (r['Kxk'], kxk), (r['Kya'], kya), (r['Re'], re)):
        worst = max(worst, abs(float(ours_v) - ref_v) / max(abs(ref_v), 1.0))
print(sys.argv[1], len(ref), 'points, worst relative difference', worst)
sys.exit(0 if len(ref) == 1014 and worst < 1e-9 else 1)
PY
done

# a model's tire element, with its own law: the single-track car's linear tire, Fy = -C alpha
"$codyna" tire --model "$src/examples/single_track_car.json" --tire front_tire --load 4000 --alpha=-0.02,0,0.03 \
  --out linear.csv > out.txt 2> err.txt || fail "model tire: $(cat err.txt)"
$py - linear.csv <<'PY' || fail "the linear tire's Fy is not -C alpha"
import csv
rows = list(csv.DictReader(open('linear.csv')))
assert len(rows) == 3, rows
for r in rows:
    a, fy = float(r['alpha']), float(r['Fy'])
    assert abs(fy - (-160000 * a)) <= 1e-9 * max(1, abs(fy)), (a, fy)
PY
# the same file again: codyna's own tire CSV may be replaced
"$codyna" tire --model "$src/examples/single_track_car.json" --tire front_tire --load 4000 --out linear.csv > /dev/null 2>&1 \
  || fail "a tire CSV codyna wrote could not be replaced"

# bad input: named, exit 1, nothing written
cp "$src/examples/single_track_car.json" model.json
sum0=$(sha256sum model.json | cut -d' ' -f1)
expect 1 "the input file" -- "$codyna" tire --model model.json --tire front_tire --load 4000 --out model.json
[ "$(sha256sum model.json | cut -d' ' -f1)" = "$sum0" ] || fail "the model was overwritten"
expect 1 "--tire nope: no such tire" -- "$codyna" tire --model model.json --tire nope --load 1 --out a.csv
expect 1 "--load: give the loads" -- "$codyna" tire --model model.json --tire front_tire --out a.csv
expect 1 "--alpha 0:1: expected a range A:B:N" -- "$codyna" tire --tir "$tires/PacejkaBook_Defaults.tir" --alpha 0:1 --out a.csv
expect 1 "--kappa x: expected a number" -- "$codyna" tire --tir "$tires/PacejkaBook_Defaults.tir" --kappa x --out a.csv
expect 1 "--side up: expected left or right" -- "$codyna" tire --tir "$tires/PacejkaBook_Defaults.tir" --side up --out a.csv
expect 1 "--speed: expected a forward speed > 0" -- "$codyna" tire --tir "$tires/PacejkaBook_Defaults.tir" --speed 0 --out a.csv
expect 1 "--tir or --model: give one" -- "$codyna" tire --out a.csv
printf '[MODEL]\nFITTYP = 99\n' > bad.tir
expect 1 "bad.tir" -- "$codyna" tire --tir bad.tir --out a.csv
[ ! -e a.csv ] || fail "a refused request wrote a.csv"

[ "$fails" -eq 0 ] && echo "tire rig: all passed"
exit "$fails"
