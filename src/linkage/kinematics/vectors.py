"""One loop vector ``sign * r * e^(i theta)`` and its time derivatives, over floats or numpy
arrays: the one definition the rates (:mod:`.rates`), their bounds (:mod:`.rate_bounds`)
and the placing rule (:mod:`.placing`) evaluate, one position at a time or a block of
positions at once.

A vector is a compiled term of :class:`~linkage.problems.loops.LoopModel` (sign, length
constant, length index, angle constant, angle index, offset): an index >= 0 reads an
unknown, ``DRIVER`` the driver, ``FIXED`` the constant. Differentiating in time (worked
example P7, docs/worked_examples.md):

    position      sign r e^(i theta)
    velocity      sign (r' + i r theta') e^(i theta)
    acceleration  sign (r'' + i r theta'' + 2 i r' theta' - r theta'^2) e^(i theta)
"""

from __future__ import annotations

import cmath
import math
import sys
from types import SimpleNamespace
from typing import Any

from ..problems.loops import DRIVER

FIXED = -1

XY = tuple[float, float]

EPS = sys.float_info.epsilon

SCALAR = SimpleNamespace(cos=math.cos, sin=math.sin, exp=cmath.exp, hypot=math.hypot, maximum=max)
"""The functions a definition below needs, for one position (floats); ``numpy`` itself
serves for a block of positions (arrays, one entry per position)."""


def value_of(idx: int, const: float, q: Any, d: Any) -> Any:
    """A vector's length or angle: unknown ``q[idx]``, the driver ``d`` or the constant."""
    return q[idx] if idx >= 0 else (d if idx == DRIVER else const)


def rate_of(idx: int, qdot: Any, ddot: Any) -> Any:
    """The rate of a vector's length or angle (a constant's is 0)."""
    return qdot[idx] if idx >= 0 else (ddot if idx == DRIVER else 0.0)


def term(t: Any, q: Any, d: Any, qd: Any, vd: Any, qdd: Any, vdd: Any,
         xp: Any = SCALAR) -> tuple[Any, Any, Any]:
    """One vector's position, velocity and acceleration (complex; arrays with ``xp`` numpy)."""
    sign, lc, li, ac, ai, off = t
    r, th = value_of(li, lc, q, d), value_of(ai, ac, q, d) + off
    r1, w = rate_of(li, qd, vd), rate_of(ai, qd, vd)
    r2, al = rate_of(li, qdd, vdd), rate_of(ai, qdd, vdd)
    e = xp.exp(1j * th)
    pos = sign * r * e
    vel = sign * (r1 + 1j * r * w) * e
    acc = sign * (r2 + 1j * r * al + 2j * r1 * w - r * w * w) * e
    return pos, vel, acc


def bias(model: Any, q: Any, d: Any, qd: Any, speed: Any, xp: Any = SCALAR) -> list[Any]:
    """The acceleration equation's right-hand side without the driver's acceleration, per
    row (x then y of each loop): each vector's ``sign (2 i r' w - r w^2) e^(i theta)``, the
    parts not multiplied by a second derivative (its Coriolis and centripetal terms)."""
    out: list[Any] = []
    for loop in model.terms:
        total: Any = 0j
        for sign, lc, li, ac, ai, off in loop:
            r, th = value_of(li, lc, q, d), value_of(ai, ac, q, d) + off
            r1, w = rate_of(li, qd, speed), rate_of(ai, qd, speed)
            total += sign * (2j * r1 * w - r * w * w) * xp.exp(1j * th)
        out += [total.real, total.imag]
    return out
