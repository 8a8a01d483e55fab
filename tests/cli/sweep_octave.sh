#!/usr/bin/env bash
# codyna sweep --mat DIR/NAME.mat (issue 22's LPV export): NAME.m runs in GNU Octave, builds one
# ss per completed variant (Octave's ss has no array dimension; MATLAB gets one ss array), and
# the poles of those ss equal the stored open_poles(:, k), and eig(a - b K) the stored
# closed_poles(:, k), to 1e-10; a failed variant (mass -1) has status 1, its reason and NaN pages.
# Usage: sweep_octave.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"; cd "$work"
fail() { echo "FAIL: $*"; exit 1; }
command -v octave-cli > /dev/null || { echo "octave-cli not installed: sweep LPV check skipped"; exit 77; }
octave-cli --no-gui --quiet --eval "pkg load control" > /dev/null 2>&1 || { echo "octave control package missing: sweep LPV check skipped"; exit 77; }

"$codyna" sweep "$src/examples/cart_pendulum.json" --vary '/bodies/1/mass=[5,-1,10,15]' --vary '/bodies/0/mass=[15,25]' \
  --out rod.h5 --mat lpv/rod_study.mat > sweep.txt || fail "the sweep failed: $(cat sweep.txt)"
grep -q "wrote lpv/rod_study.m$" sweep.txt || fail "no .m written: $(cat sweep.txt)"
cat > check.m <<'M'
run(fullfile('lpv', 'rod_study.m'));
assert(isequal(size(A), [4 4 8]) && isequal(size(B), [4 1 8]) && isequal(size(values), [8 2]));
assert(isequal(status', [0 0 1 1 0 0 0 0]));
assert(~isempty(strfind(reason{3}, '/bodies/1/mass')) && isempty(reason{1}));
assert(all(isnan(A(:, :, 3)(:))));
assert(isequal(ok', [1 2 5 6 7 8]) && numel(sys) == 6 && isa(sys{1}, 'ss'));
worst = 0;
for c = 1:numel(ok)
  j = ok(c);
  p = pole(sys{c}); [~, o] = sortrows([real(p) imag(p)]); p = p(o);
  worst = max(worst, max(abs(p - open_poles(:, j))));
  q = eig(sys{c}.a - sys{c}.b * K); [~, o] = sortrows([real(q) imag(q)]); q = q(o);
  worst = max(worst, max(abs(q - closed_poles(:, j))));
end
assert(worst < 1e-10);
printf('SWEEP_LPV_OK worst %.2g over %d variants\n', worst, numel(ok));
M
octave-cli --no-gui --quiet check.m > octave.txt 2>&1 || { cat octave.txt; fail "the Octave check failed"; }
grep SWEEP_LPV_OK octave.txt || { cat octave.txt; fail "octave did not finish"; }
