"""The four classical cases of a planar vector loop with two unknowns, each a scalar
function with its numpy twin beside it (the one home every engine reads).

After substituting what is known, a loop reads ``sum(unknown terms) + K = 0`` with K the
sum of its known vectors. With the coefficients gathered from the loop (complex numbers
given as (x, y) pairs):

- **two angles** a, b: ``P e^(ia) + Q e^(ib) + K = 0``. X = P e^(ia) lies at |P| from the
  origin and |Q| from -K: a circle intersection (:func:`~.assembly.triangle`, Kahan's
  area, so the half-chord is accurate at tangency). sigma = +1 puts X on the left of the
  line from the origin to -K.
- **an angle and the length of the same vector**: ``e^(ia) (P + s D) + K = 0``, so
  |s + P/D| = |K| / |D|: a line meets a circle.
- **an angle and the length of a different vector**: ``P e^(ia) + s E + K = 0``, so
  |s + K/E| = |P| / |E|: a line meets a circle.
- **two lengths**: ``s E + t F + K = 0``: linear (Cramer), one solution.

Line and circle: s = -Re z + sigma sqrt((R - |Im z|)(R + |Im z|)); sigma = +1 is the
larger s. Each two-way case reports its *margin*, the relative amount by which it
assembles (negative: it does not): the triangle's gap for two circles, R - |Im z| for a
line and a circle. A limit position is where a margin crosses zero.

Accuracy: no acos or asin of a rounded number; the angles come from atan2 of unnormalised
products (atan2 is scale-free), the half-chord from :func:`~.assembly.triangle`, and
R^2 - (Im z)^2 from its two factors. Pure math here: numpy is imported only by the twins.
"""

from __future__ import annotations

import math
from typing import Any

from .assembly import TANGENT_SLACK, descending_np, triangle, triangle_np, triangle_sorted_np

Pair = tuple[float, float]


def norm(x: float, y: float) -> float:
    """|x + iy| as sqrt(x^2 + y^2): every operation is correctly rounded, so the numpy twin
    (:func:`norm_np`) gives the same bits, which math.hypot and numpy.hypot do not (1 ulp
    apart in about 0.6% of inputs). Lengths are bounded (loops.LENGTH_RANGE), so the
    squares neither overflow nor underflow."""
    return math.sqrt(x * x + y * y)


def norm_np(x: Any, y: Any) -> Any:
    """:func:`norm` over arrays."""
    import numpy as np

    return np.sqrt(x * x + y * y)


def _cmul(ax: float, ay: float, bx: float, by: float) -> Pair:
    return ax * bx - ay * by, ax * by + ay * bx


def _cmul_conj(ax: float, ay: float, bx: float, by: float) -> Pair:
    """a * conj(b)."""
    return ax * bx + ay * by, ay * bx - ax * by


# --- two angles ------------------------------------------------------------------------------

def two_angles(p: Pair, q: Pair, k: Pair, sigma: float) -> tuple[float, float] | None:
    """(a, b) with P e^(ia) + Q e^(ib) + K = 0 on side ``sigma``; None when the circles
    miss (concentric ones included). Raises ZeroDivisionError when they coincide (K = 0
    and |P| = |Q|)."""
    d = norm(k[0], k[1])
    rp, rq = norm(*p), norm(*q)
    if d == 0.0:
        # concentric circles: every angle when they coincide, none when they do not
        if rp == rq:
            raise ZeroDivisionError("the known vectors sum to zero")
        return None
    got = triangle(d, rp, rq)
    if got is None:
        return None
    a, h = got
    b = ((rq - rp) * (rq + rp) + d * d) / (2.0 * d)  # d - a, without cancelling
    # X = (a + i sigma h) u with u = -K / d; e^(ia) ~ X conj(P), e^(ib) ~ (-X - K) conj(Q)
    wx, wy = _cmul_conj(-k[0], -k[1], p[0], p[1])
    # + 0.0: at tangency (h = 0) both sides give one answer, not atan2 of -0 and +0
    ex, ey = _cmul(a, sigma * h + 0.0, wx, wy)
    vx, vy = _cmul_conj(-k[0], -k[1], q[0], q[1])
    fx, fy = _cmul(b, -sigma * h + 0.0, vx, vy)
    return math.atan2(ey, ex), math.atan2(fy, fx)


def two_angles_norms_np(p: tuple[Any, Any], q: tuple[Any, Any], k: tuple[Any, Any]) -> tuple[Any, Any, Any]:
    """(|K|, |P|, |Q|) over arrays: the three distances of the two-circle case, which its
    solution and its margin both read (computed once where a caller wants both)."""
    return norm_np(k[0], k[1]), norm_np(p[0], p[1]), norm_np(q[0], q[1])


def two_angles_np(p: tuple[Any, Any], q: tuple[Any, Any], k: tuple[Any, Any],
                  sigma: float, norms: tuple[Any, Any, Any] | None = None) -> tuple[Any, Any, Any]:
    """:func:`two_angles` over arrays: (a, b, ok); NaN where ``ok`` is False. ``norms``:
    :func:`two_angles_norms_np` of the same p, q, k, where the caller has them."""
    import numpy as np

    d, rp, rq = two_angles_norms_np(p, q, k) if norms is None else norms
    a, h, ok = triangle_np(d, rp, rq)
    with np.errstate(invalid="ignore", divide="ignore"):  # K = 0: a and b are inf
        return (*angles_of_triangle_np(p, q, k, sigma, d, rp, rq, a, h), ok)


def two_angles_with_margin_np(p: tuple[Any, Any], q: tuple[Any, Any], k: tuple[Any, Any],
                               sigma: float) -> tuple[Any, Any, Any, Any]:
    """:func:`two_angles_np` and :func:`two_angles_margin_np` in one pass: (a, b, ok,
    margin). The three distances are computed and ordered once, the triangle's slack
    (:func:`~.assembly.triangle_sorted_np`) is the margin's numerator (the same
    expression, so the same bits), and numpy's warnings are held off once."""
    import numpy as np

    d, rp, rq = two_angles_norms_np(p, q, k)
    # the two coefficients' lengths first: where they are numbers (a sweep's links) they are
    # ordered once, not at every position (the same three values, so the same bits)
    x, y, z = descending_np(rp, rq, d)
    with np.errstate(invalid="ignore", divide="ignore"):  # K = 0: a and b are inf
        dd, two_d = d * d, 2.0 * d  # (read by a, h and b: formed once)
        a, h, ok, gap = triangle_sorted_np(d, rp, rq, x, y, z, dd, two_d)
        return (*angles_of_triangle_np(p, q, k, sigma, d, rp, rq, a, h, dd, two_d), ok,
                margin_of_gap_np(gap, x))


def angles_of_triangle_np(p: tuple[Any, Any], q: tuple[Any, Any], k: tuple[Any, Any], sigma: float,
                          d: Any, rp: Any, rq: Any, a: Any, h: Any, dd: Any = None,
                          two_d: Any = None) -> tuple[Any, Any]:
    """:func:`two_angles`' last lines over arrays: the two angles from the triangle (a, h)
    of the distances (d, rp, rq); ``dd`` and ``two_d``: d * d and 2.0 * d where the
    caller formed them. The caller holds numpy's warnings off (K = 0: inf)."""
    import numpy as np

    b = ((rq - rp) * (rq + rp) + (d * d if dd is None else dd)) / (2.0 * d if two_d is None else two_d)
    nkx, nky = -k[0], -k[1]
    wx, wy = _cmul_conj(nkx, nky, p[0], p[1])
    up = sigma * h + 0.0
    ex, ey = _cmul(a, up, wx, wy)
    vx, vy = _cmul_conj(nkx, nky, q[0], q[1])
    # -sigma h + 0.0, the scalar's: up is never -0.0 (x + 0.0 is not), so 0.0 - up is
    # -(sigma h) where that is not zero and +0.0 where it is, as -sigma * h + 0.0 gives
    fx, fy = _cmul(b, 0.0 - up, vx, vy)
    return np.arctan2(ey, ex), np.arctan2(fy, fx)


def two_angles_side(p: Pair, k: Pair, alpha: float) -> float:
    """sigma of a configuration: the side of X = P e^(i alpha) from the line 0 -> -K
    (+1 left, -1 right, 0 on it)."""
    x, y = _cmul(p[0], p[1], math.cos(alpha), math.sin(alpha))
    c = -k[0] * y + k[1] * x  # cross(-K, X)
    return 1.0 if c > 0.0 else -1.0 if c < 0.0 else 0.0


def two_angles_side_np(p: tuple[Any, Any], k: tuple[Any, Any], alpha: Any) -> Any:
    import numpy as np

    x, y = _cmul(p[0], p[1], np.cos(alpha), np.sin(alpha))
    return np.sign(-k[0] * y + k[1] * x)


def two_angles_margin(p: Pair, q: Pair, k: Pair) -> float:
    """How far the two circles are from parting, relative to the largest distance:
    min of the triangle's three slacks (negative: they miss); 0 where all three distances
    are 0, NaN where one is NaN (an unknown the step reads was not solved: no margin)."""
    d, rp, rq = norm(k[0], k[1]), norm(*p), norm(*q)
    if math.isnan(d + rp + rq):  # (sorted() puts a NaN anywhere: decided before it)
        return math.nan
    x, y, z = sorted((d, rp, rq), reverse=True)
    return (z - (x - y)) / x if x > 0.0 else 0.0


def two_angles_margin_np(p: tuple[Any, Any], q: tuple[Any, Any], k: tuple[Any, Any],
                         norms: tuple[Any, Any, Any] | None = None) -> Any:
    """:func:`two_angles_margin` over arrays, its three distances ordered by the circle
    intersection's own rule (:func:`~.assembly.descending_np`: a NaN among them makes all
    three NaN, so the margin is NaN there, as the scalar rule gives). ``norms`` as for
    :func:`two_angles_np`."""
    import numpy as np

    x, y, z = descending_np(*(two_angles_norms_np(p, q, k) if norms is None else norms))
    with np.errstate(invalid="ignore", divide="ignore"):
        return margin_of_gap_np(z - (x - y), x)


def margin_of_gap_np(gap: Any, x: Any) -> Any:
    """The two-circle margin from its slack ``gap`` = z - (x - y) and the largest distance
    ``x`` (:func:`two_angles_margin`'s last line over arrays; the caller holds numpy's
    warnings off)."""
    import numpy as np

    # x >= 0 or NaN: "!= 0" is the scalar's "> 0" and lets the NaN through
    return np.where(x != 0.0, gap / x, 0.0)


# --- a line and a circle ---------------------------------------------------------------------

def line_circle(z: Pair, r: float, sigma: float) -> float | None:
    """s with |s + z| = r on side ``sigma`` (+1: the larger s); None when the line misses
    the circle (by more than the rounding of a tangent)."""
    m = abs(z[1])
    lo = r - m
    if not lo >= -TANGENT_SLACK * max(r, m):  # NaN included
        return None
    return -z[0] + sigma * math.sqrt(max(lo, 0.0) * (r + m))


def line_circle_np(z: tuple[Any, Any], r: Any, sigma: float) -> tuple[Any, Any]:
    """:func:`line_circle` over arrays: (s, ok)."""
    import numpy as np

    m = np.abs(z[1])
    lo = r - m
    ok = lo >= -TANGENT_SLACK * np.maximum(r, m)
    with np.errstate(invalid="ignore"):
        return np.where(ok, -z[0] + sigma * np.sqrt(np.maximum(lo, 0.0) * (r + m)), np.nan), ok


def line_circle_margin(z: Pair, r: float) -> float:
    big = max(r, abs(z[1]))
    return (r - abs(z[1])) / big if big > 0.0 else 0.0


def line_circle_margin_np(z: tuple[Any, Any], r: Any) -> Any:
    import numpy as np

    big = np.maximum(r, np.abs(z[1]))
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(big > 0.0, (r - np.abs(z[1])) / big, 0.0)


def cdiv(a: Pair, b: Pair) -> Pair:
    n = b[0] * b[0] + b[1] * b[1]
    x, y = _cmul_conj(a[0], a[1], b[0], b[1])
    return x / n, y / n


def angle_and_its_length(p: Pair, dd: Pair, k: Pair, sigma: float) -> tuple[float, float] | None:
    """(a, s) with e^(ia) (P + s D) + K = 0; None when it cannot close. Raises
    ZeroDivisionError when D = 0, or K = 0 where it closes (then P + s D = 0 and every
    angle a is a solution: an inverted slider-crank's pin on the slide's pivot)."""
    s = line_circle(cdiv(p, dd), norm(*k) / norm(*dd), sigma)
    if s is None:
        return None
    if k[0] == 0.0 and k[1] == 0.0:
        raise ZeroDivisionError("the known vectors sum to zero")
    wx, wy = p[0] + s * dd[0], p[1] + s * dd[1]
    ex, ey = _cmul_conj(-k[0], -k[1], wx, wy)
    return math.atan2(ey, ex), s


def angle_and_its_length_np(p: tuple[Any, Any], dd: tuple[Any, Any], k: tuple[Any, Any],
                            sigma: float) -> tuple[Any, Any, Any]:
    import numpy as np

    with np.errstate(invalid="ignore", divide="ignore"):
        s, ok = line_circle_np(cdiv(p, dd), norm_np(k[0], k[1]) / norm_np(dd[0], dd[1]), sigma)
    ok = ok & ((k[0] != 0.0) | (k[1] != 0.0))  # K = 0: the angle is indeterminate
    s = np.where(ok, s, np.nan)
    wx, wy = p[0] + s * dd[0], p[1] + s * dd[1]
    ex, ey = _cmul_conj(-k[0], -k[1], wx, wy)
    return np.arctan2(ey, ex), s, ok


def angle_and_other_length(p: Pair, e: Pair, k: Pair, sigma: float) -> tuple[float, float] | None:
    """(a, s) with P e^(ia) + s E + K = 0; None when it cannot close. Raises
    ZeroDivisionError when E = 0."""
    s = line_circle(cdiv(k, e), norm(*p) / norm(*e), sigma)
    if s is None:
        return None
    wx, wy = -(k[0] + s * e[0]), -(k[1] + s * e[1])
    ex, ey = _cmul_conj(wx, wy, p[0], p[1])
    return math.atan2(ey, ex), s


def angle_and_other_length_np(p: tuple[Any, Any], e: tuple[Any, Any], k: tuple[Any, Any],
                              sigma: float) -> tuple[Any, Any, Any]:
    import numpy as np

    with np.errstate(invalid="ignore", divide="ignore"):
        s, ok = line_circle_np(cdiv(k, e), norm_np(p[0], p[1]) / norm_np(e[0], e[1]), sigma)
    wx, wy = -(k[0] + s * e[0]), -(k[1] + s * e[1])
    ex, ey = _cmul_conj(wx, wy, p[0], p[1])
    return np.arctan2(ey, ex), s, ok


def line_side(z: Pair, s: float) -> float:
    """sigma of a configuration on a line and a circle: the sign of s + Re z."""
    v = s + z[0]
    return 1.0 if v > 0.0 else -1.0 if v < 0.0 else 0.0


def line_side_np(z: tuple[Any, Any], s: Any) -> Any:
    import numpy as np

    return np.sign(s + z[0])


# --- two lengths -----------------------------------------------------------------------------

def two_lengths(e: Pair, f: Pair, k: Pair) -> tuple[float, float] | None:
    """(s, t) with s E + t F + K = 0; None when E and F are parallel and K leaves their
    line (no solution). Raises ZeroDivisionError when they are parallel and K lies along
    it (every s with its t is a solution: a change point, not "cannot be assembled")."""
    det = e[0] * f[1] - e[1] * f[0]
    if det == 0.0 and (e != (0.0, 0.0) or f != (0.0, 0.0)) and \
            e[0] * k[1] - e[1] * k[0] == 0.0 and f[0] * k[1] - f[1] * k[0] == 0.0:
        raise ZeroDivisionError("parallel slides along the known vectors")
    if det == 0.0 or not math.isfinite(det):
        return None
    return -(k[0] * f[1] - k[1] * f[0]) / det, -(e[0] * k[1] - e[1] * k[0]) / det


def two_lengths_np(e: tuple[Any, Any], f: tuple[Any, Any],
                   k: tuple[Any, Any]) -> tuple[Any, Any, Any]:
    import numpy as np

    det = e[0] * f[1] - e[1] * f[0]
    ok = (det != 0.0) & np.isfinite(det)
    with np.errstate(invalid="ignore", divide="ignore"):
        s = np.where(ok, -(k[0] * f[1] - k[1] * f[0]) / det, np.nan)
        t = np.where(ok, -(e[0] * k[1] - e[1] * k[0]) / det, np.nan)
    return s, t, ok
