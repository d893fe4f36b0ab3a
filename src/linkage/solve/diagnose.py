"""Naming a user function that returns the wrong kind of value (InputError), for the
scalar and the system front doors."""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import replace
from typing import TYPE_CHECKING, Any

from ..arguments import check_reals, real_matrix, real_result, real_vector
from ..errors import InputError
from ..result import Result

if TYPE_CHECKING:  # annotations only: the system solve does not load the scalar problem type
    from ..problems.scalar import ScalarProblem


def diagnose_scalar(problem: ScalarProblem, x0: float, rerun: Callable[[ScalarProblem], Any]) -> None:
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

def names_bad_callables(solve: Callable[..., Result]) -> Callable[..., Result]:
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

