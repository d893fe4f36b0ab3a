"""``solve_scalar``: validate once at the front door, build the method, run the loop."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

from .errors import InputError
from .iterate import Criteria, explain, run
from .methods import SCALAR_METHODS, Bisection, FixedPoint, Hybrid, Newton, RegulaFalsi, Secant
from .problems.scalar import ScalarProblem
from .result import History, Result, Status


def check_number(name: str, value: Any, *, positive: bool = False, allow_zero: bool = True) -> float:
    """A finite float (and > 0 or >= 0 when asked), or an InputError naming the value."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(v):
        raise InputError(f"{name} must be finite, got {v!r}")
    if positive and (v < 0.0 or (v == 0.0 and not allow_zero)):
        raise InputError(f"{name} must be {'>' if not allow_zero else '>='} 0, got {v!r}")
    return v


def check_criteria(tol: float, rtol: float, ftol: float | None, max_iter: int) -> Criteria:
    tol = check_number("tol", tol, positive=True, allow_zero=False)
    rtol = check_number("rtol", rtol, positive=True)
    if ftol is not None:
        ftol = check_number("ftol", ftol, positive=True, allow_zero=False)
    if isinstance(max_iter, bool) or not isinstance(max_iter, int) or max_iter < 1:
        raise InputError(f"max_iter must be an integer >= 1, got {max_iter!r}")
    return Criteria(tol, rtol, ftol, max_iter)


def _problem(f: Callable[[float], float] | ScalarProblem, fprime: Any, g: Any) -> ScalarProblem:
    if isinstance(f, ScalarProblem):
        p = f
        if fprime is not None or g is not None:
            from dataclasses import replace

            p = replace(p, fprime=fprime or p.fprime, g=g or p.g)
        return p
    if not callable(f):
        raise InputError(f"f must be callable or a ScalarProblem, got {type(f).__name__}")
    return ScalarProblem(f, fprime=fprime, g=g)


def solve_scalar(
    f: Callable[[float], float] | ScalarProblem,
    *,
    method: str,
    x0: float | None = None,
    x1: float | None = None,
    bracket: Sequence[float] | None = None,
    fprime: Callable[[float], float] | None = None,
    g: Callable[[float], float] | None = None,
    tol: float = 1e-6,
    rtol: float = 0.0,
    ftol: float | None = None,
    max_iter: int = 100,
    record: bool = True,
) -> Result:
    """Solve f(x) = 0 for one unknown with the named method.

    ``method``: one of ``bisection``, ``regula-falsi``, ``hybrid`` (bracketing: need
    ``bracket=(a, b)`` with a sign change), ``secant`` (``x0`` and ``x1``), ``newton``
    (``x0`` and ``fprime``), ``fixed-point`` (``x0`` and ``g``, iterating x = g(x)).
    A :class:`ScalarProblem` may stand in for ``f`` and supply the derivative, g and a
    default guess. Stops when the error measure is <= ``tol + rtol*|x|`` (the step, or
    the bracket's bound for bracketing methods), when ``|f| <= ftol`` if given, or at
    ``max_iter``; see :mod:`linkage.iterate` for the order of the tests.

    Always returns a :class:`Result`; check ``result.converged`` or call
    ``result.raise_for_status()``. Raises :class:`InputError` only for invalid input.

    >>> r = solve_scalar(lambda x: x*x - 2, method="newton", x0=1.0, fprime=lambda x: 2*x)
    >>> round(r.root, 12), r.status.value
    (1.414213562373, 'converged_step')
    """
    if method not in SCALAR_METHODS:
        raise InputError(f"unknown method {method!r}; choose from {', '.join(SCALAR_METHODS)}")
    crit = check_criteria(tol, rtol, ftol, max_iter)
    problem = _problem(f, fprime, g)
    guess = problem.guess
    m: Any
    if method in ("bisection", "regula-falsi", "hybrid"):
        if bracket is None:
            if guess is None:
                raise InputError(f"{method} needs a bracket (a, b) with a sign change of f")
            bracket = guess
        if len(bracket) != 2:
            raise InputError(f"a bracket is two numbers, got {len(bracket)}")
        a = check_number("bracket start", bracket[0])
        b = check_number("bracket end", bracket[1])
        if a == b:
            raise InputError(f"the bracket ends are equal ({a!r}); give an interval")
        m = {"bisection": Bisection(), "regula-falsi": RegulaFalsi(),
             "hybrid": Hybrid(crit.tol, crit.rtol)}[method]
        args: tuple[float, ...] = (a, b)
        start: dict[str, Any] = {"bracket": (a, b)}
    else:
        if x0 is None:
            if guess is None:
                raise InputError(f"{method} needs a starting point x0")
            x0 = guess[0]
        x0 = check_number("x0", x0)
        if method == "secant":
            if x1 is None:
                if guess is None:
                    raise InputError("secant needs two starting points x0 and x1")
                x1 = guess[1] if guess[1] != x0 else x0 + 1.0
            x1 = check_number("x1", x1)
            if x1 == x0:
                raise InputError(f"secant needs two different starting points, got x0 = x1 = {x0!r}")
            m = Secant()
            args = (x0, x1)
            start = {"x0": x0, "x1": x1}
        elif method == "newton":
            if problem.fprime is None:
                raise InputError("newton needs the derivative fprime")
            m = Newton()
            args = (x0,)
            start = {"x0": x0}
        else:
            if problem.g is None:
                raise InputError("fixed-point needs the iteration function g (x = g(x))")
            m = FixedPoint(evaluate_f=crit.ftol is not None)
            args = (x0,)
            start = {"x0": x0}
    try:
        state = m.init(problem, *args)
    except (ArithmeticError, ValueError) as exc:
        status, detail = explain(exc)
        return Result(method=m.name, x=args[0], status=status, iterations=0, nfev=0,
                      error=math.inf, residual=None, detail=f"at the start: {detail}",
                      history=History((), (), 0) if record else None,
                      meta={"var": problem.var, "unit": problem.unit, "title": problem.title,
                            "tol": crit.tol, "rtol": crit.rtol, **start})
    return finish(m, problem, state, crit, record, start)


def finish(m: Any, problem: ScalarProblem, state: Any, crit: Criteria, record: bool,
           start: dict[str, Any]) -> Result:
    """Run the loop from an initial state and package the outcome as a Result."""
    if state.stop is not None:
        status, detail = state.stop
        outcome_state, iterations, rows = state, 0, ([] if record else None)
    else:
        outcome_state, status, detail, iterations, rows = run(m, problem, state, crit, record=record)
    nfev = m.init_evals + iterations * m.step_evals
    x = outcome_state.x
    residual = outcome_state.fx
    if residual is None and status is not Status.INVALID_BRACKET:
        try:
            residual = problem.f(x)
            nfev += 1
        except (ArithmeticError, ValueError):
            residual = math.nan
    history = None
    if rows is not None:
        cols = m.columns(problem)
        labels = tuple(c.label(problem.var, problem.unit) for c in cols)
        history = History(labels, tuple(rows), len(cols) - 1)
    err = outcome_state.err
    return Result(
        method=m.name,
        x=x,
        status=status,
        iterations=iterations,
        nfev=nfev,
        error=err,
        residual=residual,
        detail=detail,
        history=history,
        meta={"var": problem.var, "unit": problem.unit, "title": problem.title,
              "tol": crit.tol, "rtol": crit.rtol, "ftol": crit.ftol, **start},
    )
