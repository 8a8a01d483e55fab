#!/usr/bin/env bash
# One naming scheme and readable printing (issue 21):
#   * every coordinate and rate that `codyna info` prints (a free joint's fly.rx .. fly.z and
#     fly.wx .. fly.vz, a ball's, the cart-pendulum's) is accepted by --hold, --initial and
#     --trim-free, and the exported state_names are exactly those names, in that order;
#   * a 12-state matrix is printed in blocks of columns ("columns 7 to 12 of 12"), no line
#     wider than 100 characters; the quadrotor's twelve zero modes are one row "1-12  0 (x12)"
#     with damping "-"; an equilibrium's xdot0 round-off prints as 0.
# Usage: names_and_printing.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"; cd "$work"
fail() { echo "FAIL: $*"; exit 1; }
PY=/usr/bin/python3

for model in "$src/tests/data/quadrotor.json" "$src/tests/data/spherical_pendulum.json" "$src/examples/pendulum.json"; do
  base=$(basename "$model" .json)
  "$codyna" info "$model" > "$base.info" || fail "info $model"
  coords=$(sed -n 's/^coordinates  //p' "$base.info" | sed 's/ \[[^]]*\]//g; s/, /,/g')
  rates=$(sed -n 's/^rates        //p' "$base.info" | sed 's/ \[[^]]*\]//g; s/, /,/g')
  [ -n "$coords" ] && [ -n "$rates" ] || fail "info lists no coordinates or rates: $(cat "$base.info")"
  "$codyna" linearize "$model" --operating-point initial --out "lin_$base" > "$base.lin" 2> "$base.err" || fail "linearize $model: $(cat "$base.err")"
  "$PY" - "lin_$base/$base.mat" "$coords,$rates" <<'PY'
import sys, scipy.io
names = [str(n[0]) for n in scipy.io.loadmat(sys.argv[1])["state_names"].ravel()]
want = sys.argv[2].split(",")
if names != want: sys.exit(f"exported state_names {names} != info's coordinates and rates {want}")
PY
  IFS=, read -ra all <<< "$coords,$rates"
  for name in "${all[@]}"; do
    for flag in --hold --initial; do
      "$codyna" simulate "$model" $flag "$name=0.05" --operating-point initial --t-end 0.01 --quiet --out run.h5 > /dev/null 2> bad.err ||
        fail "$flag $name=0.05 on $base refused: $(cat bad.err)"
    done
  done
  IFS=, read -ra cs <<< "$coords"
  for name in "${cs[@]}"; do
    rc=0
    "$codyna" linearize "$model" --operating-point trim --trim-free "$name" --out "trim_$base" > /dev/null 2> trim.err || rc=$?
    ! grep -q "unknown coordinate" trim.err || fail "--trim-free $name on $base: $(cat trim.err)"
  done
  echo "NAMES_OK $base: ${#all[@]} names, each accepted by --hold, --initial (and the coordinates by --trim-free), equal to state_names"
done

# printing
q="$work/quadrotor.lin"
grep -q '^  columns 7 to 12 of 12$' "$q" || fail "A not wrapped: $(cat "$q")"
long=$(awk 'length > 100 && !/^1-12 /' "$q" | head -1)
[ -z "$long" ] || fail "a line wider than 100 characters: $long"
grep -Eq '^1-12  0 \(x12\) +0 +0 +- +fly\.rx, fly\.ry, fly\.rz, fly\.x, fly\.y, fly\.z, fly\.wx' "$q" || fail "zero modes: $(grep -A3 '^#' "$q")"
[ "$(grep -c '^[0-9]' "$q" | tr -d ' ')" -ge 1 ] && ! grep -Eq '^(2|12) ' "$q" || fail "the zero modes are listed one by one"
"$codyna" linearize "$src/examples/pendulum.json" --operating-point equilibrium --out eq > eq.txt || fail "equilibrium"
grep -A2 '^xdot0' eq.txt | grep -q '^  pivot_dot = 0$' || fail "xdot0 round-off printed: $(grep -A2 '^xdot0' eq.txt)"
echo "PRINT_OK wrapped 12 x 12, one row for the twelve zero modes, round-off as 0"
