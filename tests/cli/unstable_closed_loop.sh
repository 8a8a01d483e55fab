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
echo "unstable_closed_loop: all checks passed"
