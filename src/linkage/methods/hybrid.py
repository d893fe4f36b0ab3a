"""Safeguarded bracketing hybrid (Brent's method): interpolate when it helps, bisect when not.

Each step tries inverse quadratic interpolation through the last three points (or a
secant step when only two differ) and accepts it only if it is shorter than half the
step before last and lands well inside the bracket; otherwise it bisects. Steps
shorter than the tolerance are lengthened to it, so the bracket also shrinks from
the far side. The new point always lies inside the current bracket [x, x_block].
Order about 1.84 on smooth simple roots, never worse than about twice bisection's
count (R. P. Brent, Algorithms for Minimization without Derivatives, 1973, ch. 4;
the loop follows the layout of scipy's brentq). One evaluation per step, two to start.
Error measure: the bracket width |x_block - x|, which bounds |x - r|.
At the ends of the double range: a bracket wider than the largest double is halved in
halves (x_block/2 - x/2) and bisected, and an interpolation that overflowed (inf or NaN)
is recomputed on scaled values (:func:`scaled_interpolation`), so [-1e308, 1e308] is
solved (tests/test_extreme_brackets.py).
"""

from __future__ import annotations

import math
import sys
from typing import Any, ClassVar

from ..problems.scalar import ScalarProblem
from ..records import NamedTuple, frozen
from ..result import Column, Status
from .bisection import init_bracket
from .common import new_state

_EPS = sys.float_info.epsilon


class HybridState(NamedTuple):
    x: float
    fx: float | None
    err: float
    stop: tuple[Status, str] | None
    xpre: float
    fpre: float
    xblk: float
    fblk: float
    spre: float
    scur: float
    kind: str


def _settle(xpre: float, fpre: float, xcur: float, fcur: float, xblk: float, fblk: float,
            spre: float, scur: float) -> tuple[float, float, float, float, float, float, float, float]:
    """Re-establish the invariants: [xcur, xblk] brackets the root, |f(xcur)| is smallest."""
    if fpre != 0.0 and fcur != 0.0 and (fpre < 0.0) != (fcur < 0.0):
        xblk, fblk = xpre, fpre
        spre = scur = xcur - xpre
    if abs(fblk) < abs(fcur):
        xpre, xcur, xblk = xcur, xblk, xcur
        fpre, fcur, fblk = fcur, fblk, fcur
    return xpre, fpre, xcur, fcur, xblk, fblk, spre, scur


def scaled_interpolation(xcur: float, fcur: float, xpre: float, fpre: float, xblk: float,
                         fblk: float) -> float:
    """The hybrid's interpolation step where the ordinary formula overflowed (f values or
    their products beyond the largest double): the same formula on f scaled by a power of
    two to a largest |f| in [0.5, 1), and on the x differences scaled to a largest one in
    [0.5, 1), unscaled at the end. The step is homogeneous of degree 0 in f and 1 in x, and
    scaling by a power of two is exact, so this is the ordinary formula's value wherever
    neither computation leaves the range of normal doubles (an overflow left is inf or NaN,
    which the safeguard rejects: the step bisects)."""
    ef = math.frexp(max(abs(fcur), abs(fpre), abs(fblk)))[1]
    dxp, dxb = xpre - xcur, xblk - xcur
    ex = math.frexp(max(abs(dxp), abs(dxb)))[1]
    ldexp = math.ldexp
    fcur, fpre, fblk = ldexp(fcur, -ef), ldexp(fpre, -ef), ldexp(fblk, -ef)
    dxp, dxb = ldexp(dxp, -ex), ldexp(dxb, -ex)
    try:
        if xpre == xblk:
            step = fcur * dxp / (fcur - fpre)
        else:
            dpre = (fpre - fcur) / dxp
            dblk = (fblk - fcur) / dxb
            step = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
        return ldexp(step, ex)
    except (ZeroDivisionError, OverflowError):
        return math.inf


@frozen
class Hybrid:
    """``tol``/``rtol``: the shortest step taken, which should match the stopping test."""

    tol: float = 1e-6
    rtol: float = 0.0

    name: ClassVar[str] = "hybrid"
    bracketing: ClassVar[bool] = True
    can_diverge: ClassVar[bool] = False
    needs_residual: ClassVar[bool] = False
    first_index: ClassVar[int] = 1
    init_evals: ClassVar[int] = 2
    step_evals: ClassVar[int] = 1

    def columns(self, problem: ScalarProblem) -> tuple[Column, ...]:
        return (
            Column("i", "index"),
            Column("step", "text"),
            Column("a", "x"),
            Column("b", "x"),
            Column("{v} (best)", "x"),
            Column("f({v})", "f"),
            Column("width", "x"),
        )

    def init(self, problem: ScalarProblem, a: float, b: float) -> HybridState:
        fa, fb, stop = init_bracket(problem, a, b)
        if stop is not None:
            x, fx = (a, fa) if fa == 0.0 else (b, fb)
            return HybridState(x, fx, abs(b - a), stop, a, fa, b, fb, 0.0, 0.0, "start")
        xpre, fpre, xcur, fcur, xblk, fblk, spre, scur = _settle(a, fa, b, fb, 0.0, 0.0, 0.0, 0.0)
        return HybridState(xcur, fcur, abs(xblk - xcur), None, xpre, fpre, xblk, fblk, spre, scur, "start")

    def step(self, problem: ScalarProblem, s: HybridState) -> HybridState:
        xcur, fcur, xpre, fpre, xblk, fblk, spre, scur = (
            s.x, s.fx, s.xpre, s.fpre, s.xblk, s.fblk, s.spre, s.scur)
        delta = 0.5 * (self.tol + self.rtol * abs(xcur)) + _EPS * abs(xcur)
        sbis = 0.5 * (xblk - xcur)
        if sbis - sbis != 0.0:  # a bracket wider than the largest double: halve it in halves,
            sbis = 0.5 * xblk - 0.5 * xcur
            spre = 0.0  # and bisect
        kind = "bisection"
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            try:
                if xpre == xblk:
                    stry = -fcur * (xcur - xpre) / (fcur - fpre)
                    trial = "secant"
                else:
                    dpre = (fpre - fcur) / (xpre - xcur)
                    dblk = (fblk - fcur) / (xblk - xcur)
                    stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
                    trial = "inverse quadratic"
                if stry - stry != 0.0:  # inf or NaN: a product or difference of f values overflowed
                    stry = scaled_interpolation(xcur, fcur, xpre, fpre, xblk, fblk)
            except ZeroDivisionError:
                # Products of tiny f values underflow to 0 (x^9 near its root): bisect.
                stry, trial = math.inf, "bisection"
            if 2.0 * abs(stry) < min(abs(spre), 3.0 * abs(sbis) - delta):
                spre, scur = scur, stry
                kind = trial
            else:
                spre = scur = sbis
        else:
            spre = scur = sbis
        xpre, fpre = xcur, fcur
        if abs(scur) > delta:
            xcur = xcur + scur
        elif abs(sbis) > delta:
            xcur = xcur + math.copysign(delta, sbis)
        else:
            # The bracket is at the rounding level of x: halve it and let the loop judge.
            xcur = xcur + sbis
            kind = "bisection"
        fcur = problem.f(xcur)
        xpre, fpre, xcur, fcur, xblk, fblk, spre, scur = _settle(
            xpre, fpre, xcur, fcur, xblk, fblk, spre, scur)
        return new_state(HybridState, (
            xcur, fcur, abs(xblk - xcur), None, xpre, fpre, xblk, fblk, spre, scur, kind))

    def initial_row(self, problem: ScalarProblem, s: HybridState) -> None:
        return None

    def row(self, problem: ScalarProblem, s: HybridState, i: int) -> tuple[Any, ...]:
        lo, hi = (s.x, s.xblk) if s.x <= s.xblk else (s.xblk, s.x)
        return (i, s.kind, lo, hi, s.x, s.fx, s.err)
