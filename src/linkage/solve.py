"""``solve_scalar``: validate once at the front door, build the method, run the loop."""

from __future__ import annotations

import functools
import math
import sys
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any

from .arguments import (
    check_callable,
    check_number,
    check_reals,
    guarded,
    real_matrix,
    real_result,
    real_vector,
)
from .errors import InputError
from .iterate import MAX_ITER_LIMIT, Criteria, Rows, explain, run
from .methods import SCALAR_METHODS
from .problems.scalar import ScalarProblem
from .result import History, Result, Status
from .rules import residual_gate

# A scalar solve imports only its own method; the system solvers load with the first
# system solve (python -X importtime: about 20 ms of every `linkage solve` otherwise).


def _short_int(v: int) -> str:
    text = str(v) if v < 10**30 else f"about 1e{len(str(v)) - 1}"
    return text


def check_criteria(tol: float, rtol: float, ftol: float | None, max_iter: int) -> Criteria:
    """The stopping criteria, checked (InputError naming the bad one). Remembered per
    value and type (True is not 1 here); values that cannot be remembered, such as a list,
    are checked afresh and refused with their message."""
    try:
        return _checked_criteria(tol, rtol, ftol, max_iter)
    except TypeError:
        return _check_criteria(tol, rtol, ftol, max_iter)


@functools.lru_cache(maxsize=256, typed=True)
def _checked_criteria(tol: float, rtol: float, ftol: float | None, max_iter: int) -> Criteria:
    return _check_criteria(tol, rtol, ftol, max_iter)


def _check_criteria(tol: float, rtol: float, ftol: float | None, max_iter: int) -> Criteria:
    tol = check_number("tol", tol, positive=True, allow_zero=False)
    rtol = check_number("rtol", rtol, positive=True)
    if ftol is not None:
        ftol = check_number("ftol", ftol, positive=True, allow_zero=False)
    if isinstance(max_iter, bool) or not isinstance(max_iter, int) or max_iter < 1:
        raise InputError(f"max_iter must be an integer >= 1, got {max_iter!r}")
    if max_iter > MAX_ITER_LIMIT:
        raise InputError(f"max_iter must be at most {MAX_ITER_LIMIT:,}, got {_short_int(max_iter)}: "
                         "a run that has not converged by then will not")
    return Criteria(tol, rtol, ftol, max_iter)


def _problem(f: Callable[[float], float] | ScalarProblem, fprime: Any, g: Any) -> ScalarProblem:
    if isinstance(f, ScalarProblem):
        p = f
        if fprime is not None or g is not None:
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
    if (method == "newton" and not record and type(f) is ScalarProblem and fprime is None
            and type(x0) is float and x0 - x0 == 0.0 and f.fprime is not None):
        # the common case, without the general front door: a problem with its
        # derivative and a finite start
        return _newton_lean(f, x0, check_criteria(tol, rtol, ftol, max_iter))
    if method not in SCALAR_METHODS:
        raise InputError(f"unknown method {method!r}; choose from {', '.join(SCALAR_METHODS)}")
    crit = check_criteria(tol, rtol, ftol, max_iter)
    check_callable("fprime", fprime)
    check_callable("g", g)
    problem = _problem(f, fprime, g)
    guess = problem.guess
    m: Any
    if method in ("bisection", "regula-falsi", "hybrid"):
        if bracket is None:
            if guess is None:
                raise InputError(f"{method} needs a bracket (a, b) with a sign change of f")
            bracket = guess
        a, b = check_reals("bracket", bracket, 2, ("start", "end"))
        if a == b:
            raise InputError(f"the bracket ends are equal ({a!r}); give an interval")
        cls = _method_class(method)
        m = cls(crit.tol, crit.rtol) if method == "hybrid" else cls()
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
            m = _method_class("secant")()
            args = (x0, x1)
            start = {"x0": x0, "x1": x1}
        elif method == "newton":
            if problem.fprime is None:
                raise InputError("newton needs the derivative fprime")
            return _newton_lean(problem, x0, crit, record)
        else:
            if problem.g is None:
                raise InputError("fixed-point needs the iteration function g (x = g(x))")
            m = _method_class("fixed-point")(evaluate_f=crit.ftol is not None)
            args = (x0,)
            start = {"x0": x0}
    try:
        state = m.init(problem, *args)
        if "bracket" in start:
            # f at the bracket's ends, known from init: the discontinuity check reuses them
            start["f_ends"] = (state.fa, state.fb) if hasattr(state, "fa") else (state.fpre, state.fx)
    except TypeError:
        return Result(method=m.name, x=args[0], status=Status.DOMAIN_ERROR, iterations=0, nfev=0,
                      error=math.inf, residual=None, detail="at the start: f returned a non-real value",
                      history=History((), (), 0) if record else None,
                      meta={"var": problem.var, "unit": problem.unit, "title": problem.title,
                            "tol": crit.tol, "rtol": crit.rtol, **start})
    except (ArithmeticError, ValueError) as exc:
        status, detail = explain(exc)
        return Result(method=m.name, x=args[0], status=status, iterations=0, nfev=0,
                      error=math.inf, residual=None, detail=f"at the start: {detail}",
                      history=History((), (), 0) if record else None,
                      meta={"var": problem.var, "unit": problem.unit, "title": problem.title,
                            "tol": crit.tol, "rtol": crit.rtol, **start})
    # a g (or f') that returns something other than a number fails inside the loop: name it
    return guarded(lambda: finish(m, problem, state, crit, record, start),
                   lambda: _diagnose_scalar(problem, args[0],
                                            lambda p: finish(m, p, state, crit, record, start)))


def _diagnose_scalar(problem: ScalarProblem, x0: float, rerun: Callable[[ScalarProblem], Any]) -> None:
    """InputError naming the user function that returns a non-number, at x0 or (by a
    re-run with every value checked) where the failed run met it."""
    named = [(name, fn) for name, fn in (("f", problem.f), ("fprime", problem.fprime), ("g", problem.g))
             if fn is not None]
    for name, fn in named:
        try:
            value = fn(x0)
        except Exception:
            continue
        real_result(name, value, f"at x = {x0!r}")

    def checked(name: str, fn: Any) -> Any:
        def call(x: float) -> Any:
            value = fn(x)
            try:
                real_result(name, value, f"at x = {x!r}")
            except InputError as exc:
                raise _BadReturn(str(exc)) from None
            return value
        return call

    try:
        rerun(replace(problem, **{name: checked(name, fn) for name, fn in named}))
    except _BadReturn as exc:
        raise InputError(str(exc)) from None
    except (TypeError, IndexError):
        return  # not the user's functions: the original error stands


_METHOD_MODULES = {"bisection": (".methods.bisection", "Bisection"),
                   "regula-falsi": (".methods.regula_falsi", "RegulaFalsi"),
                   "hybrid": (".methods.hybrid", "Hybrid"), "secant": (".methods.secant", "Secant"),
                   "fixed-point": (".methods.fixed_point", "FixedPoint")}
_METHOD_CLASSES: dict[str, Any] = {}


def _method_class(name: str) -> Any:
    """A scalar method's class, imported on its first use (an import statement inside a
    function costs almost a microsecond on every call; a dictionary lookup does not)."""
    cls = _METHOD_CLASSES.get(name)
    if cls is None:
        from importlib import import_module

        module, attr = _METHOD_MODULES[name]
        cls = _METHOD_CLASSES[name] = getattr(import_module(module, __package__), attr)
    return cls


_newton_loop: Any = None
"""linkage.methods.newton.newton_lean once a scalar Newton solve has loaded it (a sweep or
a system solve never does)."""


def _load_newton_loop() -> Any:
    global _newton_loop
    from .methods.newton import newton_lean

    _newton_loop = newton_lean
    return newton_lean


def _newton_lean(problem: ScalarProblem, x0: float, crit: Criteria, record: bool = False) -> Result:
    """Newton by the tight loop of :func:`~linkage.methods.newton.newton_lean`, packaged
    exactly as :func:`finish` packages the generic loop's outcome (history included when
    ``record``)."""
    extra = [0]

    def certify(x: float, fx: float, width: float) -> tuple[Status, str]:
        verdict, why, n = certify_root(problem, x, fx, width)
        extra[0] += n
        return verdict, why

    rows = Rows() if record else None
    try:
        loop = _newton_loop or _load_newton_loop()
        x, fx, err, status, detail, k = loop(problem, x0, crit.tol, crit.rtol, crit.ftol, crit.max_iter,
                                             certify, rows)
    except TypeError:  # the generic path's answer to a non-real f at the start
        return Result(method="newton", x=x0, status=Status.DOMAIN_ERROR, iterations=0, nfev=0,
                      error=math.inf, residual=None, detail="at the start: f returned a non-real value",
                      history=History((), (), 0) if record else None,
                      meta={"var": problem.var, "unit": problem.unit, "title": problem.title,
                            "tol": crit.tol, "rtol": crit.rtol, "x0": x0})
    except (ArithmeticError, ValueError) as exc:
        status, detail = explain(exc)
        return Result(method="newton", x=x0, status=status, iterations=0, nfev=0, error=math.inf,
                      residual=None, detail=f"at the start: {detail}",
                      history=History((), (), 0) if record else None,
                      meta={"var": problem.var, "unit": problem.unit, "title": problem.title,
                            "tol": crit.tol, "rtol": crit.rtol, "x0": x0})
    result = Result.fast("newton", x, status, k, 1 + 2 * k + extra[0], err, fx, detail,
                         {"var": problem.var, "unit": problem.unit, "title": problem.title,
                          "tol": crit.tol, "rtol": crit.rtol, "ftol": crit.ftol, "x0": x0})
    if rows is not None:
        from .methods.newton import Newton

        labels = column_labels(Newton(), problem.var, problem.unit, problem.u is not None,
                               problem.gprime is not None)
        result.__dict__["history"] = History.of(labels, rows, len(labels) - 1)
    return result


@functools.lru_cache(maxsize=128)
def column_labels(m: Any, var: str, unit: str, has_u: bool, has_gprime: bool) -> tuple[str, ...]:
    """A method's table headers for a problem's names and units (computed once)."""
    from .problems.scalar import ScalarProblem as _P

    shape = _P(f=abs, var=var, unit=unit, u=abs if has_u else None, gprime=abs if has_gprime else None)
    return tuple(c.label(var, unit) for c in m.columns(shape))


def check_sign_change(problem: ScalarProblem, x: float, fx: float | None, lo: float, hi: float,
                      f_ends: tuple[float, float], detail: str,
                      shrink_from: float | None = None) -> tuple[Status, str, int]:
    """A bracket [lo, hi] with a sign change that closed on a root has a small residual;
    one that closed on a jump or a pole does not. When |f| at x is not far below its size
    at ``f_ends``, bisect [lo, hi] further, keeping the sign change, until |f| falls to
    1e-3 of that size (the same shortcut as above: at a root it does, after a few
    halvings whatever point x the method ended on), at most down to the rounding level;
    at a jump |f| stays, at a pole it grows or f cannot be evaluated.
    ``shrink_from``: for the certification of an open method's small step, the size |f|
    must instead fall 16 times below (|f| at the ends of [x - w, x + w], which lie next
    to x)."""
    if fx is None or fx == 0.0:
        return Status.CONVERGED_STEP, detail, 0
    start_size = max(abs(f_ends[0]), abs(f_ends[1]))
    if not math.isfinite(start_size) or abs(fx) <= 1e-3 * start_size:
        return Status.CONVERGED_STEP, detail, 0
    lo, hi = sorted((lo, hi))
    if 0.0 in f_ends:
        return Status.CONVERGED_STEP, detail, 0  # f is exactly zero at an end: a root there
    if hi - lo <= 64.0 * math.ulp(max(abs(lo), abs(hi))):
        # A sign change within a few ulps with |f| still above 1e-3 of its size at the
        # ends (the shortcut above did not take it): a root's |f| at the floats next to
        # it is its slope times an ulp, far below that unless the user's bracket was
        # itself a few thousand ulps wide. So this is a jump, or a pole when |f| grew.
        # (An open method's certificate interval is only its tolerance wide, a few ulps
        # at tight tolerances: there only |f| above the ends, a pole, is held against it.)
        if shrink_from is not None and abs(fx) <= start_size:
            return Status.CONVERGED_STEP, detail, 0
        kind = "a pole" if abs(fx) > start_size else "a jump"
        return (Status.DISCONTINUITY, f"|f| is {abs(fx):.3g} at x = {x!r} across a sign change a few ulps "
                f"wide ({start_size:.3g} at the bracket's ends): f changes sign through {kind}", 0)
    target = 1e-3 * start_size if shrink_from is None else shrink_from / 16.0
    evals = 0
    ulp = math.ulp(max(abs(lo), abs(hi)))
    seen = [(x, fx)]
    try:
        flo = problem.f(lo)
        evals = 1
        seen.append((lo, flo))
        smallest = abs(fx)
        for _ in range(64):
            mid = 0.5 * lo + 0.5 * hi
            if hi - lo <= 64.0 * ulp or mid in (lo, hi):
                break
            fm = problem.f(mid)
            evals += 1
            if fm == 0.0:
                return Status.CONVERGED_STEP, detail, evals
            seen.append((mid, fm))
            if abs(fm) < smallest:
                smallest = abs(fm)
                if smallest <= target:
                    return Status.CONVERGED_STEP, detail, evals
            if (fm < 0.0) == (flo < 0.0):
                lo, flo = mid, fm
            else:
                hi = mid
    except (ArithmeticError, ValueError) as exc:
        return (Status.DISCONTINUITY, f"f cannot be evaluated inside the final bracket ({exc}): a pole or "
                f"a gap, not a root", evals)
    # |f| that does not shrink may be rounding noise around a root (an ill-conditioned
    # root such as an expanded (x - 1)^3), not a jump: f's own noise next to a point
    # tells. After a bracketing method the point must lie a million ulps clear of the
    # sign change, or its neighbours would read f across a jump (the noise band of such
    # a root is far wider); an open method's interval is only its tolerance wide, and
    # its own best point is read.
    clear = seen if shrink_from is not None else [
        (v, fv) for v, fv in seen if min(abs(v - lo), abs(v - hi)) > 1e6 * ulp]
    if clear:
        x_small, f_small = min(clear, key=lambda p: abs(p[1]))
        noise, n = at_noise_level(problem, x_small, f_small, abs(hi - lo) + 1.0)
        evals += n
        if noise:
            return Status.CONVERGED_STEP, detail, evals
    return (Status.DISCONTINUITY,
            f"|f| is {abs(fx):.3g} at x = {x!r} and does not shrink with the bracket", evals)


def at_noise_level(problem: ScalarProblem, x: float, fx: float, width: float) -> tuple[bool, int]:
    """Whether f(x) is indistinguishable from zero by f's own evaluation noise: f at the
    floats next to x (up to 4 each side, within ``width``) changes sign, or |f(x)| is
    within the spread of those values. (A jump or a pole has values that are steady, or
    smooth, next to x; a root's are rounding noise.) Returns (verdict, evaluations)."""
    near = []
    evals = 0
    for direction in (math.inf, -math.inf):
        t = x
        for _ in range(4):
            t = math.nextafter(t, direction)
            if abs(t - x) > width:
                break
            v = _value(problem.f, t)
            evals += 1
            if v is not None:
                near.append(v)
    if not near:
        return False, evals
    if any(v == 0.0 or (v < 0.0) != (fx < 0.0) for v in near):
        return True, evals
    return abs(fx) <= max(*near, fx) - min(*near, fx), evals


def _final_bracket(state: Any) -> tuple[float, float]:
    if hasattr(state, "xblk"):
        return state.x, state.xblk
    return state.a, state.b


def _value(f: Callable[[float], float], x: float) -> float | None:
    try:
        v = f(x)
    except (ArithmeticError, ValueError, TypeError):
        return None
    return v if isinstance(v, float) and math.isfinite(v) else None


_BIG = sys.float_info.max


def certify_root(problem: ScalarProblem, x: float, fx: float | None, width: float) -> tuple[Status, str, int]:
    """Evidence that a root of f lies within ``width`` of x, for an open method's small step.

    Accepted: |f(x)| within its own rounding bound (``problem.fbound``: f is zero to the
    precision it can be computed with), or a sign change of f across [x - width, x + width]
    that is not a jump or a pole (:func:`check_sign_change`). Otherwise ``STALLED``: a
    small step is only a symptom (Newton near a pole, an overflowing power, a flat f).
    Returns (status, detail, extra evaluations of f).
    """
    if not isinstance(fx, (int, float)) or not math.isfinite(fx):
        return Status.STALLED, f"f = {fx!r} at the last iterate", 0
    if fx == 0.0:
        return Status.CONVERGED_STEP, "", 0
    if problem.fbound is not None:
        bound = _value(problem.fbound, x)
        if bound is not None and abs(fx) <= bound:
            return Status.CONVERGED_STEP, "", 0
    lo, hi = max(x - width, -_BIG), min(x + width, _BIG)
    flo, fhi = _value(problem.f, lo), _value(problem.f, hi)
    evals = 2
    if flo is not None and fhi is not None and (flo == 0.0 or fhi == 0.0 or (flo < 0.0) != (fhi < 0.0)):
        ends = max(abs(flo), abs(fhi))
        status, detail, extra = check_sign_change(problem, x, fx, lo, hi, (flo, fhi), "", ends)
        return status, detail, evals + extra
    # No sign change across the whole interval: look inside it, on both sides of x (a root
    # pair, or a root where f is rounding noise and the ends happen to share a sign).
    for a, fa in ((lo, flo), (hi, fhi)):
        for frac in (0.5, 0.25, 0.125):
            b = x + (a - x) * frac
            fb = _value(problem.f, b)
            evals += 1
            if fb is not None and (fb == 0.0 or (fb < 0.0) != (fx < 0.0)):
                inner = sorted((x, b))
                status, detail, extra = check_sign_change(problem, x, fx, inner[0], inner[1], (fx, fb), "",
                                                          max(abs(fx), abs(fb)))
                return status, detail, evals + extra
        del fa
    if problem.fbound is None:
        # no rounding bound for a plain callable: read f's own noise next to x
        noise, n = at_noise_level(problem, x, fx, width)
        evals += n
        if noise:
            return Status.CONVERGED_STEP, "", evals
    shown = ", ".join(f"f({v:.17g}) = {fv:.3g}" if fv is not None else f"f({v:.17g}) is undefined"
                      for v, fv in ((lo, flo), (hi, fhi)))
    return (Status.STALLED,
            f"f = {fx:.3g} at {problem.var} = {x!r}; no sign change within +-{width:.3g} ({shown})"
            + ("" if problem.fbound is None else " and |f| is above its rounding level"), evals)


def finish(m: Any, problem: ScalarProblem, state: Any, crit: Criteria, record: bool,
           start: dict[str, Any]) -> Result:
    """Run the loop from an initial state and package the outcome as a Result."""
    if state.stop is not None:
        status, detail = state.stop
        outcome_state, iterations, rows = state, 0, ([] if record else None)
    else:
        certify = None
        extra_evals = [0]
        if not m.bracketing:
            def certify(x: float, fx: Any, width: float) -> tuple[Status, str]:
                known = fx is not None
                if not known:
                    fx = _value(problem.f, x)
                verdict, why, n = certify_root(problem, x, fx, width)
                extra_evals[0] += n + (not known)
                return verdict, why
        if not record and hasattr(m, "run_lean"):
            # the method's own tight loop: the generic loop's outcome, without a state per step
            outcome_state, status, detail, iterations = m.run_lean(problem, state, crit, certify)
            rows = None
        else:
            outcome_state, status, detail, iterations, rows = run(m, problem, state, crit, record=record,
                                                                  certify=certify)
    nfev = m.init_evals + iterations * m.step_evals + (0 if state.stop is not None else extra_evals[0])
    x = outcome_state.x
    residual = outcome_state.fx
    if residual is None and status is not Status.INVALID_BRACKET:
        try:
            residual = problem.f(x)
            nfev += 1
        except (ArithmeticError, ValueError):
            residual = math.nan
    if status is Status.CONVERGED_STEP:
        if m.bracketing:
            if "f_ends" in start:
                lo, hi = _final_bracket(outcome_state)
                status, detail, extra = check_sign_change(problem, x, residual, lo, hi, start["f_ends"],
                                                          detail)
                nfev += extra
    history = None
    if rows is not None:
        labels = column_labels(m, problem.var, problem.unit, problem.u is not None,
                               problem.gprime is not None)
        history = History.of(labels, rows, len(labels) - 1)
    result = Result.fast(m.name, x, status, iterations, nfev, outcome_state.err, residual, detail,
                         {"var": problem.var, "unit": problem.unit, "title": problem.title,
                          "tol": crit.tol, "rtol": crit.rtol, "ftol": crit.ftol, **start})
    if history is not None:
        result.__dict__["history"] = history
    return result


# --- systems ------------------------------------------------------------------------------

SYSTEM_METHODS: tuple[str, ...] = ("newton", "newton-fd", "lm")

MAX_RELATIVE_TOL = 1e-2
"""The loosest tolerance a mechanism accepts: 1% of its size, or 0.01 rad (0.57 deg)."""


def _names_bad_callables(solve: Callable[..., Result]) -> Callable[..., Result]:
    """A TypeError or IndexError out of a system solve is, on valid input, an F or jac that
    returned the wrong kind of value (None, a string, a short list): name it (InputError).
    Costs a call frame, not a check, on every solve."""

    @functools.wraps(solve)
    def front_door(F: Any, x0: Any = None, **options: Any) -> Result:
        try:
            return solve(F, x0, **options)
        except RecursionError:
            raise InputError("F or jac recursed without end (RecursionError)") from None
        except (TypeError, IndexError):
            _diagnose_system(F, x0, options.get("jac"))
            _rerun_checked(solve, F, x0, options)
            raise

    return front_door


def _rerun_checked(solve: Callable[..., Result], F: Any, x0: Any, options: dict[str, Any]) -> None:
    """A bare F or jac that returned the wrong kind of value after x0: the same solve once
    more, each value they return checked, so the InputError names the function and the x."""
    if not callable(F) or hasattr(F, "names"):
        return
    try:
        n = len(check_reals("x0", x0))
    except InputError:
        return
    jac = options.get("jac")

    def checked(name: str, fn: Any, check: Any) -> Any:
        def call(x: Any) -> Any:
            value = fn(x)
            try:
                check(name, value, n, f"at x = {list(x)}")
                if len(value) != n:
                    raise InputError(f"{name} must return {n} numbers, got {len(value)} at x = {list(x)}")
            except InputError as exc:
                # past the solvers' handlers (an InputError is a ValueError, which they
                # report as a domain error)
                raise _BadReturn(str(exc)) from None
            return value
        return call

    try:
        solve(checked("F", F, real_vector), x0,
              **{**options, "jac": checked("jac", jac, real_matrix) if callable(jac) else jac})
    except _BadReturn as exc:
        raise InputError(str(exc)) from None
    except (TypeError, IndexError):
        return  # not the user's functions: the original error stands


class _BadReturn(Exception):
    """A user function's wrong return value, carried out of a checked re-run."""


def _diagnose_system(F: Any, x0: Any, jac: Any) -> None:
    """InputError naming F or jac when either returns a non-number or the wrong shape at x0."""
    fn, J = (F.F, jac or F.J) if hasattr(F, "F") and hasattr(F, "names") else (F, jac)
    x = x0 if x0 is not None else getattr(F, "x0", None)
    try:
        q = check_reals("x0", x)
    except InputError:
        return
    n = len(q)
    for name, f, check in (("F", fn, real_vector), ("jac", J, real_matrix)):
        if not callable(f):
            continue
        try:
            value = f(list(q))
        except (TypeError, IndexError, KeyError, AttributeError) as exc:
            raise InputError(f"{name} fails at x0 = {q}: {type(exc).__name__}: {exc}") from None
        except Exception:
            continue
        check(name, value, n, "at x0")


@_names_bad_callables
def solve_system(
    F: Callable[..., list[float]] | Any,
    x0: Sequence[float] | None = None,
    *,
    jac: Callable[..., list[list[float]]] | None = None,
    method: str = "newton",
    tol: float = 1e-6,
    rtol: float = 0.0,
    ftol: float | None = None,
    max_iter: int = 50,
    record: bool = True,
    fd_step: float | None = None,
    damped: bool = True,
    show_jacobian: bool = False,
) -> Result:
    """Solve Phi(q) = 0 for n unknowns: ``newton`` (analytic Jacobian ``jac``),
    ``newton-fd`` (forward differences with step ``fd_step``) or ``lm``
    (Levenberg-Marquardt on the sum of squares).

    ``F`` is a callable of a sequence, or a :class:`~linkage.problems.system.SystemProblem`
    (for instance ``linkage.load_mechanism(path).problem()``), which supplies the
    Jacobian, names, units and a default ``x0``. ``x0`` is in internal units (radians).
    Converges when max|dq| <= tol + rtol max|q| and max|Phi| <= ftol (ftol defaults to
    tol), as in worked example P3, docs/worked_examples.md. For a mechanism both are relative to its size
    (``problem.length_scale``, its longest length): Phi and length steps are compared
    with tol times that size, so units do not change the answer, and tolerances above
    MAX_RELATIVE_TOL are refused. ``damped`` (default) globalises Newton (see
    :class:`~linkage.methods.newton_system.NewtonSystem`); ``damped=False`` is the
    textbook iteration.
    Returns a :class:`Result` with ``x`` (a tuple), ``nfev`` and ``njev``.
    """
    if (method == "newton" and not record and jac is not None and fd_step is None and type(x0) is tuple
            and len(x0) == 2 and type(x0[0]) is float and type(x0[1]) is float
            and x0[0] - x0[0] == 0.0 and x0[1] - x0[1] == 0.0 and callable(F)):
        # the common case without the general front door: user callables, two unknowns,
        # a finite start (the same outcome: tests/test_compile.py)
        return _newton_two(F, jac, x0, check_criteria(tol, rtol, ftol, max_iter), damped)
    NewtonSystem, max_abs, newton_system_lean, SystemProblem, generic_system = _system_solvers()
    if (method == "newton" and not record and jac is None and fd_step is None and type(F) is SystemProblem
            and len(F.names) == 2 and F.J is not None and F.step_scales is None):
        fast = _mechanism_two(F, x0, check_criteria(tol, rtol, ftol, max_iter), damped)
        if fast is not None:
            return fast
    if method not in SYSTEM_METHODS:
        raise InputError(f"unknown method {method!r} for a system; choose from {', '.join(SYSTEM_METHODS)}")
    crit = check_criteria(tol, rtol, ftol, max_iter)
    if fd_step is not None:
        fd_step = check_number("fd_step", fd_step, positive=True, allow_zero=False)
    if isinstance(F, SystemProblem):
        problem = F if jac is None else replace(F, J=jac)
        if x0 is None:
            x0 = problem.x0
    else:
        if not callable(F):
            raise InputError(f"F must be callable or a SystemProblem, got {type(F).__name__}")
        if x0 is None:
            raise InputError("x0 is required for a bare residual function")
        x0 = check_reals("x0", x0)
        if not x0:
            raise InputError("x0 must hold at least one value (a system of no unknowns has nothing to solve)")
        problem = generic_system(F, len(x0), jac)
    check_callable("jac", jac)
    if x0 is None:
        raise InputError(f"x0 needs {problem.n} values ({', '.join(problem.names)}), got 0")
    checked = check_reals("x0", x0, None, problem.names)  # finite floats, each entry named
    if len(checked) != problem.n:
        raise InputError(f"x0 needs {problem.n} values ({', '.join(problem.names)}), got {len(checked)}")
    q0 = tuple(checked)
    if problem.length_scale != 1.0 or "length" in problem.kinds or problem.length_unit:
        for name, value in (("tol", crit.tol), ("ftol", crit.ftol)):
            if value is not None and value > MAX_RELATIVE_TOL:
                raise InputError(f"{name} = {value:g} is too loose to mean anything: for a mechanism "
                                 f"it is relative to its size ({problem.length_scale:g} "
                                 f"{problem.length_unit}); use at most {MAX_RELATIVE_TOL:g}")
    if method == "newton" and problem.J is None:
        raise InputError("newton needs the Jacobian jac; use method='newton-fd' to difference it")
    kind = "fd" if method == "newton-fd" or problem.J is None else "analytic"
    if method == "lm":
        from .methods.least_squares import LevenbergMarquardt

        m: Any = LevenbergMarquardt(kind, fd_step, diagnostics=record)
    else:
        m = NewtonSystem(kind, fd_step, damped, diagnostics=record)
    try:
        phi0 = problem.F(list(q0))
    except (ArithmeticError, ValueError) as exc:
        raise InputError(f"the residual cannot be evaluated at x0: {exc}") from None
    real_vector("F", phi0, problem.n, "at x0")
    if len(phi0) != problem.n:
        raise InputError(f"the system has {len(phi0)} equations for {problem.n} unknowns")
    gate = residual_gate(crit.ftol if crit.ftol is not None else crit.tol, problem.length_scale)
    rows = None
    if method == "newton" and kind == "analytic" and not record:
        q, phi, err, status, detail, iterations, nfev, njev = newton_system_lean(
            problem, q0, phi0, crit.tol, crit.rtol, gate, crit.max_iter, damped)
        x, stopped = tuple(q), status in (Status.LOCAL_MINIMUM, Status.SINGULAR_JACOBIAN)
        residual = max_abs(phi)
    else:
        state = m.init(problem, q0, phi0) if isinstance(m, NewtonSystem) else m.init(problem, q0)
        run_crit = crit._replace(ftol=gate)
        final, status, detail, iterations, rows = run(m, problem, state, run_crit, record=record,
                                                      magnitude=max_abs)
        x, stopped, err = tuple(final.x), final.stop is not None, final.err
        nfev, njev = final.nfev, final.njev
        if hasattr(final, "phi_x"):  # Newton's last trial evaluated Phi at x already
            residual = max_abs(final.phi_x)
        else:
            try:
                residual = max_abs(problem.F(list(x)))
                nfev += 1
            except (ArithmeticError, ValueError):
                residual = math.nan
    status, detail = system_verdict(status, detail, residual, gate, stopped)
    meta: dict[str, Any] = {"tol": crit.tol, "rtol": crit.rtol, "ftol": gate, "names": problem.names,
                            "kinds": problem.kinds, "title": problem.title, **problem.meta}
    # The closed form serves the table's true-error column and the verdict on a failed
    # solve; a converged solve without history does not pay for it.
    wanted = problem.reference is not None and (record or not status.converged)
    reference = problem.reference() if wanted else None  # type: ignore[misc]
    if reference is not None:
        meta["reference"] = reference
        if not reference and not status.converged:
            reason = detail if status is Status.NO_SOLUTION else status.message
            driver = f"{problem.meta.get('driver')} = {problem.meta.get('driver_value'):g}"
            status, detail = (Status.NO_SOLUTION,
                              f"the linkage cannot be assembled at {driver} "
                              f"{problem.meta.get('driver_unit', '')} (the closed form has no real "
                              f"solution); {m.name}: {reason}")
    history = None
    if rows is not None:
        history = _system_history(m, problem, rows, show_jacobian, reference, x)
    result = Result.fast(m.name, x, status, iterations, nfev, err, residual, detail, meta)
    if history is not None or njev:
        result.__dict__.update(history=history, njev=njev)
    return result


@functools.lru_cache(maxsize=1)
def _system_solvers() -> tuple[Any, ...]:
    """The system solvers, imported on the first system solve (never by a scalar one;
    Levenberg-Marquardt only when asked for)."""
    from .methods.newton_system import NewtonSystem, max_abs, newton_system_lean
    from .problems.system import SystemProblem, generic_system

    return NewtonSystem, max_abs, newton_system_lean, SystemProblem, generic_system


@functools.lru_cache(maxsize=1)
def _two_unknowns() -> tuple[Any, ...]:
    """What :func:`_newton_two` needs, imported once (a scalar solve never pays for it)."""
    from .methods.newton_system import max_abs, newton_2x2
    from .problems.system import LeanProblem, generic_labels, generic_system

    return newton_2x2, max_abs, LeanProblem, generic_labels(2), generic_system


def system_verdict(status: Status, detail: str, residual: float, gate: float,
                   stopped: bool = True) -> tuple[Status, str]:
    """The verdict on a system solve from its loop's outcome and its final max|Phi|: a run
    the method stopped (no step lowers |Phi|, or J is singular) with |Phi| already within
    tolerance is a root to that tolerance (ill-conditioned, so the step test could not
    pass); a converged status with |Phi| above it is not."""
    if residual <= gate:
        if stopped and status in _STOPPED:
            return Status.CONVERGED_RESIDUAL, f"max|Phi| = {residual:.3g} <= {gate:.3g}; {detail}"
        return status, detail
    if status.converged:
        return Status.STALLED, f"max|Phi| = {residual:.3g} at the end, above {gate:.3g}"
    return status, detail


_STOPPED = frozenset({Status.LOCAL_MINIMUM, Status.SINGULAR_JACOBIAN})


def _two_unknown_result(problem: Any, q0: tuple[float, ...], phi0: Any, crit: Criteria, gate: float,
                        damped: bool, meta: dict[str, Any], loaded: tuple[Any, ...]) -> Result:
    """Newton on two unknowns by :func:`~linkage.methods.newton_system.newton_2x2`,
    judged and packaged as :func:`solve_system` does (``loaded``: :func:`_two_unknowns`)."""
    newton_2x2, max_abs = loaded[0], loaded[1]
    q, phi, err, status, detail, iterations, nfev, njev = newton_2x2(
        problem, q0, phi0, crit.tol, crit.rtol, gate, crit.max_iter, damped)
    residual = max_abs(phi)
    status, detail = system_verdict(status, detail, residual, gate)
    result = Result.fast("newton", tuple(q), status, iterations, nfev, err, residual, detail, meta)
    if njev:
        result.__dict__["njev"] = njev
    return result


def _newton_two(F: Callable[..., Any], jac: Callable[..., Any], x0: tuple[float, float], crit: Criteria,
                damped: bool) -> Result:
    """:func:`solve_system` for ``newton`` on user callables of two unknowns, with the
    general path's checks and packaging, but no problem object unless a step is refused."""
    loaded = _two_unknowns()
    _, _, LeanProblem, (names, kinds, _), generic_system = loaded
    try:
        phi0 = F(list(x0))
    except (ArithmeticError, ValueError) as exc:
        raise InputError(f"the residual cannot be evaluated at x0: {exc}") from None
    real_vector("F", phi0, 2, "at x0")
    if len(phi0) != 2:
        raise InputError(f"the system has {len(phi0)} equations for 2 unknowns")
    gate = crit.ftol if crit.ftol is not None else crit.tol
    problem = LeanProblem(F, jac, None, lambda: generic_system(F, 2, jac))
    meta = {"tol": crit.tol, "rtol": crit.rtol, "ftol": gate, "names": names, "kinds": kinds, "title": ""}
    return _two_unknown_result(problem, x0, phi0, crit, gate, damped, meta, loaded)


def _mechanism_two(problem: Any, x0: Any, crit: Criteria, damped: bool) -> Result | None:
    """:func:`solve_system` for ``newton`` on a compiled problem of two unknowns measured
    as they are (a four-bar), when it converges: the general path's checks and packaging
    without its generality. None for anything else (a start to check, a failure for the
    closed form to explain): the general path then runs and says what happened."""
    q0 = problem.x0 if x0 is None else x0
    if type(q0) is not tuple or len(q0) != 2 or not all(type(v) is float and v - v == 0.0 for v in q0):
        return None
    scale = problem.length_scale
    if scale != 1.0 or "length" in problem.kinds or problem.length_unit:
        if crit.tol > MAX_RELATIVE_TOL or (crit.ftol is not None and crit.ftol > MAX_RELATIVE_TOL):
            return None
    try:
        phi0 = problem.F(list(q0))
    except (ArithmeticError, ValueError):
        return None
    if len(phi0) != 2:
        return None
    gate = residual_gate(crit.ftol if crit.ftol is not None else crit.tol, scale)
    meta = {"tol": crit.tol, "rtol": crit.rtol, "ftol": gate, "names": problem.names, "kinds": problem.kinds,
            "title": problem.title, **problem.meta}
    result = _two_unknown_result(problem, q0, phi0, crit, gate, damped, meta, _two_unknowns())
    return result if result.converged else None


def _system_history(m: Any, problem: Any, rows: list[tuple[Any, ...]], show_jacobian: bool,
                    reference: dict[str, dict[str, float]] | None, x: tuple[float, ...]) -> History:
    from .problems.closed_form import wrap_degrees

    labels = [c.template for c in m.columns(problem, show_jacobian)]
    kept, elided, gap = rows.finish() if hasattr(rows, "finish") else (rows, 0, 0)
    out = []
    for r in kept:
        *head, jac, err = r
        body = list(head)
        if show_jacobian:
            body += [v for jr in jac for v in jr] if jac else [None] * (problem.n * problem.n)
        out.append((*body, err))
    branch = nearest_branch(problem, reference, x)
    if branch is not None:
        ref = reference[branch]  # type: ignore[index]
        labels.insert(-1, f"true error ({', '.join(sorted(set(problem.unit(i) for i in range(problem.n))))})"
                      f" vs {branch}")
        fixed = []
        for r in out:
            qd = r[1:1 + problem.n]
            errs = [abs(wrap_degrees(v - ref[n])) if k == "angle" else abs(v - ref[n])
                    for v, n, k in zip(qd, problem.names, problem.kinds)]
            fixed.append((*r[:-1], max(errs), r[-1]))
        out = fixed
    return History(tuple(labels), tuple(out), len(labels) - 1, elided, gap if elided else 0)


def nearest_branch(problem: Any, reference: dict[str, dict[str, float]] | None,
                   x: Sequence[float]) -> str | None:
    """The closed-form branch nearest to x (display units, angles compared mod 360)."""
    if not reference:
        return None
    from .problems.closed_form import wrap_degrees

    shown = problem.to_display(x)

    def distance(sol: dict[str, float]) -> float:
        return max(abs(wrap_degrees(v - sol[n])) if k == "angle" else abs(v - sol[n])
                   for v, n, k in zip(shown, problem.names, problem.kinds))

    return min(reference, key=lambda b: distance(reference[b]))
