#!/usr/bin/env python3
"""Plot codyna freqresp tables over the linear model's Bode plot.

usage: plot_freqresp.py OUT.png|OUT.svg PAIR CSV[=LABEL] [CSV[=LABEL] ...]

PAIR is OUTPUT/INPUT as the table's columns name it (yaw_rate/steer). Each CSV is one run of
codyna freqresp (at one amplitude, say); its nonlinear gain and phase are drawn as markers, the
linear model's (the first table's columns *_linear) as a line. Uses matplotlib (Debian's
python3-matplotlib) without a display.
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read(path, pair):
    rows = list(csv.DictReader(open(path)))
    if not rows or pair + "_magnitude" not in rows[0]:
        sys.exit("%s: no column %s_magnitude (pairs: %s)" % (path, pair, ", ".join(
            sorted({k[: -len("_magnitude")] for k in rows[0] if k.endswith("_magnitude")})) if rows else "none"))
    col = lambda name: np.array([float(r[pair + "_" + name]) for r in rows])
    return np.array([float(r["w_rad_s"]) for r in rows]), col("magnitude"), col("phase_deg"), col(
        "magnitude_linear"), col("phase_deg_linear")


def main(argv):
    if len(argv) < 4:
        sys.exit(__doc__)
    out, pair, tables = argv[1], argv[2], argv[3:]
    fig, (am, ap) = plt.subplots(2, 1, sharex=True, figsize=(7, 6))
    for k, spec in enumerate(tables):
        path, _, label = spec.partition("=")
        w, mag, ph, mag_lin, ph_lin = read(path, pair)
        if k == 0:
            am.loglog(w, mag_lin, "k-", label="linear model")
            ap.semilogx(w, np.degrees(np.unwrap(np.radians(ph_lin))), "k-")
        ph_nl = np.degrees(np.unwrap(np.radians(ph)))
        ph_nl += 360 * np.round((np.degrees(np.unwrap(np.radians(ph_lin)))[0] - ph_nl[0]) / 360)
        am.loglog(w, mag, "o", label=label or path)
        ap.semilogx(w, ph_nl, "o")
    am.set_ylabel("gain " + pair)
    ap.set_ylabel("phase (deg)")
    ap.set_xlabel("frequency (rad/s)")
    am.grid(True, which="both", alpha=0.3)
    ap.grid(True, which="both", alpha=0.3)
    am.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main(sys.argv)
