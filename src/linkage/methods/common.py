"""Shared pieces of the scalar methods."""

from __future__ import annotations

import functools
from typing import TYPE_CHECKING, Any

from ..result import History, Status

if TYPE_CHECKING:  # loaded where a table is labelled: the system methods use new_state alone
    from ..problems.scalar import ScalarProblem

new_state = tuple.__new__
"""Build a NamedTuple state without its Python-level ``__new__``.

NamedTuple construction costs about 0.5 us against 0.15 us for this; a sweep makes
millions of steps, so states are built with ``new_state(Cls, (fields...))``.
"""


def same_sign(a: float, b: float) -> bool:
    """True when a and b are both > 0 or both < 0 (no product, so no underflow)."""
    return (a > 0.0 and b > 0.0) or (a < 0.0 and b < 0.0)


def display(fn: Any, x: float) -> float | None:
    """A value computed only for the table: a failure there must not end the solve."""
    try:
        return fn(x)
    except (ArithmeticError, ValueError, TypeError):
        return None


def start_stop(problem: Any, x0: float, fx: float) -> Any:
    """An open method's verdict on its start x0 with f(x0) = fx: (CONVERGED_EXACT or
    NON_FINITE, detail), or None to iterate."""
    if fx == 0.0:
        return (Status.CONVERGED_EXACT, f"f is zero at the start {problem.var} = {x0!r}")
    if fx != fx or abs(fx) == float("inf"):
        return (Status.NON_FINITE, f"f({problem.var}={x0:g}) = {fx!r}")
    return None


def history_of(m: Any, problem: ScalarProblem, rows: Any) -> History:
    """A scalar solve's ``Result.history`` from its loop's rows (a list or an
    :class:`~linkage.iterate.Rows`), built when first read."""
    labels = column_labels(m, problem.var, problem.unit, problem.u is not None, problem.gprime is not None)
    return History.of(labels, rows, len(labels) - 1)


@functools.lru_cache(maxsize=128)
def column_labels(m: Any, var: str, unit: str, has_u: bool, has_gprime: bool) -> tuple[str, ...]:
    """A method's table headers for a problem's names and units (computed once)."""
    from ..problems.scalar import ScalarProblem

    shape = ScalarProblem(f=abs, var=var, unit=unit, u=abs if has_u else None,
                          gprime=abs if has_gprime else None)
    return tuple(c.label(var, unit) for c in m.columns(shape))
