"""Golden-section search for the smallest value of a function unimodal on [lo, hi]: the one
loop that the assembly-gap finder (kinematics.limits.dip_between) and the synthesis's
error extrema (synthesis.golden_max) share."""

from __future__ import annotations

import math
from collections.abc import Callable

GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0

Bracket = tuple[float, float, float, float, float, float]
"""(lo, x1, f(x1), x2, f(x2), hi) with lo < x1 < x2 < hi."""


def golden_min(f: Callable[[float], float], lo: float, hi: float, max_iter: int,
               until: Callable[[Bracket], bool]) -> Bracket:
    """Shrink [lo, hi] around the smallest f by golden section, f evaluated once per step,
    until ``until(bracket)`` or ``max_iter`` steps; the last bracket. A NaN compares false
    and keeps the right part."""
    x1, x2 = hi - GOLDEN * (hi - lo), lo + GOLDEN * (hi - lo)
    f1, f2 = f(x1), f(x2)
    for _ in range(max_iter):
        if until((lo, x1, f1, x2, f2, hi)):
            break
        if f1 <= f2:
            hi, x2, f2 = x2, x1, f1
            x1 = hi - GOLDEN * (hi - lo)
            f1 = f(x1)
        else:
            lo, x1, f1 = x1, x2, f2
            x2 = lo + GOLDEN * (hi - lo)
            f2 = f(x2)
    return lo, x1, f1, x2, f2, hi
