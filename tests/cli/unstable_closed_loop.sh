#!/usr/bin/env bash
# A linear controller's closed loop is checked before the run (issue 21): codyna simulate prints
# the poles of the linear closed loop about the operating point, and warns "unstable linear
# closed loop" in the summary when one has a positive real part (the run itself goes on,
# exit code 0). On the cart-pendulum:
#   * the LQR gain K (scipy's Riccati solution on the exported A, B) prints poles equal to
#     eig(A - B K) computed here, to 1e-9 relative, all stable, and no warning;
#   * the sign-flipped gain -K prints eig(A + B K) the same way, with the warning naming the
#     poles of positive real part;
#   * an LTI controller (Ac, Bc, Cc, Dc: a static output feedback written as LTI) prints
#     the poles of the loop with its state, eig of the closed-loop matrix built here.
# Usage: unstable_closed_loop.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"; cd "$work"
fail() { echo "FAIL: $*"; exit 1; }
PY=/usr/bin/python3
model="$src/examples/cart_pendulum.json"

"$codyna" linearize "$model" --out plant > /dev/null
"$PY" - <<'PY'
import numpy as np, scipy.io, scipy.linalg
d = scipy.io.loadmat("plant/cart_pendulum.mat")
A, B, C = d["A"], d["B"], d["C"]
Q, R = np.diag([10.0, 100.0, 1.0, 1.0]), np.array([[0.01]])
P = scipy.linalg.solve_continuous_are(A, B, Q, R)
K = np.linalg.solve(R, B.T @ P)
scipy.io.savemat("K.mat", {"K": K})
scipy.io.savemat("Kflip.mat", {"K": -K})
# an LTI controller: one integrator-free state xc' = -5 xc + (y - y0)[0], u = u0 + 2 xc - 30 (y - y0)[0] + 80 (y - y0)[1]
Ac, Bc = np.array([[-5.0]]), np.array([[1.0, 0.0]])
Cc, Dc = np.array([[2.0]]), np.array([[-30.0, 80.0]])
scipy.io.savemat("lti.mat", {"Ac": Ac, "Bc": Bc, "Cc": Cc, "Dc": Dc})
np.save("ABC.npy", np.hstack([A, B]))
np.save("C.npy", C)
np.save("K.npy", K)
PY
for c in K Kflip lti; do
  "$codyna" simulate "$model" --controller $c.mat --t-end 0.2 --quiet --out $c.h5 > $c.txt 2> $c.err ||
    fail "simulate --controller $c.mat exited non-zero: $(cat $c.err)"
done
"$PY" - <<'PY'
import numpy as np, re, sys
AB, C, K = np.load("ABC.npy"), np.load("C.npy"), np.load("K.npy")
A, B = AB[:, :4], AB[:, 4:]
def parse(token):
    token = token.strip()
    if not token.endswith("i"): return complex(float(token), 0.0)
    body = token[:-1]
    for k in range(len(body) - 1, 0, -1):
        if body[k] in "+-" and body[k - 1] not in "eE":
            return complex(float(body[:k]), float(body[k:]))
    sys.exit(f"cannot read pole {token}")
def printed(name):
    text = open(name + ".txt").read()
    m = re.search(r"^linear closed-loop poles \(continuous, s, about the equilibrium point\): (.*)$", text, re.M)
    if not m: sys.exit(f"{name}: no poles printed:\n{text}")
    return np.array([parse(t) for t in m.group(1).split(", ")]), text
def same(p, q, name):
    key = lambda z: (round(z.real, 6), z.imag)
    p, q = sorted(p, key=key), sorted(q, key=key)
    if len(p) != len(q): sys.exit(f"{name}: {len(p)} poles printed, {len(q)} expected")
    err = max(abs(a - b) / max(1.0, abs(b)) for a, b in zip(p, q))
    print(f"{name}: poles {np.round(np.array(p), 6)}, max relative difference from eig {err:.2e}")
    if err > 1e-9: sys.exit(f"{name}: printed poles {p} differ from {q}")
nom, nom_text = printed("K")
same(nom, np.linalg.eigvals(A - B @ K), "nominal LQR")
if max(z.real for z in nom) >= 0: sys.exit("the nominal LQR loop should be stable")
if "unstable linear closed loop" in nom_text: sys.exit("a warning on the stable loop")
flip, flip_text = printed("Kflip")
expected = np.linalg.eigvals(A + B @ K)
same(flip, expected, "flipped K")
n_bad = int(sum(z.real > 0 for z in expected))
if n_bad == 0: sys.exit("the flipped gain should be unstable")
m = re.search(r"^warning +unstable linear closed loop: (\d+) of 4 poles with positive real part \((.*)\)$", flip_text, re.M)
if not m or int(m.group(1)) != n_bad: sys.exit(f"no (or a wrong) warning in the summary:\n{flip_text}")
# the LTI loop: [x; xc]' = [[A + B Dc C, B Cc], [Bc C, Ac]] [x; xc]
Ac, Bc, Cc, Dc = np.array([[-5.0]]), np.array([[1.0, 0.0]]), np.array([[2.0]]), np.array([[-30.0, 80.0]])
Acl = np.block([[A + B @ Dc @ C, B @ Cc], [Bc @ C, Ac]])
lti, lti_text = printed("lti")
same(lti, np.linalg.eigvals(Acl), "LTI")
if (max(z.real for z in lti) > 0) != ("unstable linear closed loop" in lti_text): sys.exit("LTI: warning and poles disagree")
print("UNSTABLE_OK")
PY
grep -q "codyna: warning: unstable linear closed loop" Kflip.err || fail "no warning on stderr: $(cat Kflip.err)"
# the nonlinear run says when it leaves the region where the linear model holds (issue 21): the
# flipped gain sends the pendulum down (rod_pivot, on which A depends, more than 0.5 rad from its
# operating-point value) while the cart's position (A's column zero) is not measured; the LQR
# stays within; --linear-region moves the bound
for c in K Kflip; do
  "$codyna" simulate "$model" --controller $c.mat --t-end 4 --quiet --out ${c}_long.h5 > ${c}_long.txt 2> ${c}_long.err ||
    fail "simulate --controller $c.mat --t-end 4: $(cat ${c}_long.err)"
done
grep -Eq '^linear region    \|q - q_op\| <= 0\.5 on rod_pivot: stayed within \(largest [0-9.e-]+, rod_pivot\)$' K_long.txt ||
  fail "the LQR run: $(grep -A1 'linear region' K_long.txt)"
grep -Eq '^linear region    \|q - q_op\| <= 0\.5 on rod_pivot: left at t = [0-9.]+ s \(rod_pivot\), largest' Kflip_long.txt ||
  fail "the flipped run: $(grep -A1 'linear region' Kflip_long.txt)"
grep -q "codyna: warning: the state left the region where the linear model holds: |rod_pivot - its operating-point value| > 0.5 at t = " Kflip_long.err ||
  fail "no warning on stderr: $(cat Kflip_long.err)"
"$PY" - <<'PY'
import h5py, re, sys, json
import numpy as np
text = open("Kflip_long.txt").read()
t_left = float(re.search(r"left at t = (\S+) s", text).group(1))
with h5py.File("Kflip_long.h5", "r") as f:
    t, q = f["time"][()], f["q"][()]
    names = [n.decode() if isinstance(n, bytes) else n for n in f["names/q"][()]]
    op = json.loads(f["provenance"].attrs["settings_json"])["operating_point_q"]
k = names.index("rod_pivot")
d = np.abs(q[:, k] - op["rod_pivot"])
first = t[np.argmax(d > 0.5)]
if not (d > 0.5).any() or abs(first - t_left) > 1e-9: sys.exit(f"printed t = {t_left}, the file's first sample beyond 0.5 is {first}")
print(f"REGION_OK the flipped gain leaves |rod_pivot - op| <= 0.5 at t = {t_left} s, as the file's samples show")
PY
"$codyna" simulate "$model" --controller K.mat --t-end 4 --linear-region 1e-4 --quiet --out tight.h5 > tight.txt 2> tight.err || fail "--linear-region"
grep -q '^linear region    |q - q_op| <= 0.0001 on rod_pivot: left at' tight.txt || fail "--linear-region 1e-4: $(grep 'linear region' tight.txt)"
echo "unstable_closed_loop: all checks passed"
