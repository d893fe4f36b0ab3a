"""Path generation with prescribed timing: the four-bars whose coupler point passes through
five points with the crank at prescribed angles (docs/path_synthesis.md, "Prescribed
timing"). They are judged by :func:`linkage.synthesis.path.judge_four_bar`.

The standard form of a dyad (Sandor and Erdman, *Advanced Mechanism Design*, vol. 2, ch. 2):
a ground pivot A, a vector W that turns by beta_j and a vector Z that turns by alpha_j reach
the point P_j,

    A + W e^{i beta_j} + Z e^{i alpha_j} = P_j,   j = 1..5,  beta_1 = alpha_1 = 0.

Read it as P_j - W e^{i beta_j} = A + Z e^{i alpha_j}: the point -W of a body placed at P_j
and turned by beta_j stays on a circle about A. With the crank's turns beta_j prescribed,
that is Burmester's five-pose problem (:mod:`.burmester`; vector addition commutes, so the
crank W plays the body and the coupler side Z the crank). Each Burmester pair (centre point
G, circle point z in the body's frame, at ``first`` at pose 1) is a crank dyad: A = G,
W = -z, Z = first - G, and the circle point's turning about G is the coupler's alpha_j. The
rocker dyad turns its coupler side by the same alpha_j: Burmester's problem again, with the
body turned by alpha_j. One of its pairs is the crank dyad itself (its pin M keeps its
distance from A); the others, up to three, are rockers. So there are at most 4 x 3
four-bars. Five timed points leave no free choice; four leave one free number for each dyad
(Sandor and Erdman's table of free choices for the standard form).
"""

from __future__ import annotations

import cmath
import itertools
import math
from collections.abc import Sequence
from typing import Any

from ..errors import InputError
from ..records import frozen
from ..units import degrees, radians
from .burmester import Burmester, Crank, burmester_points

TIMED_POINTS = 5
"""A four-bar's crank dyad meets at most five points with prescribed crank angles."""
SMALLEST = 1e-80
"""Points spanning less are refused: the four-bars' lengths would fall below the engine's
least length (1e-100), which judges them."""
SAME_DYAD = 1e-7
"""A rocker problem's pair within this (of the points' size) of the crank dyad's pivots is
the crank dyad itself."""


@frozen
class TimedFourBar:
    """A four-bar from crank dyad ``crank`` and the ``rocker``-th pair of its rocker problem,
    at the first point, with its (crank, coupler, rocker) angles in rad at each point."""

    crank: int
    rocker: int
    pivots: tuple[complex, complex, complex, complex]  # A, B, M, N
    configurations: tuple[tuple[float, float, float], ...]


@frozen
class TimedSolutions:
    points: tuple[complex, ...]
    crank_deg: tuple[float, ...]
    """The prescribed crank angles (deg; only their differences count)."""
    cranks: Burmester
    """The crank problem's Burmester account: its pairs are the crank dyads (its poses, and
    the rocker problems', are the points less their mean: :func:`timed_four_bars`)."""
    rockers: tuple[Burmester | None, ...]
    """Each crank dyad's rocker problem; None where its coupler does not turn (no rocker
    problem: the coupler translates and its pins move on congruent curves)."""
    four_bars: tuple[TimedFourBar, ...]
    unmatched: int = 0
    """Crank dyads not found among their own rocker problem's pairs (a root missed there)."""

    def problems(self) -> list[Burmester]:
        """The Burmester problems solved: the crank problem, then each rocker problem."""
        return [b for b in (self.cranks, *self.rockers) if b is not None]

    def incomplete(self) -> int:
        """Where a four-bar may be missing: Burmester roots not found (of a problem's
        :data:`BURMESTER_ROOTS`, while a path failed or a real root did not settle as a rigid
        crank), and crank dyads their own rocker problem did not find."""
        return self.unmatched + sum(missing_roots(b) for b in self.problems())


BURMESTER_ROOTS = 4
"""Five poses in general position have four Burmester pairs, counted in the complex: 0, 2
or 4 of them real (Sandor and Erdman vol. 2, ch. 3; McCarthy and Soh, ch. 4). The other
paths of the 16 of the total-degree start end at infinity."""


def missing_roots(problem: Burmester) -> int:
    """Burmester roots a problem did not find: none when its real and complex roots make
    :data:`BURMESTER_ROOTS` (a failed path then was one bound for infinity); else at most the
    paths that failed or did not settle."""
    short = max(0, BURMESTER_ROOTS - len(problem.cranks) - problem.complex_count)
    return min(short, problem.failed + problem.unresolved)


def as_rows(points: Any) -> Any:
    """A numpy array of points, and numpy rows, as lists (the checks below read sequences);
    anything else as it is."""
    if hasattr(points, "tolist") and hasattr(points, "ndim"):
        return points.tolist()
    if isinstance(points, Sequence) and not isinstance(points, (str, bytes)):
        return [p.tolist() if hasattr(p, "tolist") and hasattr(p, "ndim") else p for p in points]
    return points


def is_timed(points: Any) -> bool:
    """Whether some point carries a third number (a crank angle): the timed problem."""
    points = as_rows(points)
    if isinstance(points, (str, bytes)) or not isinstance(points, Sequence):
        return False
    return any(isinstance(p, Sequence) and not isinstance(p, (str, bytes)) and len(p) == 3 for p in points)


def free_choices(count: int) -> str:
    """What is free with ``count`` timed points (fewer than five)."""
    free = TIMED_POINTS - count
    return (f"with timing, give exactly {TIMED_POINTS} points: {count} timed point"
            f"{'s leave' if count != 1 else ' leaves'} {free} free "
            f"number{'s' if free != 1 else ''} for each dyad ({2 * free} for the four-bar), a family, "
            "not a finite set")


def check_timed_points(points: Any) -> tuple[tuple[complex, ...], tuple[float, ...]]:
    """Five points (x, y, crank angle in deg), finite, distinct, the crank turning, as the
    points and the crank angles reduced modulo 360 deg (exactly, by fmod: only the angles
    modulo a turn count, and a large angle's conversion to radians would round by its size
    times 1e-16): every misuse an InputError naming it (arguments.check_number, the one rule
    for numbers)."""
    from ..arguments import check_number

    points = as_rows(points)
    if isinstance(points, (str, bytes)) or not isinstance(points, Sequence):
        raise InputError(f"points must be a list of (x, y, crank angle in deg), got {points!r}")
    shapes = {len(p) if isinstance(p, Sequence) and not isinstance(p, (str, bytes)) else 0 for p in points}
    if shapes != {3}:
        raise InputError("points: give every point with its crank angle (x, y, deg) or none (x, y), "
                         "not some of each")
    if len(points) > TIMED_POINTS:
        raise InputError(f"a four-bar meets at most {TIMED_POINTS} points with prescribed crank angles "
                         f"(the dyads' standard form has no free choice left at {TIMED_POINTS}), "
                         f"got {len(points)}")
    if len(points) < TIMED_POINTS:
        raise InputError(free_choices(len(points)))
    out = []
    for k, p in enumerate(points):
        x, y, a = (check_number(f"points[{k}]", v) for v in p)
        if not all(abs(v) < 1e12 for v in (x, y, a)):
            raise InputError(f"points[{k}] must be finite numbers below 1e12 in size, got {p!r}")
        out.append((complex(x, y), math.fmod(a, 360.0)))  # exact: radians(1e11) would round by 1e-7 rad
    pts, angles = tuple(p for p, _ in out), tuple(a for _, a in out)
    size = max(abs(p - pts[0]) for p in pts)
    if 0.0 < size < SMALLEST:  # the engine that judges the designs takes lengths from 1e-100
        raise InputError(f"points: they span {size:g}, below {SMALLEST:g}: give them in a smaller unit")
    for i in range(TIMED_POINTS):
        for j in range(i):
            if abs(pts[i] - pts[j]) <= 1e-9 * size:
                raise InputError(f"points {j + 1} and {i + 1} coincide: {pts[i].real:g}, {pts[i].imag:g}")
    if all(math.remainder(a - angles[0], 360) == 0 for a in angles):
        raise InputError("points: the crank does not turn between them (every crank angle the same)")
    for i in range(TIMED_POINTS):
        for j in range(i):
            if math.remainder(angles[i] - angles[j], 360) == 0:
                raise InputError(f"points {j + 1} and {i + 1} have the same crank angle (mod 360 deg): the "
                                 "crank, the input, cannot put the coupler point in two places at one angle")
    return pts, angles


def prescribed_turn(crank_deg: Sequence[float]) -> float:
    """The crank's turn (deg) from the first point to the last, meeting the others in their
    order: the way round (forward or back) on which that is less than a turn (only the
    angles modulo a turn count, so 300, 340, 20, 60, 100 is a turn of +160, not 100 - 300);
    forward, more than a turn, when neither is."""
    forward = sum((b - a) % 360.0 for a, b in itertools.pairwise(crank_deg))
    backward = forward - 360.0 * (len(crank_deg) - 1)
    return backward if forward >= 360.0 and backward > -360.0 else forward


def timed_four_bars(points: Any, seed: int = 0) -> TimedSolutions:
    """Every four-bar through five timed points (module docstring): Burmester's problem for
    the crank dyads, then for each one's rocker dyads."""
    given, angles = check_timed_points(points)
    # solved about the points' centre (the problem is the same when translated): far from
    # the origin, p + r z - G would cancel its digits and a root fail Burmester's rigidity test
    centre = sum(given) / len(given)
    p = tuple(q - centre for q in given)
    size = max(abs(q) for q in p)
    cranks = burmester([(q.real, q.imag, a - angles[0]) for q, a in zip(p, angles)], seed)
    rockers: list[Burmester | None] = []
    four_bars: list[TimedFourBar] = []
    unmatched = 0
    for i, c in enumerate(cranks.cranks):
        alpha = turning(c, cranks)
        if all(abs(math.remainder(a, 360.0)) <= 1e-9 for a in alpha):
            rockers.append(None)
            continue
        problem = burmester([(q.real, q.imag, a) for q, a in zip(p, alpha)], seed)
        rockers.append(problem)
        A = complex(*c.ground)
        M1 = A - complex(*c.body)  # the crank pin at the first point: A + W
        gaps = [max(abs(complex(*r.ground) - A), abs(complex(*r.first) - M1)) for r in problem.cranks]
        itself = min(range(len(gaps)), key=gaps.__getitem__) if gaps else None
        if itself is None or gaps[itself] > SAME_DYAD * size:
            unmatched += 1  # a root of the rocker problem is missing: say so, keep every pair
            itself = None
        four_bars += [moved(four_bar(i, k, c, r, p, alpha), centre)
                      for k, r in enumerate(problem.cranks) if k != itself]
    return TimedSolutions(given, angles, cranks, tuple(rockers), tuple(four_bars), unmatched)


RETRIES = 3
"""Burmester's problem is solved again with another random gamma (the next seeds), up to
this many times in all, while a root is missing (:func:`missing_roots`)."""


def burmester(poses: list[tuple[float, float, float]], seed: int) -> Burmester:
    """Burmester's problem with every root found if a few random gammas find them: a path
    that failed with one gamma is another path with the next (Sommese and Wampler, *The
    Numerical Solution of Systems of Polynomials*, the gamma trick); the try missing the
    fewest roots is kept."""
    from ..arguments import MAX_SEED

    best = burmester_points(poses, seed=seed)
    for k in range(1, RETRIES):
        if not missing_roots(best):
            break
        again = burmester_points(poses, seed=(seed + k) % (MAX_SEED + 1))
        if missing_roots(again) < missing_roots(best):
            best = again
    return best


def turning(c: Crank, problem: Burmester) -> list[float]:
    """The coupler's turn alpha_j (deg) of crank dyad ``c``: its circle point's turn about its
    centre point, from the first pose."""
    g = complex(*c.ground)
    circle = []
    for pose in problem.poses:
        r = cmath.exp(1j * radians(pose.angle_deg))
        circle.append(complex(pose.x, pose.y) + r * complex(*c.body) - g)
    return [degrees(cmath.phase(q / circle[0])) for q in circle]


def four_bar(i: int, k: int, crank: Crank, rocker: Crank, points: list[complex],
             alpha: list[float]) -> TimedFourBar:
    """The four-bar of crank dyad ``crank`` and rocker dyad ``rocker`` (a pair of the problem
    turned by ``alpha``, deg), its pins placed at each point through the coupler: M_j = P_j -
    Z e^{i alpha_j}, N_j = P_j + e^{i alpha_j} z_rocker."""
    A, B = complex(*crank.ground), complex(*rocker.ground)
    Z = complex(*crank.first) - A
    configurations = []
    for p, a in zip(points, alpha):
        turn = cmath.exp(1j * radians(a))
        m, n = p - Z * turn, p + turn * complex(*rocker.body)
        configurations.append((cmath.phase(m - A), cmath.phase(n - m), cmath.phase(n - B)))
    M1, N1 = points[0] - Z, complex(*rocker.first)
    return TimedFourBar(i, k, (A, B, M1, N1), tuple(configurations))


def moved(fb: TimedFourBar, by: complex) -> TimedFourBar:
    """The four-bar translated by ``by`` (its angles unchanged)."""
    return TimedFourBar(fb.crank, fb.rocker, tuple(v + by for v in fb.pivots),  # type: ignore[arg-type]
                        fb.configurations)
