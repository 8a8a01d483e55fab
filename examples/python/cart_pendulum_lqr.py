#!/usr/bin/env python3
"""The paper's cart-pendulum balanced by an LQR designed in Python (docs/python.md).

  1. codyna linearizes examples/cart_pendulum.json about its upright equilibrium
     (states h, theta, h_dot, theta_dot; input force; outputs h, theta);
  2. scipy designs the LQR, Q = diag(10, 100, 1, 1), R = 0.01 (the model file's weights):
     K = R^-1 B' X with X from scipy.linalg.solve_continuous_are;
  3. K goes into a .mat as `codyna simulate --controller K.mat` reads it (u = u0 - K (x - x0),
     in the export's state order: what Linearization.state_names lists);
  4. codyna runs that controller on the nonlinear model from the file's start (theta = 0.1 rad)
     and from a larger tilt (theta = 0.5 rad), each beside the linear closed loop
     (compare_linear=True);
  5. matplotlib plots the nonlinear and linear responses into a PNG.

Usage: cart_pendulum_lqr.py [PNG]   (default: cart_pendulum_lqr.png in the current folder)
Needs the module on the path: PYTHONPATH=build/python (or `cmake --install`).
"""
import os
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import scipy.io  # noqa: E402
import scipy.linalg  # noqa: E402

import codyna  # noqa: E402

MODEL = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "cart_pendulum.json")


def main():
    png = sys.argv[1] if len(sys.argv) > 1 else "cart_pendulum_lqr.png"
    study = codyna.Study(MODEL)

    # 1. the plant about the upright equilibrium
    lin = study.linearize(operating_point="equilibrium")
    print("plant            %s, states %s, input %s, outputs %s"
          % (lin.name, ", ".join(lin.state_names), ", ".join(lin.input_names), ", ".join(lin.output_names)))
    print("open-loop poles  %s" % ", ".join("%.6g" % p.real if p.imag == 0 else "%.6g%+.6gi" % (p.real, p.imag)
                                             for p in lin.eigenvalues()))

    # 2. the LQR, by scipy
    Q = np.diag([10.0, 100.0, 1.0, 1.0])
    R = np.array([[0.01]])
    X = scipy.linalg.solve_continuous_are(lin.A, lin.B, Q, R)
    K = np.linalg.solve(R, lin.B.T @ X)
    poles = np.linalg.eigvals(lin.A - lin.B @ K)
    poles = poles[np.lexsort((poles.imag, poles.real))]
    K_codyna = codyna.lqr(lin.A, lin.B, Q, R)[0]
    print("K = [%s]" % " ".join("%.10g" % k for k in K.ravel()))
    print("    (codyna.lqr gives the same K to %.1e relative)" % (np.abs(K - K_codyna).max() / np.abs(K).max()))
    print("closed-loop poles %s" % ", ".join("%.6g%+.6gi" % (p.real, p.imag) for p in poles))

    runs = {}
    with tempfile.TemporaryDirectory() as tmp:
        # 3. K as the command line's --controller K.mat reads it
        k_mat = os.path.join(tmp, "K.mat")
        scipy.io.savemat(k_mat, {"K": K})
        # 4. the nonlinear closed loop beside the linear one
        for tilt in (0.1, 0.5):
            runs[tilt] = study.simulate(controller=k_mat, compare_linear=True, t_end=5,
                                        initial={"rod_pivot": tilt})

    for tilt, run in runs.items():
        print("start theta = %.1f rad: %s, %d samples, controller: %s"
              % (tilt, "completed" if run.completed else "FAILED " + run.failure, len(run.t), run.controller))
        for k, name in enumerate(run.output_names):
            gap = np.abs(run.y[:, k] - run.y_linear[:, k])
            i = int(np.argmax(gap))
            print("  %-6s max |y - y_lin| = %.3g %s at t = %.2f s (%.2g %% of its excursion)"
                  % (name, gap[i], run.output_units[k], run.t[i], run.linear_gap["percent"][name]))
        u = run.u[:, run.input_names.index("force")]
        print("  force  max |u| = %.4g N" % np.abs(u).max())
        for w in run.warnings:
            print("  warning: " + w)

    # 5. the plot: h, theta and the force, nonlinear (solid) and linear (dashed)
    fig, axes = plt.subplots(3, 1, figsize=(8, 8.5), sharex=True)
    colors = {0.1: "tab:blue", 0.5: "tab:red"}
    for tilt, run in runs.items():
        c = colors[tilt]
        for k, ax in enumerate(axes[:2]):
            ax.plot(run.t, run.y[:, k], color=c, label="nonlinear, theta(0) = %.1f rad" % tilt)
            ax.plot(run.t, run.y_linear[:, k], "--", color=c, label="linear, theta(0) = %.1f rad" % tilt)
        axes[2].plot(run.t, run.u[:, run.input_names.index("force")], color=c, label="theta(0) = %.1f rad" % tilt)
    first = runs[0.1]
    for k, ax in enumerate(axes[:2]):
        ax.set_ylabel("%s [%s]" % (first.output_names[k], first.output_units[k]))
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize=8, ncol=2)
    axes[2].set_ylabel("force [N]")
    axes[2].set_xlabel("t [s]")
    axes[2].grid(True, alpha=0.3)
    axes[2].legend(fontsize=8)
    axes[0].set_title("cart-pendulum, LQR by scipy (Q = diag(10, 100, 1, 1), R = 0.01), run by codyna")
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    print("wrote " + png)


if __name__ == "__main__":
    main()
