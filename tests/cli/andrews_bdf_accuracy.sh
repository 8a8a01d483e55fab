#!/usr/bin/env bash
# The BDF integrators earn their tolerance (issue 11): Andrews' squeezer to
# t = 0.03 s at rtol = atol = 1e-10 through `codyna simulate`, scored by the
# Test Set's significant correct digits SCD = -log10(max_i |y_i - y_ref,i| / |y_ref,i|)
# over the seven angles against the Test Set's PSIDE reference (itself good to
# about SCD 10). IDA, CVODE BDF, auto and the default integrator (the model file's, auto) must each reach SCD 8.
# usage: andrews_bdf_accuracy.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*"; exit 1; }
PY=/usr/bin/python3; [ -x "$PY" ] || PY=python3

scd() {  # CSV file -> SCD of its last row
  "$PY" - "$1" <<'PYEOF'
import csv, math, sys
ref = {"beta": 15.81077119629904, "Theta": -15.75637105984298, "gamma": 0.04082224013073101,
       "Phi": -0.5347301163226948, "delta": 0.5244099658805304, "Omega": 0.5347301163226948,
       "epsilon": 1.048080741042263}
rows = list(csv.DictReader(open(sys.argv[1])))
last = rows[-1]
assert abs(float(last["t"]) - 0.03) < 1e-12, last["t"]
err = max(abs(float(last[k]) - v) / abs(v) for k, v in ref.items())
print("%.3f" % -math.log10(err))
PYEOF
}

for integ in ida cvode-bdf auto default; do
  flag=(); [ "$integ" = default ] || flag=(--integrator "$integ")
  "$codyna" simulate "$src/examples/andrews_squeezer.json" --open-loop "${flag[@]}" --t-end 0.03 \
    --rtol 1e-10 --atol 1e-10 --quiet --out "$work/$integ.h5" --csv "$work/$integ.csv" > "$work/$integ.txt" \
    || fail "$integ: codyna simulate exited with $?: $(cat "$work/$integ.txt")"
  s=$(scd "$work/$integ.csv")
  echo "$integ: SCD $s"
  "$PY" -c "import sys; sys.exit(0 if float('$s') >= 8.0 else 1)" || fail "$integ: SCD $s < 8 at rtol = atol = 1e-10"
done
echo PASS
