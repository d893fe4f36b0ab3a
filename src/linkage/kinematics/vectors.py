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

def value_of(idx: int, const: float, q: Any, d: Any) -> Any:
    """A vector's length or angle: unknown ``q[idx]``, the driver ``d`` or the constant."""
    return q[idx] if idx >= 0 else (d if idx == DRIVER else const)


def rate_of(idx: int, qdot: Any, ddot: Any) -> Any:
    """The rate of a vector's length or angle (a constant's is 0)."""
    return qdot[idx] if idx >= 0 else (ddot if idx == DRIVER else 0.0)


def term(t: Any, q: Any, d: Any, qd: Any, vd: Any, qdd: Any, vdd: Any) -> tuple[Any, Any, Any]:
    """One vector's position, velocity and acceleration (complex)."""
    sign, lc, li, ac, ai, off = t
    r, th = value_of(li, lc, q, d), value_of(ai, ac, q, d) + off
    r1, w = rate_of(li, qd, vd), rate_of(ai, qd, vd)
    r2, al = rate_of(li, qdd, vdd), rate_of(ai, qdd, vdd)
    e = cmath.exp(1j * th)
    pos = sign * r * e
    vel = sign * (r1 + 1j * r * w) * e
    acc = sign * (r2 + 1j * r * al + 2j * r1 * w - r * w * w) * e
    return pos, vel, acc


def bias(model: Any, q: Any, d: Any, qd: Any, speed: Any) -> list[Any]:
    """The acceleration equation's right-hand side without the driver's acceleration, per
    row (x then y of each loop): each vector's ``sign (2 i r' w - r w^2) e^(i theta)``, the
    parts not multiplied by a second derivative (its Coriolis and centripetal terms)."""
    out: list[Any] = []
    for loop in model.terms:
        total = 0j
        for sign, lc, li, ac, ai, off in loop:
            r, th = value_of(li, lc, q, d), value_of(ai, ac, q, d) + off
            r1, w = rate_of(li, qd, speed), rate_of(ai, qd, speed)
            total += sign * (2j * r1 * w - r * w * w) * cmath.exp(1j * th)
        out += [total.real, total.imag]
    return out


# --- numpy twins: the same operations on real and imaginary parts -------------------------
# Python's complex product is (a c - b d) + (a d + b c) i, each product rounded and then
# summed; numpy's may fuse a product into the sum (its SIMD complex loops), a last-bit
# change the rates' bounds would show through the loops' measured residuals. The twins
# spell each complex operation of :func:`term` and :func:`bias` out in real ufuncs (no
# fusion), so that where numpy's cos and sin are the C library's they give the same bits.


def _complex(re: Any, im: Any) -> Any:
    """re + i im, each part exactly as given (an array, or a 0-d one for a constant)."""
    import numpy as np

    out = np.array(re, dtype=complex)
    out.imag = im
    return out


def _turn(sign: float, re: Any, im: Any, c: Any, s: Any) -> Any:
    """sign (re + i im) e^(i theta), e^(i theta) = c + i s, as Python's complex products
    round it (an exact zero part adds nothing)."""
    a, b = sign * re, sign * im
    return _complex(a * c - b * s, a * s + b * c)


def term_np(t: Any, q: Any, d: Any, qd: Any, vd: Any, qdd: Any, vdd: Any) -> tuple[Any, Any, Any]:
    """:func:`term` over a block (arrays, one entry per position)."""
    import numpy as np

    sign, lc, li, ac, ai, off = t
    r, th = value_of(li, lc, q, d), value_of(ai, ac, q, d) + off
    r1, w = rate_of(li, qd, vd), rate_of(ai, qd, vd)
    r2, al = rate_of(li, qdd, vdd), rate_of(ai, qdd, vdd)
    c, s = np.cos(th), np.sin(th)
    sr = sign * r
    pos = _complex(sr * c, sr * s)
    vel = _turn(sign, r1, r * w, c, s)
    acc = _turn(sign, r2 - r * w * w, r * al + 2.0 * r1 * w, c, s)
    return pos, vel, acc


def bias_np(model: Any, q: Any, d: Any, qd: Any, speed: Any) -> list[Any]:
    """:func:`bias` over a block."""
    import numpy as np

    out: list[Any] = []
    for loop in model.terms:
        x: Any = 0.0
        y: Any = 0.0
        for sign, lc, li, ac, ai, off in loop:
            r, th = value_of(li, lc, q, d), value_of(ai, ac, q, d) + off
            r1, w = rate_of(li, qd, speed), rate_of(ai, qd, speed)
            z = _turn(sign, -(r * w * w), 2.0 * r1 * w, np.cos(th), np.sin(th))
            x, y = x + z.real, y + z.imag
        out += [x, y]
    return out


SCALAR = SimpleNamespace(cos=math.cos, sin=math.sin, hypot=math.hypot, maximum=max, term=term)
"""The functions a definition over vectors needs, for one position (floats);
:func:`numpy_kit` gives their twins for a block of positions (arrays)."""

_NUMPY: list[Any] = []


def numpy_kit() -> Any:
    """:data:`SCALAR`'s functions over numpy arrays (numpy imported when first asked)."""
    if not _NUMPY:
        import numpy as np

        kit = SimpleNamespace(cos=np.cos, sin=np.sin, hypot=np.hypot, maximum=np.maximum, term=term_np)
        _NUMPY.append(kit)
    return _NUMPY[0]
