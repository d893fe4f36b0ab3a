"""Secant method: x_{i+1} = x_i - f(x_i) (x_i - x_{i-1}) / (f(x_i) - f(x_{i-1})).

Order (1 + sqrt 5) / 2 = 1.618 near a simple root:
e_{i+1} ~ |f''(r) / (2 f'(r))|^0.618 e_i^1.618 (the student report's secant convergence analysis,
docs/worked_examples.md P2).
One evaluation per step, two to start; no derivative needed. Fails where the slope
is zero (f(x_i) = f(x_{i-1})) and, like Newton, may wander to another root or diverge.
Rows follow the student report (docs/worked_examples.md P2): row 0 is the first point; then i, x_i,
f(x_i), the slope,
x_{i+1}, |x_{i+1} - x_i|.
"""

from __future__ import annotations

from typing import Any, ClassVar

from ..iterate import Loop, build_loop
from ..problems.scalar import ScalarProblem
from ..records import NamedTuple, frozen
from ..result import Column, Status
from .common import new_state

_NAN = float("nan")


class SecantState(NamedTuple):
    x: float
    fx: float
    err: float
    stop: tuple[Status, str] | None
    xp: float
    fxp: float
    slope: float
    slope_before: float


def chord_slope(x: float, fx: float, xp: float, fxp: float) -> float:
    """The secant's slope where (f(x) - f(x_p)) / (x - x_p) came out inf, NaN or 0: the same
    quotient of halves, (f(x)/2 - f(x_p)/2) / (x/2 - x_p/2). Halving is exact, so this is
    the ordinary quotient wherever no difference overflowed (a flat chord, f(x) = f(x_p),
    is still 0, an underflowed quotient still 0); where one did (points or values of
    opposite signs near the largest double: inf/inf is NaN, a finite difference over an
    infinite one 0, a false "zero slope") it is the chord's slope, finite."""
    return (0.5 * fx - 0.5 * fxp) / (0.5 * x - 0.5 * xp)


@frozen
class Secant:
    name: ClassVar[str] = "secant"
    bracketing: ClassVar[bool] = False
    can_diverge: ClassVar[bool] = True
    needs_residual: ClassVar[bool] = False
    first_index: ClassVar[int] = 1
    init_evals: ClassVar[int] = 2
    step_evals: ClassVar[int] = 1

    def columns(self, problem: ScalarProblem) -> tuple[Column, ...]:
        return (
            Column("i", "index"),
            Column("{v}_i", "x"),
            Column("f({v}_i)", "f"),
            Column("slope", "df"),
            Column("{v}_i+1", "x"),
            Column("error", "x"),
        )

    def init(self, problem: ScalarProblem, x0: float, x1: float) -> SecantState:
        f0 = problem.f(x0)
        f1 = problem.f(x1)
        v = problem.var
        stop = None
        x, fx = x1, f1
        if f1 == 0.0:
            stop = (Status.CONVERGED_EXACT, f"f is zero at the start {v} = {x1!r}")
        elif f0 == 0.0:
            x, fx = x0, f0
            stop = (Status.CONVERGED_EXACT, f"f is zero at the start {v} = {x0!r}")
        elif any(f != f or abs(f) == float("inf") for f in (f0, f1)):
            stop = (Status.NON_FINITE, f"f({v}={x0:g}) = {f0!r}, f({v}={x1:g}) = {f1!r}")
        return SecantState(x, fx, float("inf"), stop, x0, f0, _NAN, _NAN)

    def step(self, problem: ScalarProblem, s: SecantState) -> SecantState:
        x, fx = s.x, s.fx
        if x == s.xp:
            return new_state(SecantState, (
                x, fx, _NAN,
                (Status.PRECISION_LIMIT, f"the last two points are equal in double precision "
                                         f"({problem.var} = {x!r}): no chord to follow"),
                x, fx, _NAN, s.slope))
        slope = (fx - s.fxp) / (x - s.xp)
        if slope - slope != 0.0 or slope == 0.0:  # an overflow on the way, or a flat chord: see chord_slope
            slope = chord_slope(x, fx, s.xp, s.fxp)
        if slope == 0.0:
            return new_state(SecantState, (
                x, fx, _NAN,
                (Status.ZERO_DERIVATIVE, f"the secant slope is zero at {problem.var} = {x!r}"),
                x, fx, slope, s.slope))
        x1 = x - fx / slope
        return new_state(SecantState, (x1, problem.f(x1), abs(x1 - x), None, x, fx, slope, s.slope))

    @staticmethod
    def plausible(s: SecantState) -> bool:
        """A small step means convergence only once the chord is local: from the second
        iteration on, with the last two slopes within a factor of 2 (far-apart points
        give a chord unrelated to f' at the root, and a meaningless tiny step)."""
        ratio = s.slope / s.slope_before if s.slope_before else _NAN
        return 0.5 <= ratio <= 2.0

    def run_lean(self, problem: ScalarProblem, s: SecantState, crit: Any,
                 certify: Any) -> tuple[SecantState, Status, str, int]:
        """The secant method with recording off: :data:`SECANT_LOOP`, the generic loop's
        outcome without a state per step (tests/test_compile.py, tests/test_kernel.py)."""
        return secant_lean(problem, s.x, s.fx, s.xp, s.fxp, s.slope, s.slope_before, s.err, crit.tol,
                           crit.rtol, crit.ftol, crit.max_iter, certify)

    def initial_row(self, problem: ScalarProblem, s: SecantState) -> tuple[Any, ...]:
        return (0, s.xp, s.fxp, None, None, None)

    def row(self, problem: ScalarProblem, s: SecantState, i: int) -> tuple[Any, ...]:
        if s.stop is not None:
            return (i, s.xp, s.fxp, s.slope, None, None)
        return (i, s.xp, s.fxp, s.slope, s.x, s.err)


SECANT_LOOP = Loop(
    signature="secant_lean(problem, x, fx, xp, fxp, slope, slope_before, err, tol, rtol, ftol, max_iter, "
              "certify)",
    setup="""\
        f = problem.f
        v = problem.var
        seen = [abs(t) for t in (fx, fxp) if isinstance(t, float) and t == t]
        best = min(seen) if seen else _inf
        start = max(seen) if seen else _inf
        """,
    step="""\
        if x == xp:
            xp, fxp, err, slope_before, slope = x, fx, _nan, slope, _nan
            status = _S.PRECISION_LIMIT
            detail = f"the last two points are equal in double precision ({v} = {x!r}): no chord to follow"
            break
        new_slope = (fx - fxp) / (x - xp)
        if new_slope - new_slope != 0.0 or new_slope == 0.0:
            new_slope = _chord_slope(x, fx, xp, fxp)
        if new_slope == 0.0:
            xp, fxp, err, slope_before, slope = x, fx, _nan, slope, new_slope
            status, detail = _S.ZERO_DERIVATIVE, f"the secant slope is zero at {v} = {x!r}"
            break
        x1 = x - fx / new_slope
        fx1 = f(x1)
        """,
    after="""\
        err = abs(x1 - x)
        xp, fxp, x, fx = x, fx, x1, fx1
        slope_before, slope = slope, new_slope
        """,
    result="_State(x, fx, err, None, xp, fxp, slope, slope_before), status, detail, k",
    plausible="0.5 <= (slope / slope_before if slope_before else _nan) <= 2.0",  # Secant.plausible
    guard=True, step_test="certify", diverge="streak")
"""The secant method's loop: the stopping rule of :mod:`linkage.iterate` around its step."""

secant_lean = build_loop(SECANT_LOOP, {"_State": SecantState, "_chord_slope": chord_slope}, fixed_source=True)
