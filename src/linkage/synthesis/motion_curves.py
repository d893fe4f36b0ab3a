"""Four poses: the centre-point and circle-point curves (Burmester; Sandor and Erdman,
*Advanced Mechanism Design*, vol. 2, ch. 3; McCarthy and Soh, *Geometric Design of
Linkages*, 2nd ed., ch. 4; docs/motion_synthesis.md).

A ground pivot G carries a crank through four poses when some body point z stays at one
distance from it. Each pose j = 2..4 against pose 1 is linear in z:

    2 z . (R_j^T (d_j - G) - R_1^T (d_1 - G)) = |d_1 - G|^2 - |d_j - G|^2,

three equations in two unknowns, consistent exactly where the 3 x 3 matrix [A(G) | b(G)] is
singular: its determinant, a cubic in G, vanishes on the centre-point curve. Each such G
gives its z (the circle point, drawn where it is at pose 1). One number along the curve is
free for each crank.
"""

from __future__ import annotations

import cmath
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..records import frozen
from ..units import radians
from .burmester import Pose

GRID = 321
"""Grid points a side on which the determinant's sign changes are found."""
BOX = 5.0
"""The grid spans the poses' centre +- this many times their size."""


@frozen
class Curves:
    """Points of the centre-point curve (ground pivots) and, row for row, of the
    circle-point curve (the moving pivots at pose 1); ``spread``: each crank's largest
    difference in length over the four poses, over the poses' size."""

    centre: Any
    circle: Any
    spread: Any
    box: tuple[float, float, float, float]


def frame(poses: Sequence[Pose]) -> tuple[complex, float, list[complex], list[complex]]:
    """The poses' centre and size, and each pose's origin (in those units) and rotation."""
    d = [complex(p.x, p.y) for p in poses]
    centre = sum(d) / len(d)
    size = max(abs(v - centre) for v in d) or 1.0
    turns = [cmath.exp(1j * radians(p.angle_deg)) for p in poses]
    return centre, size, [(v - centre) / size for v in d], turns


def system(d: Sequence[complex], r: Sequence[complex], g: Any) -> tuple[Any, Any]:
    """A(G) as complex rows (the x and y of each row's vector) and b(G), for G (complex,
    any shape): rows j = 2..4 along the last axis."""
    g = np.asarray(g)[..., None]
    dj, rj = np.array(d[1:]), np.array(r[1:])
    a = 2.0 * (np.conj(rj) * (dj - g) - np.conj(r[0]) * (d[0] - g))
    b = np.abs(d[0] - g) ** 2 - np.abs(dj - g) ** 2
    return a, b


def determinant(d: Sequence[complex], r: Sequence[complex], g: Any) -> Any:
    """det [A(G) | b(G)]: zero on the centre-point curve."""
    a, b = system(d, r, g)
    m = np.stack([a.real, a.imag, b], axis=-1)
    return np.linalg.det(m)


def crossings(d: Sequence[complex], r: Sequence[complex], xs: Any, ys: Any) -> Any:
    """The zeros of the determinant on the grid's edges (complex G), each by bisection along
    its edge to rounding: the centre-point curve where it crosses the grid."""
    gx, gy = np.meshgrid(xs, ys)
    grid = gx + 1j * gy
    f = determinant(d, r, grid)
    pairs = []
    for sl0, sl1 in (((slice(None), slice(None, -1)), (slice(None), slice(1, None))),
                     ((slice(None, -1), slice(None)), (slice(1, None), slice(None)))):
        change = np.sign(f[sl0]) * np.sign(f[sl1]) < 0
        pairs.append((grid[sl0][change], grid[sl1][change], f[sl0][change]))
    lo = np.concatenate([p[0] for p in pairs])
    hi = np.concatenate([p[1] for p in pairs])
    f_lo = np.concatenate([p[2] for p in pairs])
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        f_mid = determinant(d, r, mid)
        same = np.sign(f_mid) == np.sign(f_lo)
        lo, f_lo = np.where(same, mid, lo), np.where(same, f_mid, f_lo)
        hi = np.where(same, hi, mid)
    return 0.5 * (lo + hi)


def four_pose_curves(poses: Sequence[Pose], grid: int = GRID, box: float = BOX) -> Curves:
    """The centre-point curve's points where it crosses a ``grid`` x ``grid`` grid over the
    poses' centre +- ``box`` sizes, each with its circle point (least squares on the three
    equations, consistent there) and how rigid its crank is."""
    centre, size, d, r = frame(poses)
    axis = np.linspace(-box, box, grid)
    g = crossings(d, r, axis, axis)
    a, b = system(d, r, g)
    mat = np.stack([a.real, a.imag], axis=-1)
    z = np.array([np.linalg.lstsq(m, v, rcond=None)[0] for m, v in zip(mat, b)]).reshape(-1, 2)
    zc = z[:, 0] + 1j * z[:, 1]
    moving = np.array(d)[None, :] + np.array(r)[None, :] * zc[:, None]
    lengths = np.abs(moving - g[:, None])
    spread = (lengths.max(axis=1) - lengths.min(axis=1))
    to_world = lambda v: v * size + centre  # noqa: E731
    lo, hi = to_world(complex(-box, -box)), to_world(complex(box, box))
    return Curves(to_world(g), to_world(moving[:, 0]), spread, (lo.real, hi.real, lo.imag, hi.imag))
