#!/usr/bin/env bash
# codyna simulate on examples/slider_crank_driven.json (a motion input drives the crank of a
# loop, issue 19), checked from the results file with h5py against closed forms derived by hand:
# the slider x(theta) = r cos(theta) + sqrt(l^2 - r^2 sin^2(theta)), the drive torque (the
# motion_force sensor) against the virtual work of the inertia forces and the rod's weight at
# fixed s, the crank's power integrated (Simpson) against the change of mechanical energy, the
# loop closure residual, and the impulse at the start (the follower keeps its velocity).
# Measured when written: |x| 8.5e-15, |tau| 1.5e-14 of 1.07 N m, work - dE 6.6e-11 J, |phi| 4.6e-14.
# usage: slider_crank_driven.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
PY=/usr/bin/python3; [ -x "$PY" ] || PY=python3

"$codyna" simulate "$src/examples/slider_crank_driven.json" --quiet --output-step 0.001 --out "$work/run.h5" > "$work/run.txt"

"$PY" - "$work/run.h5" <<'PY'
import sys
import h5py, numpy as np
f = h5py.File(sys.argv[1], "r")
names = lambda key: [s.decode() if isinstance(s, bytes) else s for s in np.array(f[key]).tolist()]
qn, yn = names("names/q"), names("names/outputs")
t, q, v, y = np.array(f["time"]), np.array(f["q"]), np.array(f["v"]), np.array(f["y"])
r, l, a, Ic, mr, Ir, m1, m2, k, g = 0.1, 0.3, 0.15, 0.002, 0.4, 0.003, 1.0, 0.5, 200.0, 9.81
w = 2 * np.pi
th, s = q[:, qn.index("crank_pivot")], q[:, qn.index("follower_slide")]
assert np.max(np.abs(th - (0.5 + w * t))) < 1e-12, "the crank does not follow its ramp"
S, C = np.sin(th), np.cos(th)
D = np.sqrt(l * l - r * r * S * S)
D1 = -r * r * S * C / D
D2 = -r * r * np.cos(2 * th) / D - r**4 * S * S * C * C / D**3
x, x1, x2 = r * C + D, -r * S + D1, -r * C + D2
p1 = np.stack([-r * S + a / l * D1, r * (1 - a / l) * C])
p2 = np.stack([-r * C + a / l * D2, -r * (1 - a / l) * S])
psi1, psi2 = -r * C / D, r * S / D + r * C * D1 / D**2
tau = mr * (p2 * w * w * p1).sum(0) + Ir * psi2 * w * w * psi1 + mr * g * p1[1] + m1 * x2 * w * w * x1 - k * s * x1
ex = np.max(np.abs(y[:, yn.index("slider_x")] - x))
et = np.max(np.abs(y[:, yn.index("drive_torque")] - tau))
assert ex < 1e-12, ex
assert et < 1e-8 * np.max(np.abs(tau)), et
assert np.max(np.abs(s)) > 1e-2  # the follower moves
P = y[:, yn.index("drive_torque")] * w
h = t[1] - t[0]
work = h / 3 * (P[0:-2:2] + 4 * P[1:-1:2] + P[2::2]).sum()
E = np.array(f["energy/kinetic"]) + np.array(f["energy/potential"])
assert abs(work - (E[-1] - E[0])) < 1e-8, (work, E[-1] - E[0])
assert np.max(np.array(f["constraints/position_violation"])) < 1e-12
assert abs(v[0, qn.index("follower_slide")] + x1[0] * w) < 1e-12
print(f"slider {ex:.2g} m, torque {et:.2g} N m, work - dE {work - (E[-1] - E[0]):.2g} J")
PY
