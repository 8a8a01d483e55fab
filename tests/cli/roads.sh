#!/usr/bin/env bash
# Roads beyond a plane (docs/roads.md) through `codyna simulate`: the quarter car over the CSV bump
# of examples/roads lifts its body by 21.2 mm, the one on the generated ISO 8608 class C road runs
# 10 s, the same road twice gives the same CSV, and a model whose road CSV is missing is refused
# (exit 1) naming the model file, the field and the CSV's path.
# Usage: roads.sh CODYNA SOURCE_DIR WORK_DIR
set -uo pipefail
codyna="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"; cd "$work"
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
py=/usr/bin/python3
roads="$src/examples/roads"

"$codyna" simulate "$roads/quarter_car_bump.json" --out bump.h5 --csv bump.csv --quiet > out.txt 2> err.txt \
  || fail "bump: exit $?: $(cat err.txt)"
grep -q "completed, t = 0 .. 2 s" out.txt || fail "bump: $(cat out.txt)"
$py - bump.csv <<'PY' || fail "bump: the body's peak heave"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
h = [float(r["heave"]) - float(rows[0]["heave"]) for r in rows]
peak = max(h)
print("bump: peak heave %.3f mm" % (1e3 * peak))
sys.exit(0 if abs(peak - 0.02122) < 2e-5 else 1)
PY

for run in 1 2; do
  "$codyna" simulate "$roads/quarter_car_iso8608.json" --out iso$run.h5 --csv iso$run.csv --quiet > out.txt 2> err.txt \
    || fail "iso8608: exit $?: $(cat err.txt)"
  grep -q "completed, t = 0 .. 10 s" out.txt || fail "iso8608: $(cat out.txt)"
done
cmp -s iso1.csv iso2.csv || fail "iso8608: two runs of the same seed differ"

# a missing CSV: refused, exit 1, naming the file, the field and the path
sed 's/bump_tracks.csv/no_such_tracks.csv/' "$roads/quarter_car_bump.json" > missing.json
"$codyna" simulate missing.json --out missing.h5 --quiet > out.txt 2> err.txt
rc=$?
[ "$rc" -eq 1 ] || fail "missing CSV: exit $rc, expected 1: $(cat err.txt)"
grep -qF "missing.json: /effects/2/road/profile/file: " err.txt || fail "missing CSV: $(cat err.txt)"
grep -qF "no_such_tracks.csv: cannot open the file" err.txt || fail "missing CSV: $(cat err.txt)"
[ ! -e missing.h5 ] || fail "missing CSV: a results file was written"

[ "$fails" -eq 0 ] && echo PASS || exit 1
