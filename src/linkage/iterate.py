"""The one generic iteration loop. Methods supply ``init``/``step``/``row``; this owns the rest.

Stopping tests run after every step, in this fixed order (first match wins):

1. a failure the step itself reported (zero derivative, domain error, invalid or
   exhausted bracket, singular Jacobian);
2. a non-finite error or residual                                   -> ``NON_FINITE``;
3. an exact zero of the residual                                    -> ``CONVERGED_EXACT``;
4. the residual test ``|f| <= ftol`` (only when ``ftol`` is given)  -> ``CONVERGED_RESIDUAL``;
5. the step test ``err <= tol + rtol * |x|``                        -> ``CONVERGED_STEP``;
   for the open scalar methods (Newton, secant) not at a point whose |f| is worse than
   one already seen and still above 1e-8 of the start's (a tiny step from a far-away
   slope is not a root; differences at rounding level are), and only where the method
   finds its own step plausible (the secant: a local chord, see ``Secant.plausible``),
   and, when a ``certify`` test is given (the open scalar methods), only where it finds
   evidence of a root within the tolerance; without it the run goes on (a linearly
   converging iteration's step understates its error), and after ``UNCERTIFIED_LIMIT``
   small steps without evidence it ends as ``STALLED`` (or as what the test names);
   Methods with ``needs_residual`` (the systems) converge only when the step *and* the
   residual pass (P3: max|Phi| < eps and max|dq| < eps; ``ftol`` defaults to ``tol``);
   a small step with the residual above it continues, or, for methods that minimise
   the residual (``minimizes``), is ``LOCAL_MINIMUM`` (no root found from this start;
   ``NO_SOLUTION`` is kept for proven non-assembly, by a closed form);
6. growth of the error for ``DIVERGE_STREAK`` steps in a row        -> ``DIVERGED``
   (open methods only: a bracket cannot diverge; for systems only with the iterate
   running away past ``RUNAWAY`` times its starting size);
7. an error at rounding level that stops shrinking (twice), or six
   rounding-level steps, while still above the tolerance            -> ``PRECISION_LIMIT``;
8. the iteration cap                                                -> ``MAX_ITER``.

The step test mirrors the textbook section 3.9 (epsilon_s on the step, epsilon_e on the
residual) and, with ``ftol=None``, reproduces the Freudenstein tables row for row.
Recording is off unless asked for: with ``record=False`` no row is built. A recorded
history has a fixed ceiling: the first ``HISTORY_HEAD`` and the last ``HISTORY_TAIL`` rows
are kept and the count of rows left out between them is reported.
"""

from __future__ import annotations

import math
import sys
from collections import deque
from collections.abc import Callable
from typing import Any, NamedTuple

from .result import Status
from .rules import step_limit, system_converged, worse_than_seen

UNCERTIFIED_LIMIT = 4
"""Small steps without evidence of a root after which an open scalar method stops."""

DIVERGE_STREAK = 5
"""Consecutive growing steps after which an open method is declared diverged."""

RUNAWAY = 1e8
"""For systems, growing steps are divergence only once |q| exceeds this times 1 + |q0|."""

ROUNDING = 4.0 * sys.float_info.epsilon
"""Relative size of a step that is indistinguishable from rounding noise."""

_isfinite = math.isfinite

MAX_ITER_LIMIT = 100_000
"""The largest iteration cap accepted: a run that has not converged by then never will."""

HISTORY_HEAD = 200
HISTORY_TAIL = 300
"""Rows kept from the start and from the end of a long recorded run."""


class Rows(list):  # type: ignore[type-arg]
    """Recorded rows with a fixed ceiling: the head in the list, the tail in a ring."""

    def __init__(self) -> None:
        super().__init__()
        self.tail: deque[tuple[Any, ...]] = deque(maxlen=HISTORY_TAIL)
        self.elided = 0

    def add(self, row: tuple[Any, ...]) -> None:
        if len(self) < HISTORY_HEAD:
            self.append(row)
            return
        if len(self.tail) == HISTORY_TAIL:
            self.elided += 1
        self.tail.append(row)

    def finish(self) -> tuple[list[tuple[Any, ...]], int, int]:
        """(rows, elided, index in rows where the gap is)."""
        return [*self, *self.tail], self.elided, len(self)


# A NamedTuple, not a frozen dataclass: built once per class at import, it costs
# 0.1 ms against 0.7 ms, and every command's start pays for its classes.
class Criteria(NamedTuple):
    """Stopping rules. ``tol``/``rtol``: step tolerances; ``ftol``: residual tolerance."""

    tol: float = 1e-6
    rtol: float = 0.0
    ftol: float | None = None
    max_iter: int = 100


Outcome = tuple  # (final state, Status, detail, iterations, Rows or None)


def judge_certificate(verdict: Status, why: str, uncertified: int) -> tuple[Status | None, str, int]:
    """Test 5's certification, shared by the generic and the lean loops: after a step
    within the tolerance, (the status to stop with, or None to go on; its detail; the
    updated count of small steps without evidence)."""
    if verdict is Status.CONVERGED_STEP:
        return verdict, "", uncertified
    uncertified += 1
    if verdict is not Status.STALLED or uncertified >= UNCERTIFIED_LIMIT:
        return verdict, why, uncertified
    return None, "", uncertified


def rounding_stall(err: float, prev_err: float, limit: float, rounding_steps: int,
                   stalls: int) -> tuple[str | None, int, int]:
    """Test 7, shared by the generic and the lean loops, for a step at rounding level:
    (the PRECISION_LIMIT detail when the error stopped shrinking, else None; the counts)."""
    rounding_steps += 1
    stalls += err >= prev_err
    if stalls >= 2 or rounding_steps >= 6:
        return (f"error {err:.3g} is rounding noise; tolerance {limit:.3g} is out of reach",
                rounding_steps, stalls)
    return None, rounding_steps, stalls


def explain(exc: BaseException) -> tuple[Status, str]:
    if isinstance(exc, OverflowError):
        return Status.NON_FINITE, f"overflow: {exc}"
    if isinstance(exc, ZeroDivisionError):
        return Status.DOMAIN_ERROR, "division by zero"
    return Status.DOMAIN_ERROR, str(exc) or type(exc).__name__


def run(
    method: Any,
    problem: Any,
    state: Any,
    crit: Criteria,
    *,
    record: bool,
    magnitude: Callable[[Any], float] = abs,
    certify: Callable[[Any, float], tuple[Status, str]] | None = None,
) -> Outcome:
    """Iterate ``method.step`` from ``state`` until a stopping test fires.

    States are tuples with at least the fields ``x``, ``fx`` (residual, ``None`` when
    not evaluated), ``err`` (the method's error measure, >= 0) and ``stop`` (``None`` or
    a ``(Status, detail)`` pair set by the step).
    """
    rows: Rows | None = None
    if record:
        rows = Rows()
        first = method.initial_row(problem, state)
        if first is not None:
            rows.add(first)
    step = method.step
    row = method.row
    index0 = method.first_index - 1
    tol, rtol, ftol = crit.tol, crit.rtol, crit.ftol
    needs_residual = method.needs_residual
    minimizes = getattr(method, "minimizes", False)
    gate = (ftol if ftol is not None else tol) if needs_residual else math.inf
    can_diverge = method.can_diverge
    prev_err = math.inf
    check_best = can_diverge and not needs_residual  # the open scalar methods
    plausible = getattr(method, "plausible", None)
    seen = [abs(v) for v in (state.fx, getattr(state, "fxp", None)) if isinstance(v, float) and v == v]
    best_fx = min(seen) if seen else math.inf
    start_fx = max(seen) if seen else math.inf
    growth = 0
    runaway = RUNAWAY * (1.0 + magnitude(state.x))
    uncertified = 0
    stalls = 0
    rounding_steps = 0
    status = Status.MAX_ITER
    detail = ""
    k = 0
    for k in range(1, crit.max_iter + 1):
        try:
            new = step(problem, state)
        except (ArithmeticError, ValueError) as exc:
            status, detail = explain(exc)
            k -= 1
            break
        state = new
        if rows is not None:
            rows.add(row(problem, state, k + index0))
        if state.stop is not None:
            status, detail = state.stop
            break
        err = state.err
        fx = state.fx
        try:
            finite = _isfinite(err) and (fx is None or _isfinite(fx))
        except TypeError:
            # e.g. (-8) ** (1/3) in a user's function is complex in Python
            status, detail = Status.DOMAIN_ERROR, f"f returned a non-real value: {fx!r}"
            break
        if not finite:
            status, detail = Status.NON_FINITE, f"error = {err!r}, residual = {fx!r}"
            break
        if fx is not None:
            if fx == 0.0:
                status, detail = Status.CONVERGED_EXACT, ""
                break
            if ftol is not None and not needs_residual and abs(fx) <= ftol:
                status = Status.CONVERGED_RESIDUAL
                break
        x = state.x
        limit = step_limit(tol, rtol, magnitude(x)) if rtol else tol
        if err <= limit and plausible is not None and not plausible(state):
            limit = -1.0  # the method's own evidence says the small step is not convergence
        if check_best and fx is not None:
            size = abs(fx)
            if err <= limit and worse_than_seen(size, best_fx, start_fx):
                # A small step to a point worse than one already seen, with a residual
                # still of the order of the start's, is not convergence: the slope came
                # from far away (a secant chord through a huge f). Differences at rounding
                # level are allowed. Iterate on; a stall ends as precision_limit.
                limit = -1.0
            elif size < best_fx:
                best_fx = size
        if err <= limit:
            # systems: the step and the residual (linkage.rules, the one definition)
            if needs_residual and not (fx is not None and system_converged(err, abs(fx), limit, gate)):
                if minimizes:
                    status = Status.LOCAL_MINIMUM
                    detail = (f"the least-squares residual stalls at {abs(fx or math.nan):.3g}, "
                              f"above the tolerance {gate:.3g}")
                    break
            elif certify is not None:
                stop, why, uncertified = judge_certificate(*certify(state, limit), uncertified)
                if stop is not None:
                    status, detail = stop, why
                    break
            else:
                # The detail is formatted later from the result's fields: formatting here
                # would cost more than a whole Newton step.
                status = Status.CONVERGED_STEP
                break
        if can_diverge:
            growth = growth + 1 if err > prev_err else 0
            # a system's Newton may wander and recover (MGH, a mechanism far from its
            # assembly): only iterates running away are evidence of divergence
            if growth >= DIVERGE_STREAK and (not needs_residual or magnitude(x) > runaway):
                status, detail = Status.DIVERGED, f"{growth} growing steps, last {err:.3g}"
                break
        if err <= ROUNDING * magnitude(x):
            # Rounding noise: the error can no longer shrink in double precision.
            why, rounding_steps, stalls = rounding_stall(err, prev_err, limit, rounding_steps, stalls)
            if why is not None:
                status, detail = Status.PRECISION_LIMIT, why
                break
        prev_err = err
    return state, status, detail, k, rows
