"""Fixed-point iteration: x_{i+1} = g(x_i), for a root of f written as x = g(x).

Linear convergence with rate |g'(r)| when |g'(r)| < 1 (contraction); diverges or
oscillates when |g'(r)| > 1. One evaluation of g per step; f at the new point enters the
stopping tests only when a residual tolerance is given (otherwise the table computes
it for display), so recording never changes where a run stops. For the Freudenstein four-bar,
g(phi) = acos(u(phi)) with u = (R1 cos(alpha) + R3 - cos(alpha - phi)) / R2, and
g'(phi) = sin(alpha - phi) / (R2 sqrt(1 - u^2)) ~ 0.1275 at the root (the student report,
fixed-point analysis). Fails with a domain error when |u| > 1 (acos undefined).
Rows follow the student report (docs/worked_examples.md P2): i, x_i, u(x_i) (when the problem has u),
x_{i+1}, f(x_{i+1}),
g'(x_i), error = x_i - x_{i+1} (signed).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar, NamedTuple

from ..iterate import DIVERGE_STREAK, ROUNDING, explain, judge_certificate, rounding_stall
from ..problems.scalar import ScalarProblem
from ..result import Column, Status
from ..rules import step_limit, worse_than_seen
from ._common import display, new_state


class FixedPointState(NamedTuple):
    x: float
    fx: float | None
    err: float
    stop: tuple[Status, str] | None
    xp: float


@dataclass(frozen=True)
class FixedPoint:
    """``evaluate_f``: compute f(x_{i+1}) each step, for a residual test."""

    evaluate_f: bool = True

    name: ClassVar[str] = "fixed-point"
    bracketing: ClassVar[bool] = False
    can_diverge: ClassVar[bool] = True
    needs_residual: ClassVar[bool] = False
    first_index: ClassVar[int] = 1
    init_evals: ClassVar[int] = 0

    @property
    def step_evals(self) -> int:
        return 2 if self.evaluate_f else 1

    def columns(self, problem: ScalarProblem) -> tuple[Column, ...]:
        cols = [Column("i", "index"), Column("{v}_i", "x")]
        if problem.u is not None:
            cols.append(Column("u({v}_i)", "ratio"))
        cols += [Column("{v}_i+1", "x"), Column("f({v}_i+1)", "f")]
        if problem.gprime is not None:
            cols.append(Column("g'({v}_i)", "ratio"))
        cols.append(Column("error", "x"))
        return tuple(cols)

    def init(self, problem: ScalarProblem, x0: float) -> FixedPointState:
        return FixedPointState(x0, None, float("inf"), None, x0)

    def step(self, problem: ScalarProblem, s: FixedPointState) -> FixedPointState:
        x = s.x
        x1 = problem.g(x)  # type: ignore[misc]
        fx1 = problem.f(x1) if self.evaluate_f else None
        return new_state(FixedPointState, (x1, fx1, abs(x - x1), None, x))

    def run_lean(self, problem: ScalarProblem, s: FixedPointState, crit: Any,
                 certify: Any) -> tuple[FixedPointState, Status, str, int]:
        """Fixed-point iteration with recording off, as one tight loop with the generic
        loop's stopping rules for an open method and the certification: the same outcome
        (tests/test_compile.py)."""
        f, g = problem.f, problem.g
        evaluate_f = self.evaluate_f
        x, fx, err, xp = s.x, s.fx, s.err, s.xp
        tol, rtol, ftol = crit.tol, crit.rtol, crit.ftol
        best = start = abs(fx) if isinstance(fx, float) and fx == fx else math.inf
        prev_err = math.inf
        growth = uncertified = stalls = rounding_steps = k = 0
        status, detail = Status.MAX_ITER, ""
        for k in range(1, crit.max_iter + 1):
            try:
                x1 = g(x)  # type: ignore[misc]
                fx1 = f(x1) if evaluate_f else None
            except (ArithmeticError, ValueError) as exc:
                status, detail = explain(exc)
                k -= 1
                break
            xp, x, fx, err = x, x1, fx1, abs(x - x1)
            try:
                finite = math.isfinite(err) and (fx is None or math.isfinite(fx))
            except TypeError:
                status, detail = Status.DOMAIN_ERROR, f"f returned a non-real value: {fx!r}"
                break
            if not finite:
                status, detail = Status.NON_FINITE, f"error = {err!r}, residual = {fx!r}"
                break
            if fx is not None:
                if fx == 0.0:
                    status = Status.CONVERGED_EXACT
                    break
                if ftol is not None and abs(fx) <= ftol:
                    status = Status.CONVERGED_RESIDUAL
                    break
            limit = step_limit(tol, rtol, abs(x)) if rtol else tol
            if fx is not None:
                size = abs(fx)
                if err <= limit and worse_than_seen(size, best, start):
                    limit = -1.0
                elif size < best:
                    best = size
            if err <= limit:
                verdict, why = certify(FixedPointState(x, fx, err, None, xp), limit)
                stop, why, uncertified = judge_certificate(verdict, why, uncertified)
                if stop is not None:
                    status, detail = stop, why
                    break
            growth = growth + 1 if err > prev_err else 0
            if growth >= DIVERGE_STREAK:
                status, detail = Status.DIVERGED, f"{growth} growing steps, last {err:.3g}"
                break
            if err <= ROUNDING * abs(x):
                why, rounding_steps, stalls = rounding_stall(err, prev_err, limit, rounding_steps, stalls)
                if why is not None:
                    status, detail = Status.PRECISION_LIMIT, why
                    break
            prev_err = err
        return FixedPointState(x, fx, err, None, xp), status, detail, k

    def initial_row(self, problem: ScalarProblem, s: FixedPointState) -> None:
        return None

    def row(self, problem: ScalarProblem, s: FixedPointState, i: int) -> tuple[Any, ...]:
        xp = s.xp
        out: list[Any] = [i, xp]
        if problem.u is not None:
            out.append(display(problem.u, xp))
        out += [s.x, s.fx if s.fx is not None else display(problem.f, s.x)]
        if problem.gprime is not None:
            out.append(display(problem.gprime, xp))
        out.append(xp - s.x)
        return tuple(out)
