"""The range and unwrapping rule for the angles of a sweep: one definition, each function a
scalar one (lists, one sweep) with its numpy twin beside it (rows of designs, a scan).

An angle is reported continuously along the cycle, and its range is read from that curve:

1. **Driver order around the circle.** A grid of driver values *closes the circle* when
   the driver is an angle, the values run one way (all up or all down) and the step from
   the last back round to the first (a turn less the span: 1 deg for 0..359 step 1, 0 for
   0..360) is no larger than the grid's largest step. On such a grid the position after
   the last is the first, so a feasible arc that crosses the grid's end (359 -> 0) is one
   piece: the positions are read starting at the first solved one that follows an
   unsolved one (the start of a feasible arc), around to the one before it. Otherwise
   (every position solved, none solved, or a grid that does not close) they are read in
   grid order.
2. **Unwrapping.** In that order each solved angle is the representative (mod 360) in
   (p - 180, p + 180] of the previous solved value p, across unsolved positions too; the
   first in (-180, 180]. The counts are whole turns added to the value as solved
   (``value + 360 * turns``, one rounding), so the two twins agree bit for bit.
3. **Anchoring.** The whole curve is then shifted by whole turns, so that at the solved
   position nearest the file's own driver value (nearest around the circle on a closing
   grid) it is within half a turn of a reference the engine chooses: ``solve FILE``'s
   answer for a sweep, the file's guess for a scan.
4. **Range.** min and max are the extremes of the continuous values; the range is
   ``max - min``, at most a full turn, and exactly 360 for an angle that turns fully (every
   position of a closing grid solved, and the curve comes back round to its start a whole
   turn away: a coupler or follower of a double crank). So over a full-turn crank a
   rocker's range is its swing, a bounded number, and an arc across the grid's end gives
   the same range whichever driver value the grid starts at.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from typing import Any

TURN = 360.0
"""A full turn, in the unit of every angle here (degrees)."""


def driver_turn(unit: str) -> float:
    """A full turn of a driver angle in its display ``unit`` (deg or rad)."""
    return TURN if unit == "deg" else 2.0 * math.pi


# --- 1. driver order around the circle --------------------------------------------------------

def closes_circle(values: Sequence[float], turn: float = TURN) -> bool:
    """True if driver ``values`` (of an angle, ``turn`` to a full turn in their unit) run
    one way and come round to their start within one of their own steps. The grid, not
    the designs: one answer for the scalar and the array engines alike."""
    if len(values) < 2:
        return False
    rising = values[1] > values[0]
    largest = 0.0
    for a, b in itertools.pairwise(values):  # one pass, no list: a sweep may be long
        step = b - a if rising else a - b
        if not step > 0.0:
            return False
        largest = max(largest, step)
    closing = turn - abs(values[-1] - values[0])
    # 1e-9 of a turn: a grid built by adding a step (0, 0.1, ...) drifts by rounding
    slack = 1e-9 * turn
    return -slack <= closing <= largest + slack


def closes_circle_array(values: Any, turn: float = TURN, diff: Any = None, ascending: bool = False) -> bool:
    """:func:`closes_circle` of a 1-D array of driver values (one grid, read at C speed).
    ``diff``: np.diff of the values, where the caller took it; taken here when not given.
    ``ascending``: the caller has found every entry of ``diff`` above 0 (values strictly
    ascending, as the closed-form engine requires), so that is not tested again."""
    import numpy as np

    v = np.asarray(values, dtype=float)
    if len(v) < 2:
        return False
    if diff is None:
        diff = np.diff(v)
    if ascending:
        steps = diff
    else:
        steps = diff if v[1] > v[0] else -diff
        if not (steps > 0.0).all():
            return False
    closing = turn - abs(float(v[-1]) - float(v[0]))
    slack = 1e-9 * turn
    return bool(-slack <= closing <= float(steps.max()) + slack)


def circular_start(solved: Sequence[bool], closes: bool) -> int:
    """Where the reading starts: on a closing grid the first solved position that follows
    an unsolved one (circularly); 0 otherwise, or when every position or none is solved."""
    if not closes:
        return 0
    n = len(solved)
    for i in range(n):
        if solved[i] and not solved[i - 1]:
            return i
    return 0


def circular_start_array(solved: Any, closes: bool) -> Any:
    """:func:`circular_start` of each row of a 2-D boolean array."""
    import numpy as np

    solved = np.asarray(solved, dtype=bool)
    rows, n = solved.shape
    if not closes or n == 0:
        return np.zeros(rows, dtype=np.int64)
    begins = solved & ~np.roll(solved, 1, axis=1)
    # argmax finds the first True; a row without one (all or nothing solved) starts at 0
    return np.where(begins.any(axis=1), np.argmax(begins, axis=1), 0).astype(np.int64)


# --- 2. unwrapping -----------------------------------------------------------------------------

def nearest_turn(ref: float, value: float) -> float:
    """The representative of ``value`` (mod 360) in (ref - 180, ref + 180]: one step of
    rule 2, for an engine that continues an angle from one reference value."""
    return continuous(value, math.floor((ref + 180.0 - value) / TURN))


def nearest_turn_array(ref: Any, value: Any) -> Any:
    """:func:`nearest_turn` of arrays (elementwise; NaN stays NaN)."""
    import numpy as np

    with np.errstate(invalid="ignore"):
        return continuous(value, np.floor((ref + 180.0 - value) / TURN))


def unwrap_turns(values: Sequence[float | None], closes: bool) -> list[int | None]:
    """Whole turns to add to each solved value (degrees, None where unsolved) so that
    ``value + 360 * turns`` is continuous in driver order around the circle (rule 2)."""
    solved = [v is not None and math.isfinite(v) for v in values]
    n = len(values)
    start = circular_start(solved, closes)
    out: list[int | None] = [None] * n
    turns = 0
    prev: float | None = None
    for k in range(n):
        i = (start + k) % n
        v = values[i]
        if not solved[i]:
            continue
        assert v is not None
        # the representative of v in (prev - 180, prev + 180]: floor((prev + 180 - v) / 360)
        # more turns than prev's
        turns += math.floor(((0.0 if prev is None else prev) + 180.0 - v) / TURN)
        out[i] = turns
        prev = v
    return out


def unwrap_turns_array(values: Any, closes: bool, all_solved: bool = False) -> Any:
    """:func:`unwrap_turns` of each row of a 2-D array of degrees (NaN where unsolved):
    a float array of whole turns, NaN where unsolved. ``all_solved``: the caller's values are
    all finite (every position solved: the closed-form engine), so none is looked for."""
    import numpy as np

    a = np.asarray(values, dtype=float)
    rows, n = a.shape
    if n == 0:
        return a.copy()
    solved = None if all_solved else np.isfinite(a)
    if solved is None or solved.all():
        # every position solved: read in grid order from the first (rule 1), each step
        # from the previous value (0 before the first); the general path's result, its
        # operations (((prev + 180) - a) / TURN, floor, cumsum) in place in one array
        # (0 + 180 is 180 exactly; add.accumulate is cumsum's loop without its wrapper)
        step = np.empty_like(a)
        step[:, 0] = 180.0
        np.add(a[:, :-1], 180.0, out=step[:, 1:])
        step -= a
        step /= TURN
        np.floor(step, out=step)
        if not np.count_nonzero(step):
            return step  # no turn anywhere (a rocker, a coupler): the running sum of +0.0s is itself
        return np.add.accumulate(step, axis=1, out=step)
    start = circular_start_array(solved, closes)
    idx = (np.arange(n)[None, :] + start[:, None]) % n
    r = np.take_along_axis(a, idx, axis=1)
    ok = np.take_along_axis(solved, idx, axis=1)
    # the previous solved value of each position, in reading order (0 before the first)
    last = np.where(ok, np.arange(n)[None, :], -1)
    np.maximum.accumulate(last, axis=1, out=last)
    before = np.concatenate([np.full((rows, 1), -1), last[:, :-1]], axis=1)
    prev = np.where(before >= 0, np.take_along_axis(r, np.maximum(before, 0), axis=1), 0.0)
    with np.errstate(invalid="ignore"):
        step = np.where(ok, np.floor((prev + 180.0 - r) / TURN), 0.0)
    turns = np.where(ok, np.cumsum(step, axis=1), np.nan)
    out = np.empty_like(turns)
    np.put_along_axis(out, idx, turns, axis=1)
    return out


# --- 3. anchoring ------------------------------------------------------------------------------

def anchor_index(values: Sequence[float], solved: Sequence[bool], v0: float, closes: bool,
                 turn: float = TURN) -> int | None:
    """The solved position nearest the driver value ``v0`` (around the circle on a closing
    grid), the first of equals; None when nothing is solved."""
    best, best_d = None, math.inf
    for i, (v, ok) in enumerate(zip(values, solved)):
        if not ok:
            continue
        d = abs(v - v0)
        if closes:
            d = d % turn
            d = min(d, turn - d)
        if d < best_d:
            best, best_d = i, d
    return best


def anchor_index_array(values: Any, solved: Any, v0: float, closes: bool, turn: float = TURN) -> Any:
    """:func:`anchor_index` of each row of ``solved`` (values shared by the rows); 0 for a
    row with nothing solved."""
    import numpy as np

    d = np.abs(np.asarray(values, dtype=float) - v0)
    if closes:
        d = np.fmod(d, turn)  # d % turn: the same for d >= 0 (or NaN), without floor-mod's fix-ups
        d = np.minimum(d, turn - d)
    if solved is True:  # every position solved, one row: no masked copy
        return d.argmin(keepdims=True)
    return np.argmin(np.where(solved, d[None, :], np.inf), axis=1)


def turn_shift(ref: float, at: float) -> int:
    """Whole turns that bring ``at`` within half a turn of ``ref`` (ties to even)."""
    return round((ref - at) / TURN)


def turn_shift_array(ref: Any, at: Any) -> Any:
    """:func:`turn_shift` of arrays (as floats; ties to even too)."""
    import numpy as np

    return np.round((np.asarray(ref, dtype=float) - at) / TURN)


def continuous(value: float, turns: float) -> float:
    """The reported value: as solved, plus whole turns (one rounding; the array twin is the
    same expression on arrays)."""
    return value + TURN * turns


# --- 4. range ----------------------------------------------------------------------------------

def angle_extent(values: Sequence[float | None], closes: bool) -> tuple[float, float, float]:
    """(min, max, range) of continuous angle values (degrees, None where unsolved), by
    rule 4; NaNs when nothing is solved."""
    got = [v for v in values if v is not None and math.isfinite(v)]
    if not got:
        return math.nan, math.nan, math.nan
    lo, hi = min(got), max(got)
    span = min(hi - lo, TURN)
    if closes and len(got) == len(values):
        first, last = values[0], values[-1]
        assert first is not None and last is not None
        if math.floor((last - first + 180.0) / TURN) != 0:
            span = TURN
    return lo, hi, span


def angle_extent_array(values: Any, closes: bool) -> tuple[Any, Any, Any]:
    """:func:`angle_extent` of each row of a 2-D array (NaN where unsolved)."""
    import numpy as np

    a = np.asarray(values, dtype=float)
    n = a.shape[1]
    solved = np.isfinite(a)
    some = solved.any(axis=1)
    lo = np.where(some, np.where(solved, a, np.inf).min(axis=1, initial=np.inf), np.nan)
    hi = np.where(some, np.where(solved, a, -np.inf).max(axis=1, initial=-np.inf), np.nan)
    span = np.minimum(hi - lo, TURN)
    if closes and n:
        with np.errstate(invalid="ignore"):
            turning = solved.all(axis=1) & (np.floor((a[:, -1] - a[:, 0] + 180.0) / TURN) != 0)
        span = np.where(turning, TURN, span)
    return lo, hi, span
