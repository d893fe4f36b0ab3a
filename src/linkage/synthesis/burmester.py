"""Burmester's points: the pivots of every crank that carries a body through five poses.

A pose j places a body at (x_j, y_j), turned by angle_j. A crank is a ground pivot G and a
moving pivot z fixed in the body (body coordinates); at pose j the moving pivot is at
M_j = d_j + R_j z, and the crank is rigid when |M_j - G| is the same for every pose:

    |d_j + R_j z - G|^2 - |d_1 + R_1 z - G|^2 = 0,   j = 2..5,

four equations in (Gx, Gy, zx, zy). |R_j z| = |z| makes the squares of z and G cancel: each
equation is bilinear, of degree 2, and every root is found by homotopy continuation
(:mod:`linkage.homotopy`). Five poses in general position have at most four real
Burmester pairs (Burmester 1888; Sandor and Erdman, *Advanced Mechanism Design*, vol. 2,
ch. 3; McCarthy and Soh, *Geometric Design of Linkages*, 2nd ed., ch. 4), and any two of
them make a four-bar that moves the body through the five poses.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..errors import InputError
from ..homotopy import PolySystem, Solutions, condition, solve
from ..records import frozen
from ..units import radians


@frozen
class Pose:
    x: float
    y: float
    angle_deg: float


@frozen
class Crank:
    """A Burmester pair: the ground pivot, the moving pivot in the body's frame and where it
    is at the first pose, the crank's length."""

    ground: tuple[float, float]
    body: tuple[float, float]
    first: tuple[float, float]
    length: float
    residual: float  # max over poses of | |M_j - G| - length | / the poses' size
    condition: float


@frozen
class Burmester:
    poses: tuple[Pose, ...]
    cranks: tuple[Crank, ...]
    complex_count: int
    infinite: int
    singular: int
    failed: int
    solutions: Solutions
    unresolved: int = 0  # real roots of the polynomials that are not rigid cranks after Newton


POSE_TOL = 1e-9
"""A body within this (of the poses' size, and in radians) of a pose is at the pose; two poses
that close are one pose."""


def checked_poses(poses: Any, count: int = 5) -> tuple[Pose, ...]:
    """``count`` poses of finite real numbers (x, y, angle in degrees), each pose its own:
    every misuse an InputError naming it (arguments.check_number, the one rule for numbers)."""
    from ..arguments import check_number

    if isinstance(poses, (str, bytes)) or not isinstance(poses, Sequence):
        raise InputError(f"poses must be a list of {count} poses (x, y, angle in deg), got {poses!r}")
    out = []
    for k, p in enumerate(poses):
        vals = (p.x, p.y, p.angle_deg) if isinstance(p, Pose) else p
        if isinstance(vals, (str, bytes)) or not isinstance(vals, Sequence) or len(vals) != 3:
            raise InputError(f"poses[{k}] must be (x, y, angle in deg), got {p!r}")
        x, y, a = (check_number(f"poses[{k}]", v) for v in vals)
        if not all(abs(v) < 1e12 for v in (x, y, a)):
            raise InputError(f"poses[{k}] must be finite numbers below 1e12 in size, got {p!r}")
        out.append(Pose(x, y, a))
    if len(out) != count:
        raise InputError(f"Burmester's points need exactly 5 poses, got {len(out)}" if count == 5
                         else f"this needs exactly {count} poses, got {len(out)}")
    centre = sum(complex(p.x, p.y) for p in out) / count
    size = max(abs(complex(p.x, p.y) - centre) for p in out) or 1.0
    for i in range(count):
        for j in range(i):
            a, b = out[i], out[j]
            if math.hypot(a.x - b.x, a.y - b.y) <= POSE_TOL * size and \
                    abs(radians(math.remainder(a.angle_deg - b.angle_deg, 360))) <= POSE_TOL:
                raise InputError(f"poses[{j}] and poses[{i}] are the same pose (to {POSE_TOL:g} of the "
                                 "poses' size and in radians, the tolerance a pose is met to)")
    if all(math.remainder(p.angle_deg - out[0].angle_deg, 360) == 0 for p in out):
        raise InputError("poses: the body does not turn between them (every angle the same): every "
                         "body point moves alike, and Burmester's construction needs rotation")
    if all(p.x == out[0].x and p.y == out[0].y for p in out):
        raise InputError("poses: the body only turns about one point (every x, y the same): that point "
                         "and any crank through it fit, a continuum, not Burmester points")
    return tuple(out)


def _frame(poses: tuple[Pose, ...]) -> tuple[complex, float]:
    """The poses' centre and size: the system is posed in those units."""
    d = [complex(p.x, p.y) for p in poses]
    centre = sum(d) / len(d)
    size = max(abs(z - centre) for z in d)
    return centre, size if size > 0 else 1.0


def burmester_system(poses: tuple[Pose, ...]) -> PolySystem:
    """The four equations in (Gx, Gy, zx, zy), lengths in units of the poses' size about
    their centre."""
    centre, size = _frame(poses)
    rows = []
    d1 = (complex(poses[0].x, poses[0].y) - centre) / size
    r1 = complex(math.cos(radians(poses[0].angle_deg)), math.sin(radians(poses[0].angle_deg)))
    for p in poses[1:]:
        dj = (complex(p.x, p.y) - centre) / size
        rj = complex(math.cos(radians(p.angle_deg)), math.sin(radians(p.angle_deg)))
        rows.append(_difference(dj, rj, d1, r1))
    return PolySystem(4, tuple(rows))


def _difference(dj: complex, rj: complex, d1: complex, r1: complex) -> dict[tuple[int, ...], complex]:
    """|dj + rj z - G|^2 - |d1 + r1 z - G|^2 as a polynomial in (Gx, Gy, zx, zy)."""
    def square(d: complex, r: complex) -> dict[tuple[int, ...], float]:
        # |d + r z - G|^2 with r z = (r.re zx - r.im zy, r.im zx + r.re zy)
        # components: u = d.re + r.re zx - r.im zy - Gx, v = d.im + r.im zx + r.re zy - Gy
        lin_u = {(0, 0, 0, 0): d.real, (0, 0, 1, 0): r.real, (0, 0, 0, 1): -r.imag, (1, 0, 0, 0): -1.0}
        lin_v = {(0, 0, 0, 0): d.imag, (0, 0, 1, 0): r.imag, (0, 0, 0, 1): r.real, (0, 1, 0, 0): -1.0}
        out: dict[tuple[int, ...], float] = {}
        for lin in (lin_u, lin_v):
            for e1, c1 in lin.items():
                for e2, c2 in lin.items():
                    e = tuple(a + b for a, b in zip(e1, e2))
                    out[e] = out.get(e, 0.0) + c1 * c2
        return out

    a, b = square(dj, rj), square(d1, r1)
    diff = {e: a.get(e, 0.0) - b.get(e, 0.0) for e in set(a) | set(b)}
    # the squares of z and of G cancel to rounding: drop what is rounding
    return {e: complex(c) for e, c in diff.items() if abs(c) > 1e-14 * (1 + abs(a.get(e, 0.0)))}


RIGID = 1e-12
"""A crank is kept when its length varies by at most this much of the poses' size over the
five poses, after Newton's method on the crank equations."""


def burmester_points(poses: Sequence[Pose | Sequence[float]], seed: int = 0) -> Burmester:
    """Every crank (centre point and circle point) that carries a body through five poses:
    each real pair, and the complex, infinite, singular and failed paths counted."""
    from ..arguments import MAX_SEED, check_whole
    from ..homotopy import polish_real

    ps = checked_poses(poses)
    seed = check_whole("seed", seed, 0, MAX_SEED)
    system = burmester_system(ps)
    sols = solve(system, seed=seed)
    centre, size = _frame(ps)
    cranks: list[Crank] = []
    nonreal = unresolved = 0
    for e in sols.endpoints:
        if e.kind not in ("finite", "singular") or e.x is None:
            continue
        if not e.real:
            nonreal += 1
            continue
        x, _ = polish_real(system, e.x.real)
        gx, gy, zx, zy = x
        # the crank's rigidity is judged about the poses' centre, where the system is posed:
        # in absolute coordinates poses far from the origin (1e4 sizes away) lose its digits
        g = complex(gx, gy) * size
        z = complex(zx, zy) * size  # body frame: the first pose's frame, scaled back
        moving = []
        for p in ps:
            r = complex(math.cos(radians(p.angle_deg)), math.sin(radians(p.angle_deg)))
            moving.append(complex(p.x, p.y) - centre + r * z)
        lengths = [abs(m - g) for m in moving]
        residual = max(abs(v - lengths[0]) for v in lengths) / size
        G = g + centre
        moving[0] += centre
        if not residual <= RIGID:
            unresolved += 1
            continue
        if any(abs(complex(*c.ground) - G) <= 1e-9 * (size + abs(G))
               and abs(complex(*c.body) - z) <= 1e-9 * (size + abs(z)) for c in cranks):
            continue  # a root two paths reached (a double root)
        cranks.append(Crank((G.real, G.imag), (z.real, z.imag), (moving[0].real, moving[0].imag),
                            lengths[0], residual, condition(system, x.astype(complex))))
    return Burmester(ps, tuple(cranks), nonreal, sols.count("infinite"), sols.count("singular"),
                     sols.count("failed"), sols, unresolved)


def body_to_ground(p: Pose, z: tuple[float, float]) -> np.ndarray:
    """Where the body point z (body coordinates) is at pose p."""
    r = complex(math.cos(radians(p.angle_deg)), math.sin(radians(p.angle_deg)))
    w = complex(p.x, p.y) + r * complex(*z)
    return np.array([w.real, w.imag])
