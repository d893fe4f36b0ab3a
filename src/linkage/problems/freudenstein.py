"""The four-bar input-output equation of the student report (docs/worked_examples.md P2) (Freudenstein
form), posed in degrees.

    f(phi) = R1 cos(alpha) - R2 cos(phi) + R3 - cos(alpha - phi) = 0

alpha is the input angle, phi the output angle. The seed works in degrees throughout,
derivative included (f' is per degree), so this problem's unknown is phi in degrees
and tolerances are in degrees; trigonometry is evaluated in radians inside.

From link lengths (a input link, b coupler, c output link, d ground, both angles
measured from the line of centres, pointing from the output pivot to the input
pivot): R1 = d/c, R2 = d/a, R3 = (a^2 - b^2 + c^2 + d^2) / (2 a c). The seed's
R1, R2, R3 = 5/3, 5/2, 11/6 are links (a, b, c, d) = (2, 4, 3, 5).
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from typing import Any

from ..errors import InputError
from ..records import NamedTuple
from ..units import RAD_PER_DEG, degrees, radians
from .assembly import is_open, label
from .scalar import ScalarProblem

DEG = RAD_PER_DEG  # held here for the hot closures below (linkage.units)
EPS = sys.float_info.epsilon

SEED_R = (5.0 / 3.0, 5.0 / 2.0, 11.0 / 6.0)
SEED_ALPHA_DEG = 70.0


class FourBarCoefficients(NamedTuple):
    """Freudenstein's R1, R2, R3 (a NamedTuple: its class costs a start 0.1 ms, a frozen
    dataclass's 0.7 ms)."""

    r1: float
    r2: float
    r3: float


def coefficients_from_links(a: float, b: float, c: float, d: float) -> FourBarCoefficients:
    """R1, R2, R3 from the link lengths (input a, coupler b, output c, ground d)."""
    from ..arguments import check_number

    a, b, c, d = (check_number(f"link length {name}", v) for name, v in zip("abcd", (a, b, c, d)))
    for name, v in zip("abcd", (a, b, c, d)):
        if not math.isfinite(v) or v <= 0.0:
            raise InputError(f"link length {name} must be a finite number > 0, got {v!r}")
        if v < sys.float_info.min:
            raise InputError(f"link length {name} = {v!r} is subnormal: it has too few significant "
                             "digits; give the lengths in a smaller unit")
    # Only ratios matter: scale by the longest link first, so squares neither overflow
    # nor underflow (links 9e307 or 1e-300 give the same R as links 9 or 1).
    given, big = (a, b, c, d), max(a, b, c, d)
    a, b, c, d = a / big, b / big, c / big, d / big
    # a ratio (or 2 a c) can still underflow to 0 (links 1e-300 and 1e300): a division by it
    # is refused below, as a ratio that overflows is
    den = 2.0 * a * c
    r = FourBarCoefficients(d / c, d / a, (a * a - b * b + c * c + d * d) / den) if den > 0.0 else None
    if r is None or not all(math.isfinite(v) for v in (r.r1, r.r2, r.r3)):
        raise InputError(f"the link ratios {', '.join(f'{v:g}' for v in given)} are too "
                         "extreme for double precision (R1, R2, R3 leave its range)")
    return r


def fourbar_equation(
    alpha_deg: float = SEED_ALPHA_DEG,
    r1: float = SEED_R[0],
    r2: float = SEED_R[1],
    r3: float = SEED_R[2],
) -> ScalarProblem:
    """The Freudenstein equation at input angle ``alpha_deg``, unknown phi in degrees.

    Supplies f, f' and f'' (per degree), the fixed-point form g(phi) = acos(u(phi))
    with u(phi) = (R1 cos(alpha) + R3 - cos(alpha - phi)) / R2, its derivative
    g'(phi) = sin(alpha - phi) / (R2 sqrt(1 - u^2)), and a default start/bracket: the
    first sign change of f on a 10-degree grid over [0, 180] (see default_start).
    """
    from ..arguments import check_number

    alpha_deg, r1, r2, r3 = (check_number(name, v) for name, v in
                             (("alpha", alpha_deg), ("R1", r1), ("R2", r2), ("R3", r3)))
    if r2 == 0.0:
        raise InputError("R2 must be non-zero (it divides in the fixed-point form)")
    alpha = radians(alpha_deg)
    k = r1 * math.cos(alpha) + r3
    cos, sin, acos, sqrt = math.cos, math.sin, math.acos, math.sqrt

    def f(phi: float) -> float:
        p = phi * DEG
        return k - r2 * cos(p) - cos(alpha - p)

    def fprime(phi: float) -> float:
        p = phi * DEG
        return DEG * (r2 * sin(p) - sin(alpha - p))

    def fsecond(phi: float) -> float:
        p = phi * DEG
        return DEG * DEG * (r2 * cos(p) + cos(alpha - p))

    def fbound(phi: float) -> float:
        # one rounding per term and per operation, plus the rounding of phi*DEG and of
        # alpha - p carried through the slopes r2 sin(p) and sin(alpha - p)
        p = phi * DEG
        terms = abs(k) + abs(r1 * math.cos(alpha)) + abs(r2 * cos(p)) + abs(cos(alpha - p))
        slopes = (abs(r2 * sin(p)) + abs(sin(alpha - p))) * (abs(p) + abs(alpha))
        return 4.0 * EPS * (terms + slopes)

    def u(phi: float) -> float:
        return (k - cos(alpha - phi * DEG)) / r2

    def g(phi: float) -> float:
        uu = (k - cos(alpha - phi * DEG)) / r2
        if not -1.0 <= uu <= 1.0:
            raise ValueError(f"acos(u) undefined: u = {uu:.9g} at phi = {phi:.9g} deg")
        return acos(uu) / DEG

    def gprime(phi: float) -> float:
        uu = (k - cos(alpha - phi * DEG)) / r2
        return sin(alpha - phi * DEG) / (r2 * sqrt(1.0 - uu * uu))

    return ScalarProblem(
        f=f, fprime=fprime, fsecond=fsecond, g=g, gprime=gprime, u=u, fbound=fbound,
        var="phi", unit="deg",
        title=(f"four-bar input-output equation, alpha = {alpha_deg:g} deg, "
               f"R1 = {r1:.10g}, R2 = {r2:.10g}, R3 = {r3:.10g}"),
        guess=default_start(f, fprime),
    )


def default_start(f: Callable[[float], float],
                  fprime: Callable[[float], float]) -> tuple[float, float] | None:
    """The first sign change of f on a 10-degree grid over [0, 180], as (x0, x1).

    x0 is the end whose Newton step stays inside the bracket (so open methods stay
    on the branch the bracket holds), x1 the other end; None if f never changes sign.
    At alpha = 70 this is the student report's (50, 60).
    """
    prev, fprev = 0.0, f(0.0)
    for i in range(1, 19):
        x = 10.0 * i
        fx = f(x)
        if fprev == 0.0 or fx == 0.0 or (fprev < 0.0) != (fx < 0.0):
            d = fprime(prev)
            step_inside = d != 0.0 and prev <= prev - fprev / d <= x
            return (prev, x) if step_inside else (x, prev)
        prev, fprev = x, fx
    return None


def equation_roots(alpha_deg: float, r1: float, r2: float, r3: float) -> list[float]:
    """Both roots phi (deg, in (-180, 180]) of the input-output equation, in closed form:
    (R2 + cos a) cos phi + sin a sin phi = R1 cos a + R3, so
    phi = atan2(sin a, R2 + cos a) +- acos(K / |(R2 + cos a, sin a)|). [] when the
    linkage cannot be assembled at alpha; one root at a limit position."""
    a = radians(alpha_deg)
    p, q = r2 + math.cos(a), math.sin(a)
    k = r1 * math.cos(a) + r3
    size = math.hypot(p, q)
    if size == 0.0 or abs(k) > size:
        return []
    base, spread = math.atan2(q, p), math.acos(max(-1.0, min(1.0, k / size)))
    roots = {(degrees(base + s * spread) + 180.0) % 360.0 - 180.0 for s in (1.0, -1.0)}
    return sorted(roots)


def branch_root(alpha_deg: float, r1: float, r2: float, r3: float, sign: float) -> float:
    """The root phi (deg, unwrapped) on one branch of the input-output equation:
    atan2(sin a, R2 + cos a) + sign * acos(K / |(R2 + cos a, sin a)|), the two roots of
    :func:`equation_roots` told apart by ``sign`` (+1 or -1). A branch keeps its sign
    between limit positions, where the two roots meet (acos at 0 or pi); NaN where the
    linkage cannot be assembled."""
    a = radians(alpha_deg)
    p, q = r2 + math.cos(a), math.sin(a)
    size = math.hypot(p, q)
    k = r1 * math.cos(a) + r3
    if size == 0.0 or abs(k) > size:
        return math.nan
    return degrees(math.atan2(q, p) + sign * math.acos(k / size))


def branch_root_np(alpha_deg: Any, r1: Any, r2: Any, r3: Any, sign: Any) -> Any:
    """:func:`branch_root` over arrays (broadcast): NaN where there is no assembly."""
    import numpy as np

    a = radians(np.asarray(alpha_deg, float))
    p, q = r2 + np.cos(a), np.sin(a)
    size = np.hypot(p, q)
    ratio = (r1 * np.cos(a) + r3) / np.where(size == 0.0, np.nan, size)
    with np.errstate(invalid="ignore"):
        spread = np.where(np.abs(ratio) <= 1.0, np.arccos(np.clip(ratio, -1.0, 1.0)), np.nan)
    return degrees(np.arctan2(q, p) + sign * spread)


def branch_sign(alpha_deg: float, phi_deg: float, r1: float, r2: float, r3: float) -> float:
    """The sign (+1 or -1) of :func:`branch_root` whose root is ``phi_deg``: the side of
    atan2(sin a, R2 + cos a) the root lies on (+1 for a root at a limit position)."""
    a = radians(alpha_deg)
    base = degrees(math.atan2(math.sin(a), r2 + math.cos(a)))
    # phi - base wrapped exactly into [-180, 180] (fmod is exact, so are the +-360 after it),
    # the same operations as the numpy twin (branch_sign_np); +-180 (acos at pi,
    # a limit position) is +1 whichever way rounding put it
    d = math.fmod(phi_deg - base, 360.0)
    d = d - 360.0 if d > 180.0 else d + 360.0 if d < -180.0 else d
    return 1.0 if d >= 0.0 or d == -180.0 else -1.0


def branch_sign_np(alpha_deg: Any, phi_deg: Any, r1: Any, r2: Any, r3: Any) -> Any:
    """:func:`branch_sign` over arrays: the same operations."""
    import numpy as np

    a = radians(np.asarray(alpha_deg, float))
    base = degrees(np.arctan2(np.sin(a), r2 + np.cos(a)))
    d = np.fmod(phi_deg - base, 360.0)
    d = np.where(d > 180.0, d - 360.0, np.where(d < -180.0, d + 360.0, d))
    return np.where((d >= 0.0) | (d == -180.0), 1.0, -1.0)


def links_of(r1: float, r2: float, r3: float,
             ground: float = 1.0) -> tuple[float, float, float, float] | None:
    """Link lengths (input a, coupler b, output c, ground d) with R1 = d/c, R2 = d/a,
    R3 = (a^2 - b^2 + c^2 + d^2) / (2ac), for a ground of ``ground``; None if no real
    coupler length fits."""
    if r1 <= 0.0 or r2 <= 0.0:
        return None
    d = ground
    a, c = d / r2, d / r1
    b2 = a * a + c * c + d * d - 2.0 * a * c * r3
    return (a, math.sqrt(b2), c, d) if b2 > 0.0 else None


def file_convention(alpha_deg: float, phi_deg: float,
                    links: tuple[float, float, float, float]) -> dict[str, float | str]:
    """The same position in the mechanism-file convention (sample_inputs/crank_rocker.toml:
    ground O2 -> O4 along +x, every angle from +x). The equation measures alpha and phi
    from the line of centres pointing from the output pivot O4 to the input pivot O2, the
    opposite direction, so theta2 = alpha + 180 and theta4 = phi + 180; theta3 is the
    coupler's direction from A to B. Angles in (-180, 180]."""
    a, _, c, d = links
    t2, t4 = radians(alpha_deg + 180.0), radians(phi_deg + 180.0)
    A = a * complex(math.cos(t2), math.sin(t2))
    B = d + c * complex(math.cos(t4), math.sin(t4))
    t3 = math.atan2((B - A).imag, (B - A).real)

    def wrap(v: float) -> float:
        return (v + 180.0) % 360.0 - 180.0 if (v + 180.0) % 360.0 != 0.0 else 180.0

    branch = label(is_open(t3, t4))
    return {"theta2": wrap(alpha_deg + 180.0), "theta3": wrap(degrees(t3)),
            "theta4": wrap(phi_deg + 180.0), "branch": branch}
