"""The synthesis asked for, checked: the function, its ranges and the precision points'
spacing (docs/synthesis.md). Each bad value is one InputError naming its option."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import field
from typing import Any

from ..errors import InputError
from ..records import frozen

SPACINGS = ("chebyshev", "uniform", "optimal")
MIN_TRANSMISSION_DEG = 30.0
MAX_POINTS = 100
GRID = 2001
"""Dense x grid on which the structural error's extrema are located (then refined)."""
TABLE_POINTS = 21
SOLVER_TOL = 1e-11
"""The continuation's step tolerance on phi (deg)."""
BRANCH_TOL_DEG = 1e-6
"""A precision point further than this from the followed branch is on another assembly."""
EQUIOSCILLATION = 0.01
"""--spacing optimal's promise: the extrema equal within 1% of the largest."""



@frozen
class PrecisionPoint:
    x: float
    y: float
    alpha_deg: float
    phi_deg: float
    residual: float
    """The equation's value there with the R found (zero to rounding for an exact fit)."""



@frozen
class Request:
    """A synthesis asked for, checked."""

    f: Callable[[float], float]
    text: str
    x_range: tuple[float, float]
    alpha_range: tuple[float, float]
    phi_range: tuple[float, float]
    points: int = 3
    spacing: str = "chebyshev"
    at: tuple[float, ...] | None = None
    ground: float = 1.0
    min_transmission: float = MIN_TRANSMISSION_DEG
    table_points: int = TABLE_POINTS
    y_ends: tuple[float, float] = field(default=(0.0, 1.0))

    def alpha(self, x: float) -> float:
        lo, hi = self.x_range
        a0, a1 = self.alpha_range
        return a0 + (x - lo) / (hi - lo) * (a1 - a0)

    def phi(self, y: float) -> float:
        y0, y1 = self.y_ends
        p0, p1 = self.phi_range
        return p0 + (y - y0) / (y1 - y0) * (p1 - p0)

    @property
    def y_per_deg(self) -> float:
        """Units of y per degree of phi (the output scale)."""
        (y0, y1), (p0, p1) = self.y_ends, self.phi_range
        return (y1 - y0) / (p1 - p0)


def function_of(f: str | Callable[[float], float]) -> tuple[Callable[[float], float], str]:
    """f as a callable and as text: a string is parsed by the same safe parser as
    ``--equation`` (problems.expression)."""
    if isinstance(f, str):
        from ..problems.expression import Expression

        if not f.strip():
            raise InputError("--function: give an expression in x, e.g. log10(x)")
        return Expression.parse(f, what="function").function(), f
    if callable(f):
        return f, getattr(f, "__name__", "f")
    raise InputError(f"function: give an expression in x or a callable, got {type(f).__name__}")


def parse_range(name: str, value: Any) -> tuple[float, float]:
    from ..arguments import check_number

    if isinstance(value, str):
        parts = value.split(":")
        if len(parts) != 2:
            raise InputError(f"{name} {value!r}: write LO:HI")
        from ..numbers import parse_number

        lo, hi = (parse_number(name, p) for p in parts)
    else:
        try:
            lo, hi = value
        except (TypeError, ValueError):
            raise InputError(f"{name}: give two numbers (LO, HI), got {value!r}") from None
        lo, hi = check_number(name, lo), check_number(name, hi)
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise InputError(f"{name}: the ends must be finite, got {lo!r}:{hi!r}")
    if lo == hi:
        raise InputError(f"{name} {lo:g}:{hi:g}: the two ends must differ")
    if max(abs(lo), abs(hi)) > 1e6:
        raise InputError(f"{name} {lo:g}:{hi:g}: ends beyond 1e6 are not supported")
    return float(lo), float(hi)


def make_request(
    f: str | Callable[[float], float],
    x_range: Any,
    alpha_range: Any,
    phi_range: Any,
    *,
    points: int = 3,
    spacing: str = "chebyshev",
    at: Sequence[float] | str | None = None,
    ground: float = 1.0,
    min_transmission: float = MIN_TRANSMISSION_DEG,
    table_points: int = TABLE_POINTS,
) -> Request:
    """The request checked: each bad value one InputError naming its option."""
    from ..arguments import check_number

    fn, text = function_of(f)
    xr = parse_range("--x", x_range)
    if xr[1] < xr[0]:
        raise InputError(
            f"--x {xr[0]:g}:{xr[1]:g}: LO must be below HI (the angle ranges may run either way)"
        )
    ar, pr = parse_range("--alpha", alpha_range), parse_range("--phi", phi_range)
    for name, (lo, hi) in (("--alpha", ar), ("--phi", pr)):
        if abs(hi - lo) >= 360.0:
            raise InputError(
                f"{name} {lo:g}:{hi:g}: a span of a full turn or more maps two x to one "
                "position; give less than 360 deg"
            )
    if isinstance(points, bool) or not isinstance(points, int) or not 3 <= points <= MAX_POINTS:
        raise InputError(f"--points must be a whole number from 3 to {MAX_POINTS}, got {points!r}")
    if spacing not in SPACINGS:
        raise InputError(f"--spacing {spacing!r}: give one of {', '.join(SPACINGS)}")
    xs_at = None if at is None else parse_at(at, xr)
    if xs_at is not None:
        points = len(xs_at)
    if spacing == "optimal" and (points != 3 or xs_at is not None):
        raise InputError(
            "--spacing optimal places 3 precision points (R1, R2, R3 are three "
            "unknowns: with more points the fit is least squares and has no zeros to "
            "move); drop --points/--at"
        )
    ground = check_number("--ground", ground)
    if not 1e-9 <= ground <= 1e9:
        raise InputError(f"--ground must be a length from 1e-9 to 1e9, got {ground:g}")
    min_transmission = check_number("--min-transmission", min_transmission)
    if not 0.0 <= min_transmission <= 90.0:
        raise InputError(f"--min-transmission must be from 0 to 90 deg, got {min_transmission:g}")
    if (
        isinstance(table_points, bool)
        or not isinstance(table_points, int)
        or not 2 <= table_points <= 100_001
    ):
        raise InputError(f"--rows must be a whole number from 2 to 100001, got {table_points!r}")
    y_ends = (value_of(fn, xr[0]), value_of(fn, xr[1]))
    if y_ends[0] == y_ends[1]:
        raise InputError(
            f"f({xr[0]:g}) = f({xr[1]:g}) = {y_ends[0]:g}: the ends of y must differ to map onto --phi"
        )
    return check_conditioning(Request(
        fn,
        text,
        xr,
        ar,
        pr,
        points,
        spacing,
        xs_at,
        float(ground),
        float(min_transmission),
        table_points,
        y_ends,
    ))


def parse_at(at: Sequence[float] | str, xr: tuple[float, float]) -> tuple[float, ...]:
    """--at: the precision points' x, checked (3 to MAX_POINTS, distinct, inside --x), ascending."""
    from ..arguments import check_number
    from ..numbers import parse_number

    try:
        items = at.split(",") if isinstance(at, str) else list(at)
    except TypeError:
        raise InputError(f"--at: give the precision points' x as a list, got {at!r}") from None
    xs_at = tuple(parse_number("--at", v) if isinstance(v, str) else check_number("--at", v) for v in items)
    if len(xs_at) < 3:
        raise InputError(f"--at: give at least 3 precision points, got {len(xs_at)}")
    if len(xs_at) > MAX_POINTS:
        raise InputError(f"--at: at most {MAX_POINTS} precision points, got {len(xs_at)}")
    if any(not xr[0] <= v <= xr[1] for v in xs_at):
        bad = next(v for v in xs_at if not xr[0] <= v <= xr[1])
        raise InputError(f"--at {bad:g} is outside --x {xr[0]:g}:{xr[1]:g}")
    if len(set(xs_at)) != len(xs_at):
        raise InputError("--at: the precision points must differ")
    return tuple(sorted(xs_at))


CONDITIONING_SAMPLES = 11
"""Points of x (ends included) at which |y| is read for :func:`rounding_deg`."""
EPS = 2.0**-52
"""The spacing of doubles at 1 (machine epsilon)."""


def rounding_deg(req: Request) -> float:
    """How far rounding alone moves a precision point's angles (deg), to first order. x is
    known to eps |x| and y = f(x) to eps |y| (its evaluation) plus eps |x f'(x)| (x's own
    rounding carried through f, whose condition is |x f'(x) / f(x)|; f' taken as the
    range's secant). Mapped onto the angles, t = (x - LO) / (HI - LO) then carries
    eps max|x| / (HI - LO) and u = (y - f(LO)) / (f(HI) - f(LO)) that plus
    eps max|y| / |f(HI) - f(LO)|; times the spans of alpha and phi."""
    (lo, hi), (y0, y1) = req.x_range, req.y_ends
    (a0, a1), (p0, p1) = req.alpha_range, req.phi_range
    n = CONDITIONING_SAMPLES
    size_y = max(abs(value_of(req.f, lo + (hi - lo) * i / (n - 1))) for i in range(n))
    t_noise = EPS * max(abs(lo), abs(hi)) / (hi - lo)
    u_noise = t_noise + EPS * size_y / abs(y1 - y0)
    return max(t_noise * abs(a1 - a0), u_noise * abs(p1 - p0))


def check_conditioning(req: Request) -> Request:
    """``req``, unless its range is so narrow, for its f, that rounding moves the precision
    points' angles (:func:`rounding_deg`) by more than BRANCH_TOL_DEG, the distance to
    which a point is judged on its branch: the fit would be a fit of rounding noise."""
    noise = rounding_deg(req)
    if noise > BRANCH_TOL_DEG:
        (lo, hi), (y0, y1) = req.x_range, req.y_ends
        raise InputError(
            f"--x {lo!r}:{hi!r} is too narrow for this function: x spans {hi - lo:.3g} and "
            f"y {abs(y1 - y0):.3g}, so rounding (machine epsilon {EPS:.3g}) moves the precision "
            f"points' angles by up to {noise:.3g} deg, more than the {BRANCH_TOL_DEG:g} deg a point "
            "is judged to; widen --x"
        )
    return req


def value_of(f: Callable[[float], float], x: float) -> float:
    try:
        y = float(f(x))
    except (ValueError, ZeroDivisionError, OverflowError, TypeError) as exc:
        raise InputError(f"f({x:.12g}) cannot be evaluated: {exc}") from None
    if not math.isfinite(y):
        raise InputError(f"f({x:.12g}) = {y!r}: the function must be finite over --x")
    return y
