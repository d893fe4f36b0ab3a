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

from typing import Any, ClassVar

from ..iterate import Loop, build_loop
from ..problems.scalar import ScalarProblem
from ..records import NamedTuple, frozen
from ..result import Column, Status
from .common import display, new_state


class FixedPointState(NamedTuple):
    x: float
    fx: float | None
    err: float
    stop: tuple[Status, str] | None
    xp: float


@frozen
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
        """Fixed-point iteration with recording off: :data:`FIXED_POINT_LOOP`, the generic
        loop's outcome (tests/test_compile.py, tests/test_kernel.py)."""
        return fixed_point_lean(problem, s.x, s.fx, s.err, s.xp, self.evaluate_f, crit.tol, crit.rtol,
                                crit.ftol, crit.max_iter, certify)

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


FIXED_POINT_LOOP = Loop(
    signature="fixed_point_lean(problem, x, fx, err, xp, evaluate_f, tol, rtol, ftol, max_iter, certify)",
    setup="""\
        f, g = problem.f, problem.g
        best = start = abs(fx) if isinstance(fx, float) and fx == fx else _inf
        """,
    step="""\
        x1 = g(x)
        fx1 = f(x1) if evaluate_f else None
        """,
    after="xp, x, fx, err = x, x1, fx1, abs(x - x1)",
    result="_State(x, fx, err, None, xp), status, detail, k",
    fx_optional=True, guard=True, step_test="certify", diverge="streak")
"""Fixed-point iteration's loop: the stopping rule of :mod:`linkage.iterate` around x = g(x)."""

fixed_point_lean = build_loop(FIXED_POINT_LOOP, {"_State": FixedPointState}, fixed_source=True)
