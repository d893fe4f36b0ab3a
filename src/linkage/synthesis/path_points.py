"""The nine points of a path synthesis through fewer (docs/path_synthesis.md, "Five to eight
points").

A four-bar has nine dimensions of design, so the four-bars whose coupler point passes
through n < 9 points form a (9 - n)-dimensional family. Each choice of 9 - n extra points
picks the finitely many of them that also pass through those: the nine-point problem
(:mod:`linkage.homotopy.ninepoint`). So every design found passes through the given
points, and sampling the extra points samples the family.

The extra points go between consecutive given points, never before the first or after the
last: a design is judged over its motion from the first point to the last, in order
(:func:`linkage.synthesis.path.judge`), and an extra point on the way is met in order by a
design that follows the path. They are placed on a smooth closed curve through the given
points in their order, a centripetal Catmull-Rom spline (Yuksel, Schaefer and Keyser,
"Parameterization and applications of Catmull-Rom curves", Computer-Aided Design 43(7),
2011: no cusps or self-intersections within a segment), in the widest gaps. Sample 0 takes
them evenly spaced along the curve; each later sample moves each one along the curve and
across it by a seeded random offset.
"""

from __future__ import annotations

import itertools

import numpy as np

from ..errors import InputError
from ..records import frozen

POINTS = 9
"""A four-bar's dimensions of design: nine points fix finitely many."""
FEWEST = 5
"""Fewer given points leave a family of five or more dimensions to sample: the issue's range."""
ALONG = 0.3
"""A sampled extra point moves along the curve by up to this fraction of its share of the gap
(so the extra points of one gap keep their order and stay inside it)."""
ACROSS = 0.15
"""...and across the gap by up to this fraction of the gap's chord."""
FARTHEST = 1e150
"""Points at most about this far apart (their squares stay finite in double precision)."""
APART = 1e-9
"""Two points closer than this, relative to the points' spread, coincide; a point nearer a
line than this is on it (the resolution at which a design is judged to pass through a
point, :data:`linkage.synthesis.path.ON_POINT`)."""
MOST_ON_A_LINE = 6
"""A four-bar's coupler curve is a tricircular sextic (S. Roberts, "On three-bar motion in
plane space", Proc. London Math. Soc. 7, 1875; Hartenberg and Denavit, *Kinematic Synthesis
of Linkages*, 1964), and no four-bar traces an exact straight line, so no line is part of
it: by Bezout's theorem a line meets it in at most 6 points. Nine points with more on one
line lie on no proper coupler curve, and the homotopy's paths end degenerate (five
collinear points, whose extra points fell on their line, tracked for more than 400 s;
tests/test_path_synthesis_points.py holds the refusal)."""


def as_points(name: str, points: object) -> list[complex]:
    """Pairs (x, y) of finite numbers (arguments.check_number, the one rule for numbers) as
    complex numbers x + iy, or InputError naming ``name``: a row of three numbers is refused,
    not read as its first two (a crank angle would be dropped without a word)."""
    from ..arguments import check_number

    try:
        rows = [list(p) for p in points]  # type: ignore[union-attr]
    except TypeError:
        rows = None
    if rows is None or isinstance(points, (str, bytes)):
        raise InputError(f"{name} must be pairs of numbers (x, y)")
    for k, row in enumerate(rows):
        if len(row) != 2:
            raise InputError(f"{name}[{k}] must be a pair of numbers (x, y), got {len(row)} of them"
                             + (" (with a crank angle, every point is timed: give five, to synthesize_path)"
                                if len(row) == 3 and name == "points" else ""))
    return [complex(check_number(f"{name}[{k}]", x), check_number(f"{name}[{k}]", y))
            for k, (x, y) in enumerate(rows)]


def spread(pts: list[complex]) -> float:
    """The points' size, the scale of every tolerance on them: the largest distance from the
    first point."""
    return max(abs(p - pts[0]) for p in pts)


def on_one_line(pts: list[complex]) -> list[int]:
    """The most points (indices, in order) within :data:`APART` of their :func:`spread` of
    one line, the line through some two of them: a tolerance relative to the points' size,
    so the same at any unit of length (the distance |Im((p - p_i) conj(u))|, u the line's
    unit direction, is exact to rounding of the points' size)."""
    size = spread(pts)
    best: list[int] = []
    for i, j in itertools.combinations(range(len(pts)), 2):
        u = (pts[j] - pts[i]) / abs(pts[j] - pts[i])
        near = [k for k, p in enumerate(pts) if abs(((p - pts[i]) * u.conjugate()).imag) <= APART * size]
        if len(near) > len(best):
            best = near
    return best


def check_off_line(nine: NinePoints, via: bool) -> None:
    """InputError when more than :data:`MOST_ON_A_LINE` of the nine points lie on one line
    (:func:`on_one_line`): then no four-bar's coupler curve passes through them. The message
    says that the points lie on one line when every given point does (``via``: the extra
    points were the user's, else the curve's, which then lie on that line too)."""
    on = on_one_line(list(nine.points))
    if len(on) <= MOST_ON_A_LINE:
        return
    why = (f"a four-bar's coupler curve (a tricircular sextic, never a straight line) meets a line in at "
           f"most {MOST_ON_A_LINE} points")
    given = [k for k in range(len(nine.points)) if k not in nine.extra]
    if set(given) <= set(on):
        extra = ("" if not nine.extra else ", and so do the via points" if via else
                 ", and so would the extra points on the curve through them (via: give "
                 f"{len(nine.extra)} off the line)")
        raise InputError(f"points: the points lie on one line (to {APART:.0e} of their spread){extra}: "
                         f"{why}".replace("e-0", "e-"))
    names = [f"{'via' if via else 'extra'} point {nine.extra.index(k) + 1}" if k in nine.extra
             else f"point {given.index(k) + 1}" for k in on]
    raise InputError(f"points: {len(on)} of the nine points lie on one line ({', '.join(names)}): {why}")


def check_distinct(name: str, pts: list[complex], labels: list[str]) -> None:
    """InputError (its message starting with ``name``) when two points coincide (to 1e-9 of
    their spread, naming both by ``labels``) or the points are more than FARTHEST apart."""
    size = spread(pts)
    if size > FARTHEST or size == 0.0:
        raise InputError(f"{name}: the points must be distinct and at most about 1e150 apart")
    for i in range(len(pts)):
        for j in range(i):
            if abs(pts[i] - pts[j]) <= APART * size:
                raise InputError(f"{name}: {labels[j]} and {labels[i]} coincide: "
                                 f"{pts[i].real:g}, {pts[i].imag:g}")


def check_via(via: object, given: list[complex]) -> list[complex]:
    """The extra points a user gives (``via``): 9 - len(given) finite pairs, distinct from
    the given points and each other, or InputError; and the nine points solved with them (or
    with the curve's first sample, without ``via``) checked by :func:`nine_points`."""
    extra = [] if via is None else as_points("via", via)
    want = POINTS - len(given)
    if extra and len(extra) != want:
        raise InputError(f"via: {len(given)} points need {want} extra point{'s' if want != 1 else ''} "
                         f"to make nine, got {len(extra)}")
    labels = [f"point {k + 1}" for k in range(len(given))] + [f"via point {k + 1}" for k in range(len(extra))]
    check_distinct("via", given + extra, labels)
    nine_points(given, extra, 0, 0)  # its checks, before any tracking (sample 0 does not use the seed)
    return extra


@frozen
class NinePoints:
    """The nine points solved: the given points in their order with the extra points
    between them, ``extra`` the positions of the extra ones."""

    points: tuple[complex, ...]
    extra: tuple[int, ...]

    @property
    def given(self) -> tuple[complex, ...]:
        return tuple(p for k, p in enumerate(self.points) if k not in self.extra)


def curve_point(pts: list[complex], k: int, s: float) -> complex:
    """The closed centripetal Catmull-Rom curve through ``pts`` (in order, the last joined
    to the first) at fraction ``s`` of the way from point k to point k + 1 (Barry and
    Goldman's pyramid of linear interpolations, knots spaced by the square root of the
    chords)."""
    n = len(pts)
    p0, p1, p2, p3 = (pts[(k + i) % n] for i in (-1, 0, 1, 2))
    t1 = abs(p1 - p0) ** 0.5
    t2 = t1 + abs(p2 - p1) ** 0.5
    t3 = t2 + abs(p3 - p2) ** 0.5
    t = t1 + s * (t2 - t1)

    def mix(a: complex, b: complex, ta: float, tb: float) -> complex:
        return a * (tb - t) / (tb - ta) + b * (t - ta) / (tb - ta)

    a1, a2, a3 = mix(p0, p1, 0.0, t1), mix(p1, p2, t1, t2), mix(p2, p3, t2, t3)
    return mix(mix(a1, a2, 0.0, t2), mix(a2, a3, t1, t3), t1, t2)


def gap_counts(pts: list[complex], count: int) -> list[int]:
    """How many of ``count`` extra points go in each gap between consecutive points: one
    at a time to the gap whose chord, shared among its extra points, is widest (the first
    such gap on a tie)."""
    chords = [abs(b - a) for a, b in itertools.pairwise(pts)]
    counts = [0] * len(chords)
    for _ in range(count):
        k = max(range(len(chords)), key=lambda i: chords[i] / (counts[i] + 1))
        counts[k] += 1
    return counts


def sampled(pts: list[complex], seed: int, sample: int) -> NinePoints:
    """The given points and 9 - n extra points on the curve through them (module
    docstring): sample 0 evenly spaced, later ones moved by the random numbers of
    (``seed``, ``sample``)."""
    rng = np.random.default_rng([seed, sample])
    out: list[complex] = []
    extra: list[int] = []
    for k, m in enumerate([*gap_counts(pts, POINTS - len(pts)), 0]):
        out.append(pts[k])
        if not m:
            continue
        a, b = pts[k], pts[k + 1]
        across = 1j * (b - a)  # the chord turned a quarter turn
        for j in range(m):
            along, side = (rng.uniform(-ALONG, ALONG), rng.uniform(-ACROSS, ACROSS)) if sample else (0.0, 0.0)
            extra.append(len(out))
            out.append(curve_point(pts, k, (j + 1 + along) / (m + 1)) + side * across)
    return NinePoints(tuple(out), tuple(extra))


def inserted(pts: list[complex], via: list[complex]) -> NinePoints:
    """The given points with each extra point of ``via`` (in turn) put into the gap between
    consecutive points where it lengthens the polyline least (cheapest insertion)."""
    out = list(pts)
    marks = [False] * len(pts)
    for v in via:
        def detour(i: int, v: complex = v) -> float:
            return abs(out[i] - v) + abs(v - out[i + 1]) - abs(out[i + 1] - out[i])

        k = min(range(len(out) - 1), key=detour)
        out.insert(k + 1, v)
        marks.insert(k + 1, True)
    return NinePoints(tuple(out), tuple(k for k, m in enumerate(marks) if m))


def nine_points(given: list[complex], via: list[complex], seed: int, sample: int) -> NinePoints:
    """The nine points solved for ``given`` (checked, 5 to 9): the user's extra points
    ``via`` when given, else sample ``sample`` of the curve's; InputError when they are
    not distinct or more than :data:`MOST_ON_A_LINE` lie on one line (:func:`check_off_line`)."""
    if len(given) == POINTS or via:
        nine = inserted(given, via)
    else:
        nine = sampled(given, seed, sample)
        check_distinct("points", list(nine.points), [f"point {k + 1} of the nine" for k in range(POINTS)])
    check_off_line(nine, bool(via))
    return nine
