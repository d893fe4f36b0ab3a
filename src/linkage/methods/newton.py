"""Newton's method: x_{i+1} = x_i - f(x_i) / f'(x_i).

Order 2 near a simple root: e_{i+1} ~ (f''(r) / (2 f'(r))) e_i^2 (the student report, Newton
convergence analysis; the textbook section 3.9, eq. 4). Two evaluations per step (f and
f'), one more to start. Fails at f'(x) = 0 (stalls), near a local extremum (huge
jumps, P1 with x0 = 2.5), at inflection points (may cycle: x^3 - 2x + 2 from 0) and
where f flattens toward infinity (atan(x) from 1.5 diverges); multiple roots reduce
it to linear convergence. Which root it finds depends on x0 (P1).
Rows follow the student report (docs/worked_examples.md P2): i, x_i, f(x_i), f'(x_i), x_{i+1}, |x_{i+1}
- x_i|.
"""

from __future__ import annotations

from typing import Any, ClassVar

from ..iterate import HISTORY_HEAD, Loop, build_loop, dedent
from ..problems.scalar import ScalarProblem
from ..records import NamedTuple, frozen
from ..result import FAST_NAMES, Column, Status, fast_source
from .common import history_of, new_state, start_stop


class NewtonState(NamedTuple):
    x: float
    fx: float
    err: float
    stop: tuple[Status, str] | None
    xp: float
    fxp: float
    dfxp: float


@frozen
class Newton:
    name: ClassVar[str] = "newton"
    bracketing: ClassVar[bool] = False
    can_diverge: ClassVar[bool] = True
    needs_residual: ClassVar[bool] = False
    first_index: ClassVar[int] = 1
    init_evals: ClassVar[int] = 1
    step_evals: ClassVar[int] = 2

    def columns(self, problem: ScalarProblem) -> tuple[Column, ...]:
        return (
            Column("i", "index"),
            Column("{v}_i", "x"),
            Column("f({v}_i)", "f"),
            Column("f'({v}_i)", "df"),
            Column("{v}_i+1", "x"),
            Column("error", "x"),
        )

    def init(self, problem: ScalarProblem, x0: float) -> NewtonState:
        fx = problem.f(x0)
        stop = start_stop(problem, x0, fx)
        return NewtonState(x0, fx, float("inf"), stop, x0, fx, float("nan"))

    def step(self, problem: ScalarProblem, s: NewtonState) -> NewtonState:
        x = s.x
        fx = s.fx
        d = problem.fprime(x)  # type: ignore[misc]
        if d == 0.0:
            return new_state(NewtonState, (
                x, fx, float("nan"),
                (Status.ZERO_DERIVATIVE, f"f'({problem.var}) = 0 at {problem.var} = {x!r}, f = {fx:.6g}"),
                x, fx, d))
        x1 = x - fx / d
        return new_state(NewtonState, (x1, problem.f(x1), abs(x1 - x), None, x, fx, d))

    def initial_row(self, problem: ScalarProblem, s: NewtonState) -> None:
        return None

    def row(self, problem: ScalarProblem, s: NewtonState, i: int) -> tuple[Any, ...]:
        if s.stop is not None:
            return (i, s.xp, s.fxp, s.dfxp, None, None)
        return (i, s.xp, s.fxp, s.dfxp, s.x, s.err)


def _join(*parts: str) -> str:
    """Source fragments written at one indentation, joined and dedented together."""
    return dedent("".join(part.rstrip(" ") for part in parts))


def _packaged(record: bool, status: str, k: str, extra: str, err: str, detail: str, indent: int) -> str:
    """The loop's outcome as its Result (for the start's verdict and the loop's end),
    returned, as lines at ``indent`` spaces: ``k`` steps, each two evaluations, after the
    start's one, and ``extra`` made by the certificate; meta and history kept raw
    (:func:`linkage.result.fast_source`, the statements of :meth:`Result.fast`)."""
    history = "(_history, _method, problem, rows)" if record else None
    lines = fast_source('"newton"', "x", status, k, f"1 + 2 * {k} + {extra}", err, "fx", detail,
                        "(_meta, problem, crit, x0)", history)
    return "".join(" " * indent + line + "\n" for line in lines)


def newton_meta(problem: ScalarProblem, crit: tuple[Any, ...], x0: float) -> dict[str, Any]:
    """A Newton solve's ``Result.meta``, built when first read; ``crit`` the loop's: a
    :class:`~linkage.iterate.Criteria` or its values as a plain tuple (read by position)."""
    return {"var": problem.var, "unit": problem.unit, "title": problem.title,
            "tol": crit[0], "rtol": crit[1], "ftol": crit[2], "x0": x0}


def newton_loop(record: bool) -> Loop:
    """Newton's step around the ordered stopping rule, recording rows into ``rows`` (an
    :class:`~linkage.iterate.Rows`, required) when ``record``; without it the loop has no row
    bookkeeping (and ignores ``rows``). Both take the rule's quiet path
    (:func:`linkage.iterate.quiet_path`)."""
    name = "newton_lean" if record else "newton_quiet"
    return Loop(
        signature=f"{name}(problem, x0, crit, certify, rows=None)",
        setup=_join("""\
            append = rows.append  # the first HISTORY_HEAD rows, as Rows.add
            """ if record else "", """\
            tol, rtol, ftol, max_iter = crit
            f, fp = problem.f, problem.fprime
            x = x0
            fx = f(x)
            if fx == 0.0 or fx - fx != 0.0:  # the start's verdict (_start_stop) can only be a stop
                stop = _start_stop(problem, x0, fx)
                if stop is not None:
            """, _packaged(record, "stop[0]", "0", "0", "_inf", "stop[1]", 20), """\
            if isinstance(fx, float):
                best = start = abs(fx)
            else:  # the guard's start (test 5); best as the largest float: a finite bound
                best, start = _BIG, _inf
            err = _inf
            """),
        step=_join("""\
            d = fp(x)
            if d == 0.0:
            """, """\
                rows.add((k, x, fx, d, None, None))
            """ if record else "", """\
                err = _nan
                status = _S.ZERO_DERIVATIVE
                detail = f"f'({problem.var}) = 0 at {problem.var} = {x!r}, f = {fx:.6g}"
                break
            x1 = x - fx / d
            """, """\
            fx1 = f(x1)
            """ if record else """\
            fx = f(x1)  # its row is not kept: fx itself, left as it was if f raises
            """),
        after=_join("""\
            err = x1 - x if x1 >= x else x - x1  # |x1 - x| (the same bits), no second float
            """, """\
            if k <= _HEAD:
                append((k, x, fx, d, x1, err))
            else:
                rows.add((k, x, fx, d, x1, err))
            x, fx = x1, fx1
            """ if record else """\
            x = x1
            """),
        tail=_packaged(record, "status", "k", "extra", "err", "detail", 0),
        guard=True, step_test="certify", counted=True, diverge="streak", quiet=True)


NEWTON_LOOP = newton_loop(record=True)
"""Newton as one tight loop: the stopping rule of :mod:`linkage.iterate` around Newton's
step, without states or method dispatch; the generic loop's status, root, iteration count
and, into ``rows`` (an :class:`~linkage.iterate.Rows`), its table row for row
(tests/test_compile.py, tests/test_kernel.py). ``newton_lean(problem, x0, crit, certify,
rows)`` returns the solve's :class:`~linkage.result.Result` (its meta and history built when
first read); ``crit`` is a :class:`~linkage.iterate.Criteria` or its values as a plain tuple
(which unpacks faster); ``certify(problem, x, fx, width)`` decides a small step
(:func:`linkage.solve.certify_root`)."""

_NAMES = {"_start_stop": start_stop, "_meta": newton_meta, "_history": history_of, "_method": Newton(),
          **FAST_NAMES}
newton_lean = build_loop(NEWTON_LOOP, {**_NAMES, "_HEAD": HISTORY_HEAD}, fixed_source=True)

NEWTON_QUIET_LOOP = newton_loop(record=False)
newton_quiet = build_loop(NEWTON_QUIET_LOOP, _NAMES, fixed_source=True)
"""``newton_lean`` without rows (its ``rows`` is ignored): the same outcome, bit for bit."""
