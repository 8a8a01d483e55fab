#!/usr/bin/env bash
# The paper's loop, closed through GNU Octave: codyna exports the cart-pendulum,
# Octave designs K = lqr(sys, Q, R) and saves it with save -v7, codyna
# simulates the nonlinear model with that K and must hold the rod upright;
# codyna's own LQR must equal Octave's K to 1e-8. Bad controller files give
# clear errors.
# usage: octave_round_trip.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*"; exit 1; }
command -v octave-cli > /dev/null || { echo "octave-cli not installed: round trip skipped"; exit 77; }
PY=/usr/bin/python3; [ -x "$PY" ] || PY=python3
model="$src/examples/cart_pendulum.json"

"$codyna" linearize "$model" --operating-point equilibrium --out "$work" > /dev/null
cat > "$work/design.m" <<'OCT'
run(fullfile(work, 'cart_pendulum.m'));
K = lqr(sys, diag([10 100 1 1]), 0.01);
save('-v7', fullfile(work, 'K.mat'), 'K');
Kbad = K(1:3); save('-v7', fullfile(work, 'K_wrong_size.mat'), 'Kbad'); K = Kbad;
save('-v7', fullfile(work, 'K_short.mat'), 'K');
K = lqr(sys, diag([10 100 1 1]), 0.01); K(2) = NaN; save('-v7', fullfile(work, 'K_nan.mat'), 'K');
K = lqr(sys, diag([10 100 1 1]), 0.01); save('-text', fullfile(work, 'K_text.mat'), 'K');
fid = fopen(fullfile(work, 'K_octave.txt'), 'w'); fprintf(fid, '%.17g ', K); fclose(fid);
printf('CODYNA_OK\n');
OCT
(cd "$work" && octave-cli --no-gui --quiet --eval "work='$work'; source('$work/design.m');" > "$work/octave.txt" 2>&1) || { cat "$work/octave.txt"; fail "octave design failed"; }
grep -q CODYNA_OK "$work/octave.txt" || { cat "$work/octave.txt"; fail "octave did not finish"; }

# the nonlinear closed loop with Octave's K, from the model's 0.1 rad start
"$codyna" simulate "$model" --controller "$work/K.mat" --t-end 8 --quiet --out "$work/octave_K.h5" > "$work/sim.txt" || { cat "$work/sim.txt"; fail "simulate with Octave's K"; }
"$PY" - "$work/octave_K.h5" <<'PY'
import sys, math
import h5py, numpy as np
with h5py.File(sys.argv[1], "r") as f:
    t = np.array(f["time"]); y = np.array(f["y"]); u = np.array(f["u"])
    names = [s.decode() if isinstance(s, bytes) else s for s in np.array(f["names/outputs"]).tolist()]
theta = y[:, names.index("theta")]
h = y[:, names.index("h")]
late = t >= 5.0
assert abs(theta[0] - 0.1) < 1e-12, theta[0]
assert np.max(np.abs(theta[late])) < math.radians(0.5), np.max(np.abs(theta[late]))
assert np.max(np.abs(h[late])) < 0.05, np.max(np.abs(h[late]))
assert np.max(np.abs(u)) < 500, np.max(np.abs(u))
print(f"ROUND_TRIP_OK max|theta| after 5 s = {np.max(np.abs(theta[late])):.2e} rad, max|u| = {np.max(np.abs(u)):.1f} N")
PY

# codyna's own LQR, same weights, equals Octave's K
"$codyna" simulate "$model" --lqr --q-weights 10,100,1,1 --r-weights 0.01 --t-end 1 --quiet --out "$work/own.h5" > "$work/own.txt"
own=$(sed -n 's/^K(force) = \[\(.*\)\]$/\1/p' "$work/own.txt")
[ -n "$own" ] || { cat "$work/own.txt"; fail "no K printed"; }
"$PY" - "$own" "$(cat "$work/K_octave.txt")" <<'PY'
import sys
a = [float(x) for x in sys.argv[1].split()]
b = [float(x) for x in sys.argv[2].split()]
assert len(a) == len(b) == 4, (a, b)
err = max(abs(x - y) for x, y in zip(a, b)) / max(abs(y) for y in b)
assert err < 1e-8, err
print(f"LQR_OK codyna K vs Octave K: max relative difference {err:.1e}")
PY

# bad controller files: clear messages, exit code 1
expect_error() {
  local rc=0
  "$codyna" simulate "$model" --controller "$1" --t-end 0.1 --quiet --out "$work/bad.h5" > /dev/null 2> "$work/err.txt" || rc=$?
  [ "$rc" -eq 1 ] || fail "$1: exit code $rc ($(cat "$work/err.txt"))"
  grep -qF "$2" "$work/err.txt" || fail "$1: message '$(cat "$work/err.txt")' lacks '$2'"
}
expect_error "$work/K_short.mat" "variable K is 1 x 3, expected 1 x 4"
expect_error "$work/K_wrong_size.mat" "no controller found"
expect_error "$work/K_nan.mat" "K"
expect_error "$work/K_text.mat" "text format"
expect_error "$work/missing.mat" "missing.mat"
[ ! -e "$work/bad.h5" ] || fail "a failed run left a results file"
echo "octave_round_trip: all checks passed"
