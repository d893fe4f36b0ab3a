"""Function generation: the student report's equation run backwards (Freudenstein's synthesis).

The seed solves R1 cos(alpha) - R2 cos(phi) + R3 - cos(alpha - phi) = 0 for phi given the
constants. Here the constants are the unknowns: a function y = f(x) over LO..HI is mapped
linearly onto the input angle alpha (LO -> A0, HI -> A1) and the output angle phi
(f(LO) -> P0, f(HI) -> P1), both in the student report's convention (alpha at O2, phi at O4, from
the line O4 -> O2), and at each precision point the equation is linear in (R1, R2, R3).
Three points give a 3x3 system; more a least-squares fit by orthogonal factorisation.

The linkage found is then analysed as a user's would be: the input-output equation is
followed with continuation (kinematics.equation_sweep, the four-bar equation's own solver) over the
whole x range on the branch through the first precision point, and its output compared
with the function asked for (the structural error). Defects are named, never hidden.

The rules live here once, each with its numpy twin where the search (many candidates at
a time) needs one: the precision points (:func:`precision_xs`), the linear system
(:func:`solve_coefficients`, :func:`solve_coefficients_np`), the linkage of a solution
(:func:`linkage_of`), the branch's closed form (freudenstein.branch_root and its twin) and
whether a precision point is off the followed branch (:func:`off_branch` and its twin).
"""

from __future__ import annotations

import itertools
import math
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

from .errors import InputError

SPACINGS = ("chebyshev", "uniform", "optimal")
DEFECTS = ("no_linkage", "branch", "grashof", "order", "transmission")
"""Every defect's name, as JSON and exit 1 report them."""
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


@dataclass(frozen=True)
class PrecisionPoint:
    x: float
    y: float
    alpha_deg: float
    phi_deg: float
    residual: float
    """The equation's value there with the R found (zero to rounding for an exact fit)."""


@dataclass(frozen=True)
class Defect:
    name: str
    message: str


@dataclass(frozen=True)
class Linkage:
    """The real linkage of a solution: positive lengths (input a, coupler b, output c,
    ground d) and whether the input or output link is drawn the other way (a negative R2
    or R1 is a link turned by 180 deg: its angle is alpha + 180 or phi + 180)."""

    a: float
    b: float
    c: float
    d: float
    input_turned: bool
    output_turned: bool

    @property
    def coefficients(self) -> tuple[float, float, float]:
        """R1, R2, R3 of the real linkage (its own angles: alpha', phi')."""
        return real_coefficients(self.a, self.b, self.c, self.d)

    def alpha_shift(self) -> float:
        return 180.0 if self.input_turned else 0.0

    def phi_shift(self) -> float:
        return 180.0 if self.output_turned else 0.0


def real_coefficients(a: Any, b: Any, c: Any, d: Any) -> tuple[Any, Any, Any]:
    """R1 = d/c, R2 = d/a, R3 = (a^2 - b^2 + c^2 + d^2) / (2ac) of positive lengths: numbers
    or arrays alike (the same operations either way)."""
    return d / c, d / a, (a * a - b * b + c * c + d * d) / (2.0 * a * c)


@dataclass(frozen=True)
class CurvePoint:
    x: float
    y: float
    alpha_deg: float
    phi_desired_deg: float
    phi_generated_deg: float | None
    error_deg: float | None
    error_y: float | None
    transmission_deg: float | None
    status: str


@dataclass(frozen=True)
class FunctionSynthesis:
    """Everything ``linkage synthesize`` reports, as a value."""

    function: str
    x_range: tuple[float, float]
    alpha_range: tuple[float, float]
    phi_range: tuple[float, float]
    spacing: str
    R: tuple[float, float, float]
    fit_residual: float
    """The least-squares residual norm |A R - b| (rounding only, for three points)."""
    precision_points: tuple[PrecisionPoint, ...]
    linkage: Linkage | None
    grashof: str | None
    branch: str | None
    """The followed assembly at the first precision point: open or crossed."""
    curve: tuple[CurvePoint, ...]
    max_error_deg: float | None
    at_x: float | None
    max_error_y: float | None
    extrema: tuple[tuple[float, float], ...]
    """(x, error_deg) of each local extremum of the structural error, refined."""
    transmission: tuple[float, float] | None
    """(min, max) of the transmission angle, folded into 0..90 deg, over the range."""
    transmission_at_x: float | None
    defects: tuple[Defect, ...]
    notes: tuple[str, ...] = ()
    chebyshev_max_error_deg: float | None = None
    """With optimal spacing: the Chebyshev spacing's max error, for comparison."""
    equioscillation: float | None = None
    """(largest - smallest extremum) / largest: 0 for perfect equioscillation."""
    min_transmission_deg: float = MIN_TRANSMISSION_DEG
    request: Request | None = field(default=None, repr=False, compare=False)

    @property
    def defect_names(self) -> list[str]:
        return [d.name for d in self.defects]

    @property
    def links(self) -> dict[str, float] | None:
        k = self.linkage
        return None if k is None else {"input": k.a, "coupler": k.b, "output": k.c, "ground": k.d}


# --- the request -----------------------------------------------------------------------------


@dataclass(frozen=True)
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
        from .problems.expression import Expression

        if not f.strip():
            raise InputError("--function: give an expression in x, e.g. log10(x)")
        return Expression.parse(f, what="function").function(), f
    if callable(f):
        return f, getattr(f, "__name__", "f")
    raise InputError(f"function: give an expression in x or a callable, got {type(f).__name__}")


def _range(name: str, value: Any) -> tuple[float, float]:
    from .arguments import check_number

    if isinstance(value, str):
        parts = value.split(":")
        if len(parts) != 2:
            raise InputError(f"{name} {value!r}: write LO:HI")
        from .numbers import parse_number

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
    from .arguments import check_number

    fn, text = function_of(f)
    xr = _range("--x", x_range)
    if xr[1] < xr[0]:
        raise InputError(
            f"--x {xr[0]:g}:{xr[1]:g}: LO must be below HI (the angle ranges may run either way)"
        )
    ar, pr = _range("--alpha", alpha_range), _range("--phi", phi_range)
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
    xs_at: tuple[float, ...] | None = None
    if at is not None:
        from .numbers import parse_number

        try:
            items = at.split(",") if isinstance(at, str) else list(at)
        except TypeError:
            raise InputError(f"--at: give the precision points' x as a list, got {at!r}") from None
        xs_at = tuple(
            parse_number("--at", v) if isinstance(v, str) else check_number("--at", v) for v in items
        )
        if len(xs_at) < 3:
            raise InputError(f"--at: give at least 3 precision points, got {len(xs_at)}")
        if len(xs_at) > MAX_POINTS:
            raise InputError(f"--at: at most {MAX_POINTS} precision points, got {len(xs_at)}")
        if any(not xr[0] <= v <= xr[1] for v in xs_at):
            bad = next(v for v in xs_at if not xr[0] <= v <= xr[1])
            raise InputError(f"--at {bad:g} is outside --x {xr[0]:g}:{xr[1]:g}")
        if len(set(xs_at)) != len(xs_at):
            raise InputError("--at: the precision points must differ")
        xs_at = tuple(sorted(xs_at))
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
    y_ends = (_value(fn, xr[0]), _value(fn, xr[1]))
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
    size_y = max(abs(_value(req.f, lo + (hi - lo) * i / (n - 1))) for i in range(n))
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


def _value(f: Callable[[float], float], x: float) -> float:
    try:
        y = float(f(x))
    except (ValueError, ZeroDivisionError, OverflowError, TypeError) as exc:
        raise InputError(f"f({x:.12g}) cannot be evaluated: {exc}") from None
    if not math.isfinite(y):
        raise InputError(f"f({x:.12g}) = {y!r}: the function must be finite over --x")
    return y


# --- the rules ---------------------------------------------------------------------------------


def chebyshev_xs(n: int, lo: float, hi: float) -> list[float]:
    """Chebyshev spacing: x_j = (lo + hi)/2 - (hi - lo)/2 cos((2j - 1) pi / (2n)), ascending."""
    mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    return [mid - half * math.cos((2 * j - 1) * math.pi / (2 * n)) for j in range(1, n + 1)]


def uniform_xs(n: int, lo: float, hi: float) -> list[float]:
    """Equal steps with both ends included."""
    return [lo + (hi - lo) * j / (n - 1) for j in range(n)]


def precision_xs(req: Request) -> list[float]:
    if req.at is not None:
        return list(req.at)
    lo, hi = req.x_range
    return uniform_xs(req.points, lo, hi) if req.spacing == "uniform" else chebyshev_xs(req.points, lo, hi)


def system(alphas_deg: Sequence[float], phis_deg: Sequence[float]) -> tuple[list[list[float]], list[float]]:
    """Freudenstein's equation at each point as a row of A R = b:
    [cos alpha, -cos phi, 1] . (R1, R2, R3) = cos(alpha - phi)."""
    rows, rhs = [], []
    for al, ph in zip(alphas_deg, phis_deg):
        a, p = math.radians(al), math.radians(ph)
        rows.append([math.cos(a), -math.cos(p), 1.0])
        rhs.append(math.cos(a - p))
    return rows, rhs


COND_LIMIT = 1e12


def solve_coefficients(
    alphas_deg: Sequence[float], phis_deg: Sequence[float]
) -> tuple[tuple[float, float, float], float]:
    """(R1, R2, R3) and the residual norm: three points solved exactly, more by least squares
    through a QR factorisation (never the normal equations, which square the condition)."""
    import numpy as np

    rows, rhs = system(alphas_deg, phis_deg)
    a, b = np.array(rows), np.array(rhs)
    cond = np.linalg.cond(a)
    if not np.isfinite(cond) or cond > COND_LIMIT:
        raise InputError(
            f"the precision points give a singular system for R1, R2, R3 (condition "
            f"number {cond:.3g}): move them apart or change the angle ranges"
        )
    if len(rows) == 3:
        r = np.linalg.solve(a, b)
    else:
        q, tri = np.linalg.qr(a)
        r = np.linalg.solve(tri, q.T @ b)
    residual = float(np.linalg.norm(a @ r - b))
    return (float(r[0]), float(r[1]), float(r[2])), residual


def solve_coefficients_np(alphas_deg: Any, phis_deg: Any) -> Any:
    """:func:`solve_coefficients` for many candidates at once (three points each): arrays
    of shape (n, 3) in, (n, 3) of R out; NaN rows where the system is singular."""
    import numpy as np

    a, p = np.radians(alphas_deg), np.radians(phis_deg)
    mat = np.stack([np.cos(a), -np.cos(p), np.ones_like(a)], axis=-1)
    rhs = np.cos(a - p)
    cond = np.linalg.cond(mat)
    good = np.isfinite(cond) & (cond <= COND_LIMIT)
    out = np.full(a.shape, np.nan)
    if good.any():
        out[good] = np.linalg.solve(mat[good], rhs[good][..., None])[..., 0]
    return out


ZERO_R = 1e-12
"""R1 or R2 within this (relative to the largest R, or 1) of zero is zero: a link 1e12
grounds long is no link."""


def linkage_of(r: Sequence[float], ground: float) -> tuple[Linkage | None, str | None]:
    """The real linkage of (R1, R2, R3) for a ground ``ground``, or None and why not.
    R1 = d/c, R2 = d/a, R3 = (a^2 - b^2 + c^2 + d^2) / (2ac) with a, c signed: a negative
    one is the link drawn the other way (length |a|, angle + 180 deg)."""
    r1, r2, r3 = r
    if not all(math.isfinite(v) for v in r):
        return None, "R1, R2, R3 are not finite"
    tiny = ZERO_R * max(1.0, abs(r1), abs(r2), abs(r3))
    if abs(r1) <= tiny or abs(r2) <= tiny:
        # said as 0, which by ZERO_R it is: its rounding (a sign, 1e-16) is the LAPACK
        # kernel's, different from one CPU to another
        which = "output link (R1 = 0)" if abs(r1) <= tiny else "input link (R2 = 0)"
        return None, f"the {which} would be infinitely long: R = d / length is zero to rounding"
    d = ground
    a, c = d / r2, d / r1
    b2 = a * a + c * c + d * d - 2.0 * a * c * r3
    if not b2 > 0.0:
        return None, (
            f"the coupler's squared length b^2 = a^2 + c^2 + d^2 - 2 a c R3 = {b2:.6g} is "
            "not positive: no real linkage fits these precision points"
        )
    return Linkage(abs(a), math.sqrt(b2), abs(c), d, a < 0.0, c < 0.0), None


def linkage_of_np(r: Any, ground: float) -> tuple[Any, Any, Any, Any, Any, Any]:
    """:func:`linkage_of` over rows of R: (a, b, c, d, input_turned, output_turned), NaN
    lengths where there is no real linkage."""
    import numpy as np

    r1, r2, r3 = r[..., 0], r[..., 1], r[..., 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        a, c = ground / r2, ground / r1
        b2 = a * a + c * c + ground * ground - 2.0 * a * c * r3
        tiny = ZERO_R * np.maximum(1.0, np.maximum(np.abs(r1), np.maximum(np.abs(r2), np.abs(r3))))
        ok = np.isfinite(a) & np.isfinite(c) & (np.abs(r1) > tiny) & (np.abs(r2) > tiny) & (b2 > 0.0)
        b = np.where(ok, np.sqrt(np.where(ok, b2, 1.0)), np.nan)
    return (
        np.where(ok, np.abs(a), np.nan),
        b,
        np.where(ok, np.abs(c), np.nan),
        np.full(a.shape, float(ground)),
        a < 0.0,
        c < 0.0,
    )


def transmission_deg(k: Linkage, alpha_real_deg: float, phi_real_deg: float) -> float:
    """The transmission angle (deg, folded into 0..90) of the real linkage at its own angles:
    between the coupler A -> B and the output link O4 -> B (closed_form.transmission), with O4 at
    the origin, O2 at (d, 0), A = O2 + a e^(i alpha'), B = c e^(i phi')."""
    from .problems.closed_form import transmission

    a_pt = complex(k.d, 0.0) + k.a * complex(
        math.cos(math.radians(alpha_real_deg)), math.sin(math.radians(alpha_real_deg))
    )
    b_pt = k.c * complex(math.cos(math.radians(phi_real_deg)), math.sin(math.radians(phi_real_deg)))
    t3 = math.degrees(math.atan2((b_pt - a_pt).imag, (b_pt - a_pt).real))
    return transmission(t3, phi_real_deg)


def transmission_deg_np(a: Any, c: Any, d: Any, alpha_real_deg: Any, phi_real_deg: Any) -> Any:
    """:func:`transmission_deg` over arrays."""
    import numpy as np

    from .problems.closed_form import transmission_np

    al, ph = np.radians(alpha_real_deg), np.radians(phi_real_deg)
    ax, ay = d + a * np.cos(al), a * np.sin(al)
    bx, by = c * np.cos(ph), c * np.sin(ph)
    t3 = np.degrees(np.arctan2(by - ay, bx - ax))
    return transmission_np(t3, phi_real_deg)


def branch_label(k: Linkage, alpha_real_deg: float, phi_real_deg: float) -> str:
    """open or crossed (the project's words, problems.assembly) of a real position."""
    from .problems.freudenstein import file_convention

    return str(file_convention(alpha_real_deg, phi_real_deg, (k.a, k.b, k.c, k.d))["branch"])


def off_branch(alpha_real_deg: float, phi_real_deg: float, real_r: Sequence[float], sign: float) -> bool:
    """Whether a precision point (its real angles) lies on the other assembly than the
    branch ``sign`` (freudenstein.branch_root) followed from point 1, reached or not: its
    own root (the one on its phi's side, freudenstein.branch_sign: the point itself for an
    exact fit, the nearer root for least squares, whose points lie off the linkage by the
    fit's error) and the followed branch's root differ by more than BRANCH_TOL_DEG. At a
    limit position the two meet (no defect); where the linkage cannot be assembled at
    all there is neither (the grashof defect says so)."""
    from .problems.freudenstein import branch_root, branch_sign

    own = branch_sign(alpha_real_deg, phi_real_deg, *real_r)
    if own == sign:
        return False
    apart = math.remainder(
        branch_root(alpha_real_deg, *real_r, own) - branch_root(alpha_real_deg, *real_r, sign), 360.0
    )
    return abs(apart) > BRANCH_TOL_DEG


def off_branch_np(alpha_real_deg: Any, phi_real_deg: Any, r1: Any, r2: Any, r3: Any, sign: Any) -> Any:
    """:func:`off_branch` over arrays (broadcast)."""
    import numpy as np

    from .problems.freudenstein import branch_root_np, branch_sign_np

    own = branch_sign_np(alpha_real_deg, phi_real_deg, r1, r2, r3)
    apart = branch_root_np(alpha_real_deg, r1, r2, r3, own) - branch_root_np(alpha_real_deg, r1, r2, r3, sign)
    with np.errstate(invalid="ignore"):
        return (own != sign) & (np.abs(np.remainder(apart + 180.0, 360.0) - 180.0) > BRANCH_TOL_DEG)


def grashof_of(k: Linkage) -> str:
    from .problems.closed_form import grashof

    return grashof(k.d, k.a, k.b, k.c)


def assembly_gap(real_r: Sequence[float], alpha0_deg: float, alpha1_deg: float) -> bool:
    """Whether the linkage of ``real_r`` cannot be assembled somewhere in the input range
    (its own alpha, either order), between grid points or not: it assembles at alpha iff
    |K| <= |(R2 + cos a, sin a)| (freudenstein.branch_root), i.e. iff
    g(cos a) = 1 + R2^2 + 2 R2 cos a - (R1 cos a + R3)^2 >= 0, a parabola in cos a opening
    downwards, so its least over the range is at the least or the greatest cos a there."""
    r1, r2, r3 = real_r
    lo, hi = sorted((alpha0_deg, alpha1_deg))
    ends = (math.cos(math.radians(lo)), math.cos(math.radians(hi)))
    top = 1.0 if math.floor(hi / 360.0) >= math.ceil(lo / 360.0) else max(ends)
    bottom = -1.0 if math.floor((hi - 180.0) / 360.0) >= math.ceil((lo - 180.0) / 360.0) else min(ends)
    return min(1.0 + r2 * r2 + 2.0 * r2 * c - (r1 * c + r3) ** 2 for c in (bottom, top)) < 0.0


def assembly_gap_np(r1: Any, r2: Any, r3: Any, alpha0_deg: Any, alpha1_deg: Any) -> Any:
    """:func:`assembly_gap` over arrays."""
    import numpy as np

    lo, hi = np.minimum(alpha0_deg, alpha1_deg), np.maximum(alpha0_deg, alpha1_deg)
    c_lo, c_hi = np.cos(np.radians(lo)), np.cos(np.radians(hi))
    top = np.where(np.floor(hi / 360.0) >= np.ceil(lo / 360.0), 1.0, np.maximum(c_lo, c_hi))
    bottom = np.where(
        np.floor((hi - 180.0) / 360.0) >= np.ceil((lo - 180.0) / 360.0), -1.0, np.minimum(c_lo, c_hi)
    )

    def g(c: Any) -> Any:
        return 1.0 + r2 * r2 + 2.0 * r2 * c - (r1 * c + r3) ** 2

    with np.errstate(invalid="ignore"):
        return np.minimum(g(bottom), g(top)) < 0.0




# --- the structural error --------------------------------------------------------------------


@dataclass(frozen=True)
class Design:
    """One synthesised linkage with what its error needs: the real R, the branch sign at
    the first precision point, and the shifts between the equation's angles and its own."""

    req: Request
    R: tuple[float, float, float]
    linkage: Linkage
    real_R: tuple[float, float, float]
    sign: float

    def real_alpha(self, x: float) -> float:
        return self.req.alpha(x) + self.linkage.alpha_shift()

    def closed_error(self, x: float, y: float) -> float:
        """phi generated - phi desired (deg) by the branch's closed form; NaN where the
        linkage cannot be assembled."""
        from .problems.freudenstein import branch_root

        phi = branch_root(self.real_alpha(x), *self.real_R, self.sign) - self.linkage.phi_shift()
        return math.remainder(phi - self.req.phi(y), 360.0)


def design_of(
    req: Request, r: tuple[float, float, float], first: PrecisionPoint
) -> tuple[Design | None, str | None]:
    from .problems.freudenstein import branch_sign

    k, why = linkage_of(r, req.ground)
    if k is None:
        return None, why
    real_r = k.coefficients
    sign = branch_sign(first.alpha_deg + k.alpha_shift(), first.phi_deg + k.phi_shift(), *real_r)
    return Design(req, r, k, real_r, sign), None


def golden_max(g: Callable[[float], float], lo: float, hi: float, iters: int = 80) -> tuple[float, float]:
    """The x in [lo, hi] where g is largest (g unimodal there) and g there: the golden-section
    loop (methods.golden) on -g, then the best of the last bracket and its ends."""
    from .methods.golden import golden_min

    a, c, fc, d, fd, b = golden_min(lambda x: -g(x), lo, hi, iters,
                                    lambda k: k[5] - k[0] <= 1e-15 * max(1.0, abs(k[0]), abs(k[5])))
    ends = ((a, g(a)), (c, -fc), (d, -fd), (b, g(b)))
    return max(ends, key=lambda t: t[1] if math.isfinite(t[1]) else -1.0)


def extrema(
    design: Design, grid: int = GRID, reached: bool = False
) -> tuple[list[tuple[float, float]], list[float], list[float]]:
    """The structural error's local extrema (x, error_deg), refined by golden section from
    a dense grid (ends included), and the grid's x and errors (NaN: no assembly). Where
    the linkage cannot be assembled there are none, unless ``reached``: then the assembled
    runs' extrema, an end at a limit position being the last x that assembles (the error
    is steepest there)."""
    req = design.req
    lo, hi = req.x_range
    xs = [lo + (hi - lo) * i / (grid - 1) for i in range(grid)]
    errs = [design.closed_error(x, _value(req.f, x)) for x in xs]
    out: list[tuple[float, float]] = []
    if not reached and any(not math.isfinite(e) for e in errs):
        return out, xs, errs
    mag = [abs(e) if math.isfinite(e) else -1.0 for e in errs]
    for i in range(grid):
        if mag[i] < 0.0:
            continue
        left = mag[i - 1] if i > 0 else -1.0
        right = mag[i + 1] if i < grid - 1 else -1.0
        if (mag[i] >= left and mag[i] > right) or (mag[i] > left and mag[i] >= right):
            if (left < 0.0 < i) or (right < 0.0 and i < grid - 1):
                x = _last_assembled(design, xs[i], xs[i - 1] if left < 0.0 else xs[i + 1])
            elif 0 < i < grid - 1:
                x, _ = golden_max(
                    lambda t: abs(design.closed_error(t, _value(req.f, t))), xs[i - 1], xs[i + 1]
                )
            else:
                x = xs[i]
            out.append((x, design.closed_error(x, _value(req.f, x))))
    # neighbours of one sign with a zero between them belong to different lobes; keep the
    # largest of each run of one sign (plateaus of rounding give several)
    lobes: list[tuple[float, float]] = []
    for x, e in out:
        if lobes and (lobes[-1][1] > 0.0) == (e > 0.0) and not _zero_between(errs, xs, lobes[-1][0], x):
            if abs(e) > abs(lobes[-1][1]):
                lobes[-1] = (x, e)
            continue
        lobes.append((x, e))
    return lobes, xs, errs


def _last_assembled(design: Design, inside: float, outside: float) -> float:
    """The x between an assembled ``inside`` and an unassembled ``outside`` nearest the
    limit position that still assembles (bisection)."""
    f = design.req.f
    for _ in range(60):
        mid = 0.5 * (inside + outside)
        if mid in (inside, outside):
            break
        if math.isfinite(design.closed_error(mid, _value(f, mid))):
            inside = mid
        else:
            outside = mid
    return inside


def _zero_between(errs: Sequence[float], xs: Sequence[float], x0: float, x1: float) -> bool:
    inside = [e for x, e in zip(xs, errs) if x0 < x < x1]
    return any((e > 0.0) != (inside[0] > 0.0) for e in inside) if inside else False


def follow(design: Design, xs: Sequence[float], first: PrecisionPoint) -> list[float | None]:
    """The generated phi (deg, the equation's convention) at each x, by the four-bar equation's solver
    (Newton with continuation, kinematics.equation_sweep) from the first precision point,
    both ways; None from the first position it cannot reach on that branch onwards (a
    limit position in between, even one narrower than the steps). Near a limit the two
    roots are close and a continuation step can land on the other one: a root nearer the
    other branch's closed form (freudenstein.branch_root with -sign) than the followed
    one's is such a jump, and the walk restarts there from the followed branch's root."""
    from .kinematics.equation_sweep import equation_sweep
    from .problems.freudenstein import branch_root

    k, real_r, sign = design.linkage, design.real_R, design.sign
    seed = (first.alpha_deg + k.alpha_shift(), first.phi_deg + k.phi_shift())
    order = sorted(range(len(xs)), key=lambda i: xs[i])
    ahead = [i for i in order if xs[i] >= first.x]
    behind = [i for i in reversed(order) if xs[i] < first.x]
    out: list[float | None] = [None] * len(xs)
    for part in (ahead, behind):
        start, last, j, restarted = seed, seed[0], 0, -1
        while j < len(part):
            alphas = [design.real_alpha(xs[i]) for i in part[j:]]
            rows = equation_sweep(alphas, real_r, "newton", SOLVER_TOL, seed=start)
            jump = None
            for m, (i, row, al) in enumerate(zip(part[j:], rows, alphas)):
                if row.phi is None or assembly_gap(real_r, last, al):
                    break  # beyond a limit: the rest of this side is not on the followed branch
                on, other = branch_root(al, *real_r, sign), branch_root(al, *real_r, -sign)
                if abs(math.remainder(row.phi - on, 360.0)) > abs(math.remainder(row.phi - other, 360.0)):
                    jump = (j + m, (al, on))
                    break
                out[i], last = row.phi - k.phi_shift(), al
            if jump is None or jump[0] == restarted:
                break
            (j, start), restarted = jump, jump[0]
    return out


def structural_error(design: Design, xs: Sequence[float], first: PrecisionPoint) -> list[CurvePoint]:
    req, k = design.req, design.linkage
    phis = follow(design, xs, first)
    out = []
    for x, phi in zip(xs, phis):
        y = _value(req.f, x)
        want = req.phi(y)
        al = req.alpha(x)
        if phi is None:
            out.append(CurvePoint(x, y, al, want, None, None, None, None, "not_reached"))
            continue
        err = math.remainder(phi - want, 360.0)
        mu = transmission_deg(k, al + k.alpha_shift(), phi + k.phi_shift())
        out.append(CurvePoint(x, y, al, want, phi, err, err * req.y_per_deg, mu, "converged"))
    return out


# --- synthesis -------------------------------------------------------------------------------------


def precision_points(
    req: Request, xs: Sequence[float]
) -> tuple[list[PrecisionPoint], tuple[float, float, float], float]:
    ys = [_value(req.f, x) for x in xs]
    als = [req.alpha(x) for x in xs]
    phs = [req.phi(y) for y in ys]
    r, res = solve_coefficients(als, phs)
    pts = []
    for x, y, al, ph in zip(xs, ys, als, phs):
        a, p = math.radians(al), math.radians(ph)
        pts.append(
            PrecisionPoint(x, y, al, ph, r[0] * math.cos(a) - r[1] * math.cos(p) + r[2] - math.cos(a - p))
        )
    return pts, r, res


def synthesize(req: Request) -> FunctionSynthesis:
    """Synthesise, analyse and judge one function generator."""
    if req.spacing == "optimal":
        return _optimal(req)
    return _synthesize(req, precision_xs(req))


def _synthesize(req: Request, xs: Sequence[float]) -> FunctionSynthesis:
    pts, r, res = precision_points(req, xs)
    base = FunctionSynthesis(
        function=req.text,
        x_range=req.x_range,
        alpha_range=req.alpha_range,
        phi_range=req.phi_range,
        spacing="at" if req.at is not None else req.spacing,
        R=r,
        fit_residual=res,
        precision_points=tuple(pts),
        linkage=None,
        grashof=None,
        branch=None,
        curve=(),
        max_error_deg=None,
        at_x=None,
        max_error_y=None,
        extrema=(),
        transmission=None,
        transmission_at_x=None,
        defects=(),
        min_transmission_deg=req.min_transmission,
        request=req,
    )
    design, why = design_of(req, r, pts[0])
    if design is None:
        return replace(base, defects=(Defect("no_linkage", f"no real linkage: {why}"),))
    k = design.linkage
    notes = []
    if k.input_turned:
        notes.append(
            f"R2 = {r[1]:.6g} < 0: the input link is drawn the other way (length {k.a:.6g}, "
            "its angle alpha + 180 deg)"
        )
    if k.output_turned:
        notes.append(
            f"R1 = {r[0]:.6g} < 0: the output link is drawn the other way (length {k.c:.6g}, "
            "its angle phi + 180 deg)"
        )
    lobes, grid_xs, grid_errs = extrema(design, reached=True)
    lo, hi = req.x_range
    table = [lo + (hi - lo) * i / (req.table_points - 1) for i in range(req.table_points)]
    extra = [x for x, _ in lobes] + [p.x for p in pts]
    curve_xs = sorted(set(table) | set(extra))
    curve = structural_error(design, curve_xs, pts[0])
    solved = [c for c in curve if c.error_deg is not None]
    worst = max(solved, key=lambda c: abs(c.error_deg or 0.0)) if solved else None
    mus = [(c.transmission_deg, c.x) for c in solved if c.transmission_deg is not None]
    # the transmission's extremes between samples: the dense grid by the closed form
    mus += _dense_transmission(design, grid_xs, grid_errs) or []
    defects = judge(design, pts, curve, grid_xs, grid_errs, mus)
    first_real = (pts[0].alpha_deg + k.alpha_shift(), pts[0].phi_deg + k.phi_shift())
    mu_min = min(mus) if mus else None
    result = replace(
        base,
        linkage=k,
        grashof=grashof_of(k),
        branch=branch_label(k, *first_real),
        curve=tuple(curve),
        max_error_deg=abs(worst.error_deg) if worst and worst.error_deg is not None else None,
        at_x=worst.x if worst else None,
        max_error_y=abs(worst.error_y) if worst and worst.error_y is not None else None,
        extrema=tuple((x, _solved_error(curve, x, e)) for x, e in lobes),
        transmission=(mu_min[0], max(mus)[0]) if mus and mu_min else None,
        transmission_at_x=mu_min[1] if mu_min else None,
        defects=tuple(defects),
        notes=tuple(notes),
    )
    return result


def drawn_position(s: FunctionSynthesis) -> tuple[float, float] | None:
    """(alpha, phi) in the equation's convention of the reported linkage at precision
    point 1, phi as the linkage generates it there (the followed value of the report's
    curve, which a mechanism file of the linkage is drawn at): with more than three points
    the fit passes near the desired phi, not through it, and a drawing at the desired phi
    would be another linkage. None where the linkage has no position there."""
    if s.linkage is None or not s.precision_points:
        return None
    p = s.precision_points[0]
    c = next((c for c in s.curve if c.x == p.x), None)
    if c is None or c.phi_generated_deg is None:
        return None
    return p.alpha_deg, c.phi_generated_deg


def dense_curve(s: FunctionSynthesis, n: int = 401) -> list[CurvePoint]:
    """The structural error at ``n`` even steps of x (with the table's points, extrema and
    precision points), by the same solver as the table: for a plot."""
    req = s.request
    if req is None or s.linkage is None:
        return list(s.curve)
    design, _ = design_of(req, s.R, s.precision_points[0])
    if design is None:
        return list(s.curve)
    lo, hi = req.x_range
    xs = sorted({lo + (hi - lo) * i / (n - 1) for i in range(n)} | {c.x for c in s.curve})
    return structural_error(design, xs, s.precision_points[0])


def _solved_error(curve: Sequence[CurvePoint], x: float, fallback: float) -> float:
    for c in curve:
        if c.x == x and c.error_deg is not None:
            return c.error_deg
    return fallback


def _dense_transmission(
    design: Design, xs: Sequence[float], errs: Sequence[float]
) -> list[tuple[float, float]] | None:
    import numpy as np

    from .problems.freudenstein import branch_root_np

    k = design.linkage
    good = np.isfinite(np.asarray(errs))
    if not good.any():
        return None
    x = np.asarray(xs)[good]
    al = np.array([design.real_alpha(v) for v in x])
    ph = branch_root_np(al, *design.real_R, design.sign)
    fold = transmission_deg_np(k.a, k.c, k.d, al, ph)  # folded (closed_form.transmission)
    i, j = int(np.nanargmin(fold)), int(np.nanargmax(fold))
    return [(float(fold[i]), float(x[i])), (float(fold[j]), float(x[j]))]


def judge(
    design: Design,
    pts: Sequence[PrecisionPoint],
    curve: Sequence[CurvePoint],
    grid_xs: Sequence[float],
    grid_errs: Sequence[float],
    mus: Sequence[tuple[float, float]],
) -> list[Defect]:
    """The defects of a synthesised linkage, each named with what shows it; ``mus`` its
    transmission angles (folded, deg) with their x."""
    req, k = design.req, design.linkage
    out: list[Defect] = []
    kind = grashof_of(k)
    # branch: a precision point on the other assembly than the one followed from point 1,
    # reached or beyond a limit (the points are then on no one circuit: grashof too)
    first_label = branch_label(k, pts[0].alpha_deg + k.alpha_shift(), pts[0].phi_deg + k.phi_shift())
    off = [
        (j, p)
        for j, p in enumerate(pts)
        if off_branch(p.alpha_deg + k.alpha_shift(), p.phi_deg + k.phi_shift(), design.real_R, design.sign)
    ]
    if off:
        said = ", ".join(
            f"{j + 1} (x = {p.x:.6g}, "
            f"{branch_label(k, p.alpha_deg + k.alpha_shift(), p.phi_deg + k.phi_shift())})"
            for j, p in off
        )
        out.append(
            Defect(
                "branch",
                f"branch: precision point {said} is not on the {first_label} assembly "
                "through point 1: the linkage must be taken apart to reach every point",
            )
        )
    # grashof: the motion asked for against what this linkage's type allows
    gap = next((c for c in curve if c.phi_generated_deg is None), None)
    runs = _nan_runs(grid_xs, grid_errs)
    if runs:
        said = ", ".join(f"{a:.6g} to {b:.6g}" if a != b else f"{a:.6g}" for a, b in runs[:3])
        out.append(
            Defect(
                "grashof",
                f"grashof: this {kind} linkage cannot move its input through the "
                f"range: it cannot be assembled for x from {said} (alpha "
                f"{req.alpha(runs[0][0]):.6g} to {req.alpha(runs[0][1]):.6g} deg)",
            )
        )
    elif gap is not None:
        out.append(
            Defect(
                "grashof",
                f"grashof: this {kind} linkage cannot move its input through the "
                f"range on one branch: the branch through point 1 ends at a limit "
                f"position before x = {gap.x:.6g} (alpha = {req.alpha(gap.x):.6g} deg)",
            )
        )
    elif assembly_gap(design.real_R, design.real_alpha(req.x_range[0]), design.real_alpha(req.x_range[1])):
        out.append(
            Defect(
                "grashof",
                f"grashof: this {kind} linkage cannot move its input through the "
                "range: it cannot be assembled in a gap narrower than the "
                f"{GRID}-point grid's step",
            )
        )
    # order: the output turns back where the function does not
    if all(math.isfinite(e) for e in grid_errs):
        want = [req.phi(_value(req.f, x)) for x in grid_xs]
        gen = [w + e for w, e in zip(want, grid_errs)]
        turns_gen, turns_want = _turns(gen), _turns(want)
        if len(turns_gen) > len(turns_want):
            extra = _turns_diff(turns_gen, turns_want) or sorted(turns_gen)
            x_turn = grid_xs[extra[0]]
            out.append(
                Defect(
                    "order",
                    f"order: the output turns back at x = {x_turn:.6g} where the "
                    "function does not, so it passes the output positions out of "
                    "order",
                )
            )
    # transmission
    if mus:
        mu, x_mu = min(mus)
        if mu < req.min_transmission:
            out.append(
                Defect(
                    "transmission",
                    f"transmission: the transmission angle falls to "
                    f"{mu:.4g} deg (at x = {x_mu:.6g}), below "
                    f"{req.min_transmission:g} deg",
                )
            )
    return out


def _nan_runs(xs: Sequence[float], errs: Sequence[float]) -> list[tuple[float, float]]:
    """The runs of grid x where the linkage cannot be assembled (first and last x of each)."""
    runs: list[tuple[float, float]] = []
    start = None
    for i, e in enumerate(errs):
        if not math.isfinite(e):
            start = xs[i] if start is None else start
            last = xs[i]
        elif start is not None:
            runs.append((start, last))
            start = None
    if start is not None:
        runs.append((start, last))
    return runs


def _turns(values: Sequence[float]) -> set[int]:
    """Indices where a sampled curve changes direction (steps below rounding ignored)."""
    scale = max((abs(v) for v in values), default=1.0)
    floor = 1e-9 * max(scale, 1.0)
    out, last = set(), 0
    for i in range(1, len(values)):
        step = values[i] - values[i - 1]
        if abs(step) <= floor:
            continue
        s = 1 if step > 0 else -1
        if last and s != last:
            out.add(i - 1)
        last = s
    return out


def turns_np(values: Any) -> Any:
    """:func:`_turns` over the rows of an array: how many times each row changes direction."""
    import numpy as np

    scale = np.maximum(np.max(np.abs(values), axis=-1, keepdims=True), 1.0)
    step = np.diff(values, axis=-1)
    sign = np.where(np.abs(step) <= 1e-9 * scale, 0.0, np.sign(step))
    # carry the last non-zero direction over steps below rounding (as _turns skips them)
    idx = np.where(sign != 0.0, np.arange(sign.shape[-1]), 0)
    np.maximum.accumulate(idx, axis=-1, out=idx)
    carried = np.take_along_axis(sign, idx, axis=-1)
    moving = carried != 0.0
    changes = (carried[..., 1:] != carried[..., :-1]) & moving[..., 1:] & moving[..., :-1]
    return changes.sum(axis=-1)


def _turns_diff(gen: set[int], want: set[int], width: int = 3) -> list[int]:
    return sorted(i for i in gen if not any(abs(i - j) <= width for j in want))


# --- optimal spacing ---------------------------------------------------------------------------


def moves_through_range(s: FunctionSynthesis) -> bool:
    """Whether a synthesis has a linkage that moves its input through the whole range on
    the branch through point 1: neither no_linkage nor grashof (so its error curve exists
    everywhere; a branch, order or transmission defect is a quality of that curve)."""
    return s.linkage is not None and s.max_error_deg is not None and not {"no_linkage", "grashof"} & set(
        s.defect_names
    )


def _optimal(req: Request) -> FunctionSynthesis:
    """Optimal (equal-ripple) spacing by a Remez exchange, from Chebyshev's design: on a
    reference of four alternating extrema, Newton's method finds the constants R and a
    level E with error(x_k) = +-E alternately; the reference then moves to the new
    extrema, until they are equal. The precision points are the error's zeros between
    them, and the design is synthesised from those again (so every figure reported is
    the one rule's, from its precision points). It runs whenever Chebyshev's linkage moves
    through the range (:func:`moves_through_range`): the optimum's defects are reported as
    any design's, not a reason to keep Chebyshev's."""
    cheb = _synthesize(replace(req, spacing="chebyshev"), chebyshev_xs(3, *req.x_range))
    if not moves_through_range(cheb):
        names = ", ".join(n for n in cheb.defect_names if n in ("no_linkage", "grashof"))
        return replace(
            cheb,
            notes=(
                *cheb.notes,
                f"optimal spacing equalises the error over the range, and Chebyshev's design, "
                f"where it starts, has none there ({names}): kept Chebyshev's spacing",
            ),
        )
    xs = remez(req, cheb)
    best = _synthesize(replace(req, spacing="optimal"), xs) if xs is not None else None
    spread = _spread(best) if best is not None else None
    why = (
        "did not reach equal extrema"
        if best is None or spread is None or spread > EQUIOSCILLATION
        else f"gave a linkage that cannot move through the range ({', '.join(best.defect_names)})"
        if not moves_through_range(best)
        else "came out no better"
        if best.max_error_deg is None or cheb.max_error_deg is None or best.max_error_deg > cheb.max_error_deg
        else None
    )
    if why is not None or best is None:
        return replace(
            cheb,
            chebyshev_max_error_deg=cheb.max_error_deg,
            equioscillation=_spread(cheb),
            notes=(*cheb.notes, f"optimal spacing {why}: kept Chebyshev's spacing"),
        )
    return replace(best, chebyshev_max_error_deg=cheb.max_error_deg, equioscillation=spread)


def remez(req: Request, start: FunctionSynthesis) -> list[float] | None:
    """The three precision points of the equal-ripple design (None if the exchange fails)."""
    import numpy as np

    k0 = start.linkage
    pts, r, _ = precision_points(req, [p.x for p in start.precision_points])
    design, _ = design_of(req, r, pts[0])
    if design is None or k0 is None:
        return None
    sign = design.sign

    def design_at(rv: Sequence[float]) -> Design | None:
        k, _ = linkage_of(rv, req.ground)
        if k is None or (k.input_turned, k.output_turned) != (k0.input_turned, k0.output_turned):
            return None
        return Design(req, (float(rv[0]), float(rv[1]), float(rv[2])), k, k.coefficients, sign)

    def reference(d: Design) -> tuple[list[float], float] | None:
        lobes, _, errs = extrema(d, grid=801)
        if len(lobes) < 4 or any(not math.isfinite(e) for e in errs):
            return None
        sizes = [abs(e) for _, e in lobes]
        window = alternation_set(sizes)
        i = next(i for i in range(len(sizes) - 3) if sizes[i : i + 4] == window)
        ref = lobes[i : i + 4]
        return [x for x, _ in ref], (1.0 if ref[0][1] > 0 else -1.0)

    rv = np.array(r)
    for _ in range(30):
        ref = reference(design)
        if ref is None:
            return None
        xk, s0 = ref
        yk = [_value(req.f, x) for x in xk]
        signs = np.array([s0 * (-1.0) ** j for j in range(4)])
        errs = np.array([design.closed_error(x, y) for x, y in zip(xk, yk)])
        level = float(np.mean(np.abs(errs)))
        spread = (np.max(np.abs(errs)) - np.min(np.abs(errs))) / np.max(np.abs(errs))
        if spread < 1e-9:
            break
        unknowns = np.array([*rv, level])
        for _newton in range(20):
            d = design_at(unknowns[:3])
            if d is None:
                return None
            e = np.array([d.closed_error(x, y) for x, y in zip(xk, yk)])
            fval = e - signs * unknowns[3]
            if not np.all(np.isfinite(fval)):
                return None
            jac = np.empty((4, 4))
            for j in range(3):
                h = 1e-7 * max(abs(unknowns[j]), 1e-3)
                up = unknowns[:3].copy()
                up[j] += h
                dj = design_at(up)
                if dj is None:
                    return None
                jac[:, j] = (np.array([dj.closed_error(x, y) for x, y in zip(xk, yk)]) - e) / h
            jac[:, 3] = -signs
            try:
                step = np.linalg.solve(jac, -fval)
            except np.linalg.LinAlgError:
                return None
            unknowns = unknowns + step
            if np.max(np.abs(step[:3]) / np.maximum(np.abs(unknowns[:3]), 1e-12)) < 1e-13:
                break
        rv = unknowns[:3]
        nd = design_at(rv)
        if nd is None:
            return None
        design = nd
    # the precision points: a zero of the error between each neighbouring pair of the
    # reference (bisection on the closed form)
    ref = reference(design)
    if ref is None:
        return None
    xk, _ = ref
    zeros = []
    for x0, x1 in itertools.pairwise(xk):
        g = lambda t: design.closed_error(t, _value(req.f, t))  # noqa: E731
        a, b, ga = x0, x1, g(x0)
        if not (ga > 0.0) != (g(x1) > 0.0):
            return None
        for _ in range(200):
            m = 0.5 * (a + b)
            if m in (a, b):
                break
            gm = g(m)
            if (gm > 0.0) == (ga > 0.0):
                a, ga = m, gm
            else:
                b = m
        zeros.append(0.5 * (a + b))
    return zeros


def alternation_set(sizes: Sequence[float]) -> list[float]:
    """The four neighbouring lobes the exchange equalises: of every run of four, the one
    holding the largest lobe whose smallest member is largest (an error with extra zeros
    besides the precision points has more than four lobes)."""
    top = max(range(len(sizes)), key=lambda i: sizes[i])
    windows = [list(sizes[i : i + 4]) for i in range(len(sizes) - 3) if i <= top < i + 4]
    return max(windows, key=min)


def _spread(s: FunctionSynthesis) -> float | None:
    """(largest - smallest) / largest over the alternation set (:func:`alternation_set`); a
    curve with fewer than four lobes (a precision point off the followed branch is no zero
    of its error) lacks lobes of size 0, so its spread is 1. None without an error curve."""
    if s.max_error_deg is None:
        return None
    sizes = [abs(e) for _, e in s.extrema]
    window = alternation_set(sizes + [0.0] * (4 - len(sizes)))
    top = max(window)
    return (top - min(window)) / top if top > 0.0 else 0.0


def synthesize_function(
    f: str | Callable[[float], float],
    x_range: Any,
    alpha_range: Any,
    phi_range: Any,
    points: int = 3,
    spacing: str = "chebyshev",
    *,
    at: Sequence[float] | None = None,
    ground: float = 1.0,
    min_transmission: float = MIN_TRANSMISSION_DEG,
    samples: int = TABLE_POINTS,
) -> FunctionSynthesis:
    """A four-bar function generator for y = f(x) over ``x_range``, x mapped onto the input
    angle ``alpha_range`` and y onto the output angle ``phi_range`` (degrees, the student report's
    convention), by Freudenstein's equation at ``points`` precision points spaced by
    ``spacing`` (chebyshev, uniform or optimal) or placed ``at``; analysed over the range
    with the four-bar equation's solver. ``f``: an expression in x (as ``--function``) or a callable."""
    try:
        req = make_request(f, x_range, alpha_range, phi_range, points=points, spacing=spacing, at=at,
                           ground=ground, min_transmission=min_transmission, table_points=samples)
    except InputError as exc:  # the messages name the command's options: here the arguments
        raise InputError(API_NAMES.sub(lambda m: API_ARGUMENTS[m.group(0)], str(exc))) from None
    return synthesize(req)


API_ARGUMENTS = {"--x": "x_range", "--alpha": "alpha_range", "--phi": "phi_range", "--points": "points",
                 "--spacing": "spacing", "--at": "at", "--ground": "ground",
                 "--min-transmission": "min_transmission", "--samples": "samples", "--rows": "samples",
                 "--function": "f"}
API_NAMES = re.compile("|".join(sorted(map(re.escape, API_ARGUMENTS), key=len, reverse=True)) + r"(?![\w-])")


# --- the search: many candidates at a time ------------------------------------------------------

SEARCH_NAMES = ("alpha0", "alpha_span", "phi0", "phi_span")
"""The free choices a search varies (deg): each angle range's start and span."""
SEARCH_CHUNK = 200
"""Candidates per task: each holds a few arrays of GRID values per candidate."""


@dataclass(frozen=True)
class SearchJob:
    """What a search task needs (picklable: the function travels as its text)."""

    text: str
    x_range: tuple[float, float]
    alpha_range: tuple[float, float]
    phi_range: tuple[float, float]
    names: tuple[str, ...]
    points: int
    spacing: str
    at: tuple[float, ...] | None
    ground: float
    min_transmission: float


def search_request(job: SearchJob) -> Request:
    return make_request(
        job.text,
        job.x_range,
        job.alpha_range,
        job.phi_range,
        points=job.points,
        spacing=job.spacing,
        at=job.at,
        ground=job.ground,
        min_transmission=job.min_transmission,
    )


def evaluate_candidates(req: Request, a0: Any, da: Any, p0: Any, dp: Any, grid: int = GRID) -> dict[str, Any]:
    """Every candidate (alpha range A0..A0+dA, phi range P0..P0+dP) synthesised and judged
    at once: the numpy twins of :func:`_synthesize`'s rules on the dense grid (the closed
    form on the branch through point 1, no continuation), with the largest error refined
    by a parabola through its grid neighbours. Columns, one entry per candidate."""
    import numpy as np

    from .problems.freudenstein import branch_root_np, branch_sign_np

    a0, da, p0, dp = (np.asarray(v, float) for v in (a0, da, p0, dp))
    lo, hi = req.x_range
    y0, y1 = req.y_ends
    xs = np.array(precision_xs(req))
    ys = np.array([_value(req.f, x) for x in xs])
    t = (xs - lo) / (hi - lo)
    u = (ys - y0) / (y1 - y0)
    alphas = a0[:, None] + t[None, :] * da[:, None]
    phis = p0[:, None] + u[None, :] * dp[:, None]
    if len(xs) == 3:
        r = solve_coefficients_np(alphas, phis)
    else:
        r = np.array([solve_coefficients(list(al), list(ph))[0] for al, ph in zip(alphas, phis)])
    a, b, c, d, turned_in, turned_out = linkage_of_np(r, req.ground)
    real = np.stack(real_coefficients(a, b, c, d), axis=-1)
    shift_a, shift_p = np.where(turned_in, 180.0, 0.0), np.where(turned_out, 180.0, 0.0)
    sign = branch_sign_np(alphas[:, 0] + shift_a, phis[:, 0] + shift_p, real[:, 0], real[:, 1], real[:, 2])
    gx = np.linspace(lo, hi, grid)
    gy = np.array([_value(req.f, x) for x in gx])
    gt, gu = (gx - lo) / (hi - lo), (gy - y0) / (y1 - y0)
    def generated(tt: Any) -> Any:
        al = a0[:, None] + tt[None, :] * da[:, None] + shift_a[:, None]
        return al, branch_root_np(al, real[:, 0:1], real[:, 1:2], real[:, 2:3], sign[:, None]) - shift_p[
            :, None
        ]

    al_g, phi_g = generated(gt)
    want = p0[:, None] + gu[None, :] * dp[:, None]
    err = np.remainder(phi_g - want + 180.0, 360.0) - 180.0
    linkage_ok = np.isfinite(a)
    lo_real, hi_real = a0 + shift_a, a0 + da + shift_a
    assembles = (
        linkage_ok
        & np.all(np.isfinite(err), axis=-1)
        & ~assembly_gap_np(real[:, 0], real[:, 1], real[:, 2], lo_real, hi_real)
    )
    # branch: a precision point on the other assembly (the one rule, off_branch)
    branch = linkage_ok & np.any(
        off_branch_np(
            alphas + shift_a[:, None],
            phis + shift_p[:, None],
            real[:, 0:1],
            real[:, 1:2],
            real[:, 2:3],
            sign[:, None],
        ),
        axis=-1,
    )
    mag = np.where(np.isfinite(err), np.abs(err), -1.0)
    k = np.argmax(mag, axis=-1)
    rows = np.arange(len(a0))
    best = mag[rows, k]
    # parabola through the grid neighbours of an interior maximum
    inner = (k > 0) & (k < grid - 1)
    km, kp = np.clip(k - 1, 0, grid - 1), np.clip(k + 1, 0, grid - 1)
    fm, f0, fp = mag[rows, km], best, mag[rows, kp]
    curv = fm - 2.0 * f0 + fp
    with np.errstate(invalid="ignore", divide="ignore"):
        offset = np.where(inner & (curv < 0.0), 0.5 * (fm - fp) / curv, 0.0)
    offset = np.clip(offset, -0.5, 0.5)
    peak = f0 - 0.25 * (fm - fp) * offset
    h = (hi - lo) / (grid - 1)
    at_x = gx[k] + offset * h
    max_err = np.where(assembles, peak, np.nan)
    fold = transmission_deg_np(a[:, None], c[:, None], d[:, None], al_g, phi_g + shift_p[:, None])
    lowest = np.min(np.where(np.isfinite(fold), fold, np.inf), axis=-1)
    min_mu = np.where(linkage_ok & np.isfinite(lowest), lowest, np.nan)
    with np.errstate(invalid="ignore"):
        # the generated output unwrapped as the scalar rule reads it: desired + error
        gen = want + np.where(np.isfinite(err), err, 0.0)
        order = assembles & (turns_np(gen) > turns_np(want))
        low_mu = linkage_ok & (min_mu < req.min_transmission)
    from .problems.closed_form import grashof_np

    kinds = np.where(
        linkage_ok,
        grashof_np(
            np.where(linkage_ok, d, 1.0),
            np.where(linkage_ok, a, 1.0),
            np.where(linkage_ok, b, 1.0),
            np.where(linkage_ok, c, 1.0),
        ),
        "",
    )
    names = [
        ("no_linkage", ~linkage_ok),
        ("branch", branch),
        ("grashof", linkage_ok & ~assembles),
        ("order", order),
        ("transmission", low_mu),
    ]
    defects = np.array([" ".join(n for n, m in names if m[i]) for i in range(len(a0))], dtype=object)
    return {
        "R1": r[:, 0],
        "R2": r[:, 1],
        "R3": r[:, 2],
        "input": a,
        "coupler": b,
        "output": c,
        "ground": np.where(linkage_ok, d, np.nan),
        "grashof": kinds.astype(object),
        "max_error_deg": max_err,
        "at_x": np.where(assembles, at_x, np.nan),
        "max_error_y": max_err * abs(req.y_per_deg),
        "min_transmission_deg": min_mu,
        "defects": defects,
        "ok": defects == "",
    }


def search_chunk(job: SearchJob, start: int, designs: Any) -> dict[str, Any]:
    """One task of a search: the candidates ``start, start + 1, ...`` as columns."""
    import numpy as np

    req = search_request(job)
    given = {
        "alpha0": job.alpha_range[0],
        "alpha_span": job.alpha_range[1] - job.alpha_range[0],
        "phi0": job.phi_range[0],
        "phi_span": job.phi_range[1] - job.phi_range[0],
    }
    n = designs.shape[0]
    cols = {
        name: (designs[:, job.names.index(name)] if name in job.names else np.full(n, given[name]))
        for name in SEARCH_NAMES
    }
    out = {"design": np.arange(start, start + n)}
    out.update(cols)
    out.update(evaluate_candidates(req, cols["alpha0"], cols["alpha_span"], cols["phi0"], cols["phi_span"]))
    return out


@dataclass(frozen=True)
class SearchResult:
    rows: dict[str, Any]
    """The kept candidates (no defects), best first: columns."""
    scanned: int
    without_defects: int
    job: SearchJob


def search(
    f: str,
    x_range: Any,
    alpha_range: Any,
    phi_range: Any,
    vary: Sequence[str],
    *,
    points: int = 3,
    spacing: str = "chebyshev",
    at: Sequence[float] | str | None = None,
    ground: float = 1.0,
    min_transmission: float = MIN_TRANSMISSION_DEG,
    samples: int | None = None,
    seed: int = 0,
    sampling: str = "lhs",
    top: int = 10,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: Callable[[int], None] | None = None,
) -> SearchResult:
    """Synthesise every candidate of a grid (or ``samples`` random draws) over the free
    choices (``vary``: alpha0, alpha_span, phi0, phi_span as NAME=LO:HI[:N], degrees),
    keep those without defects, best (smallest max structural error) first: on the scan's
    chunked runner, so ``scheduler`` may be a dask cluster's address. ``alpha_range`` and
    ``phi_range`` give what is not varied (None where both of its names are)."""
    from .scan import MAX_DESIGNS, DesignPlan, Keeper, concat, parse_vary, run_chunks, take

    if not isinstance(f, str):
        raise InputError("a search takes the function as text (it travels to the workers)")
    if spacing == "optimal":
        raise InputError(
            "--search keeps the spacing fixed (chebyshev, uniform or --at): optimal "
            "spacing is for one design; run it on the best candidate"
        )
    varies = [parse_vary(v) for v in vary]
    if not varies:
        raise InputError(
            "--search: give at least one --vary NAME=LO:HI[:N] (alpha0, alpha_span, phi0, phi_span)"
        )
    seen: set[str] = set()
    for v in varies:
        if v.name not in SEARCH_NAMES:
            raise InputError(f"--vary {v.name}: a search varies {', '.join(SEARCH_NAMES)} (degrees)")
        if v.name in seen:
            raise InputError(f"--vary {v.name} is given twice")
        seen.add(v.name)
        if v.name.endswith("_span") and (v.lo <= 0.0 <= v.hi or max(abs(v.lo), abs(v.hi)) >= 360.0):
            raise InputError(
                f"--vary {v.name}={v.lo:g}:{v.hi:g}: a span must stay on one side of 0 and within +-360 deg"
            )
        if max(abs(v.lo), abs(v.hi)) > 1e6:
            raise InputError(f"--vary {v.name}: bounds beyond 1e6 deg are not supported")
    if isinstance(top, bool) or not isinstance(top, int) or not 1 <= top <= 100_000:
        raise InputError(f"--top must be a whole number from 1 to 100000, got {top!r}")

    def base(name: str, given: Any) -> tuple[float, float]:
        if given is not None:
            return _range(f"--{name}", given)
        start = next((v for v in varies if v.name == f"{name}0"), None)
        span = next((v for v in varies if v.name == f"{name}_span"), None)
        if start is None or span is None:
            raise InputError(f"--{name}: give the range, or vary both {name}0 and {name}_span")
        return start.lo, start.lo + span.lo

    ar, pr = base("alpha", alpha_range), base("phi", phi_range)
    req = make_request(
        f,
        x_range,
        ar,
        pr,
        points=points,
        spacing=spacing,
        at=at,
        ground=ground,
        min_transmission=min_transmission,
    )
    plan = DesignPlan(varies, samples, seed, sampling)
    if plan.total > MAX_DESIGNS:
        raise InputError(f"{plan.total:,} candidates: at most {MAX_DESIGNS:,}")
    job = SearchJob(
        req.text,
        req.x_range,
        req.alpha_range,
        req.phi_range,
        plan.names,
        req.points,
        req.spacing,
        req.at,
        req.ground,
        req.min_transmission,
    )
    keeper = Keeper("max_error_deg", False, top, None)
    scanned = good = 0
    for cols in run_chunks(job, plan, SEARCH_CHUNK, scheduler=scheduler, workers=workers, task=search_chunk):
        scanned += len(cols["design"])
        import numpy as np

        ok = np.flatnonzero(cols["ok"])
        good += len(ok)
        if len(ok):
            keeper.add(take(cols, ok))
        if progress is not None:
            progress(scanned)
    rows = keeper.result() or concat([])
    return SearchResult(rows, scanned, good, job)
