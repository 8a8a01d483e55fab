#!/usr/bin/env bash
# Installs what is missing, builds, and runs the main job headless on the
# paper's cart-pendulum: model summary, linearization about the upright
# equilibrium and export (.m + .mat), an LQR designed on that plant, the
# closed-loop simulation on the nonlinear model from a 0.1 rad offset beside
# the linear prediction, results as HDF5 + CSV. Files land in out/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
# only what the demo runs: the CLI's packages and the CLI (scripts/test.sh installs and builds
# the rest, reusing what this built)
./scripts/deps.sh cli
./scripts/build.sh --cli
CODYNA=build/bin/codyna
MODEL=examples/cart_pendulum.json
OUT=out/demo
mkdir -p "$OUT"
echo
echo "== codyna info $MODEL"
"$CODYNA" info "$MODEL"
echo
echo "== codyna linearize $MODEL --operating-point equilibrium"
"$CODYNA" linearize "$MODEL" --operating-point equilibrium --out "$OUT"
echo
echo "== codyna simulate $MODEL --lqr (designed on the linear plant, run on the nonlinear one)"
"$CODYNA" simulate "$MODEL" --lqr --q-weights 10,100,1,1 --r-weights 0.01 --compare-linear --t-end 8 \
  --out "$OUT/cart_pendulum.h5" --csv "$OUT/cart_pendulum.csv"
if command -v octave-cli > /dev/null; then
  echo
  echo "== GNU Octave runs the exported $OUT/cart_pendulum.m"
  octave-cli --no-gui --quiet --eval "run('$OUT/cart_pendulum.m'); disp('eig(A) ='); disp(eig(sys.a).'); K = lqr(sys, diag([10 100 1 1]), 0.01)" 2>/dev/null || true
else
  echo
  echo "== GNU Octave is not installed: scripts/test.sh (or scripts/deps.sh) installs it; then"
  echo "   octave-cli --eval \"run('$OUT/cart_pendulum.m'); K = lqr(sys, diag([10 100 1 1]), 0.01)\""
fi
echo
echo "files written:"
ls -l "$OUT"
