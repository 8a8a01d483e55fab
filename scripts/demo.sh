#!/usr/bin/env bash
# Installs what is missing, builds, and runs the main job headless on the
# paper's cart-pendulum: model summary, linearization and export (.m + .mat),
# closed-loop simulation where available. Files land in out/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/deps.sh
./scripts/build.sh
CODYNA=build/bin/codyna
MODEL=examples/cart_pendulum.json
OUT=out/demo
mkdir -p "$OUT"
echo
echo "== codyna info $MODEL"
"$CODYNA" info "$MODEL"
if "$CODYNA" linearize --help > /dev/null 2>&1; then
  echo
  echo "== codyna linearize $MODEL (upright equilibrium)"
  "$CODYNA" linearize "$MODEL" --operating-point equilibrium --out "$OUT"
fi
if "$CODYNA" simulate --help > /dev/null 2>&1; then
  echo
  echo "== codyna simulate $MODEL (LQR on the nonlinear model)"
  "$CODYNA" simulate "$MODEL" --lqr --out "$OUT/cart_pendulum.h5" --csv "$OUT/cart_pendulum.csv"
fi
echo
echo "files written:"
ls -l "$OUT"
