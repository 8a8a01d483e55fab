#!/usr/bin/env bash
# The exported linear closed loop (codyna linearize --closed-loop) read by GNU Octave:
# the cart-pendulum with codyna's LQR. Octave designs its own K = lqr(A, B, Q, R) on the
# exported plant and checks Acl = A - B K, the poles poles_cl = eig(A - B K), and that
# Octave's step() of ss(Acl, Bcl, Ccl, Dcl) equals the step curves codyna wrote
# (NAME_cl_step.csv) to 1e-8 of their largest value. A PID loop from a model file is
# checked against a closed loop Octave builds by hand from the plant and the gains.
# usage: closed_loop_octave.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*"; exit 1; }
command -v octave-cli > /dev/null || { echo "octave-cli not installed: closed-loop export check skipped"; exit 77; }
octave-cli --no-gui --quiet --eval "pkg load control" > /dev/null 2>&1 || { echo "octave control package missing: closed-loop export check skipped"; exit 77; }
model="$src/examples/cart_pendulum.json"

"$codyna" linearize "$model" --operating-point equilibrium --lqr --q-weights 10,100,1,1 --r-weights 0.01 \
  --closed-loop --out "$work" > "$work/lin.txt" 2> "$work/lin.err" || { cat "$work/lin.txt" "$work/lin.err"; fail "linearize --closed-loop"; }
for f in cart_pendulum.mat cart_pendulum.m cart_pendulum_cl.mat cart_pendulum_cl.m cart_pendulum_cl_step.csv cart_pendulum_cl_freq.csv; do
  [ -s "$work/$f" ] || fail "$f not written"
done
grep -q "Nbar tracks h" "$work/lin.err" || { cat "$work/lin.err"; fail "no note on which output Nbar tracks"; }

cat > "$work/check.m" <<'OCT'
pkg load control
run(fullfile(work, 'cart_pendulum.m'));      % A B C D of the plant
run(fullfile(work, 'cart_pendulum_cl.m'));   % Acl ... and sys_cl
K = lqr(A, B, diag([10 100 1 1]), 0.01);
e_A = norm(Acl - (A - B * K), 'fro') / norm(A - B * K, 'fro');
p = eig(A - B * K);
pc = complex(poles_cl(:, 1), poles_cl(:, 2));
[~, i1] = sort(real(p) + 1e-3 * imag(p)); [~, i2] = sort(real(pc) + 1e-3 * imag(pc));
e_p = max(abs(p(i1) - pc(i2))) / max(abs(p));
assert(isequal(input_names_cl(:)', {'r_h', 'r_theta'}), 'input names');
assert(isequal(output_names_cl(:)', {'h', 'theta', 'u_force'}), 'output names');
% Octave's step on codyna's time grid, against codyna's curves (inputs outer, outputs inner)
y = step(sys_cl, t_step);                       % nt x ny x nu
csv = dlmread(fullfile(work, 'cart_pendulum_cl_step.csv'), ',', 1, 0);
assert(max(abs(csv(:, 1) - t_step)) < 1e-12, 'time grid');
ny = size(Ccl, 1); nu = size(Bcl, 2);
e_s = 0;
for j = 1:nu
  for i = 1:ny
    e_s = max(e_s, max(abs(csv(:, 1 + (j - 1) * ny + i) - y(:, i, j))));
  end
end
e_s = e_s / max(abs(y(:)));
% the frequency curves against H(jw) = Ccl (jw I - Acl)^-1 Bcl + Dcl evaluated here
fr = dlmread(fullfile(work, 'cart_pendulum_cl_freq.csv'), ',', 1, 0);
assert(max(abs(fr(:, 1) - w_freq)) < 1e-12 * max(w_freq), 'frequency grid');
e_m = 0; e_ph = 0;
for k = 1:numel(w_freq)
  H = Ccl * ((1i * w_freq(k) * eye(size(Acl)) - Acl) \ Bcl) + Dcl;
  for j = 1:nu
    for i = 1:ny
      c = 2 + 2 * ((j - 1) * ny + (i - 1));
      if abs(H(i, j)) == 0, continue; end
      e_m = max(e_m, abs(fr(k, c) - abs(H(i, j))) / abs(H(i, j)));
      d = fr(k, c + 1) - angle(H(i, j)) * 180 / pi;
      e_ph = max(e_ph, abs(d - 360 * round(d / 360)));   % the CSV's phase is unwrapped
    end
  end
end
% the offsets: the plant's operating point, the references' base y0, the efforts' u0
assert(isequal(x0_cl, x0) && isequal(u0_cl, y0) && isequal(y0_cl, [y0; u0]), 'offsets');
assert(isequal(state_names_cl(:)', state_names(:)'), 'state names');
% the reference gain: unit DC gain from r_h to h (Nbar), none to theta
dc = Dcl - Ccl * (Acl \ Bcl);
printf('CL_NUMBERS e_A=%.3g e_poles=%.3g e_step=%.3g e_mag=%.3g e_phase_deg=%.3g dc_h=%.15g dc_theta=%.3g\n', e_A, e_p, e_s, e_m, e_ph, dc(1, 1), dc(2, 1));
assert(e_A < 1e-8, 'Acl vs A - B K');
assert(e_p < 1e-8, 'poles vs eig(A - B K)');
assert(e_s < 1e-8, 'step response vs Octave step');
assert(e_m < 1e-10 && e_ph < 1e-8, 'frequency response vs H(jw)');
assert(abs(dc(1, 1) - 1) < 1e-9 && abs(dc(2, 1)) < 1e-9, 'DC gain');
printf('CODYNA_CL_OK\n');
OCT
(cd "$work" && octave-cli --no-gui --quiet --eval "work='$work'; source('$work/check.m');" > "$work/octave.txt" 2>&1) \
  || { cat "$work/octave.txt"; fail "octave check of the LQR closed loop failed"; }
grep -q CODYNA_CL_OK "$work/octave.txt" || { cat "$work/octave.txt"; fail "octave did not finish"; }
grep CL_NUMBERS "$work/octave.txt"

# a controller from Octave: K saved by Octave, the loop exported by codyna --controller K.mat
# is A - B K with that very K
mkdir -p "$work/fromfile"
(cd "$work" && octave-cli --no-gui --quiet --eval "pkg load control; run(fullfile('$work', 'cart_pendulum.m')); K = lqr(A, B, diag([1 50 1 1]), 0.1); save('-v7', fullfile('$work', 'fromfile', 'K.mat'), 'K'); printf('K_SAVED\n');" > "$work/fromfile/octave.txt" 2>&1) || true
grep -q K_SAVED "$work/fromfile/octave.txt" || { cat "$work/fromfile/octave.txt"; fail "octave could not save K"; }
"$codyna" linearize "$model" --operating-point equilibrium --controller "$work/fromfile/K.mat" --closed-loop --out "$work/fromfile" \
  > "$work/fromfile/lin.txt" 2>&1 || { cat "$work/fromfile/lin.txt"; fail "linearize --controller K.mat --closed-loop"; }
cat > "$work/fromfile/check.m" <<'OCT'
run(fullfile(work, 'cart_pendulum.m'));
run(fullfile(work, 'cart_pendulum_cl.m'));
load(fullfile(work, 'K.mat'));
e = norm(Acl - (A - B * K), 'fro') / norm(A - B * K, 'fro');
printf('FILE_K_NUMBERS e_A=%.3g\n', e);
assert(e < 1e-14, 'Acl vs A - B K with the file K');
printf('CODYNA_FILE_OK\n');
OCT
(cd "$work/fromfile" && octave-cli --no-gui --quiet --eval "work='$work/fromfile'; source('$work/fromfile/check.m');" > "$work/fromfile/check.txt" 2>&1) \
  || { cat "$work/fromfile/check.txt"; fail "octave check of the loop with a K file failed"; }
grep -q CODYNA_FILE_OK "$work/fromfile/check.txt" || { cat "$work/fromfile/check.txt"; fail "octave did not finish the K file check"; }
grep FILE_K_NUMBERS "$work/fromfile/check.txt"

# a second export replaces codyna's own files; a file codyna did not write is never replaced
"$codyna" linearize "$model" --operating-point equilibrium --lqr --closed-loop --out "$work" > /dev/null 2>&1 || fail "second export"
echo "my notes" > "$work/cart_pendulum_cl_freq.csv"
rm "$work/cart_pendulum.mat"   # refused before any work: the plant is not written either
set +e
"$codyna" linearize "$model" --operating-point equilibrium --lqr --closed-loop --out "$work" > "$work/guard.txt" 2>&1
rc=$?
set -e
[ $rc -ne 0 ] || fail "a foreign cart_pendulum_cl_freq.csv was replaced"
grep -q "cart_pendulum_cl_freq.csv" "$work/guard.txt" || { cat "$work/guard.txt"; fail "the refusal does not name the file"; }
[ "$(cat "$work/cart_pendulum_cl_freq.csv")" = "my notes" ] || fail "the foreign file was changed"
[ ! -e "$work/cart_pendulum.mat" ] || fail "the plant was exported before the refusal"
echo "guard: exit $rc, $(head -c 200 "$work/guard.txt")"

# a PID loop on a spring-mass, from the model file: Octave closes the loop by hand
# (x = [pos; vel; xi], u = kp (r - y) + ki xi - kd y', xi' = r - y; poles -1, -2, -3) and
# compares the matrices, the poles and Octave's step with codyna's curves
mkdir -p "$work/pid"
cat > "$work/pid/slider.json" <<'JSON'
{"codyna_model": 1, "name": "slider",
 "bodies": [{"name": "block", "mass": 2, "inertia": [0.1, 0.1, 0.1]}],
 "joints": [{"name": "x", "type": "prismatic", "parent": "ground", "child": "block", "axis": [1, 0, 0]}],
 "effects": [{"name": "spring", "type": "joint_spring_damper", "joint": "x", "stiffness": 3, "damping": 0.5}],
 "actuators": [{"name": "force", "type": "joint_force", "joint": "x", "unit": "N"}],
 "sensors": [{"name": "pos", "type": "joint_position", "joint": "x", "unit": "m"}],
 "plant": {"inputs": ["force"], "outputs": ["pos"]},
 "controller": {"type": "pid", "kp": [[19]], "ki": [[12]], "kd": [[11.5]], "operating_point": "initial"},
 "analysis": {"operating_point": "initial", "closed_loop": {"enabled": true, "step_time": 10, "step_points": 201}}}
JSON
"$codyna" linearize "$work/pid/slider.json" --out "$work/pid" > "$work/pid/lin.txt" 2>&1 || { cat "$work/pid/lin.txt"; fail "linearize of the PI loop"; }
cat > "$work/pid/check.m" <<'OCT'
pkg load control
run(fullfile(work, 'slider.m'));
run(fullfile(work, 'slider_cl.m'));
kp = 19; ki = 12; kd = 11.5;
assert(isequal(C, [1 0]), 'C');
Cv = [0 1];   % the output's rate: the velocity state
Ah = [A - B * (kp * C + kd * Cv), B * ki; -C, 0];
Bh = [B * kp; 1];
Ch = [C, 0; -(kp * C + kd * Cv), ki];
Dh = [0; kp];
assert(max(abs(sort(eig(Ah)) - [-3; -2; -1])) < 1e-12, 'PID poles -1, -2, -3');
e_A = norm(Acl - Ah, 'fro') / norm(Ah, 'fro');
y = step(ss(Ah, Bh, Ch, Dh), t_step);
csv = dlmread(fullfile(work, 'slider_cl_step.csv'), ',', 1, 0);
e_s = max(max(abs(csv(:, 2:3) - y))) / max(abs(y(:)));
p = sort(real(eig(Ah))); pc = sort(poles_cl(:, 1));
assert(max(abs(poles_cl(:, 2))) == 0, 'real poles');
e_p = max(abs(p - pc)) / max(abs(p));
printf('PI_NUMBERS e_A=%.3g e_poles=%.3g e_step=%.3g\n', e_A, e_p, e_s);
assert(e_A < 1e-12 && e_p < 1e-10 && e_s < 1e-8, 'PI loop');
printf('CODYNA_PI_OK\n');
OCT
(cd "$work/pid" && octave-cli --no-gui --quiet --eval "work='$work/pid'; source('$work/pid/check.m');" > "$work/pid/octave.txt" 2>&1) \
  || { cat "$work/pid/octave.txt"; fail "octave check of the PI loop failed"; }
grep -q CODYNA_PI_OK "$work/pid/octave.txt" || { cat "$work/pid/octave.txt"; fail "octave did not finish the PI check"; }
grep PI_NUMBERS "$work/pid/octave.txt"

# a sampled LTI controller (Ts = 0.05 s, a discrete PD: u[k] = -110 e[k] + 100 e[k-1], e = y - r):
# the loop is discrete, around the plant's ZOH model; Octave discretizes the plant with c2d and
# closes the loop by hand
mkdir -p "$work/lti"
sed 's/"controller": {"type": "pid", [^}]*}/"controller": {"type": "lti", "Ac": [[0]], "Bc": [[1]], "Cc": [[100]], "Dc": [[-110]], "Ts": 0.05, "operating_point": "initial"}/' \
  "$work/pid/slider.json" | sed 's/"step_points": 201/"step_points": 2/' > "$work/lti/slider.json"
grep -q '"type": "lti"' "$work/lti/slider.json" || fail "the LTI model was not written"
"$codyna" linearize "$work/lti/slider.json" --out "$work/lti" > "$work/lti/lin.txt" 2>&1 || { cat "$work/lti/lin.txt"; fail "linearize of the sampled loop"; }
cat > "$work/lti/check.m" <<'OCT'
pkg load control
run(fullfile(work, 'slider.m'));
run(fullfile(work, 'slider_cl.m'));
Ts = 0.05; Ac = 0; Bc = 1; Cc = 100; Dc = -110;
assert(Ts_cl == Ts, 'Ts_cl');
[Ad, Bd] = ssdata(c2d(ss(A, B, C, D), Ts, 'zoh'));
Ah = [Ad + Bd * Dc * C, Bd * Cc; Bc * C, Ac];
Bh = [-Bd * Dc; -Bc];
Ch = [C, 0; Dc * C, Cc];
Dh = [0; -Dc];
e_A = norm(Acl - Ah, 'fro') / norm(Ah, 'fro');
e_B = norm(Bcl - Bh, 'fro') / norm(Bh, 'fro');
assert(numel(t_step) == 201 && max(abs(diff(t_step) - Ts)) < 1e-12, 'samples of the discrete loop');
y = step(ss(Ah, Bh, Ch, Dh, Ts), t_step);
csv = dlmread(fullfile(work, 'slider_cl_step.csv'), ',', 1, 0);
e_s = max(max(abs(csv(:, 2:3) - y))) / max(abs(y(:)));
printf('LTI_NUMBERS e_A=%.3g e_B=%.3g e_step=%.3g max|z|=%.6f\n', e_A, e_B, e_s, max(abs(eig(Ah))));
assert(e_A < 1e-12 && e_B < 1e-12 && e_s < 1e-8, 'sampled loop');
assert(max(abs(eig(Ah))) < 0.93 && max(abs(complex(poles_cl(:, 1), poles_cl(:, 2)) - 0)) < 0.93, 'a stable discrete loop');
printf('CODYNA_LTI_OK\n');
OCT
(cd "$work/lti" && octave-cli --no-gui --quiet --eval "work='$work/lti'; source('$work/lti/check.m');" > "$work/lti/octave.txt" 2>&1) \
  || { cat "$work/lti/octave.txt"; fail "octave check of the sampled loop failed"; }
grep -q CODYNA_LTI_OK "$work/lti/octave.txt" || { cat "$work/lti/octave.txt"; fail "octave did not finish the sampled loop check"; }
grep LTI_NUMBERS "$work/lti/octave.txt"

# --closed-loop without a controller is an error (exit code 1) naming the field
grep -v '"controller"' "$work/pid/slider.json" > "$work/pid/bare.json"
set +e
"$codyna" linearize "$work/pid/bare.json" --closed-loop --out "$work/none" > "$work/none.txt" 2>&1
rc=$?
set -e
[ $rc -eq 1 ] || { cat "$work/none.txt"; fail "closed loop without a controller: exit code $rc, expected 1"; }
grep -q "/analysis/controller: the closed loop needs a controller" "$work/none.txt" || { cat "$work/none.txt"; fail "no clear message without a controller"; }
echo "closed-loop export: OK"
