"""Levenberg-Marquardt: minimise sum Phi_i(q)^2, the analogue of the textbook section's spreadsheet solver.

Step: (J^T J + mu diag(J^T J)) dq = -J^T Phi, accepted only if it lowers the sum of
squares; mu shrinks by 3 after a success and doubles after a failure (Marquardt,
SIAM J. Appl. Math. 11, 1963). Near a zero-residual solution it behaves like
Gauss-Newton (fast, about quadratic); where the loops cannot close it settles on a
least-squares point with residual above the tolerance, and the loop then reports
``local_minimum`` rather than success (the textbook section: the spreadsheet's Solver stops at a
minimum, which is a solution only if the minimum is zero). Where a closed form proves
that no assembly exists, the solve reports ``no_solution`` instead.
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

from ..linalg import SingularMatrix, cond1, det_from_lu, lu, lu_solve
from ..problems.system import SystemProblem
from ..records import NamedTuple, frozen
from ..result import Column, Status
from ..rules import counts_made
from .common import new_state
from .newton_system import (
    fd_jacobian,
    max_abs,
    newton_direction,
    normal_equations,
    step_measure,
    system_columns,
    system_row,
)

MU_MAX = 1e16
ROUNDING_RESIDUAL = 64 * 2.220446049250313e-16
"""max|Phi| at or below this times the length scale is rounding in the loop sums."""


class LMState(NamedTuple):
    x: tuple[float, ...]
    fx: float | None
    err: float
    stop: tuple[Status, str] | None
    q: tuple[float, ...]
    phi: tuple[float, ...]
    jac: tuple[tuple[float, ...], ...]
    dq: tuple[float, ...]
    det: float
    cond: float
    mu: float
    cost: float
    phi_new: tuple[float, ...]
    nfev: int
    njev: int
    bounded: bool = True
    """Whether ``err`` bounds the distance to a root: the undamped step was solved from a J
    that Newton's own test calls nonsingular (newton_system.newton_direction)."""


@frozen
class LevenbergMarquardt:
    jacobian: str = "analytic"
    fd_step: float | None = None
    diagnostics: bool = True

    name: ClassVar[str] = "lm"
    bracketing: ClassVar[bool] = False
    can_diverge: ClassVar[bool] = False
    needs_residual: ClassVar[bool] = True
    minimizes: ClassVar[bool] = True
    first_index: ClassVar[int] = 1

    def columns(self, problem: SystemProblem, show_jacobian: bool = False) -> tuple[Column, ...]:
        return system_columns(problem, show_jacobian, step_label="dq")

    def init(self, problem: SystemProblem, q0: tuple[float, ...]) -> LMState:
        phi = problem.F(list(q0))
        cost = sum(v * v for v in phi)
        nan = math.nan
        return LMState(tuple(q0), max_abs(phi), math.inf, None, tuple(q0), tuple(phi), (), (), nan,
                       nan, 1e-3, cost, tuple(phi), 1, 0)

    def step(self, problem: SystemProblem, s: LMState) -> LMState:
        q = list(s.x)
        phi = list(s.phi_new)
        nfev, njev = s.nfev, s.njev
        if self.jacobian == "fd":
            jac = fd_jacobian(problem, q, phi, self.fd_step)
            nfev += len(q)
        else:
            jac = problem.J(q)  # type: ignore[misc]
            njev += 1
        try:  # an evaluation counts once it returned, in a step that raises too (iterate.counts_made)
            n = len(q)
            jtj, g = normal_equations(jac, phi)
            try:
                fj = lu(jac)
                det, cond = det_from_lu(fj), (cond1(jac, fj) if self.diagnostics else math.nan)
                # the error estimate is the undamped (Gauss-Newton) step, as Newton's: a damped
                # step is small wherever mu is large, at a local minimum too, and bounds nothing;
                # nor does the undamped one where J is singular by Newton's own test (a tiny
                # residual over a vanishing pivot: Hypothesis found r1 = r2, r3 = r4 at theta2 =
                # 4e-94 rad stopped 45 deg from every root with "error 2.3e-13")
                direction = newton_direction(jac, phi)[0]
                newton = step_measure(direction if direction is not None else lu_solve(fj, [-v for v in phi]),
                                      problem.step_scales)
            except SingularMatrix:
                det, cond, newton, direction = 0.0, math.inf, math.inf, None
            if direction is None and max_abs(phi) <= ROUNDING_RESIDUAL * problem.length_scale:
                # the loops close to rounding where J is singular: no step can certify a root
                # here, and none can lower |Phi| further; stopped, the verdict is the residual's
                return new_state(LMState, (
                    tuple(q), max_abs(phi), newton,
                    (Status.SINGULAR_JACOBIAN, "J is singular here and the loops close to rounding level: "
                                               "a small step bounds no distance to a root"),
                    tuple(q), tuple(phi), tuple(map(tuple, jac)), tuple(0.0 for _ in q), det, cond, s.mu,
                    s.cost, tuple(phi), nfev, njev, False))
            mu = s.mu
            while True:
                a = [row[:] for row in jtj]
                for i in range(n):
                    a[i][i] += mu * max(jtj[i][i], 1e-12)
                try:
                    dq = lu_solve(lu(a), [-v for v in g])
                except SingularMatrix:
                    dq = None
                if dq is not None:
                    trial = [qi + di for qi, di in zip(q, dq)]
                    phi_t = problem.F(trial)
                    nfev += 1
                    cost_t = sum(v * v for v in phi_t)
                    if cost_t < s.cost:
                        return new_state(LMState, (
                            tuple(trial), max_abs(phi_t), max(step_measure(dq, problem.step_scales), newton),
                            None,
                            tuple(q), tuple(phi),
                            tuple(map(tuple, jac)), tuple(dq), det, cond, max(mu / 3.0, 1e-12), cost_t,
                            tuple(phi_t), nfev, njev, direction is not None))
                mu *= 2.0
                if mu > MU_MAX:
                    # No step lowers the residual: a local minimum of |Phi|^2.
                    return new_state(LMState, (
                        tuple(q), max_abs(phi), newton,
                        (Status.LOCAL_MINIMUM, f"no step lowers |Phi|^2 below {s.cost:.3g} from here "
                                               f"(mu above {MU_MAX:g})"),
                        tuple(q), tuple(phi), tuple(map(tuple, jac)),
                        tuple(0.0 for _ in q), det, cond, mu, s.cost, tuple(phi), nfev, njev,
                        direction is not None))
        except (ArithmeticError, ValueError) as exc:
            raise counts_made(exc, nfev, njev)  # noqa: B904 (the same exception, its traceback kept)

    @staticmethod
    def plausible(s: LMState) -> bool:
        """A small step is convergence only where it bounds the distance to a root: with J
        singular the iterates can close in on a family of roots of a nearby mechanism (r1 =
        r2, r3 = r4 at theta2 = 4e-94 rad: 45 deg from every root) with ever smaller steps."""
        return s.bounded

    def initial_row(self, problem: SystemProblem, s: LMState) -> None:
        return None

    def row(self, problem: SystemProblem, s: LMState, i: int) -> tuple[Any, ...]:
        return system_row(problem, i, s.q, s.phi, s.dq, s.det, s.cond, s.jac, s.err)
