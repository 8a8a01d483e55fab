#!/usr/bin/env bash
# codyna sweep --simulate's figures of merit (docs/parameter-studies.md, "Figures of merit")
# against closed forms computed here, independently of codyna:
#   * a mass-spring-damper (m = 1 kg, k = 4 N/m, no controller) released from x = 0.1 m at rest,
#     its damping c over a grid: x(t) = x0 exp(-zeta w t) (cos wd t + zeta / sqrt(1 - zeta^2) sin wd t)
#     for c = 0.8, 1.6, 2.4 N s/m (zeta 0.2, 0.4, 0.6),
#     so the overshoot is 100 exp(-zeta pi / sqrt(1 - zeta^2)) % and the settling time (|x| <= 2 %
#     of x0 for good) is found on a grid of 1 us of that formula;
#   * the same mass (no damper) under u = -(10 x + 4 v) held above -2 N, released from x = 1 m:
#     it sits at the limit until 10 x + 4 v = 2 on the arc x = -1/2 + 3/2 cos 2t (root found here),
#     then stays linear (checked with expm on a 1 ms grid): saturation time = that instant, within
#     one output step (the report counts output intervals); with the limit at -1000 N: 0 s;
#   * the figures equal in the HDF5, the CSV and the MAT file, and the summary names them.
# Usage: sweep_figures.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"; cd "$work"
fail() { echo "FAIL: $*"; exit 1; }
PY=/usr/bin/python3

"$PY" - <<'PY'
import json
def model(name, effects, actuator, controller, q0, t_end):
    return {
        "codyna_model": 1, "name": name,
        "bodies": [{"name": "mass", "mass": 1.0, "com": [0, 0, 0], "inertia": [0.1, 0.1, 0.1]}],
        "joints": [{"name": "slider", "type": "prismatic", "parent": "ground", "child": "mass",
                    "axis": [1, 0, 0], "q0": q0, "v0": 0.0}],
        "constraints": [],
        "effects": effects,
        "actuators": [actuator],
        "sensors": [{"name": "x", "type": "joint_position", "joint": "slider", "dof": 0, "unit": "m"}],
        "plant": {"inputs": ["force"], "outputs": ["x"]},
        "solver": {"integrator": "auto", "rtol": 1e-11, "atol": 1e-13, "t_end": t_end, "output_step": 0.001},
        "controller": controller,
    }
spring = {"name": "spring", "type": "joint_spring_damper", "joint": "slider", "dof": 0,
          "stiffness": 4.0, "damping": 0.8, "rest_position": 0.0}
force = {"name": "force", "type": "joint_force", "joint": "slider", "dof": 0, "gain": 1.0, "unit": "N"}
json.dump(model("msd", [spring], force, {"type": "none"}, 0.1, 12.0), open("msd.json", "w"), indent=1)
limited = dict(force, min=-2.0, max=1000.0)
json.dump(model("msd_limited", [dict(spring, damping=0.0)], limited,
                {"type": "state_feedback", "K": [[10.0, 4.0]], "operating_point": "equilibrium"}, 1.0, 8.0),
          open("limited.json", "w"), indent=1)
PY

"$codyna" sweep msd.json --vary '/effects/0/damping=[0.8,1.6,2.4]' --simulate --quiet \
  --out msd.h5 --csv msd.csv --mat mat/msd.mat > msd.txt || fail "the damping sweep: $(cat msd.txt)"
grep -q "^overshoot        largest [0-9.]* % (x), variant 0" msd.txt || fail "summary: $(cat msd.txt)"
grep -q "^settling time    longest [0-9.]* s (2 % band) (x), variant 0" msd.txt || fail "summary: $(cat msd.txt)"
"$codyna" sweep limited.json --vary '/actuators/0/min=[-2,-1000]' --simulate --quiet --out limited.h5 --csv limited.csv \
  > limited.txt || fail "the saturation sweep: $(cat limited.txt)"
grep -q "^at a limit       longest 0.26[0-9]* s (force), variant 0" limited.txt || fail "summary: $(cat limited.txt)"

"$PY" - <<'PY'
import csv, h5py, numpy as np, scipy.io, scipy.linalg, scipy.optimize
m, k, x0, t_end = 1.0, 4.0, 0.1, 12.0
f = h5py.File("msd.h5", "r")
assert (f["simulation/status"][:] == 0).all(), f["simulation/reason"][:]
over, settle = f["simulation/overshoot"][:], f["simulation/settling_time"][:]
assert over.shape == (3, 1) and settle.shape == (3, 1)
assert np.isnan(f["simulation/saturation_time"][:]).all()   # the force has no limits
t = np.arange(0, t_end + 5e-7, 1e-6)
worst_o = worst_s = 0
for i, c in enumerate([0.8, 1.6, 2.4]):
    w = np.sqrt(k / m); zeta = c / (2 * np.sqrt(k * m)); wd = w * np.sqrt(1 - zeta**2)
    x = x0 * np.exp(-zeta * w * t) * (np.cos(wd * t) + zeta / np.sqrt(1 - zeta**2) * np.sin(wd * t))
    o = 100 * np.exp(-zeta * np.pi / np.sqrt(1 - zeta**2))
    out = np.nonzero(np.abs(x) > 0.02 * x0)[0][-1]          # the last instant outside the band
    ts = t[out + 1]
    worst_o = max(worst_o, abs(over[i, 0] - o))
    worst_s = max(worst_s, abs(settle[i, 0] - ts))
    assert abs(over[i, 0] - o) < 1e-5, (c, over[i, 0], o)       # % points
    assert abs(settle[i, 0] - ts) < 2e-5, (c, settle[i, 0], ts)  # s
print("overshoot vs exp(-zeta pi/sqrt(1-zeta^2)): %.1e %%; settling time vs the closed form: %.1e s" % (worst_o, worst_s))

# the same numbers in the CSV and the MAT file
rows = list(csv.DictReader(open("msd.csv")))
for i, r in enumerate(rows):
    assert float(r["overshoot:x"]) == over[i, 0] and float(r["settling_time:x"]) == settle[i, 0], r
    assert r["saturation_time:force"] == "nan"
mat = scipy.io.loadmat("mat/msd.mat")
assert np.array_equal(mat["overshoot"], over) and np.array_equal(mat["settling_time"], settle)
assert np.array_equal(mat["peak_input"], f["simulation/peak_input"][:], equal_nan=True)
assert np.array_equal(mat["final_error"][:, 0], f["simulation/final_error"][:])

# saturation: u = -(10 x + 4 v) held above -2 N, the spring k = 4, no damper, from x = 1 at rest
U, kp, kd = 2.0, 10.0, 4.0
g = h5py.File("limited.h5", "r")
assert (g["simulation/status"][:] == 0).all(), g["simulation/reason"][:]
sat = g["simulation/saturation_time"][:]
# at the limit u = -U: x = -U/k + (1 + U/k) cos 2t, v = -2 (1 + U/k) sin 2t, until kp x + kd v = U
xs = lambda s: -U / k + (1 + U / k) * np.cos(2 * s)
vs = lambda s: -2 * (1 + U / k) * np.sin(2 * s)
t1 = scipy.optimize.brentq(lambda s: kp * xs(s) + kd * vs(s) - U, 0.0, 0.7, xtol=1e-14)
# then linear: [x, v]' = [[0, 1], [-(k + kp), -kd]] [x, v], never at a limit again (u > -U, u < 1000)
A = np.array([[0, 1], [-(k + kp) / m, -kd / m]])
z = np.array([scipy.linalg.expm(A * si) @ [xs(t1), vs(t1)] for si in np.arange(0, 8.0 - t1, 1e-3)])
u = -(kp * z[:, 0] + kd * z[:, 1])
assert u[1:].min() > -U and u.max() < 1000, (u[1:].min(), u.max())
dt = 0.001
assert t1 <= sat[0, 0] <= t1 + dt + 1e-9, (sat[0, 0], t1)
assert sat[1, 0] == 0.0, sat[1]   # limits -1000 and 1000: never reached
print("saturation time %.6f s vs the closed form's %.6f s (output step %.0e s)" % (sat[0, 0], t1, dt))
rows = list(csv.DictReader(open("limited.csv")))
assert float(rows[0]["saturation_time:force"]) == sat[0, 0]
PY
echo "sweep figures: ok"
