"""``solve_scalar``: validate once at the front door, build the method, run the loop.

A method is what its entry in :data:`linkage.methods.METHODS` says: what it starts from,
what it needs, how it is built. Nothing here names a method except Newton's fast path."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any

from ..arguments import check_callable, check_method, check_number, check_reals, guarded
from ..errors import InputError
from ..iterate import Criteria, Rows, explain, run
from ..methods import METHODS, MethodEntry, method_class
from ..methods.common import history_of
from ..problems.scalar import ScalarProblem
from ..result import History, Result, Status
from .certificate import certify_root, check_sign_change, final_bracket, value_or_none
from .criteria import RecentCriteria, check_criteria
from .diagnose import diagnose_scalar


def problem_of(f: Callable[[float], float] | ScalarProblem, fprime: Any, g: Any) -> ScalarProblem:
    """The problem to solve: ``f`` itself, with ``fprime`` and ``g`` put in when given."""
    if isinstance(f, ScalarProblem):
        p = f
        if fprime is not None or g is not None:
            p = replace(p, fprime=fprime or p.fprime, g=g or p.g)
        return p
    if not callable(f):
        raise InputError(f"f must be callable or a ScalarProblem, got {type(f).__name__}")
    return ScalarProblem(f, fprime=fprime, g=g)


_recent = RecentCriteria()
"""The criteria the scalar front door checked last (its fast path reads them by identity)."""


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

    ``method``: a name in :data:`linkage.methods.METHODS`: ``bisection``,
    ``regula-falsi``, ``hybrid`` (bracketing: need ``bracket=(a, b)`` with a sign change),
    ``secant`` (``x0`` and ``x1``), ``newton`` (``x0`` and ``fprime``), ``fixed-point``
    (``x0`` and ``g``, iterating x = g(x)), and any method registered there.
    A :class:`ScalarProblem` may stand in for ``f`` and supply the derivatives, g and a
    default guess. Stops when the error measure is <= ``tol + rtol*|x|`` (the step, or
    the bracket's bound for bracketing methods), when ``|f| <= ftol`` if given, or at
    ``max_iter``; see :mod:`linkage.iterate` for the order of the tests.

    Always returns a :class:`Result`; check ``result.converged`` or call
    ``result.raise_for_status()``. Raises :class:`InputError` only for invalid input.

    >>> r = solve_scalar(lambda x: x*x - 2, method="newton", x0=1.0, fprime=lambda x: 2*x)
    >>> round(r.root, 12), r.status.value
    (1.414213562373, 'converged_step')
    """
    if not (method == "newton" and type(f) is ScalarProblem and fprime is None
            and type(x0) is float and x0 - x0 == 0.0 and f.fprime is not None):
        # (the general front door first: its jumps are short, so CPython 3.11 specialises
        # the comparisons before them, which a jump past the whole fast path prevents)
        return solve_checked(f, method, x0, x1, bracket, fprime, g, tol, rtol, ftol, max_iter, record)
    # the common case, without the general front door: a problem with its derivative and a
    # finite start (what the general front door checks, and then the same call)
    seen = _recent.seen
    if seen[0] is tol and seen[1] is rtol and seen[2] is ftol and seen[3] is max_iter:
        crit, values = seen[4], seen[5]
    else:
        crit = _recent.check(tol, rtol, ftol, max_iter)
        values = tuple(crit)
    if record:
        return newton_result(f, x0, crit, True)
    try:  # newton_result's quiet loop, called here (one Python frame fewer), on crit's values
        return (_newton_quiet or _load_newton_loops())(f, x0, values, certify_root)
    except (TypeError, ArithmeticError, ValueError) as exc:
        return newton_failed(f, x0, crit, False, exc)


def solve_checked(f: Callable[[float], float] | ScalarProblem, method: str, x0: Any, x1: Any, bracket: Any,
                  fprime: Any, g: Any, tol: float, rtol: float, ftol: float | None, max_iter: int,
                  record: bool) -> Result:
    """:func:`solve_scalar`'s general front door: every argument checked, then the method
    run. Its own function: the fast path's frame then holds only the arguments (a frame's
    every local is set up and cleared on each call)."""
    entry = METHODS[check_method("method", method, METHODS)]  # the registry itself: registered later too
    crit = check_criteria(tol, rtol, ftol, max_iter)
    check_callable("fprime", fprime)
    check_callable("g", g)
    problem = problem_of(f, fprime, g)
    args, start = starting_points(entry, problem, x0, x1, bracket)
    for attribute, what in entry.needs:
        if getattr(problem, attribute) is None:
            raise InputError(f"{method} needs {what}")
    if method == "newton":
        return newton_result(problem, args[0], crit, record)
    m = entry.make(method_class(method), crit)
    try:
        state = m.init(problem, *args)
        if entry.bracketing:
            # f at the bracket's ends, known from init: the discontinuity check reuses them
            start["f_ends"] = (state.fa, state.fb) if hasattr(state, "fa") else (state.fpre, state.fx)
    except TypeError:
        return failed_at_start(m.name, problem, args[0], crit, record, start, Status.DOMAIN_ERROR,
                               "f returned a non-real value")
    except (ArithmeticError, ValueError) as exc:
        return failed_at_start(m.name, problem, args[0], crit, record, start, *explain(exc))
    return finish_guarded(m, problem, state, crit, record, start, args[0])


def finish_guarded(m: Any, problem: ScalarProblem, state: Any, crit: Criteria, record: bool,
                   start: dict[str, Any], x0: float) -> Result:
    """:func:`finish`, where a g (or f') that returns something other than a number, failing
    inside the loop, is named (:func:`diagnose_scalar`). Its own function: the closures it
    makes would otherwise be cells that :func:`solve_scalar`'s every call, the fast path's
    included, allocates on entry."""
    return guarded(lambda: finish(m, problem, state, crit, record, start),
                   lambda: diagnose_scalar(problem, x0, lambda p: finish(m, p, state, crit, record, start)))


def starting_points(entry: MethodEntry, problem: ScalarProblem, x0: Any, x1: Any,
                    bracket: Any) -> tuple[tuple[float, ...], dict[str, Any]]:
    """The method's start (checked; the problem's guess where none is given) and how the
    Result's meta names it."""
    method = entry.name
    guess = problem.guess
    if entry.bracketing:
        if bracket is None:
            if guess is None:
                raise InputError(f"{method} needs a bracket (a, b) with a sign change of f")
            bracket = guess
        a, b = check_reals("bracket", bracket, 2, ("start", "end"))
        if a == b:
            raise InputError(f"the bracket ends are equal ({a!r}); give an interval")
        return (a, b), {"bracket": (a, b)}
    if x0 is None:
        if guess is None:
            raise InputError(f"{method} needs a starting point x0")
        x0 = guess[0]
    x0 = check_number("x0", x0)
    if entry.starts != "x0 x1":
        return (x0,), {"x0": x0}
    if x1 is None:
        if guess is None:
            raise InputError(f"{method} needs two starting points x0 and x1")
        x1 = guess[1] if guess[1] != x0 else x0 + 1.0
    x1 = check_number("x1", x1)
    if x1 == x0:
        raise InputError(f"{method} needs two different starting points, got x0 = x1 = {x0!r}")
    return (x0, x1), {"x0": x0, "x1": x1}


def failed_at_start(name: str, problem: ScalarProblem, x: float, crit: Criteria, record: bool,
                    start: dict[str, Any], status: Status, detail: str) -> Result:
    """The Result of a run whose start cannot be evaluated."""
    return Result(method=name, x=x, status=status, iterations=0, nfev=0, error=math.inf, residual=None,
                  detail=f"at the start: {detail}", history=History((), (), 0) if record else None,
                  meta={"var": problem.var, "unit": problem.unit, "title": problem.title,
                        "tol": crit.tol, "rtol": crit.rtol, **start})


_newton_quiet: Any = None
"""linkage.methods.newton.newton_quiet once a scalar Newton solve has loaded it (a sweep or
a system solve never does); ``newton_lean`` is then in :data:`_newton_lean`."""
_newton_lean: Any = None


def _load_newton_loops() -> Any:
    """Both loops loaded (the recording one first: a reader that sees the quiet one sees it);
    the quiet one returned."""
    global _newton_quiet, _newton_lean
    from ..methods.newton import newton_lean, newton_quiet

    _newton_lean = newton_lean
    _newton_quiet = newton_quiet
    return newton_quiet


def newton_result(problem: ScalarProblem, x0: float, crit: Criteria, record: bool = False) -> Result:
    """Newton by its generated loop (:func:`~linkage.methods.newton.newton_lean`), which
    packages its outcome as :func:`finish` packages the generic loop's (history included
    when ``record``)."""
    quiet = _newton_quiet or _load_newton_loops()
    try:
        if record:
            return _newton_lean(problem, x0, crit, certify_root, Rows())
        return quiet(problem, x0, crit, certify_root)
    except (TypeError, ArithmeticError, ValueError) as exc:
        return newton_failed(problem, x0, crit, record, exc)


def newton_failed(problem: ScalarProblem, x0: float, crit: Criteria, record: bool, exc: Exception) -> Result:
    """The Result of a Newton solve whose loop raised ``exc`` (a TypeError, ArithmeticError
    or ValueError its own tests did not catch): what the generic path answers for a start
    it cannot evaluate (a TypeError: a non-real f)."""
    if isinstance(exc, TypeError):
        return failed_at_start("newton", problem, x0, crit, record, {"x0": x0}, Status.DOMAIN_ERROR,
                               "f returned a non-real value")
    return failed_at_start("newton", problem, x0, crit, record, {"x0": x0}, *explain(exc))


def scalar_meta(problem: ScalarProblem, crit: Criteria, start: dict[str, Any]) -> dict[str, Any]:
    """A scalar solve's ``Result.meta`` (the start as ``start`` names it), built when first read."""
    return {"var": problem.var, "unit": problem.unit, "title": problem.title,
            "tol": crit.tol, "rtol": crit.rtol, "ftol": crit.ftol, **start}


def iterate_from(m: Any, problem: ScalarProblem, state: Any, crit: Criteria,
                 record: bool) -> tuple[Any, Status, str, int, Any, int]:
    """Run the method's loop from its initial state: (final state, status, detail,
    iterations, rows or None, evaluations of f for the certification)."""
    if state.stop is not None:
        status, detail = state.stop
        return state, status, detail, 0, ([] if record else None), 0
    certify = None
    extra_evals = [0]
    if not m.bracketing:
        def certify(x: float, fx: Any, width: float) -> tuple[Status, str]:
            known = fx is not None
            if not known:
                fx = value_or_none(problem.f, x)
            verdict, why, n = certify_root(problem, x, fx, width)
            extra_evals[0] += n + (not known)
            return verdict, why
    if not record and hasattr(m, "run_lean"):
        # the method's own generated loop: the generic loop's outcome, without a state per step
        final, status, detail, iterations = m.run_lean(problem, state, crit, certify)
        return final, status, detail, iterations, None, extra_evals[0]
    final, status, detail, iterations, rows = run(m, problem, state, crit, record=record, certify=certify)
    return final, status, detail, iterations, rows, extra_evals[0]


def finish(m: Any, problem: ScalarProblem, state: Any, crit: Criteria, record: bool,
           start: dict[str, Any]) -> Result:
    """Run the loop from an initial state and package the outcome as a Result."""
    final, status, detail, iterations, rows, extra = iterate_from(m, problem, state, crit, record)
    nfev = m.init_evals + iterations * m.step_evals + extra
    x = final.x
    residual = final.fx
    if residual is None and status is not Status.INVALID_BRACKET:
        try:
            residual = problem.f(x)
            nfev += 1
        except (ArithmeticError, ValueError):
            residual = math.nan
    if status is Status.MAX_ITER and hasattr(m, "cap_detail"):  # bisection: the halvings it needed
        detail = m.cap_detail(start["bracket"], crit.tol, crit.rtol, iterations, final.err)
    if status is Status.CONVERGED_STEP and m.bracketing and "f_ends" in start:
        lo, hi = final_bracket(final)
        status, detail, more = check_sign_change(problem, x, residual, lo, hi, start["f_ends"], detail)
        nfev += more
    return Result.fast(m.name, x, status, iterations, nfev, final.err, residual, detail, 0,
                       (scalar_meta, problem, crit, start),
                       None if rows is None else (history_of, m, problem, rows))
