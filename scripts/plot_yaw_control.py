#!/usr/bin/python3
"""Draws docs/figures/sedan_esc_swd.png: the sedan's sine with dwell (FMVSS 126, 3 rad at the
steering wheel, 25 m/s) without and with its yaw-rate controller (docs/vehicles.md, "A yaw-rate
controller"), from the two runs' CSV files as `codyna maneuver ... --csv` writes them.

usage: plot_yaw_control.py OUT.png OPEN.csv CONTROLLED.csv
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read(path):
    with open(path) as f:
        names = f.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return {n: data[:, k] for k, n in enumerate(names)}


def main(argv):
    if len(argv) != 4:
        sys.stderr.write(__doc__)
        return 2
    out, runs = argv[1], [("without the controller", read(argv[2]), "tab:red"),
                          ("with the controller", read(argv[3]), "tab:blue")]
    fig, ax = plt.subplots(2, 2, figsize=(11, 7.5))
    for label, r, colour in runs:
        t = r["t"]
        beta = np.degrees(np.arctan2(r["body.vy"], np.abs(r["body.vx"])))
        ax[0, 0].plot(t, r["yaw_rate"], color=colour, label=label)
        ax[0, 1].plot(t, beta, color=colour, label=label)
        ax[1, 0].plot(r["body.x"] - r["body.x"][0], r["body.y"] - r["body.y"][0], color=colour, label=label)
        if "yaw_rate_reference" in r:
            ax[0, 0].plot(t, r["yaw_rate_reference"], color="0.4", ls="--", lw=1, label="intended (reference)")
            ax[1, 1].plot(t, r["brake_fl"], color="tab:green", label="brake_fl")
            ax[1, 1].plot(t, r["brake_fr"], color="tab:purple", label="brake_fr")
    ax[0, 0].set(xlabel="t (s)", ylabel="yaw rate (rad/s)", title="yaw rate")
    ax[0, 1].set(xlabel="t (s)", ylabel="sideslip (deg)", title="sideslip at the centre of mass")
    ax[0, 1].axhline(10, color="0.6", lw=0.8, ls=":")
    ax[0, 1].axhline(-10, color="0.6", lw=0.8, ls=":")
    ax[1, 0].set(xlabel="x (m)", ylabel="y (m)", title="path of the centre of mass")
    ax[1, 0].set_aspect("equal", adjustable="datalim")
    ax[1, 1].set(xlabel="t (s)", ylabel="torque (N m)", title="front brake torques (the controller's)")
    for a in ax.flat:
        a.grid(True, lw=0.4)
        a.legend(fontsize=8)
    fig.suptitle("sedan, sine with dwell 3 rad at 25 m/s (FMVSS 126)")
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
