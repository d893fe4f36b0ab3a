"""Limit positions of a derived closed form (:mod:`.derive`): the driver values where a
branch stops assembling, located exactly.

A branch (a sign tuple, :attr:`~.derive.Derivation.branches`) assembles at a driver value
when every two-way step's margin (:meth:`~.derive.Derivation.margins`) is >= 0; a limit
position is where one of them crosses zero. Each margin is a smooth function of the driver
with a simple root there (the triangle's slack, or R - |Im z|, goes through zero with a
nonzero slope), so bisection on its sign brackets the root down to adjacent doubles: the
limit to a few ulps of the driver, with no acos of a rounded number. For a set of branches
(the assemblies a sweep followed) the set assembles where any of them does:
:func:`assembles` is max over branches of min over margins.

One home, scalar and numpy side by side: :func:`assembles` / :func:`assembles_np`,
:func:`limit_between` / :func:`limits_between_np`. Drivers are given in the caller's unit
and evaluated at ``x * scale`` (degrees and pi/180 for an angle), so the limit is found
to the ulps of the number the user reads.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from .derive import Derivation

Signs = tuple[float, ...]

MAX_HALVINGS = 2200
"""Enough halvings to reach adjacent doubles from any finite bracket (the exponent range)."""


def assembles(d: Derivation, x: float, branches: Sequence[Signs], scale: float = 1.0,
              params: Mapping[str, float] | None = None) -> float:
    """How far the best of ``branches`` is from its limit at driver ``x`` (times ``scale``:
    internal units): max over branches of its smallest margin; >= 0 where one assembles,
    -inf where none can be evaluated."""
    best = -math.inf
    for signs in branches:
        got = [m for m in d.margins(x * scale, signs, params) if m == m]  # NaN: a later step
        worst = min(got) if got else -math.inf
        if worst > best:
            best = worst
    return best


def assembles_np(d: Derivation, x: Any, branches: Sequence[Signs], scale: float = 1.0,
                 params: Mapping[str, Any] | None = None) -> Any:
    """:func:`assembles` over arrays of drivers (and, for designs, parameters)."""
    import numpy as np

    x = np.asarray(x, float)
    best = np.full(x.shape, -np.inf)
    for signs in branches:
        ms = d.margins_np(x * scale, signs, params)
        worst = np.full(x.shape, np.inf)
        for m in ms:
            worst = np.fmin(worst, m)  # fmin: a NaN (a later step) is ignored
        worst = np.where(np.isinf(worst) & (worst > 0), -np.inf, worst)  # no margin at all
        best = np.fmax(best, worst)
    return best


def limit_between(d: Derivation, a: float, b: float, branches: Sequence[Signs], scale: float = 1.0,
                  params: Mapping[str, float] | None = None) -> float:
    """The limit between drivers ``a`` and ``b``, where :func:`assembles` has opposite signs
    (>= 0 at one end, < 0 at the other): bisection on its sign down to adjacent doubles.
    Returns the last driver that assembles (the limit position, a real configuration)."""
    good, bad = (a, b) if assembles(d, a, branches, scale, params) >= 0.0 else (b, a)
    for _ in range(MAX_HALVINGS):
        mid = 0.5 * (good + bad)
        if mid == good or mid == bad:
            break
        if assembles(d, mid, branches, scale, params) >= 0.0:
            good = mid
        else:
            bad = mid
    return good


def limits_between_np(d: Derivation, a: Any, b: Any, branches: Sequence[Signs], scale: float = 1.0,
                      params: Mapping[str, Any] | None = None) -> Any:
    """:func:`limit_between` over arrays of brackets (each a sign change of
    :func:`assembles_np`): the same halvings, every bracket at once."""
    import numpy as np

    a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
    at_a = assembles_np(d, a, branches, scale, params) >= 0.0
    good, bad = np.where(at_a, a, b), np.where(at_a, b, a)
    for _ in range(MAX_HALVINGS):
        mid = 0.5 * (good + bad)
        live = (mid != good) & (mid != bad)
        if not live.any():
            break
        ok = assembles_np(d, mid, branches, scale, params) >= 0.0
        good = np.where(live & ok, mid, good)
        bad = np.where(live & ~ok, mid, bad)
    return good
