"""The batch engine's warm starts (:mod:`.batch`, step 2): each position's guess from the
coarse pass, by cubic Hermite interpolation between its two coarse neighbours with the
exact tangents dq/dv there (error ~ h^4: two Newton steps do). The cubic of each coarse
interval is written once as c0 + c1 u + c2 u^2 + c3 u^3 in u = (v - left) / width
(Burden and Faires, *Numerical Analysis*, section 3.4), so a block of positions gathers four
coefficients per unknown and evaluates them by Horner's rule."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .angles import nearest_turn_array


@dataclass(frozen=True)
class Coarse:
    """The coarse pass as the blocks read it, arranged per interval [grid[c], grid[c + 1]]
    where a block would otherwise recompute it per position."""

    grid: np.ndarray
    pair_usable: np.ndarray  # both ends solved, with a tangent
    width: np.ndarray
    cubic: tuple[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray], ...]
    """per unknown, the interval's c0..c3 (display units), one entry per interval"""
    allowed: np.ndarray     # how far a position may move from its guess (continuity)


def coarse_intervals(grid: np.ndarray, usable: np.ndarray, sol: np.ndarray, slopes: np.ndarray,
                     kinds: Sequence[str]) -> Coarse:
    """:class:`Coarse` from the coarse pass: its grid, where it is usable (solved, with a
    tangent), its solutions and its tangents dq/dv (one row per grid point, display units).
    An angle's right end is taken as the turn nearest its left end."""
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
    slope_rows = np.ascontiguousarray(slopes.T)
    cubic = []
    for j in range(len(kinds)):
        y0, y1 = rows[j], nxt[j]
        m0 = slope_rows[j] * width
        m1 = (slope_rows[j] if one else np.append(slope_rows[j][1:], 0.0)) * width
        # the Hermite basis h00 y0 + h10 m0 + h01 y1 + h11 m1 gathered by powers of u
        dy = y1 - y0
        cubic.append((y0, m0, 3.0 * dy - 2.0 * m0 - m1, m0 + m1 - 2.0 * dy))
    return Coarse(grid, pair, width, tuple(cubic), allowed)


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
    for c0, c1, c2, c3 in coarse.cubic:
        q = take(c3, left)
        q *= u
        q += take(c2, left)
        q *= u
        q += take(c1, left)
        q *= u
        q += take(c0, left)
        refs.append(q)
    return refs, left, usable
