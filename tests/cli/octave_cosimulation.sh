#!/usr/bin/env bash
# Co-simulation from GNU Octave (the paper's MEX S-function, without Simulink):
# Octave designs the LQR on codyna's exported plant, then closes the loop
# itself, stepping the nonlinear codyna plant through codyna_plant.mex every
# 5 ms; the rod must stay upright. Bad calls raise Octave errors with codyna's
# messages.
# usage: octave_cosimulation.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*"; exit 1; }
mexdir="$(cd "$(dirname "$codyna")/.." && pwd)/mex"
command -v octave-cli > /dev/null || { echo "octave-cli not installed: co-simulation skipped"; exit 77; }
[ -f "$mexdir/codyna_plant.mex" ] || { echo "codyna_plant.mex not built (liboctave-dev missing): co-simulation skipped"; exit 77; }
model="$src/examples/cart_pendulum.json"
"$codyna" linearize "$model" --operating-point equilibrium --out "$work" > /dev/null

cat > "$work/cosim.m" <<'OCT'
addpath(mexdir);
run(fullfile(work, 'cart_pendulum.m'));
K = lqr(sys, diag([10 100 1 1]), 0.01);
h = codyna_plant('open', model);
info = codyna_plant('info', h);
assert(isequal(info.input_names, {'force'}) && isequal(info.output_names, {'h'; 'theta'}));
dt = 0.005; n = round(6 / dt); theta = zeros(n, 1); umax = 0;
for k = 1:n
  [q, v] = codyna_plant('state', h);
  x = [q; v] - x0;                   % same state order as the export (positions, then rates)
  u = u0 - K * x;
  umax = max(umax, abs(u));
  y = codyna_plant('step', h, u, dt);
  theta(k) = y(2);
end
late = theta(round(4 / dt):end);
assert(abs(late) < 0.5 * pi / 180, 'rod not upright: %g', max(abs(late)));
assert(umax < 200);
% errors come back as Octave errors with codyna's message
try, codyna_plant('step', h, [1 2], dt); error('no error'); catch e, assert(strcmp(e.identifier, 'codyna:plant')); assert(!isempty(strfind(e.message, 'expected 1 Plant/In values'))); end
try, codyna_plant('open', fullfile(work, 'nope.json')); error('no error'); catch e, assert(!isempty(strfind(e.message, 'nope.json'))); assert(numel(strfind(e.message, 'codyna_plant:')) == 1, e.message); end
codyna_plant('close', h);
try, codyna_plant('outputs', h); error('no error'); catch e, assert(!isempty(strfind(e.message, 'no open plant'))); end
printf('COSIM_OK max|theta| after 4 s = %.2e rad, max|u| = %.1f N\n', max(abs(late)), umax);
OCT
(cd "$work" && octave-cli --no-gui --quiet --eval "work='$work'; mexdir='$mexdir'; model='$model'; source('$work/cosim.m');" > "$work/octave.txt" 2>&1) || { cat "$work/octave.txt"; fail "octave co-simulation failed"; }
grep -q COSIM_OK "$work/octave.txt" || { cat "$work/octave.txt"; fail "octave did not finish"; }
grep COSIM_OK "$work/octave.txt"
echo "octave_cosimulation: all checks passed"
