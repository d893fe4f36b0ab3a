"""The floor of issue 33's row 5 (361-position ``linkage.sweep`` / numpy closed form <= 3x):
the least a sweep that keeps the single solve's promise must compute, written by hand in
numpy as tight as :func:`linkage.measure.hand.fourbar_open`, timed against that closed form
alone, interleaved, medians.

The floor takes what ``linkage.sweep`` takes (a list of 361 driver values, deg) and does
only this: the values as an array, checked strictly ascending; the open branch's closed
form (``fourbar_open``'s operations); every position's assembly margin above the
closed-form engine's floor (``MARGIN_FLOOR``); the evidence that each answer is a root to
the single solve's standard (Phi and J at the reported angles, the Newton step they imply,
judged by :func:`linkage.rules.system_converged_array`); det J of one sign; the angles in
degrees. No unwrapping, no anchoring to ``solve FILE``, no branch names, no touch check,
no result object: each of those is work ``linkage.sweep`` does on top.

Its answers are checked against ``linkage.sweep``'s (the same angles within 1e-9 deg, every
position certified) before anything is timed, so the floor computes the real thing.

    python benchmarks/sweep_floor.py              # 15 pairs of each
    python benchmarks/sweep_floor.py --repeats 31
"""

from __future__ import annotations

import argparse
import math
from typing import Any

import numpy as np

import linkage
from linkage.kinematics.closed import MARGIN_FLOOR
from linkage.measure.hand import fourbar_open
from linkage.measure.targets import crank_rocker
from linkage.measure.timing import interleaved_pairs
from linkage.rules import residual_gate, system_converged_array
from linkage.units import degrees, radians

POSITIONS = 361
TOL = 1e-12


def floor_sweep(values: list[float], r1: float, r2: float, r3: float, r4: float,
                length_scale: float) -> tuple[Any, Any, Any, Any]:
    """theta3, theta4 (deg), det J and the certified mask of a crank-rocker over ``values``
    (deg): the least honest sweep (the module's list)."""
    d = np.asarray(values, dtype=float)
    if np.count_nonzero(np.diff(d) > 0.0) != d.size - 1:
        raise ValueError("driver values not strictly ascending")
    t2 = radians(d)
    ax = np.cos(t2)
    ax *= r2
    ay = np.sin(t2)
    ay *= r2
    dx = ax - r1
    d2 = dx * dx
    d2 += ay * ay
    a = d2 + (r4 * r4 - r3 * r3)
    a /= 2.0 * d2
    h = np.square(a)
    np.subtract(r4 * r4 / d2, h, out=h)  # (h / d)^2: the margin of the triangle's inequality
    if np.count_nonzero(h > MARGIN_FLOOR) != h.size:
        raise ValueError("a position near a limit")
    np.sqrt(h, out=h)
    bx = a * dx
    bx += h * ay
    by = a * ay
    by -= h * dx
    t4 = np.arctan2(by, bx)
    bx += r1 - ax
    by -= ay
    t3 = np.arctan2(by, bx)
    # the evidence at the reported angles: Phi, J, det J and the Newton step (not taken)
    c3, s3, c4, s4 = np.cos(t3), np.sin(t3), np.cos(t4), np.sin(t4)
    px = ax + r3 * c3
    px -= r4 * c4
    px -= r1
    py = ay + r3 * s3
    py -= r4 * s4
    j11, j12, j21, j22 = -r3 * s3, r4 * s4, r3 * c3, -r4 * c4
    det = j11 * j22
    det -= j12 * j21
    d3 = (j22 * px - j12 * py) / det
    d4 = (j11 * py - j21 * px) / det
    step = np.maximum(np.abs(d3), np.abs(d4))
    resid = np.maximum(np.abs(px), np.abs(py))
    certified = system_converged_array(step, resid, TOL, residual_gate(TOL, length_scale))
    if not (np.count_nonzero(det > 0.0) == det.size or np.count_nonzero(det < 0.0) == det.size):
        raise ValueError("det J changes sign")
    return degrees(t3), degrees(t4), det, certified


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=15)
    args = ap.parse_args()
    m, links = crank_rocker()
    grid = np.linspace(0.0, 360.0, POSITIONS)
    values = [float(v) for v in grid]
    t3, t4, _, certified = floor_sweep(values, *links, m.length_scale)
    swept = linkage.sweep(m, values)
    names = [u.name for u in m.unknowns]
    for mine, name in ((t3, names[0]), (t4, names[1])):
        theirs = np.asarray(swept.column(name), dtype=float)
        # the same angle: differences of whole turns aside (the sweep unwraps, the floor does not)
        gap = np.abs(np.remainder(mine - theirs + 180.0, 360.0) - 180.0)
        assert gap.max() < 1e-9, (name, gap.max())
    assert certified.all()
    floor = interleaved_pairs(lambda: floor_sweep(values, *links, m.length_scale),
                              lambda: fourbar_open(radians(grid), *links), args.repeats, 0.005)
    whole = interleaved_pairs(lambda: linkage.sweep(m, values),
                              lambda: fourbar_open(radians(grid), *links), args.repeats, 0.005)
    print(f"{POSITIONS} positions of crank_rocker.toml, {args.repeats} interleaved pairs, medians")
    print(f"  floor (closed form + evidence) {floor.a_median * 1e6:7.1f} us   "
          f"numpy closed form {floor.b_median * 1e6:6.1f} us   ratio {floor.ratio:.2f}")
    print(f"  linkage.sweep                  {whole.a_median * 1e6:7.1f} us   "
          f"numpy closed form {whole.b_median * 1e6:6.1f} us   ratio {whole.ratio:.2f}")
    print(f"  row 5's target: <= 3x; the floor alone is {floor.ratio:.2f}x "
          f"({'below' if floor.ratio <= 3.0 else 'above'} it)")
    assert math.isfinite(floor.ratio)


if __name__ == "__main__":
    main()
