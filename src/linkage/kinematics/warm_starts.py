"""The batch engine's warm starts (:mod:`.batch`, step 2): each position's guess from the
coarse pass, by quintic Hermite interpolation between its two coarse neighbours with the
exact first and second derivatives dq/dv and d2q/dv2 there (error ~ h^6 q^(6) / 46080:
with the default grid of a degree, within 1e-12 rad of the solution where the motion is
smooth, so that one Newton step meets the stopping rule; elsewhere more steps do). The
quintic of each coarse interval is written once as c0 + c1 u + ... + c5 u^5 in
u = (v - left) / width (Burden and Faires, *Numerical Analysis*, section 3.4, the
osculating polynomial), so a block of positions gathers six coefficients per unknown and
evaluates them by Horner's rule."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..records import frozen
from .angles import nearest_turn_array


@frozen
class Coarse:
    """The coarse pass as the blocks read it, arranged per interval [grid[c], grid[c + 1]]
    where a block would otherwise recompute it per position."""

    grid: np.ndarray
    pair_usable: np.ndarray  # both ends solved, with a tangent
    width: np.ndarray
    quintic: tuple[tuple[np.ndarray, ...], ...]
    """per unknown, the interval's c0..c5 (display units), one entry per interval"""
    allowed: np.ndarray     # how far a position may move from its guess (continuity)


def coarse_intervals(grid: np.ndarray, usable: np.ndarray, sol: np.ndarray, slopes: np.ndarray,
                     curvatures: np.ndarray, kinds: Sequence[str]) -> Coarse:
    """:class:`Coarse` from the coarse pass: its grid, where it is usable (solved, with a
    tangent), its solutions, its tangents dq/dv and second derivatives d2q/dv2 (one row per
    grid point, display units). An angle's right end is taken as the turn nearest its left end."""
    rows = np.ascontiguousarray(sol.T)
    one = len(grid) == 1  # a one-point grid is one interval, from the point to itself
    nxt = rows.copy() if one else np.concatenate((rows[:, 1:], rows[:, -1:]), axis=1)
    for j, k in enumerate(kinds):
        if k == "angle":
            nxt[j] = nearest_turn_array(rows[j], nxt[j])
    with np.errstate(invalid="ignore"):
        spread = np.zeros(1) if one else np.nanmax(np.abs(sol[1:] - sol[:-1]), axis=1, initial=0.0)
    allowed = 2.0 * np.where(np.isfinite(spread), spread, 0.0) + 1e-6
    pair = usable.copy() if one else np.append(usable[:-1] & usable[1:], False)
    width = np.zeros(1) if one else np.append(grid[1:] - grid[:-1], 0.0)
    slope_rows, bend_rows = np.ascontiguousarray(slopes.T), np.ascontiguousarray(curvatures.T)

    def at_right(row: np.ndarray) -> np.ndarray:
        return row if one else np.append(row[1:], 0.0)

    quintic = []
    for j in range(len(kinds)):
        y0, dy = rows[j], nxt[j] - rows[j]
        m0, m1 = slope_rows[j] * width, at_right(slope_rows[j]) * width
        a0, a1 = bend_rows[j] * width * width, at_right(bend_rows[j]) * width * width
        # the Hermite basis of y0, m0, a0, a1, m1, y1 gathered by powers of u
        quintic.append((y0, m0, 0.5 * a0,
                        10.0 * dy - 6.0 * m0 - 4.0 * m1 - 1.5 * a0 + 0.5 * a1,
                        -15.0 * dy + 8.0 * m0 + 7.0 * m1 + 1.5 * a0 - a1,
                        6.0 * dy - 3.0 * m0 - 3.0 * m1 - 0.5 * a0 + 0.5 * a1))
    return Coarse(grid, pair, width, tuple(quintic), allowed)


def grid_left(grid: np.ndarray, vals: np.ndarray) -> np.ndarray:
    """Each value's coarse interval: the index of its left end, clip(searchsorted(grid,
    vals, side="right"), 1, len(grid) - 1) - 1. For ascending values (a sweep's) by one
    repeat of the interval numbers, a fraction of the binary searches' time."""
    top = max(len(grid) - 1, 1)
    if len(vals) > 1 and not (vals[1:] >= vals[:-1]).all():
        return np.clip(np.searchsorted(grid, vals, side="right"), 1, top) - 1
    # grid[c] <= vals[i] exactly when i >= first[c]: the values between first[c - 1] and
    # first[c] have c grid points at or below them
    first = np.searchsorted(vals, grid, side="left")
    counts = np.diff(first, prepend=0, append=len(vals))
    return np.repeat(np.clip(np.arange(len(grid) + 1), 1, top) - 1, counts)


def warm_starts(coarse: Coarse, vals: np.ndarray) -> tuple[list[np.ndarray], np.ndarray, np.ndarray]:
    """Step 2, the warm starts (display units, one array per unknown); with each
    position's left grid index and whether its interval is usable."""
    take = np.take
    left = grid_left(coarse.grid, vals)
    usable = take(coarse.pair_usable, left)
    width = take(coarse.width, left)
    u = vals - take(coarse.grid, left)
    if width.min() > 0.0:
        u /= width
    else:  # a one-point grid
        u = np.where(width > 0, u / np.where(width > 0, width, 1.0), 0.0)
    refs = []
    for coefficients in coarse.quintic:
        q = take(coefficients[-1], left)
        for c in coefficients[-2::-1]:
            q *= u
            q += take(c, left)
        refs.append(q)
    return refs, left, usable
