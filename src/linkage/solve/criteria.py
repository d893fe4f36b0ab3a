"""The stopping criteria of a solve, checked once at the front door."""

from __future__ import annotations

import functools
from typing import Any

from ..arguments import check_number
from ..errors import InputError
from ..iterate import MAX_ITER_LIMIT, Criteria

MAX_RELATIVE_TOL = 1e-2
"""The loosest tolerance a mechanism accepts: 1% of its size, or 0.01 rad (0.57 deg)."""


def _short_int(v: int) -> str:
    text = str(v) if v < 10**30 else f"about 1e{len(str(v)) - 1}"
    return text


def check_criteria(tol: float, rtol: float, ftol: float | None, max_iter: int) -> Criteria:
    """The stopping criteria, checked (InputError naming the bad one). Remembered per
    value and type (True is not 1 here); values that cannot be remembered, such as a list,
    are checked afresh and refused with their message."""
    try:
        return _checked_criteria(tol, rtol, ftol, max_iter)
    except TypeError:
        return _check_criteria(tol, rtol, ftol, max_iter)


@functools.lru_cache(maxsize=256, typed=True)
def _checked_criteria(tol: float, rtol: float, ftol: float | None, max_iter: int) -> Criteria:
    return _check_criteria(tol, rtol, ftol, max_iter)


def _check_criteria(tol: float, rtol: float, ftol: float | None, max_iter: int) -> Criteria:
    tol = check_number("tol", tol, positive=True, allow_zero=False)
    rtol = check_number("rtol", rtol, positive=True)
    if ftol is not None:
        ftol = check_number("ftol", ftol, positive=True, allow_zero=False)
    if isinstance(max_iter, bool) or not isinstance(max_iter, int) or max_iter < 1:
        raise InputError(f"max_iter must be an integer >= 1, got {max_iter!r}")
    if max_iter > MAX_ITER_LIMIT:
        raise InputError(f"max_iter must be at most {MAX_ITER_LIMIT:,}, got {_short_int(max_iter)}: "
                         "a run that has not converged by then will not")
    return Criteria(tol, rtol, ftol, max_iter)


class RecentCriteria:
    """One front door's criteria checked last, kept with the very objects they were checked
    from. A solve given the same objects again (a session's constants, the defaults) reads
    ``seen[4]`` after four identity tests, where the remembered check costs a hashed call
    (about 0.15 us of a 3 us solve); ``seen[5]`` holds the same values as a plain tuple,
    which a loop unpacks without the iterator a NamedTuple's unpacking makes. Kept only for
    floats, ints and None, which cannot change under the same identity."""

    __slots__ = ("seen",)

    def __init__(self) -> None:
        self.seen: tuple[Any, ...] = (None, None, None, None, None, None)

    def check(self, tol: float, rtol: float, ftol: float | None, max_iter: int) -> Criteria:
        """:func:`check_criteria`, remembering the values when they are immutable."""
        crit = check_criteria(tol, rtol, ftol, max_iter)
        if (type(tol) is float and type(rtol) is float and (ftol is None or type(ftol) is float)
                and type(max_iter) is int):
            self.seen = (tol, rtol, ftol, max_iter, crit, tuple(crit))  # one assignment: all or none
        return crit
