"""One function generator synthesised at given precision points and analysed over its
range: the report's value (docs/synthesis.md)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import field, replace

from ..records import frozen
from ..units import radians
from .defects import Defect, judge
from .error_curve import CurvePoint, dense_transmission, design_of, extrema, structural_error
from .request import MIN_TRANSMISSION_DEG, PrecisionPoint, Request, value_of
from .solve import Linkage, branch_label, grashof_of, solve_coefficients


@frozen
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


def precision_points(
    req: Request, xs: Sequence[float]
) -> tuple[list[PrecisionPoint], tuple[float, float, float], float]:
    ys = [value_of(req.f, x) for x in xs]
    als = [req.alpha(x) for x in xs]
    phs = [req.phi(y) for y in ys]
    r, res = solve_coefficients(als, phs)
    pts = []
    for x, y, al, ph in zip(xs, ys, als, phs):
        a, p = radians(al), radians(ph)
        pts.append(
            PrecisionPoint(x, y, al, ph, r[0] * math.cos(a) - r[1] * math.cos(p) + r[2] - math.cos(a - p))
        )
    return pts, r, res



def synthesize_at(req: Request, xs: Sequence[float]) -> FunctionSynthesis:
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
    mus += dense_transmission(design, grid_xs, grid_errs) or []
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
