"""Newton-Raphson for loop-closure systems: solve J(q_k) dq = -Phi(q_k), q_k+1 = q_k + dq.

Quadratic convergence near a solution where J is nonsingular (seed 001 section 3.9,
eq. 7; PROBLEMS.md P3). One residual and one Jacobian evaluation per step; with the
Jacobian by forward differences (``newton-fd``, seed 000's recipe: perturb one
coordinate by h, take (Phi(q + h e_j) - Phi(q)) / h as column j, restore it), n + 1
residual evaluations and order falling toward linear as h grows. ``damped`` adds a
backtracking line search on |Phi|^2 (Armijo, halving down to 1/1024) for poor
starting guesses. Fails where det J = 0 (toggle or dead-centre positions, a start
such as theta3 = theta4): a named ``singular_jacobian`` stop with det and condition
number. Rows follow P3: k, q_k, Phi(q_k), max|Phi|, dq (rad and deg), det J, cond J.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from typing import Any, ClassVar, NamedTuple

from ..problems.system import SystemProblem
from ..result import Column, Status
from ._common import new_state
from ._linalg import SingularMatrix, cond1, det_from_lu, lu, lu_solve, pivot_ratio

SINGULAR_RATIO = 1e-12
"""Smallest |pivot| / largest |pivot| of J before a step is refused as singular."""


def max_abs(v: Any) -> float:
    """max |v_i|, NaN if any entry is NaN (the builtin max would silently skip it)."""
    m = 0.0
    for c in v:
        a = abs(c)
        if a > m or a != a:
            if a != a:
                return math.nan
            m = a
    return m


def fd_jacobian(problem: SystemProblem, q: list[float], phi: list[float],
                h: float | None) -> list[list[float]]:
    """Forward differences, one coordinate at a time; columns as in seed 000."""
    n = len(q)
    cols = []
    for j in range(n):
        step = h if h is not None else math.sqrt(sys.float_info.epsilon) * max(1.0, abs(q[j]))
        qj = list(q)
        qj[j] = q[j] + step
        pj = problem.F(qj)
        cols.append([(pj[i] - phi[i]) / step for i in range(len(phi))])
    return [[cols[j][i] for j in range(n)] for i in range(len(phi))]


class NewtonSystemState(NamedTuple):
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
    alpha: float
    nfev: int
    njev: int


def singular_detail(det: float, cond: float) -> str:
    return f"det J = {det:.6g}, cond J = {cond:.3g}"


@dataclass(frozen=True)
class NewtonSystem:
    """``jacobian``: "analytic" or "fd"; ``fd_step``: h for "fd" (None: sqrt(eps) max(1, |q|));
    ``damped``: backtracking line search; ``diagnostics``: compute cond J every step."""

    jacobian: str = "analytic"
    fd_step: float | None = None
    damped: bool = False
    diagnostics: bool = True

    bracketing: ClassVar[bool] = False
    can_diverge: ClassVar[bool] = True
    needs_residual: ClassVar[bool] = True
    minimizes: ClassVar[bool] = False
    first_index: ClassVar[int] = 1

    @property
    def name(self) -> str:
        return "newton-fd" if self.jacobian == "fd" else "newton"

    def columns(self, problem: SystemProblem, show_jacobian: bool = False) -> tuple[Column, ...]:
        return system_columns(problem, show_jacobian, step_label="dq")

    def init(self, problem: SystemProblem, q0: tuple[float, ...]) -> NewtonSystemState:
        nan = math.nan
        return NewtonSystemState(tuple(q0), None, math.inf, None, tuple(q0), (), (), (), nan, nan,
                                 1.0, 0, 0)

    def step(self, problem: SystemProblem, s: NewtonSystemState) -> NewtonSystemState:
        q = list(s.x)
        phi = problem.F(q)
        nfev, njev = s.nfev + 1, s.njev
        if self.jacobian == "fd":
            jac = fd_jacobian(problem, q, phi, self.fd_step)
            nfev += len(q)
        else:
            jac = problem.J(q)  # type: ignore[misc]
            njev += 1
        resid = max_abs(phi)
        if len(q) == 2 and not self.damped:
            # Two unknowns (every four-bar, the slider-crank): Cramer's rule, no LU.
            (a, b), (c, d) = jac
            det = a * d - b * c
            scale = max(abs(a), abs(b), 1e-300) * max(abs(c), abs(d), 1e-300)
            if abs(det) > SINGULAR_RATIO * scale:
                dq = [(b * phi[1] - d * phi[0]) / det, (c * phi[0] - a * phi[1]) / det]
                cond = cond1(jac) if self.diagnostics else math.nan
                x = (q[0] + dq[0], q[1] + dq[1])
                return new_state(NewtonSystemState, (
                    x, resid, max_abs(dq), None, tuple(q), tuple(phi), tuple(map(tuple, jac)),
                    tuple(dq), det, cond, 1.0, nfev, njev))
        try:
            f = lu(jac)
            ratio = pivot_ratio(f)
        except SingularMatrix:
            f, ratio = None, 0.0
        if f is None or ratio < SINGULAR_RATIO:
            det = det_from_lu(f) if f is not None else 0.0
            cond = cond1(jac)
            return new_state(NewtonSystemState, (
                tuple(q), resid, math.nan,
                (Status.SINGULAR_JACOBIAN, singular_detail(det, cond)),
                tuple(q), tuple(phi), tuple(map(tuple, jac)), (), det, cond, 1.0, nfev, njev))
        dq = lu_solve(f, [-v for v in phi])
        det = det_from_lu(f)
        cond = cond1(jac, f) if self.diagnostics else math.nan
        alpha = 1.0
        if self.damped:
            base = sum(v * v for v in phi)
            while alpha > 1.0 / 1024.0:
                trial = problem.F([qi + alpha * di for qi, di in zip(q, dq)])
                nfev += 1
                if sum(v * v for v in trial) <= (1.0 - 1e-4 * alpha) * base:
                    break
                alpha *= 0.5
        step = [alpha * d for d in dq]
        x = tuple(qi + di for qi, di in zip(q, step))
        return new_state(NewtonSystemState, (
            x, resid, max_abs(step), None, tuple(q), tuple(phi), tuple(map(tuple, jac)),
            tuple(step), det, cond, alpha, nfev, njev))

    def initial_row(self, problem: SystemProblem, s: NewtonSystemState) -> None:
        return None

    def row(self, problem: SystemProblem, s: NewtonSystemState, i: int) -> tuple[Any, ...]:
        return system_row(problem, i, s.q, s.phi, s.dq, s.det, s.cond, s.jac, s.err)


def system_columns(problem: SystemProblem, show_jacobian: bool, step_label: str) -> tuple[Column, ...]:
    """P3's layout, generated from the unknowns' names and kinds (the error column last)."""
    L = problem.length_unit
    cols = [Column("k", "index")]
    for i, name in enumerate(problem.names):
        cols.append(Column(f"{name} ({problem.unit(i)})" if problem.unit(i) else name, "text"))
    for r in range(len(problem.equation_names)):
        cols.append(Column(f"Phi{r + 1} ({L})" if L else f"Phi{r + 1}", "text"))
    cols.append(Column(f"max|Phi| ({L})" if L else "max|Phi|", "text"))
    for i, name in enumerate(problem.names):
        unit = problem.step_unit(i)
        cols.append(Column(f"d{name} ({unit})" if unit else f"d{name}", "text"))
        if problem.kinds[i] == "angle":
            cols.append(Column(f"d{name} (deg)", "text"))
    cols.append(Column(f"det J ({det_unit(problem)})" if det_unit(problem) else "det J", "text"))
    cols.append(Column("cond J", "text"))
    if show_jacobian:
        for r in range(len(problem.equation_names)):
            for c, name in enumerate(problem.names):
                unit = jac_unit(problem, c)
                label = f"dPhi{r + 1}/d{name}"
                cols.append(Column(f"{label} ({unit})" if unit else label, "text"))
    units = sorted({problem.step_unit(i) for i in range(problem.n)} - {""})
    cols.append(Column(f"max|{step_label}| ({', '.join(units)})" if units else f"max|{step_label}|", "text"))
    return tuple(cols)


def jac_unit(problem: SystemProblem, col: int) -> str:
    L = problem.length_unit
    if problem.kinds[col] == "angle":
        return f"{L}/rad" if L else "1/rad"
    return ""


def det_unit(problem: SystemProblem) -> str:
    if not problem.length_unit:
        return ""
    n_len = problem.n - sum(k == "length" for k in problem.kinds)
    n_ang = sum(k == "angle" for k in problem.kinds)
    top = f"{problem.length_unit}^{n_len}" if n_len > 1 else (problem.length_unit if n_len == 1 else "1")
    bottom = f"rad^{n_ang}" if n_ang > 1 else ("rad" if n_ang == 1 else "")
    return f"{top}/{bottom}" if bottom else top


def system_row(problem: SystemProblem, k: int, q: Any, phi: Any, dq: Any, det: float, cond: float,
               jac: Any, err: float, show_jacobian: bool = False) -> tuple[Any, ...]:
    row: list[Any] = [k, *problem.to_display(q), *phi, max_abs(phi) if phi else None]
    for i, kind in enumerate(problem.kinds):
        d = dq[i] if dq else None
        row.append(d)
        if kind == "angle":
            row.append(math.degrees(d) if d is not None else None)
    row += [det, cond]
    row.append(jac)  # expanded (or dropped) by the solve function: see solve_system
    row.append(err)
    return tuple(row)
