"""Draws docs/angle_conventions.png: how linkage measures a four-bar's angles.

    python docs/angle_conventions.py
"""

from __future__ import annotations

import cmath
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.patches import Arc

from linkage.problems.closed_form import fourbar_positions

# the course notes' linkage (links 2, 4, 3, 5, scaled by 20) at alpha = 70 deg, where the
# notes find phi = 54.8878 deg: theta2 = 250 deg, theta4 = 234.8878 deg
r1, r2, r3, r4 = 100.0, 40.0, 80.0, 60.0
alpha, phi = 70.0, 54.88776318877914
t2 = math.radians(alpha + 180.0)
sols = fourbar_positions(r1, r2, r3, r4, 0.0, theta2=t2).values()
sol = min(sols, key=lambda s: abs(cmath.exp(1j * s["theta4"]) - cmath.exp(1j * math.radians(phi + 180))))
t3, t4 = sol["theta3"], sol["theta4"]
O2, O4 = 0j, complex(r1, 0)
A = r2 * cmath.exp(1j * t2)
B = O4 + r4 * cmath.exp(1j * t4)

fig, ax = plt.subplots(figsize=(8.5, 5.2))
for p, q, c, lw in ((O2, A, "tab:red", 3), (A, B, "tab:blue", 2.5), (O4, B, "tab:blue", 2.5)):
    ax.plot([p.real, q.real], [p.imag, q.imag], color=c, lw=lw)
ax.plot([O2.real, O4.real], [0, 0], color="0.5", ls="--", lw=1.2)
for name, p, off in (("O2", O2, (-22, -14)), ("A", A, (-14, 6)), ("B", B, (6, 4)), ("O4", O4, (6, -14))):
    ax.plot([p.real], [p.imag], "o", ms=7, mfc="white", mec="black", zorder=5)
    ax.annotate(name, (p.real, p.imag), textcoords="offset points", xytext=off, fontsize=10)


def angle(center: complex, start: float, end: float, radius: float, color: str, label: str,
          ls: str = "-") -> None:
    lo, hi = sorted((math.degrees(start), math.degrees(end)))
    ax.add_patch(Arc((center.real, center.imag), 2 * radius, 2 * radius, theta1=lo, theta2=hi,
                     color=color, lw=1.5, ls=ls))
    mid = math.radians((lo + hi) / 2)
    at = center + 1.15 * radius * cmath.exp(1j * mid)
    ax.annotate(label, (at.real, at.imag), color=color, fontsize=11, ha="center", va="center")


# mechanism files: every angle from +x (ground O2 -> O4)
for c in (O2, A, O4):
    ax.annotate("", xy=(c.real + 28, c.imag), xytext=(c.real, c.imag),
                arrowprops=dict(arrowstyle="->", color="0.3", lw=1))
angle(O2, 0.0, t2 % (2 * math.pi), 14, "tab:red", "θ2")
angle(A, 0.0, t3, 22, "tab:blue", "θ3")
angle(O4, 0.0, t4 % (2 * math.pi), 13, "tab:blue", "θ4")
# the input-output equation: from the line O4 -> O2 (pointing the other way)
ax.annotate("", xy=(O4.real - 30, 0), xytext=(O4.real, 0),
            arrowprops=dict(arrowstyle="->", color="tab:green", lw=1.2))
ax.annotate("", xy=(O2.real - 26, 0), xytext=(O2.real, 0),
            arrowprops=dict(arrowstyle="->", color="tab:green", lw=1.2))
angle(O2, math.pi, t2 % (2 * math.pi), 30, "tab:green", "α", ls="--")
angle(O4, math.pi, t4 % (2 * math.pi), 28, "tab:green", "φ", ls="--")
ax.set_aspect("equal")
ax.set_xlim(-50, 140)
ax.set_ylim(-75, 35)
ax.grid(True, alpha=0.2)
ax.set_xlabel("x (mm): mechanism files put the ground O2 -> O4 along +x")
ax.set_ylabel("y (mm)")
ax.set_title("Mechanism files (solid): θ2, θ3, θ4 counterclockwise from +x.  Input-output equation\n"
             "(dashed): α at O2 and φ at O4, counterclockwise from the line pointing O4 -> O2.\n"
             f"So θ2 = α + 180° and θ4 = φ + 180°: here α = {alpha:g}°, φ = {phi:.4f}°, "
             f"θ2 = {alpha + 180:g}°, θ4 = {phi + 180:.4f}°.", fontsize=10)
out = Path(__file__).resolve().parent / "angle_conventions.png"
fig.savefig(out, dpi=120, bbox_inches="tight")
print(f"wrote {out}")
