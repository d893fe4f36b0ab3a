"""The closed-form rules of four-bars and slider-cranks, each a scalar function with its
numpy twin beside it (the one home every engine reads; tests/test_closed_form_honesty.py
holds each twin equal to its scalar rule):

- circle intersection: :func:`triangle` / :func:`triangle_np`, and the positions built on it
  (:func:`fourbar_by_crank`, :func:`fourbar_by_rocker`, :func:`slider_crank`, each with a
  ``_np`` twin);
- the branch rule: :func:`is_open` / :func:`is_open_np` (four-bar: sin(theta4 - theta3) > 0,
  whatever drives it), :func:`slider_is_open` / :func:`slider_is_open_np` (cos(theta3) > 0).

The transmission angle and Grashof classification (:func:`~.closed_form.transmission`,
:func:`~.closed_form.grashof`, each with its ``_np`` twin) live in closed_form.py beside
the angle wrapping and the classification they use.

Accuracy: near a limit position the answer moves like the square root of the distance to
the limit, so it is ill-conditioned there; these formulas keep the computed answer within
a few ulps of that conditioning (relative perturbations of the inputs) and add nothing
worse. No acos or asin of a rounded number near +-1: the half-chord of a circle
intersection comes from Kahan's product of accurately formed factors (the area of the
triangle of the three distances), the distance between two points given in polar form
from (r1 - r2)^2 + 4 r1 r2 sin^2(phi / 2) (no cancellation), angles from atan2, and the
slider's cos(theta3) from sqrt((1 - v)(1 + v)) with 1 -+ v formed from the lengths.
Pure math here: numpy is imported only by the twins, so a single solve never loads it.
"""

from __future__ import annotations

import math
from typing import Any

MIRROR = " (mirror)"
"""The suffix of a second assembly of one name at a driver value: with theta4 driving, the
two assemblies at one theta4 (mirror images of A across the line O2-B) can carry the same
label; the second is keyed ``open (mirror)``, so both stay reachable. The closed forms
(:mod:`.closed_form`) and the derived branch names (:mod:`.derive`) both write it."""


class Indeterminate(ValueError):
    """A change point, not a position: a step whose known vectors leave every value of an
    unknown a solution (coincident circles, parallel slides)."""


# --- circle intersection --------------------------------------------------------------------

TANGENT_SLACK = 4.0 * 2.220446049250313e-16
"""Circles that miss each other by at most this times the largest of the three distances
are tangent (one double solution), not apart: the distances carry that much rounding
(a four-bar at its exact limit, r1 = r4 = 3, r2 = r3 = 0.2, theta2 = 0, closes, and
"no_solution" there would be a false claim)."""


def triangle(d: float, r: float, rho: float) -> tuple[float, float] | None:
    """Where X lies with |X - P| = r and |X - Q| = rho, |Q - P| = d > 0: (a, h), the
    distance of X's foot along P->Q from P and its height above that line (the
    half-chord, h >= 0); None when the circles do not meet. Kahan's ordering makes h
    accurate to a few ulps of the triangle the three distances describe."""
    x, y, z = sorted((d, r, rho), reverse=True)
    gap = z - (x - y)
    if not gap >= -TANGENT_SLACK * x:  # NaN included
        return None
    gap = max(gap, 0.0)
    area4 = (x + (y + z)) * gap * (z + (x - y)) * (x + (y - z))
    h = math.sqrt(max(area4, 0.0)) / (2.0 * d)
    a = ((r - rho) * (r + rho) + d * d) / (2.0 * d)
    return a, h


def triangle_np(d: Any, r: Any, rho: Any) -> tuple[Any, Any, Any]:
    """:func:`triangle` over arrays: (a, h, ok), h NaN where ``ok`` is False."""
    import numpy as np

    d, r, rho = np.asarray(d, float), np.asarray(r, float), np.asarray(rho, float)
    with np.errstate(invalid="ignore", divide="ignore"):  # (inf - inf: NaN, refused)
        a, h, ok, _ = triangle_sorted_np(d, r, rho, *descending_np(d, r, rho))
    return a, h, ok


def triangle_sorted_np(d: Any, r: Any, rho: Any, x: Any, y: Any, z: Any, dd: Any = None,
                       two_d: Any = None) -> tuple[Any, Any, Any, Any]:
    """:func:`triangle_np`'s body, the three distances already ordered (``x, y, z`` =
    :func:`descending_np` of them): (a, h, ok, gap), ``gap`` = z - (x - y) before it is
    clamped, the slack the two-circle margin (:func:`~.dyads.margin_of_gap_np`) divides by
    x, so a caller wanting both orders and subtracts once. ``dd`` and ``two_d``: d * d and
    2.0 * d where the caller formed them. The caller holds numpy's invalid and divide
    warnings off (inf - inf and K = 0 are refused through ``ok``)."""
    import numpy as np

    x_y = x - y  # (read twice, as the scalar's two x - y: the same bits)
    raw = z - x_y
    ok = (raw >= -TANGENT_SLACK * x) & (d > 0.0)
    gap = np.maximum(raw, 0.0)
    area4 = (x + (y + z)) * gap * (z + x_y) * (x + (y - z))
    if two_d is None:
        two_d = 2.0 * d
    h = np.where(ok, np.sqrt(np.maximum(area4, 0.0)) / two_d, np.nan)
    a = ((r - rho) * (r + rho) + (d * d if dd is None else dd)) / two_d
    return a, h, ok, raw


def descending_np(p: Any, q: Any, s: Any) -> tuple[Any, Any, Any]:
    """The three largest first, as ``sorted((p, q, s), reverse=True)`` orders each position,
    by comparisons alone (the same values as a sort, for a fraction of a stacked sort's
    time, and scalars stay scalars: two link lengths order once, not once per position).
    With a NaN among them all three are NaN (``np.minimum`` and ``np.maximum`` propagate
    it): :func:`triangle_np`'s gap is NaN there, so ``ok`` is False, and the two-circle
    margin (:func:`~.dyads.two_angles_margin_np`, the other reader) is NaN."""
    import numpy as np

    lo, hi = np.minimum(p, q), np.maximum(p, q)
    return np.maximum(hi, s), np.maximum(lo, np.minimum(hi, s)), np.minimum(lo, s)


def _frame(x: float, y: float, t1: float) -> tuple[float, float, float]:
    """(d, ux, uy): the length of (x, y) and its direction turned by t1."""
    d = math.hypot(x, y)
    c1, s1 = math.cos(t1), math.sin(t1)
    return d, (c1 * x - s1 * y) / d if d else 0.0, (s1 * x + c1 * y) / d if d else 0.0


def _frame_np(x: Any, y: Any, t1: Any) -> tuple[Any, Any, Any]:
    import numpy as np

    d = np.hypot(x, y)
    c1, s1 = np.cos(t1), np.sin(t1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return d, (c1 * x - s1 * y) / d, (s1 * x + c1 * y) / d


# Both solutions of each closed form, in a fixed order: sigma = +1, then -1 (the side of
# the line between the two known points the free joint lies on).
SIDES = (1.0, -1.0)


def fourbar_by_crank(r1: float, r2: float, r3: float, r4: float, t1: float,
                     t2: float) -> list[tuple[float, float]] | None:
    """(theta3, theta4) of both assemblies at crank angle t2 (rad, in (-pi, pi]); [] when
    it cannot be assembled, None when A lies on O4 with r3 = r4 (every B is a solution).

    A - O4 in the ground's frame: (r2 - r1) - 2 r2 sin^2(phi / 2) + i r2 sin(phi)."""
    phi = t2 - t1
    half = math.sin(0.5 * phi)
    d, ux, uy = _frame((r2 - r1) - 2.0 * r2 * half * half, r2 * math.sin(phi), t1)
    if d == 0.0:
        return None if r3 == r4 else []
    got = triangle(d, r4, r3)  # B from O4 (r4) and from A (r3)
    if got is None:
        return []
    a, h = got
    b = ((r4 - r3) * (r4 + r3) - d * d) / (2.0 * d)  # a - d, without cancelling
    return [(math.atan2(b * uy + s * h * ux, b * ux - s * h * uy),
             math.atan2(a * uy + s * h * ux, a * ux - s * h * uy)) for s in SIDES]


def fourbar_by_crank_np(r1: Any, r2: Any, r3: Any, r4: Any, t1: Any,
                        t2: Any) -> tuple[list[tuple[Any, Any]], Any]:
    """:func:`fourbar_by_crank` over arrays: ([(theta3, theta4) for each side], ok)."""
    import numpy as np

    phi = t2 - t1
    half = np.sin(0.5 * phi)
    d, ux, uy = _frame_np((r2 - r1) - 2.0 * r2 * half * half, r2 * np.sin(phi), t1)
    a, h, ok = triangle_np(d, r4, r3)
    with np.errstate(invalid="ignore", divide="ignore"):
        b = ((r4 - r3) * (r4 + r3) - d * d) / (2.0 * d)
    return [(np.arctan2(b * uy + s * h * ux, b * ux - s * h * uy),
             np.arctan2(a * uy + s * h * ux, a * ux - s * h * uy)) for s in SIDES], ok


def fourbar_by_rocker(r1: float, r2: float, r3: float, r4: float, t1: float,
                      t4: float) -> list[tuple[float, float]] | None:
    """(theta2, theta3) of both assemblies at rocker angle t4 (rad): the mirror images of
    A across the line O2-B. [] / None as :func:`fourbar_by_crank`.

    B - O2 in the ground's frame: (r1 - r4) + 2 r4 cos^2(phi / 2) + i r4 sin(phi)."""
    phi = t4 - t1
    half = math.cos(0.5 * phi)
    d, ux, uy = _frame((r1 - r4) + 2.0 * r4 * half * half, r4 * math.sin(phi), t1)
    if d == 0.0:
        return None if r2 == r3 else []
    got = triangle(d, r2, r3)  # A from O2 (r2) and from B (r3)
    if got is None:
        return []
    a, h = got
    b = ((r3 - r2) * (r3 + r2) + d * d) / (2.0 * d)  # d - a
    return [(math.atan2(a * uy + s * h * ux, a * ux - s * h * uy),
             math.atan2(b * uy - s * h * ux, b * ux + s * h * uy)) for s in SIDES]


def fourbar_by_rocker_np(r1: Any, r2: Any, r3: Any, r4: Any, t1: Any,
                         t4: Any) -> tuple[list[tuple[Any, Any]], Any]:
    """:func:`fourbar_by_rocker` over arrays: ([(theta2, theta3) for each side], ok)."""
    import numpy as np

    phi = t4 - t1
    half = np.cos(0.5 * phi)
    d, ux, uy = _frame_np((r1 - r4) + 2.0 * r4 * half * half, r4 * np.sin(phi), t1)
    a, h, ok = triangle_np(d, r2, r3)
    with np.errstate(invalid="ignore", divide="ignore"):
        b = ((r3 - r2) * (r3 + r2) + d * d) / (2.0 * d)
    return [(np.arctan2(a * uy + s * h * ux, a * ux - s * h * uy),
             np.arctan2(b * uy - s * h * ux, b * ux + s * h * uy)) for s in SIDES], ok


def slider_crank(r2: float, r3: float, e: float, t2: float) -> list[tuple[float, float]]:
    """(theta3, s) of both assemblies, open (cos theta3 >= 0) first; [] when it cannot be
    assembled. sin(theta3) = v = (e - r2 sin t2) / r3; cos(theta3) = +-sqrt((1 - v)(1 + v))
    with r3 (1 -+ v) formed from the lengths; theta3 by atan2, the crossed one pi - that."""
    s2 = r2 * math.sin(t2)
    lo, hi = (r3 - e) + s2, (r3 + e) - s2  # r3 (1 - v), r3 (1 + v)
    if not (lo >= 0.0 and hi >= 0.0):
        return []
    c = math.sqrt(lo * hi)  # r3 cos(theta3), open
    t3 = math.atan2(e - s2, c)
    x2 = r2 * math.cos(t2)
    return [(t3, x2 + c), (math.pi - t3, x2 - c)]


def slider_crank_np(r2: Any, r3: Any, e: Any, t2: Any) -> tuple[list[tuple[Any, Any]], Any]:
    """:func:`slider_crank` over arrays: ([(theta3, s) open, crossed], ok)."""
    import numpy as np

    s2 = r2 * np.sin(t2)
    lo, hi = (r3 - e) + s2, (r3 + e) - s2
    ok = (lo >= 0.0) & (hi >= 0.0)
    with np.errstate(invalid="ignore"):
        c = np.where(ok, np.sqrt(lo * hi), np.nan)
    t3 = np.arctan2(e - s2, c)
    x2 = r2 * np.cos(t2)
    return [(t3, x2 + c), (math.pi - t3, x2 - c)], ok


# --- the branch rule ------------------------------------------------------------------------


def open_rule(word: str, sign: float, coupler: Any, output: Any, xp: Any = math) -> Any:
    """The one open/crossed rule (worked example P3, docs/worked_examples.md), of a loop whose
    coupler points along ``coupler`` and whose output along ``output`` (rad; scalars with
    ``xp`` = math, arrays with numpy). A four-bar (``word`` "fourbar") is open where the
    output turns anticlockwise from the coupler, sin(output - coupler) > 0; a slider is open
    where the coupler runs along the slide, cos(output - coupler) > 0. ``sign`` (+1 or -1,
    exact) is the orientation the loop traverses them in. A property of the configuration,
    whatever drives it.

    The four-bar's sign of sin(turn) is read as the sign of tan(turn / 2), its equal
    (sin x = 2 tan(x/2) cos^2(x/2); turn / 2 is exact): numpy's tangent runs on the vector
    unit where its sine does not, and this rule was the batch sweep's largest single cost
    (benchmarks/target_rows.py 6). The two differ only at turn = +-2^-1074, whose half
    rounds to 0: a configuration 1e-323 rad from its toggle, called crossed.
    tests/test_open_rule.py holds the verdicts to sin's."""
    turn = output - coupler
    return sign * (xp.tan(turn * 0.5) if word == "fourbar" else xp.cos(turn)) > 0.0


def is_open(t3: float, t4: float) -> bool:
    """A four-bar configuration (coupler theta3, rocker theta4, rad) is open by
    :func:`open_rule`: sin(theta4 - theta3) > 0, crossed otherwise."""
    return open_rule("fourbar", 1.0, t3, t4)


def is_open_np(t3: Any, t4: Any) -> Any:
    """:func:`is_open` over arrays (rad)."""
    import numpy as np

    return open_rule("fourbar", 1.0, t3, t4, np)


def slider_is_open(t3: float) -> bool:
    """A slider-crank (coupler theta3, rad; the slide along +x) is open by :func:`open_rule`:
    cos(theta3) > 0, the slider on the far side of the crank pivot from the coupler's turn."""
    return open_rule("slider", 1.0, t3, 0.0)


def slider_is_open_np(t3: Any) -> Any:
    """:func:`slider_is_open` over arrays (rad)."""
    import numpy as np

    return open_rule("slider", 1.0, t3, 0.0, np)


def label(open_: bool) -> str:
    """The branch's name."""
    return "open" if open_ else "crossed"


def rocker_angle(r1: float, r2: float, r3: float, t1: float, t2: float, t3: float) -> float:
    """theta4 of a closed four-bar from theta2 and theta3 (rad): the direction of
    B - O4 = r2 e^(i t2) + r3 e^(i t3) - r1 e^(i t1). A rocker-driven solution is labelled
    by :func:`is_open` of its theta3 and this (its own theta4, whatever the file's is)."""
    return math.atan2(r2 * math.sin(t2) + r3 * math.sin(t3) - r1 * math.sin(t1),
                      r2 * math.cos(t2) + r3 * math.cos(t3) - r1 * math.cos(t1))


def rocker_angle_np(r1: Any, r2: Any, r3: Any, t1: Any, t2: Any, t3: Any) -> Any:
    """:func:`rocker_angle` over arrays."""
    import numpy as np

    return np.arctan2(r2 * np.sin(t2) + r3 * np.sin(t3) - r1 * np.sin(t1),
                      r2 * np.cos(t2) + r3 * np.cos(t3) - r1 * np.cos(t1))
