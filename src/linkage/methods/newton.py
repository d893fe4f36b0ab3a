"""Newton's method: x_{i+1} = x_i - f(x_i) / f'(x_i).

Order 2 near a simple root: e_{i+1} ~ (f''(r) / (2 f'(r))) e_i^2 (the student report, Newton
convergence analysis; the textbook section 3.9, eq. 4). Two evaluations per step (f and
f'), one more to start. Fails at f'(x) = 0 (stalls), near a local extremum (huge
jumps, P1 with x0 = 2.5), at inflection points (may cycle: x^3 - 2x + 2 from 0) and
where f flattens toward infinity (atan(x) from 1.5 diverges); multiple roots reduce
it to linear convergence. Which root it finds depends on x0 (P1).
Rows follow the student report (docs/worked_examples.md P2): i, x_i, f(x_i), f'(x_i), x_{i+1}, |x_{i+1}
- x_i|.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar, NamedTuple

from ..iterate import DIVERGE_STREAK, ROUNDING, explain, judge_certificate, rounding_stall
from ..problems.scalar import ScalarProblem
from ..result import Column, Status
from ..rules import step_limit, worse_than_seen
from ._common import new_state


class NewtonState(NamedTuple):
    x: float
    fx: float
    err: float
    stop: tuple[Status, str] | None
    xp: float
    fxp: float
    dfxp: float


@dataclass(frozen=True)
class Newton:
    name: ClassVar[str] = "newton"
    bracketing: ClassVar[bool] = False
    can_diverge: ClassVar[bool] = True
    needs_residual: ClassVar[bool] = False
    first_index: ClassVar[int] = 1
    init_evals: ClassVar[int] = 1
    step_evals: ClassVar[int] = 2

    def columns(self, problem: ScalarProblem) -> tuple[Column, ...]:
        return (
            Column("i", "index"),
            Column("{v}_i", "x"),
            Column("f({v}_i)", "f"),
            Column("f'({v}_i)", "df"),
            Column("{v}_i+1", "x"),
            Column("error", "x"),
        )

    def init(self, problem: ScalarProblem, x0: float) -> NewtonState:
        fx = problem.f(x0)
        stop = None
        if fx == 0.0:
            stop = (Status.CONVERGED_EXACT, f"f is zero at the start {problem.var} = {x0!r}")
        elif fx != fx or abs(fx) == float("inf"):
            stop = (Status.NON_FINITE, f"f({problem.var}={x0:g}) = {fx!r}")
        return NewtonState(x0, fx, float("inf"), stop, x0, fx, float("nan"))

    def step(self, problem: ScalarProblem, s: NewtonState) -> NewtonState:
        x = s.x
        fx = s.fx
        d = problem.fprime(x)  # type: ignore[misc]
        if d == 0.0:
            return new_state(NewtonState, (
                x, fx, float("nan"),
                (Status.ZERO_DERIVATIVE, f"f'({problem.var}) = 0 at {problem.var} = {x!r}, f = {fx:.6g}"),
                x, fx, d))
        x1 = x - fx / d
        return new_state(NewtonState, (x1, problem.f(x1), abs(x1 - x), None, x, fx, d))

    def initial_row(self, problem: ScalarProblem, s: NewtonState) -> None:
        return None

    def row(self, problem: ScalarProblem, s: NewtonState, i: int) -> tuple[Any, ...]:
        if s.stop is not None:
            return (i, s.xp, s.fxp, s.dfxp, None, None)
        return (i, s.xp, s.fxp, s.dfxp, s.x, s.err)


def newton_lean(problem: ScalarProblem, x0: float, tol: float, rtol: float, ftol: float | None,
                max_iter: int, certify: Any,
                rows: Any = None) -> tuple[float, float, float, Status, str, int]:
    """Newton as one tight loop: the generic loop's stopping rules for this method
    (:mod:`linkage.iterate`, tests 1-8, in order) written out without states or method
    dispatch. Gives the generic loop's status, root, iteration count and, when ``rows``
    (an :class:`~linkage.iterate.Rows`) is given, its table row for row
    (tests/test_compile.py checks both on the stress battery; the worked examples' tables use it).

    Returns (x, f(x), last error, status, detail, iterations); ``certify(x, fx, width)``
    decides a small step as in the generic loop.
    """
    add = rows.add if rows is not None else None
    f, fp = problem.f, problem.fprime
    isfinite = math.isfinite
    x = x0
    fx = f(x)
    if fx == 0.0:
        return x, fx, math.inf, Status.CONVERGED_EXACT, f"f is zero at the start {problem.var} = {x0!r}", 0
    if fx != fx or abs(fx) == math.inf:
        return x, fx, math.inf, Status.NON_FINITE, f"f({problem.var}={x0:g}) = {fx!r}", 0
    best = start = abs(fx) if isinstance(fx, float) else math.inf
    prev_err = math.inf
    err = math.inf
    growth = uncertified = stalls = rounding_steps = 0
    k = 0
    for k in range(1, max_iter + 1):
        try:
            d = fp(x)  # type: ignore[misc]
            if d == 0.0:
                if add is not None:
                    add((k, x, fx, d, None, None))
                return (x, fx, math.nan, Status.ZERO_DERIVATIVE,
                        f"f'({problem.var}) = 0 at {problem.var} = {x!r}, f = {fx:.6g}", k)
            x1 = x - fx / d
            fx1 = f(x1)
        except (ArithmeticError, ValueError) as exc:
            status, detail = explain(exc)
            return x, fx, err, status, detail, k - 1
        err = x1 - x
        if err < 0.0:
            err = -err
        if add is not None:
            add((k, x, fx, d, x1, err))
        x, fx = x1, fx1
        # inline finiteness: v - v is 0.0 for a finite float, NaN for inf and NaN
        if type(fx) is not float or type(err) is not float:
            try:
                finite = isfinite(err) and isfinite(fx)
            except TypeError:
                return x, fx, err, Status.DOMAIN_ERROR, f"f returned a non-real value: {fx!r}", k
        else:
            finite = err - err == 0.0 and fx - fx == 0.0
        if not finite:
            return x, fx, err, Status.NON_FINITE, f"error = {err!r}, residual = {fx!r}", k
        if fx == 0.0:
            return x, fx, err, Status.CONVERGED_EXACT, "", k
        size = fx if fx > 0.0 else -fx
        if ftol is not None and size <= ftol:
            return x, fx, err, Status.CONVERGED_RESIDUAL, "", k
        ax = x if x >= 0.0 else -x
        limit = step_limit(tol, rtol, ax) if rtol else tol
        if err <= limit:
            if worse_than_seen(size, best, start):
                limit = -1.0
            else:
                if size < best:
                    best = size
                stop, why, uncertified = judge_certificate(*certify(x, fx, limit), uncertified)
                if stop is not None:
                    return x, fx, err, stop, why, k
        elif size < best:
            best = size
        growth = growth + 1 if err > prev_err else 0
        if growth >= DIVERGE_STREAK:
            return x, fx, err, Status.DIVERGED, f"{growth} growing steps, last {err:.3g}", k
        if err <= ROUNDING * ax:
            why, rounding_steps, stalls = rounding_stall(err, prev_err, limit, rounding_steps, stalls)
            if why is not None:
                return x, fx, err, Status.PRECISION_LIMIT, why, k
        prev_err = err
    return x, fx, err, Status.MAX_ITER, "", k
