#!/usr/bin/env bash
# --compare-linear integrates the linear closed loop far below the nonlinear run's tolerances
# (issue 21): on an exactly linear plant (the CTMS quarter-bus suspension: vertical sliders,
# joint spring-dampers, an LQR whose force saturates, a step of road force on the wheel) the
# nonlinear run (CVODE at rtol 1e-8) and the linear run (ARKODE Dormand-Prince at rtol 1e-11)
# must agree to 1e-8 on every output (the fixed-step RK4 of before was 7.8e-6 off), and the
# summary prints both runs' tolerances and the linear run's own error estimate beside the gap.
# Usage: compare_linear_exact.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"; cd "$work"
fail() { echo "FAIL: $*"; exit 1; }
PY=/usr/bin/python3

"$codyna" simulate "$src/tests/data/bus_suspension.json" --disturbance road_force=5000@0.1 --compare-linear --quiet \
  --out bus.h5 > bus.txt 2> bus.err || fail "simulate: $(cat bus.err)"
grep -q 'saturation       U at its limit' bus.txt || fail "the actuator never saturates: the test would not exercise the limits"
grep -Eq '^  nonlinear run: cvode-adams at rtol 1e-08, atol 1e-10; linear run: Dormand-Prince 5\(4\) at rtol 1e-11, atol 1e-13 \(a rerun at 100x looser tolerances differs by [0-9.e-]+\)$' bus.txt ||
  fail "no tolerances beside the gap: $(grep -A4 'linear vs' bus.txt)"
"$PY" - <<'PY'
import re, sys, h5py
import numpy as np
text = open("bus.txt").read()
gaps = [float(g) for g in re.findall(r"max \|y - y_lin\| (\S+)", text)]
estimate = float(re.search(r"differs by (\S+)\)", text).group(1))
with h5py.File("bus.h5", "r") as f:
    y, yl = f["y"][()], f["y_linear"][()]
gap = np.abs(y - yl).max(axis=0)
if len(gaps) != 2 or max(gaps) >= 1e-8 or gap.max() >= 1e-8: sys.exit(f"gap {gaps} (file {gap}) not below 1e-8")
if not np.allclose(gap, gaps, rtol=1e-5): sys.exit(f"printed {gaps} != file {gap}")
if not estimate < 1e-8: sys.exit(f"the linear run's error estimate {estimate}")
print(f"EXACT_OK gap {gap.max():.3g} m on an exactly linear plant (< 1e-8), linear run's own estimate {estimate:.3g}")
PY
