#!/usr/bin/env python3
"""Work-precision plots from the CSV of build/bin/codyna_work_precision.

    /usr/bin/python3 scripts/plot_work_precision.py docs/work_precision/work_precision.csv docs/work_precision

One PNG per problem: error against CPU time (log-log), one line per integrator,
codyna solid, Simbody (integrator names starting "simbody-") dashed, and the IFToMM
high-precision bound as a horizontal line where one exists.
"""
import csv
import math
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

TITLES = {
    "andrews": "Andrews' squeezer, t = 0.03 s: max relative error of the 7 angles",
    "a01": "IFToMM A01 pendulum, 10 s: max position error of the mass [m]",
    "a02": "IFToMM A02, N = 40 four-bars, 20 s: max crank angle error [rad] (exact reduction)",
    "bricard": "IFToMM A04 Bricard, 10 s: max error of point C [m] (reference run)",
    "a05": "IFToMM A05 stiff flyball, 10 s: max slider height error [m] (reference run)",
    "heavy_top": "Heavy top, 10 s: max relative change of energy and vertical momentum",
    "double_pendulum": "Double pendulum, 1000 s: max relative energy change",
}
_HIGH = (1e-3, "IFToMM high precision (1e-3)")
BOUNDS = {"a01": _HIGH, "a02": _HIGH, "bricard": _HIGH, "a05": _HIGH}  # problem -> (value, label)
# problem -> the (CPU time [s], error) points a method must reach or pass below and to the left of
TARGETS = {"a02": ([(0.2, 1e-3), (1.0, 1e-6)], "issue 41's targets (1e-3 in 0.2 s, 1e-6 in 1 s)")}


def main(path, outdir, suffix=""):
    runs = defaultdict(lambda: defaultdict(list))
    with open(path) as f:
        for row in csv.DictReader(f):
            err, cpu = float(row["error"]), float(row["cpu_s"])
            if row["completed"] != "1" or not math.isfinite(err) or err <= 0:
                continue
            runs[row["problem"]][row["integrator"]].append((cpu, max(err, 1e-16), float(row["tol"])))
    for problem, by_int in runs.items():
        fig, ax = plt.subplots(figsize=(9, 5))
        for name, pts in sorted(by_int.items()):
            pts.sort(key=lambda p: -p[2])
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], "--" if name.startswith("simbody-") else "-",
                      marker="o", ms=3, label=name)
        if problem in BOUNDS:
            v, lab = BOUNDS[problem]
            ax.axhline(v, color="grey", lw=1, ls=":", label=lab)
        if problem in TARGETS:
            pts, lab = TARGETS[problem]
            ax.plot([p[0] for p in pts], [p[1] for p in pts], "k+", ms=12, mew=1.5, ls="none", label=lab)
        ax.set_xlabel("CPU time [s] (best of repeats)")
        ax.set_ylabel("error")
        ax.set_title(TITLES.get(problem, problem), fontsize=10)
        ax.grid(True, which="major", alpha=0.4)
        ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1))  # (outside: no line hidden)
        fig.tight_layout()
        out = f"{outdir}/{problem}{suffix}.png"
        fig.savefig(out, dpi=100)
        plt.close(fig)
        print("wrote", out)


if __name__ == "__main__":
    # (a third argument is appended to each file's name: a02_alf.png from one problem's own run)
    main(sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else "docs/work_precision", sys.argv[3] if len(sys.argv) > 3 else "")
