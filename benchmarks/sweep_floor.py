"""The floor of issue 33's row 5 (361-position ``linkage.sweep`` / numpy closed form <= 3x):
the least a sweep that keeps the single solve's promise computes
(:func:`linkage.measure.hand.fourbar_open_certified`: the closed form, every position's
margin, the evidence that each answer is a root, det J's sign), written by hand as tight as
:func:`linkage.measure.hand.fourbar_open`, timed against that closed form alone, and
``linkage.sweep`` against it too; interleaved pairs, medians. ``linkage bench`` prints the
floor's ratio beside row 5.

Before anything is timed, the floor's angles are checked against ``linkage.sweep``'s (within
1e-9 deg, whole turns aside) and every position certified, so it computes the real thing.

    python benchmarks/sweep_floor.py              # 15 pairs of each
    python benchmarks/sweep_floor.py --repeats 31
    python benchmarks/sweep_floor.py --positions 3   # the fixed cost of a call
"""

from __future__ import annotations

import argparse

import numpy as np

import linkage
from linkage.kinematics.closed import MARGIN_FLOOR
from linkage.measure.hand import fourbar_open, fourbar_open_certified
from linkage.measure.targets import crank_rocker, tolerance
from linkage.measure.timing import interleaved_pairs
from linkage.rules import residual_gate
from linkage.units import radians

POSITIONS = 361


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=15)
    ap.add_argument("--positions", type=int, default=POSITIONS, help="driver values over 0..360 deg")
    args = ap.parse_args()
    m, links = crank_rocker()
    grid = np.linspace(0.0, 360.0, args.positions)
    values = [float(v) for v in grid]
    tol = tolerance()
    gate = residual_gate(tol, m.length_scale)

    def floor() -> tuple[np.ndarray, ...]:
        return fourbar_open_certified(values, *links, tol, gate, MARGIN_FLOOR)

    t3, t4, _, certified = floor()
    swept = linkage.sweep(m, values)
    for mine, unknown in zip((t3, t4), m.unknowns):
        theirs = np.asarray(swept.column(unknown.name), dtype=float)
        gap = np.abs(np.remainder(mine - theirs + 180.0, 360.0) - 180.0)
        if not gap.max() < 1e-9:
            raise SystemExit(f"the floor's {unknown.name} is {gap.max():.3g} deg from linkage.sweep's")
    if not certified.all():
        raise SystemExit("the floor does not certify every position")

    def bare() -> tuple[np.ndarray, np.ndarray]:
        return fourbar_open(radians(grid), *links)

    low = interleaved_pairs(floor, bare, args.repeats, 0.005)
    whole = interleaved_pairs(lambda: linkage.sweep(m, values), bare, args.repeats, 0.005)
    print(f"{args.positions} positions of crank_rocker.toml, {args.repeats} interleaved pairs, medians")
    print(f"  the floor (closed form and evidence) {low.a_median * 1e6:7.1f} us / "
          f"closed form {low.b_median * 1e6:6.1f} us = {low.ratio:.2f}x")
    print(f"  linkage.sweep                        {whole.a_median * 1e6:7.1f} us / "
          f"closed form {whole.b_median * 1e6:6.1f} us = {whole.ratio:.2f}x")
    print(f"  row 5's target <= 3x; linkage.sweep is {whole.ratio / low.ratio:.2f}x the floor")


if __name__ == "__main__":
    main()
