#!/usr/bin/env bash
# The paper's two examples end to end: codyna linearize -> NAME.m + NAME.mat,
# then GNU Octave runs NAME.m as a user would, checks sizes, names and
# eig(sys.a) against the closed forms, and designs an LQR gain; Python reads
# the v5 file with scipy and the v7.3 file with h5py.
# usage: linearize_paper_examples.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*"; exit 1; }

"$codyna" linearize "$src/examples/pendulum.json" --operating-point equilibrium --out "$work/v5" > "$work/pendulum.txt"
"$codyna" linearize "$src/examples/cart_pendulum.json" --operating-point equilibrium --out "$work/v5" > "$work/cart.txt"
"$codyna" linearize "$src/examples/cart_pendulum.json" --operating-point equilibrium --mat-version 7.3 --out "$work/v73" > /dev/null
grep -q "wrote $work/v5/pendulum.mat" "$work/pendulum.txt" || fail "pendulum export not reported"
"$codyna" linearize "$src/examples/pendulum.json" --trajectory 2 --trajectory-step 0.1 --out "$work/traj" > /dev/null
[ -f "$work/v5/cart_pendulum.m" ] || fail "cart_pendulum.m missing"

# bad input: clear message, non-zero exit, no file
if "$codyna" linearize "$src/examples/pendulum.json" --method nonsense --out "$work/bad" 2> "$work/err.txt"; then fail "bad --method accepted"; fi
grep -q "expected exact, fd-forward or fd-central" "$work/err.txt" || fail "unclear error: $(cat "$work/err.txt")"
[ ! -e "$work/bad/pendulum.mat" ] || fail "a failed run left a file"

if command -v octave-cli > /dev/null; then
  cat > "$work/check.m" <<'OCT'
g = 9.81;
% paper 4.1: uniform rod 10 kg, 2 m, upright
run(fullfile(work, 'v5', 'pendulum.m'));
assert(isequal(size(A), [2 2]) && isequal(size(B), [2 1]) && isequal(size(C), [1 2]));
assert(isequal(plant_inputs, {'torque'}) && isequal(plant_outputs, {'theta'}));
assert(strcmp(state_names{1}, 'pivot') && strcmp(state_names{2}, 'pivot_dot'));
assert(abs(A(2,1) - 3*g/4) < 1e-10 && abs(B(2) - 0.075) < 1e-12);
assert(isequal(sys.inputname, {'torque'}) && isequal(sys.outputname, {'theta'}));
e = sort(real(eig(sys.a)));
assert(max(abs(e - [-sqrt(3*g/4); sqrt(3*g/4)])) < 1e-10);
K1 = lqr(sys, eye(2), 1);
% linearizations along the PD trajectory: A(2,1,k) = 3g/(2l) sin(theta(t_k)) at every point
T = load(fullfile(work, 'traj', 'pendulum.mat'));
assert(isequal(size(T.A), [2 2 21]) && numel(T.t) == 21);
assert(max(abs(squeeze(T.A(2,1,:)) - 3*g/4 * sin(T.x0(1,:)'))) < 1e-10);
run(fullfile(work, 'traj', 'pendulum.m')); s5 = plant_at(5); assert(abs(s5.a(2,1) - T.A(2,1,5)) < 1e-15);
assert(all(real(eig(sys.a - sys.b*K1)) < 0));
clear A B C D sys
% paper 4.2: cart 20 kg, rod 10 kg / 2 m, upright
run(fullfile(work, 'v5', 'cart_pendulum.m'));
m2 = 20; m3 = 10; l3 = 2; den = 4*m2 + m3;
assert(isequal(size(A), [4 4]) && isequal(size(B), [4 1]) && isequal(size(C), [2 4]));
assert(isequal(plant_outputs, {'h'; 'theta'}) || isequal(plant_outputs, {'h', 'theta'}));
assert(isequal(sys.statename(:)', {'cart_slider', 'rod_pivot', 'cart_slider_dot', 'rod_pivot_dot'}));
assert(abs(A(3,2) + 3*m3*g/den) < 1e-10 && abs(A(4,2) - 6*(m2+m3)*g/(den*l3)) < 1e-10);
assert(abs(B(3) - 4/den) < 1e-12 && abs(B(4) + 6/(l3*den)) < 1e-12);
w = sqrt(6*(m2+m3)*g/(den*l3));
e = sort(real(eig(sys.a)));
assert(max(abs(e - [-w; 0; 0; w])) < 1e-10);
K = lqr(sys, diag([10 100 1 1]), 0.01);
assert(isequal(size(K), [1 4]) && all(real(eig(sys.a - sys.b*K)) < 0));
save('-v7', fullfile(work, 'K.mat'), 'K');
printf('CODYNA_OK K = [%s]\n', num2str(K, 10));
OCT
  (cd "$work" && octave-cli --no-gui --quiet --eval "work='$work'; source('$work/check.m');" > "$work/octave.txt" 2>&1) || { cat "$work/octave.txt"; fail "octave check failed"; }
  grep -q CODYNA_OK "$work/octave.txt" || { cat "$work/octave.txt"; fail "octave did not finish"; }
  grep CODYNA_OK "$work/octave.txt"
else
  echo "octave-cli not installed: Octave peer check skipped"
fi

PY=/usr/bin/python3; [ -x "$PY" ] || PY=python3
"$PY" - "$work" <<'PY'
import sys
work = sys.argv[1]
import numpy as np
import scipy.io
m = scipy.io.loadmat(f"{work}/v5/cart_pendulum.mat")
g, m2, m3, l3 = 9.81, 20.0, 10.0, 2.0
den = 4 * m2 + m3
assert m["A"].shape == (4, 4)
assert abs(m["A"][3, 1] - 6 * (m2 + m3) * g / (den * l3)) < 1e-10
names = [str(x[0]) for x in m["state_names"].ravel()]
assert names == ["cart_slider", "rod_pivot", "cart_slider_dot", "rod_pivot_dot"], names
import h5py
with h5py.File(f"{work}/v73/cart_pendulum.mat", "r") as f:
    A = np.array(f["A"]).T  # MATLAB stores column-major
    assert A.shape == (4, 4)
    assert abs(A[3, 1] - 6 * (m2 + m3) * g / (den * l3)) < 1e-10
print("PYTHON_OK")
PY
echo "linearize_paper_examples: all checks passed"
