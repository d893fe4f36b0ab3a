"""Our system solvers on the Moré-Garbow-Hillstrom square systems, beside scipy's.

A case is *solved* when the solver reports success and max|F| at its answer is at
most ``SOLVED_RESIDUAL``; a *false success* is a reported success with max|F| above
it. Every solver gets the exact Jacobian. Used by ``benchmarks/mgh.py``, the stress
battery and the tests.
"""

from __future__ import annotations

import math
from typing import Any

from ..problems.catalog import mgh_cases
from ..records import frozen

SOLVED_RESIDUAL = 1e-8
TOL = 1e-10
MAX_ITER = 200


@frozen
class Outcome:
    case: str
    solver: str
    success: bool  # what the solver claims
    residual: float  # max|F| at its answer
    status: str

    @property
    def solved(self) -> bool:
        return self.success and self.residual <= SOLVED_RESIDUAL

    @property
    def false_success(self) -> bool:
        return self.success and not self.residual <= SOLVED_RESIDUAL


def _max_abs(v: Any) -> float:
    m = 0.0
    for c in v:
        a = abs(c)
        if a != a:
            return math.nan
        m = max(m, a)
    return m


def ours(method: str, damped: bool, label: str) -> Any:
    from ..solve import solve_system

    def run(case: str, system: Any, x0: tuple[float, ...]) -> Outcome:
        r = solve_system(system.F, x0, jac=system.J, method=method, damped=damped, tol=TOL, ftol=TOL,
                         max_iter=MAX_ITER, record=False)
        try:
            res = _max_abs(system.F(list(r.x)))
        except (ArithmeticError, ValueError):
            res = math.nan
        return Outcome(case, label, r.converged, res, r.status.value)

    return run


def scipy_root(method: str) -> Any:
    import numpy as np
    from scipy.optimize import root

    def run(case: str, system: Any, x0: tuple[float, ...]) -> Outcome:
        def fun(x: Any) -> tuple[Any, Any]:
            xs = list(map(float, x))
            return np.array(system.F(xs)), np.array(system.J(xs))

        try:
            with np.errstate(all="ignore"):
                sol = root(fun, np.array(x0, dtype=float), jac=True, method=method)
            res = _max_abs(system.F(list(map(float, sol.x))))
            return Outcome(case, f"scipy {method}", bool(sol.success), res, str(sol.message)[:60])
        except (ArithmeticError, ValueError) as exc:
            return Outcome(case, f"scipy {method}", False, math.nan, f"raised {type(exc).__name__}")

    return run


def has_scipy() -> bool:
    try:
        import scipy.optimize  # noqa: F401
    except ImportError:
        return False
    return True


def run_table(with_scipy: bool = True) -> dict[str, list[Outcome]]:
    """Every solver on every case: {solver label: outcomes in case order}."""
    solvers = {"newton (default)": ours("newton", True, "newton (default)"),
               "newton --plain": ours("newton", False, "newton --plain"),
               "lm": ours("lm", True, "lm")}
    if with_scipy and has_scipy():
        solvers["scipy hybr"] = scipy_root("hybr")
        solvers["scipy lm"] = scipy_root("lm")
    out: dict[str, list[Outcome]] = {k: [] for k in solvers}
    for label, system, factor in mgh_cases():
        x0 = system.start(factor)
        for name, solver in solvers.items():
            try:
                out[name].append(solver(label, system, x0))
            except (ArithmeticError, ValueError) as exc:
                out[name].append(Outcome(label, name, False, math.nan, f"raised {type(exc).__name__}"))
    return out


def summary(table: dict[str, list[Outcome]]) -> list[tuple[str, int, int, int]]:
    """(solver, cases, solved, false successes)."""
    return [(name, len(rows), sum(o.solved for o in rows), sum(o.false_success for o in rows))
            for name, rows in table.items()]
