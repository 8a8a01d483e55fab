#!/usr/bin/env bash
# A ball rolling without slip on a plate (examples/ball_plate.json, a rolling_ball constraint:
# non-holonomic): `codyna info` says 5 coordinates and 3 rates; `codyna linearize` exports an
# 8-state plant whose .m and .mat GNU Octave runs as they are, and Octave's own minreal and zero
# find each axis to be the ball and beam: a double integrator at 0 with zeros at
# +-sqrt(m g R / J) (the feedthrough (J/R) s^2 over m g that the motion input keeps), the gain
# m g / (m + J/R^2) at low frequency, and no coupling between the axes; a run with the plate
# swung by a sine keeps the ball on it and rolling (the drift printed stays at the tolerance).
# usage: ball_plate.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*"; exit 1; }
model="$src/examples/ball_plate.json"

"$codyna" info "$model" > "$work/info.txt" || { cat "$work/info.txt"; fail "info"; }
grep -q "^DOF          5 coordinates, 3 rates" "$work/info.txt" || { cat "$work/info.txt"; fail "info: coordinates and rates"; }
grep -q "3 equations, 3 independent, 2 on the velocities only" "$work/info.txt" || { cat "$work/info.txt"; fail "info: rows"; }

"$codyna" linearize "$model" --out "$work" > "$work/lin.txt" || { cat "$work/lin.txt"; fail "linearize"; }
grep -q "(5 DOF, 3 rates)" "$work/lin.txt" && grep -q "rates not states" "$work/lin.txt" || { cat "$work/lin.txt"; fail "linearize: the rates the rolling fixes are not said"; }
[ -f "$work/ball_plate.m" ] && [ -f "$work/ball_plate.mat" ] || fail "no .m/.mat pair"

if command -v octave-cli > /dev/null; then
  cat > "$work/check.m" <<'OCT'
pkg load control
run(fullfile(work, 'ball_plate.m'));
assert(isequal(size(sys.a), [8 8]));
m = 0.111; R = 0.015; J = 9.99e-6; g = 9.8; me = m + J / R^2;
% X from alpha_y and Y from alpha_x: minimal realizations, their poles and zeros
for io = [1 2; 2 1]'
  s1 = minreal(sys(io(1), io(2)), 1e-9);
  p = sort(abs(pole(s1))); z = sort(real(zero(s1)));
  assert(numel(p) == 2 && max(p) < 1e-6, sprintf('poles %g', p));
  assert(numel(z) == 2 && abs(z(2) - sqrt(m * g * R / J)) < 1e-6 * sqrt(m * g * R / J) && abs(z(1) + z(2)) < 1e-6, ...
         sprintf('zeros %g', z));
  % at s = j w: (+-)(m g - (J/R) (j w)^2) / (me (j w)^2)
  sgn = 1; if io(1) == 2, sgn = -1; end
  for w = [0.1 1 10 100]
    G = squeeze(freqresp(sys(io(1), io(2)), w));
    E = sgn * (m * g + (J / R) * w^2) / (-me * w^2);
    assert(abs(G - E) < 1e-9 * abs(E), sprintf('w = %g: %g vs %g', w, real(G), real(E)));
  end
end
% no coupling between the axes
for w = [0.1 1 10]
  assert(abs(squeeze(freqresp(sys(1, 1), w))) < 1e-12 && abs(squeeze(freqresp(sys(2, 2), w))) < 1e-12);
end
printf('CODYNA_OK zeros +-%.6g rad/s\n', sqrt(m * g * R / J));
OCT
  (cd "$work" && octave-cli --no-gui --quiet --eval "work='$work'; source('$work/check.m');" > "$work/octave.txt" 2>&1) ||
    { cat "$work/octave.txt"; fail "octave check"; }
  grep -q CODYNA_OK "$work/octave.txt" || { cat "$work/octave.txt"; fail "octave did not finish"; }
  grep CODYNA_OK "$work/octave.txt"
else
  echo "octave-cli not installed: the Octave check is skipped"
fi

# the plate swung about y by a sine: the ball stays on it (height) and rolls (no slip)
"$codyna" simulate "$model" --open-loop --inputs alpha_x --t-end 2 --quiet --out "$work/run.h5" \
  --disturbance '{"actuator": "alpha_y", "type": "sine", "amplitude": 0.05, "frequency": 1.0}' \
  > "$work/sim.txt" 2>&1 || { cat "$work/sim.txt"; fail "simulate"; }
cat "$work/sim.txt"
/usr/bin/python3 - "$work/run.h5" <<'PY'
import sys
import h5py, numpy as np
with h5py.File(sys.argv[1], "r") as f:
    y = np.array(f["y"]); names = [s.decode() if isinstance(s, bytes) else s for s in np.array(f["names/outputs"]).tolist()]
    drift = np.array(f["constraints/position_violation"]); slip = np.array(f["constraints/velocity_violation"])
x = y[:, names.index("X")]
assert abs(x[0] - 0.1) < 1e-12, x[0]
assert np.max(np.abs(x - 0.1)) > 1e-3, "the ball did not move"
assert np.max(drift) < 1e-8 and np.max(slip) < 1e-8, (np.max(drift), np.max(slip))
print(f"RUN_OK X moved by {np.max(np.abs(x - 0.1)):.3g} m; height drift {np.max(drift):.1e} m, slip {np.max(slip):.1e} m/s")
PY
