#!/usr/bin/env python3
"""Draws docs/figures/tire_axes.svg and .png: the ISO-W axes of a tire's contact and the signs of
the slips and forces (docs/tires.md, "Axes and slips"). Run with /usr/bin/python3 (matplotlib from
Debian); the files are committed, so nothing runs this at build time."""
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.patches import FancyArrowPatch, Rectangle, Ellipse, Arc, Circle
from matplotlib.transforms import Affine2D

out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "docs", "figures", "tire_axes")
if len(sys.argv) > 1:
    out = sys.argv[1]

plt.rcParams.update({"font.size": 10, "svg.fonttype": "none"})
fig, axes = plt.subplots(1, 3, figsize=(13.5, 4.8))
INK, FORCE, VEL, AX = "#222222", "#1f5fbf", "#c0392b", "#444444"


def arrow(ax, x0, y0, x1, y1, color=INK, lw=1.6, style="-|>", ms=12, ls="-"):
    ax.add_patch(FancyArrowPatch((x0, y0), (x1, y1), arrowstyle=style, mutation_scale=ms, color=color, lw=lw,
                                 linestyle=ls, shrinkA=0, shrinkB=0))


def setup(ax, title):
    ax.set_aspect("equal")
    ax.axis("off")
    ax.set_title(title, fontsize=11)


# (a) top view: heading x, left y, the contact's velocity V at slip angle alpha, the side force Fy
ax = axes[0]
setup(ax, "top view (z toward you)")
ax.set_xlim(-2.2, 2.6)
ax.set_ylim(-2.0, 2.3)
ax.add_patch(Rectangle((-1.3, -0.28), 2.6, 0.56, facecolor="#d9d9d9", edgecolor=INK, lw=1.2))
ax.plot([0], [0], "o", color=INK, ms=4)
ax.text(0.08, -0.45, "P", fontsize=10)
arrow(ax, 0, 0, 2.2, 0, AX)
ax.text(2.28, -0.08, "x (heading)", fontsize=10)
arrow(ax, 0, 0, 0, 2.0, AX)
ax.text(0.1, 2.0, "y (left)", fontsize=10)
alpha = math.radians(22)
arrow(ax, 0, 0, 1.9 * math.cos(alpha), 1.9 * math.sin(alpha), VEL)
ax.text(1.9 * math.cos(alpha) + 0.05, 1.9 * math.sin(alpha) + 0.05, "V (contact)", color=VEL, fontsize=10)
ax.add_patch(Arc((0, 0), 2.2, 2.2, theta1=0, theta2=22, color=VEL, lw=1.2))
ax.text(1.17, 0.18, r"$\alpha$", color=VEL, fontsize=12)
arrow(ax, -0.6, 0, -0.6, -1.5, FORCE, lw=2.2)
ax.text(-0.55, -1.75, r"$F_y < 0$ for $\alpha > 0$", color=FORCE, fontsize=10)
# M_z: positive counterclockwise here (about z, toward you)
ax.add_patch(FancyArrowPatch((0.55 * math.cos(math.radians(140)), 0.55 * math.sin(math.radians(140))),
                             (0.55 * math.cos(math.radians(220)), 0.55 * math.sin(math.radians(220))),
                             connectionstyle="arc3,rad=0.45", arrowstyle="-|>", mutation_scale=10, color=FORCE, lw=1.4))
ax.text(-1.75, 0.55, r"$M_z$ (+ about z)", color=FORCE, fontsize=10)
ax.text(-2.15, 1.55, r"$\alpha = \mathrm{atan}(V_y / |V_x|)$", fontsize=10)

# (b) rear view: the wheel tilted by camber gamma (top to the right: positive), the load Fz
ax = axes[1]
setup(ax, "rear view (x into the page)")
ax.set_xlim(-2.0, 2.0)
ax.set_ylim(-0.5, 3.3)
ax.plot([-1.9, 1.9], [0, 0], color=INK, lw=1.2)
ax.text(1.1, -0.3, "road", fontsize=9)
gamma = math.radians(12)
R = 1.5
# wheel plane: a thin rectangle tilted about the contact point (its top to the right)
wheel = Rectangle((-0.18, 0), 0.36, 2 * R, facecolor="#d9d9d9", edgecolor=INK, lw=1.2)
wheel.set_transform(Affine2D().rotate(-gamma) + ax.transData)
ax.add_patch(wheel)
cx, cy = R * math.sin(gamma), R * math.cos(gamma)
ax.plot([cx], [cy], "o", color=INK, ms=4)
ax.text(cx + 0.3, cy - 0.05, "c (centre)", fontsize=10)
ax.plot([0], [0], "o", color=INK, ms=4)
ax.text(0.05, 0.1, "P", fontsize=10)
ax.plot([0, 0], [0, 2.9], color=AX, lw=0.8, ls="--")
ax.add_patch(Arc((0, 0), 2.6, 2.6, theta1=90 - 12, theta2=90, color=INK, lw=1.2))
ax.text(-0.75, 1.45, r"$\gamma > 0$", fontsize=11)
arrow(ax, 0, 0, -1.6, 0, AX)
ax.text(-1.95, 0.12, "y (left)", fontsize=10)
arrow(ax, -1.2, 0, -1.2, 1.4, FORCE, lw=2.2)
ax.text(-1.85, 1.5, r"$F_z$ (load, z up)", color=FORCE, fontsize=10)
ax.text(-1.9, 2.9, r"$\gamma = \mathrm{asin}(n \cdot a)$, a the spin axis (left)", fontsize=9)

# (c) side view: forward speed Vx, spin Omega, rolling radius Re, the slip kappa and Fx
ax = axes[2]
setup(ax, "side view from the left (y into the page)")
ax.set_xlim(-2.0, 2.6)
ax.set_ylim(-0.8, 3.2)
ax.plot([-1.9, 2.5], [0, 0], color=INK, lw=1.2)
Rw = 1.2
ax.add_patch(Circle((0, Rw), Rw, facecolor="#d9d9d9", edgecolor=INK, lw=1.2))
ax.plot([0], [Rw], "o", color=INK, ms=4)
arrow(ax, 0, Rw, 1.9, Rw, VEL)
ax.text(1.95, Rw + 0.08, r"$V_x$", color=VEL, fontsize=12)
# forward roll: clockwise here, + about y (into the page)
ax.add_patch(FancyArrowPatch((0.7 * math.cos(math.radians(150)), Rw + 0.7 * math.sin(math.radians(150))),
                             (0.7 * math.cos(math.radians(30)), Rw + 0.7 * math.sin(math.radians(30))),
                             connectionstyle="arc3,rad=-0.55", arrowstyle="-|>", mutation_scale=10, color=VEL, lw=1.4))
ax.text(-1.25, 2.55, r"$\Omega$ (forward roll: + about y)", color=VEL, fontsize=9)
ax.plot([0, 0], [0, Rw], color=AX, lw=0.8, ls="--")
ax.text(0.05, 0.35, r"$R_e$", fontsize=11)
arrow(ax, 0, 0, 1.5, 0, FORCE, lw=2.2)
ax.text(0.6, -0.35, r"$F_x > 0$ for $\kappa > 0$ (driving)", color=FORCE, fontsize=10)
ax.text(-1.9, 2.85, r"$\kappa = -(V_x - \Omega R_e) / |V_x|$", fontsize=11)

fig.suptitle("ISO-W axes at the contact point P: x forward along the wheel's heading in the road plane, "
             "z the road's normal (up), y = z x x (left)", fontsize=11)
fig.tight_layout(rect=(0, 0, 1, 0.93))
fig.savefig(out + ".svg")
fig.savefig(out + ".png", dpi=110)
print("wrote", out + ".svg", out + ".png")
