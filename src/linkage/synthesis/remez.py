"""Optimal (equal-ripple) spacing of three precision points by a Remez exchange from
Chebyshev's design (docs/synthesis.md, "Optimal spacing")."""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any

from .error_curve import Design, design_of, extrema
from .function import FunctionSynthesis, precision_points, synthesize_at
from .request import EQUIOSCILLATION, Request, value_of
from .solve import chebyshev_xs, linkage_of


def moves_through_range(s: FunctionSynthesis) -> bool:
    """Whether a synthesis has a linkage that moves its input through the whole range on
    the branch through point 1: neither no_linkage nor grashof (so its error curve exists
    everywhere; a branch, order or transmission defect is a quality of that curve)."""
    return s.linkage is not None and s.max_error_deg is not None and not {"no_linkage", "grashof"} & set(
        s.defect_names
    )


def optimal(req: Request) -> FunctionSynthesis:
    """Optimal (equal-ripple) spacing by a Remez exchange, from Chebyshev's design: on a
    reference of four alternating extrema, Newton's method finds the constants R and a
    level E with error(x_k) = +-E alternately; the reference then moves to the new
    extrema, until they are equal. The precision points are the error's zeros between
    them, and the design is synthesised from those again (so every figure reported is
    the one rule's, from its precision points). It runs whenever Chebyshev's linkage moves
    through the range (:func:`moves_through_range`): the optimum's defects are reported as
    any design's, not a reason to keep Chebyshev's."""
    cheb = synthesize_at(replace(req, spacing="chebyshev"), chebyshev_xs(3, *req.x_range))
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
    best = synthesize_at(replace(req, spacing="optimal"), xs) if xs is not None else None
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
    sign, turned = design.sign, (k0.input_turned, k0.output_turned)

    def design_at(rv: Sequence[float]) -> Design | None:
        k, _ = linkage_of(rv, req.ground)
        if k is None or (k.input_turned, k.output_turned) != turned:
            return None
        return Design(req, (float(rv[0]), float(rv[1]), float(rv[2])), k, k.coefficients, sign)

    rv = np.array(r)
    for _ in range(30):
        ref = reference(design)
        if ref is None:
            return None
        xk, s0 = ref
        yk = [value_of(req.f, x) for x in xk]
        signs = np.array([s0 * (-1.0) ** j for j in range(4)])
        errs = np.abs([design.closed_error(x, y) for x, y in zip(xk, yk)])
        if (np.max(errs) - np.min(errs)) / np.max(errs) < 1e-9:
            break
        solved = equal_ripple(design_at, xk, yk, signs, np.array([*rv, float(np.mean(errs))]))
        nd = None if solved is None else design_at(solved[:3])
        if nd is None:
            return None
        rv, design = solved[:3], nd
    ref = reference(design)
    return None if ref is None else error_zeros(design, ref[0])


def reference(d: Design) -> tuple[list[float], float] | None:
    """The exchange's reference: the x of the four alternating extrema it equalises
    (:func:`alternation_set`) and the sign of the first; None without four lobes."""
    lobes, _, errs = extrema(d, grid=801)
    if len(lobes) < 4 or any(not math.isfinite(e) for e in errs):
        return None
    sizes = [abs(e) for _, e in lobes]
    window = alternation_set(sizes)
    i = next(i for i in range(len(sizes) - 3) if sizes[i : i + 4] == window)
    ref = lobes[i : i + 4]
    return [x for x, _ in ref], (1.0 if ref[0][1] > 0 else -1.0)


def equal_ripple(
    design_at: Callable[[Sequence[float]], Design | None],
    xk: Sequence[float],
    yk: Sequence[float],
    signs: Any,
    unknowns: Any,
) -> Any | None:
    """Newton's method (forward-difference Jacobian) on error(x_k) = +-E alternately for
    (R1, R2, R3, E) from ``unknowns``; None where a step leaves the linkage's kind."""
    import numpy as np

    def errors(d: Design) -> Any:
        return np.array([d.closed_error(x, y) for x, y in zip(xk, yk)])

    for _newton in range(20):
        d = design_at(unknowns[:3])
        if d is None:
            return None
        e = errors(d)
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
            jac[:, j] = (errors(dj) - e) / h
        jac[:, 3] = -signs
        try:
            step = np.linalg.solve(jac, -fval)
        except np.linalg.LinAlgError:
            return None
        unknowns = unknowns + step
        if np.max(np.abs(step[:3]) / np.maximum(np.abs(unknowns[:3]), 1e-12)) < 1e-13:
            break
    return unknowns


def error_zeros(design: Design, xk: Sequence[float]) -> list[float] | None:
    """The precision points: a zero of the error between each neighbouring pair of the
    reference (bisection on the closed form); None where a pair does not change sign."""
    req = design.req
    zeros = []
    for x0, x1 in itertools.pairwise(xk):
        g = lambda t: design.closed_error(t, value_of(req.f, t))  # noqa: E731
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
