"""Draw docs/path_synthesis_timed.png: five points with the crank's angle at each (the worked
example of docs/path_synthesis.md, "Prescribed timing"), the coupler curves of the
designs without defects (each the circuit through the first point, followed by the engine;
a design's Roberts cognate traces the same curve), and the best one drawn at the first point
with its crank at every point, and its cognate with the same timing.

    python docs/path_synthesis_timed_figure.py
"""

from __future__ import annotations

import cmath

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from linkage.render.path_synthesis import timed_ranked
from linkage.synthesis.path import coupler_curve, synthesize_path
from linkage.units import radians

POINTS = [(0.1579, 2.4375, 20), (0.3675, 3.0987, 60), (-0.1131, 3.2206, 100), (-0.7817, 2.8793, 140),
          (-1.3129, 2.2146, 180)]


def main() -> None:
    res = synthesize_path(POINTS)
    order = timed_ranked(res)
    good = [g for g in order if not res.designs[res.groups[g][0]].defects]
    fig, ax = plt.subplots(figsize=(7.5, 6.5))
    for g in good:  # a cognate traces the same curve: one per group
        curve = coupler_curve(res.designs[res.groups[g][0]])
        ax.plot(curve.real, curve.imag, lw=1.5, label=f"design {order.index(g) + 1}")
    best, *cognate = (res.designs[i] for i in res.groups[good[0]])
    for fb, style in ((best, "k-"), *((c, "k--") for c in cognate)):
        A, B, M, N, P = fb.ground_a, fb.ground_b, fb.pin_m, fb.pin_n, fb.coupler_point
        ax.plot([A.real, M.real, N.real, B.real], [A.imag, M.imag, N.imag, B.imag], style, lw=1.8)
        ax.fill([M.real, N.real, P.real], [M.imag, N.imag, P.imag], color="0.6", alpha=0.4)
        ax.plot([A.real, B.real], [A.imag, B.imag], "k^", ms=10)
    A, M = best.ground_a, best.pin_m
    r2 = abs(M - A)
    for k, deg in enumerate(best.crank_deg):
        m = A + r2 * cmath.exp(1j * radians(deg))
        ax.plot([A.real, m.real], [A.imag, m.imag], "k:", lw=0.8)
        ax.annotate(f"at {k + 1}", (m.real, m.imag), fontsize=8, textcoords="offset points", xytext=(3, -3))
    ax.plot([x for x, _, _ in POINTS], [y for _, y, _ in POINTS], "ko", ms=6, zorder=5)
    for k, (x, y, deg) in enumerate(POINTS):
        right = x > 0.3  # keep the labels of the top two points apart
        ax.annotate(f"{k + 1}: crank {deg} deg", (x, y), textcoords="offset points",
                    xytext=(8, -2) if right else (-8, 6), ha="left" if right else "right")
    ax.margins(0.08)
    ax.set_aspect("equal")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="lower right", fontsize=8)
    ax.set_title(f"Five points at prescribed crank angles: {len(good)} of {len(res.groups)} designs without "
                 "defects;\ndesign 1 at point 1 (its crank dotted at each point), its cognate dashed")
    fig.savefig("docs/path_synthesis_timed.png", dpi=110, bbox_inches="tight")
    print(f"{len(res.designs)} four-bars, {len(res.groups)} up to cognates, {len(good)} without defects; "
          "wrote docs/path_synthesis_timed.png")


if __name__ == "__main__":
    main()
