"""Halley's method: x_{i+1} = x_i - 2 f(x_i) f'(x_i) / (2 f'(x_i)^2 - f(x_i) f''(x_i)).

Order 3 near a simple root (Newton's method applied to f / sqrt|f'|; see e.g. the
Wikipedia article "Halley's method", section "Cubic convergence"). Three evaluations per
step (f, f' and f''), one more to start; it needs the exact second derivative (an
equation's is derived symbolically, :mod:`linkage.problems.expression`; the four-bar's is
in :mod:`linkage.problems.freudenstein`): a finite difference would spoil the order. Fails
where the denominator 2 f'^2 - f f'' is zero; like Newton it may wander to another root.
Rows: i, x_i, f(x_i), f'(x_i), f''(x_i), x_{i+1}, |x_{i+1} - x_i|.
"""

from __future__ import annotations

from typing import Any, ClassVar

from ..problems.scalar import ScalarProblem
from ..records import NamedTuple, frozen
from ..result import Column, Status
from .common import new_state, start_stop


class HalleyState(NamedTuple):
    x: float
    fx: float
    err: float
    stop: tuple[Status, str] | None
    xp: float
    fxp: float
    dfxp: float
    d2fxp: float


@frozen
class Halley:
    name: ClassVar[str] = "halley"
    bracketing: ClassVar[bool] = False
    can_diverge: ClassVar[bool] = True
    needs_residual: ClassVar[bool] = False
    first_index: ClassVar[int] = 1
    init_evals: ClassVar[int] = 1
    step_evals: ClassVar[int] = 3

    def columns(self, problem: ScalarProblem) -> tuple[Column, ...]:
        return (Column("i", "index"), Column("{v}_i", "x"), Column("f({v}_i)", "f"),
                Column("f'({v}_i)", "df"), Column("f''({v}_i)", "d2f"), Column("{v}_i+1", "x"),
                Column("error", "x"))

    def init(self, problem: ScalarProblem, x0: float) -> HalleyState:
        fx = problem.f(x0)
        stop = start_stop(problem, x0, fx)
        nan = float("nan")
        return HalleyState(x0, fx, float("inf"), stop, x0, fx, nan, nan)

    def step(self, problem: ScalarProblem, s: HalleyState) -> HalleyState:
        x, fx = s.x, s.fx
        d = problem.fprime(x)  # type: ignore[misc]
        dd = problem.fsecond(x)  # type: ignore[misc]
        den = 2.0 * d * d - fx * dd
        if den == 0.0:
            why = f"2 f'^2 - f f'' = 0 at {problem.var} = {x!r} (f' = {d:.6g}, f'' = {dd:.6g})"
            return new_state(HalleyState, (x, fx, float("nan"), (Status.ZERO_DERIVATIVE, why), x, fx, d, dd))
        x1 = x - 2.0 * fx * d / den
        return new_state(HalleyState, (x1, problem.f(x1), abs(x1 - x), None, x, fx, d, dd))

    def initial_row(self, problem: ScalarProblem, s: HalleyState) -> None:
        return None

    def row(self, problem: ScalarProblem, s: HalleyState, i: int) -> tuple[Any, ...]:
        if s.stop is not None:
            return (i, s.xp, s.fxp, s.dfxp, s.d2fxp, None, None)
        return (i, s.xp, s.fxp, s.dfxp, s.d2fxp, s.x, s.err)
