"""Draw docs/path_synthesis_problem3.png: Problem 3's nine points and the coupler curves of
its real four-bars without a branch or order defect (one of each cognate group), each
curve the circuit through the first point, followed by the engine.

    python docs/path_synthesis_figure.py
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from linkage.synthesis.path import PROBLEM_3, coupler_curve, synthesize_path


def main() -> None:
    res = synthesize_path(PROBLEM_3)
    good = [group for group in res.designs if not {"branch", "order"} & set(group[0].defects)]
    fig, ax = plt.subplots(figsize=(7, 7))
    for group in good:
        curve = coupler_curve(group[0])
        ax.plot(curve.real, curve.imag, lw=0.8)
    ax.plot([x for x, _ in PROBLEM_3], [y for _, y in PROBLEM_3], "ko", ms=6, zorder=5)
    for k, (x, y) in enumerate(PROBLEM_3):
        ax.annotate(str(k + 1), (x, y), textcoords="offset points", xytext=(5, 5))
    ax.set_xlim(-1.5, 2.5)
    ax.set_ylim(-1.5, 2.5)
    ax.set_aspect("equal")
    ax.grid(True, alpha=0.3)
    least = ", ".join(f"{g[0].transmission_min_deg:.2g}" for g in good)
    ax.set_title(f"Problem 3 (Wampler, Morgan, Sommese 1992): {len(good)} of {len(res.designs)} real "
                 f"four-bars pass through\nthe points in order on one circuit (least transmission "
                 f"{least} deg)")
    fig.savefig("docs/path_synthesis_problem3.png", dpi=110, bbox_inches="tight")
    print(f"{len(res.designs)} real, {len(good)} without a branch or order defect; "
          "wrote docs/path_synthesis_problem3.png")
    for group in res.designs:
        print(group[0].grashof, group[0].defects, [g.defects for g in group[1:]])


if __name__ == "__main__":
    main()
