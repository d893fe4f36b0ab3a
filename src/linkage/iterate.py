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
import os
import sys
from collections import deque
from collections.abc import Callable
from types import CodeType
from typing import Any

from .records import NamedTuple
from .result import STATUS_MEMBERS, Status
from .rules import counts_after, state_after, step_limit, system_converged_source, worse_than_seen

UNCERTIFIED_LIMIT = 4
"""Small steps without evidence of a root after which an open scalar method stops."""

DIVERGE_STREAK = 5
"""Consecutive growing steps after which an open method is declared diverged."""

RUNAWAY = 1e8
"""For systems, growing steps are divergence only once |q| exceeds this times 1 + |q0|."""

ROUNDING = 4.0 * sys.float_info.epsilon
"""Relative size of a step that is indistinguishable from rounding noise (a power of two:
:func:`scalar_quiet_path` divides by it exactly)."""

MAX_ITER_LIMIT = 100_000
"""The largest iteration cap accepted: a run that has not converged by then never will."""

HISTORY_HEAD = 200
HISTORY_TAIL = 300
"""Rows kept from the start and from the end of a long recorded run."""


class Rows(list):  # type: ignore[type-arg]
    """Recorded rows with a fixed ceiling: the head in the list, the tail in a ring (made
    only when a run outgrows the head: a short run pays for no ring)."""

    tail: deque[tuple[Any, ...]] | None = None
    elided = 0

    def add(self, row: tuple[Any, ...]) -> None:
        if len(self) < HISTORY_HEAD:
            self.append(row)
            return
        tail = self.tail
        if tail is None:
            tail = self.tail = deque(maxlen=HISTORY_TAIL)
        if len(tail) == HISTORY_TAIL:
            self.elided += 1
        tail.append(row)

    def finish(self) -> tuple[list[tuple[Any, ...]], int, int]:
        """(rows, elided, index in rows where the gap is)."""
        return [*self, *(self.tail or ())], self.elided, len(self)


# A NamedTuple, not a frozen dataclass: built once per class at import, it costs
# 0.1 ms against 0.7 ms, and every command's start pays for its classes.
class Criteria(NamedTuple):
    """Stopping rules. ``tol``/``rtol``: step tolerances; ``ftol``: residual tolerance."""

    tol: float = 1e-6
    rtol: float = 0.0
    ftol: float | None = None
    max_iter: int = 100


STEPS = range(1, Criteria().max_iter + 1)  # k = 1..max_iter at the default cap: the loops' one range
Outcome = tuple  # (final state, Status, detail, iterations, Rows or None)


def judge_certificate(verdict: Status, why: str, uncertified: int) -> tuple[Status | None, str, int]:
    """Test 5's certification, shared by the generic and the lean loops: after a step
    within the tolerance, (the status to stop with, or None to go on; its detail; the
    updated count of small steps without evidence)."""
    if verdict is STATUS_MEMBERS.CONVERGED_STEP:
        return verdict, "", uncertified
    uncertified += 1
    if verdict is not STATUS_MEMBERS.STALLED or uncertified >= UNCERTIFIED_LIMIT:
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


# --- the ordered stopping rule, and the loops generated from it ----------------------------------
#
# Tests 2-8 above are written once, here, as source text (:func:`stopping_tests`). Every loop -
# the generic one (:func:`run`), the scalar methods' tight loops (:mod:`linkage.methods`), the
# systems' Newton and the compiled models' Newton for two unknowns
# (:mod:`linkage.methods.newton_two`) - is generated from it around the method's own step
# (:class:`Loop`) and compiled once per process, so the order lives in one place and the tight
# loops pay for no call per test. ``loop_source`` prints what runs.

_CONVERGED_NAMES = frozenset({"CONVERGED_STEP", "CONVERGED_EXACT", "CONVERGED_RESIDUAL"})


SCALAR_MAGNITUDE = "(x if x >= 0.0 else -x)"
"""|x| of a scalar iterate, as a loop's source computes it."""


class Loop(NamedTuple):
    """A method's part of a generated loop; the stopping tests are :func:`stopping_tests`'.

    The step (``step``, inside the ``try`` whose arithmetic and domain errors end the run
    as ``explain`` names them; then ``after``) leaves in ``x`` the new iterate, in ``fx``
    its residual (``None`` when not evaluated; for a system max|Phi| at the point the step
    was taken from) and in ``err`` the method's error measure; it may end the run itself
    (test 1) with ``status, detail = ...; break``. ``setup`` runs before the loop and
    must set ``x``, ``fx``, ``err`` (and ``best``, ``start`` with ``guard``, ``runaway``
    with ``diverge == "runaway"``). A certifying loop calls ``certify(x, fx, limit)``.
    """

    signature: str
    setup: str = ""
    step: str = ""
    after: str = ""
    result: str = "x, fx, err, status, detail, k"
    tail: str = ""
    """Source after the loop in place of ``return result`` (which it must do itself)."""
    fx_optional: bool = False
    residual_test: bool = True
    """Test 4, |f| <= ftol (scalar problems; a system's residual is part of test 5)."""
    plausible: str = ""
    """An expression: a small step is convergence only where it holds (test 5)."""
    guard: bool = False
    """The open scalar methods' guard (:func:`linkage.rules.worse_than_seen`, test 5)."""
    step_test: str = "converged"
    """Test 5's verdict on a small step: ``converged``, ``certify``, ``system`` (with the
    residual gate) or ``minimizes`` (``system``, and a stall is a local minimum)."""
    counted: bool = False
    """With ``certify``: the loop calls ``certify(problem, x, fx, limit)`` in the form of
    :func:`linkage.solve.certify_root` (status, detail, evaluations of f it made) and adds
    the evaluations up in ``extra`` (no closure per solve to count them)."""
    diverge: str = ""
    """Test 6: ``""`` (a bracket cannot diverge), ``streak`` or ``runaway`` (systems)."""
    diverge_when: str = ""
    """An expression: test 6 runs only where it holds (``not damped``)."""
    magnitude: str = SCALAR_MAGNITUDE
    limit: str = "_step_limit(tol, rtol, ax) if rtol else tol"
    failure: str = ""
    """When given, every stop other than convergence runs this line instead (``return None``)."""
    on_raise: str = ""
    """Source run where the step raised (``exc``), before the run ends as ``explain`` names
    it: the loop's counts after it (:data:`linkage.rules.COUNTS_ON_RAISE`)."""
    quiet: bool = False
    """Emit :func:`quiet_path` before the tests (needs ``tol`` and ``rtol`` as names, and
    ``ftol`` with ``residual_test``)."""
    quiet_residual: str = ""
    """The quiet path's test that f is finite and not zero, in place of reading ``fx``: an
    expression that implies it (it may be false where f is; the tests then decide)."""
    quiet_rounding: str = ""
    """The quiet path's test that the error is above rounding, in place of
    ``err > _ROUNDING * magnitude``: an expression that, with the error above ``qtol``,
    implies it (it may be false where the test passes; the tests then decide)."""
    late: str = ""
    """Source after a step the quiet path did not continue from, before the tests: what
    they read that the step left uncomputed (with ``quiet_residual``, ``fx``)."""


class _Emitter:
    """Lines of loop source at the loop body's indentation, and a stop as ``loop`` says."""

    def __init__(self, loop: Loop) -> None:
        self.loop = loop
        self.lines: list[str] = []

    def put(self, level: int, text: str) -> None:
        self.lines.append("    " * (level + 2) + text)

    def stop(self, level: int, status: str, detail: str = '""') -> None:
        if self.loop.failure and status not in _CONVERGED_NAMES:
            self.put(level, self.loop.failure)
            return
        self.put(level, f"status, detail = _S.{status}, {detail}")
        self.put(level, "break")


def stopping_tests(loop: Loop) -> list[str]:
    """Tests 2-8 of the module docstring, in order, as the body of the loop after a step
    (indented for it), for ``loop``'s options."""
    out = _Emitter(loop)
    if loop.quiet:
        quiet_path(out)
    out.lines += _block(loop.late, 2)
    _value_tests(out)
    _step_test(out)
    _growth_tests(out)
    return out.lines


def quiet_path(out: _Emitter) -> None:
    """A step after which no test can fire, recognised in one condition and continued from
    with exactly the state the tests would leave (the guard's best |f|, no growth, the
    error as the previous one); any other step goes through tests 2-7 in order. Only
    without ``rtol`` and a residual test's ``ftol`` (``qtol``, the threshold the loop's
    preamble sets: ``tol`` where the path is allowed, else infinity, so the flag costs
    nothing per step). One chain of comparisons: the error above ``qtol`` (test 5, so
    neither the guard, the plausibility, a certificate nor a system's residual gate is
    consulted) and finite, by not being above the previous error where test 6 runs
    (``prev_err`` starts at the largest float and only ever holds finite errors), else by
    ``< inf``; f (a system's max|Phi|) finite and not zero (tests 2-4); the error above
    rounding (test 7). A value that does not compare as a real number (a complex f, a
    missing residual) raises TypeError here and takes the tests, which name it; any real
    number type takes the path a float would, with the same state after it.

    Written as one ``and`` of single comparisons, no chain (``qtol < err <= prev_err``):
    CPython 3.11 specialises a float comparison only where a jump follows it, so a chain's
    comparisons are generic (:func:`scalar_quiet_path`; ``err > qtol`` is ``qtol < err``
    reflected, the same verdict for every real number type)."""
    loop, put = out.loop, out.put
    if takes_scalar_quiet_path(loop):
        scalar_quiet_path(out)
        return
    finite_err = "err <= prev_err" if loop.diverge else "err < _inf"
    put(0, "try:")
    residual = loop.quiet_residual or QUIET_RESIDUAL
    rounding = loop.quiet_rounding or f"err > _ROUNDING * {loop.magnitude}"
    put(1, f"if err > qtol and {finite_err} and {residual} and {rounding}:")
    if loop.guard:
        put(2, "size = fx if fx >= 0.0 else -fx")
        put(2, "if size < best:")
        put(3, "best = size")
    if loop.diverge and loop.diverge_when:
        put(2, f"if {loop.diverge_when}:")
        put(3, "growth = 0")
    elif loop.diverge:
        put(2, "growth = 0")
    put(2, "prev_err = err")
    put(2, "continue")
    put(0, "except TypeError:")
    put(1, "pass")


QUIET_RESIDUAL = "fx > _ninf and fx < _inf and fx != 0.0"
"""The quiet path's default test that f is finite and not zero (``_ninf``, not ``-_inf``,
which would negate, making a float, at every test)."""


def takes_scalar_quiet_path(loop: Loop) -> bool:
    """An open scalar method's loop (the guard, a divergence streak, |x| as the magnitude,
    a residual after every step): its quiet path is :func:`scalar_quiet_path`."""
    return (loop.guard and loop.diverge == "streak" and not loop.fx_optional
            and loop.magnitude == SCALAR_MAGNITUDE)


def scalar_quiet_path(out: _Emitter) -> None:
    """:func:`quiet_path` for an open scalar method (Newton): comparisons only, each a test
    that cannot fire: the error above ``qtol`` (``tol`` where the path is allowed, else
    infinity, so the flag costs nothing per step) and not above the previous one (test 6;
    ``prev_err`` starts at the largest float, so this also says the error is finite);
    ``0 < |f| < best``: |f| finite, not zero (tests 2-4) and below the best seen, which it
    becomes (a step that does not improve |f| takes the tests, which give the same state);
    the error above rounding (test 7): implied by ``|x| < xcap``, where ``xcap`` is
    ``qtol / ROUNDING`` (exact: ROUNDING and its inverse, by which the preamble multiplies,
    are powers of two; so ``ROUNDING * |x| <= qtol < err``), else compared as test 7 does.
    A value that does not compare as a real number (a complex f) raises TypeError here and
    takes the tests, which name it; so any real number type takes the same path as a float
    would.

    Written as one ``and`` of single comparisons, no chain and no negated bound: CPython
    3.11 specialises a float comparison only where a jump follows it (a chain's middle
    comparison is generic), and ``-err`` or ``ROUNDING * x`` would make a float per step."""
    put = out.put
    put(0, "try:")
    put(1, "size = fx if fx >= 0.0 else -fx")
    put(1, "if (err > qtol and err <= prev_err and size < best and size > 0.0")
    put(1, "        and (x < xcap and x > nxcap or err > _ROUNDING * (x if x >= 0.0 else -x))):")
    put(2, "best = size")
    put(2, "growth = 0")
    put(2, "prev_err = err")
    put(2, "continue")
    put(0, "except TypeError:")
    put(1, "pass")


def _value_tests(out: _Emitter) -> None:
    """2. a non-finite error or residual; 3. an exact zero; 4. the residual test."""
    loop, put, stop = out.loop, out.put, out.stop
    # v - v is 0.0 for a finite float, NaN otherwise
    put(0, "if type(err) is float and type(fx) is float:")
    put(1, "finite = err - err == 0.0 and fx - fx == 0.0")
    put(0, "else:")
    put(1, "try:")
    put(2, "finite = _isfinite(err) and (fx is None or _isfinite(fx))")
    put(1, "except TypeError:  # e.g. (-8) ** (1/3) in a user's function is complex in Python")
    stop(2, "DOMAIN_ERROR", 'f"f returned a non-real value: {fx!r}"')
    put(0, "if not finite:")
    stop(1, "NON_FINITE", 'f"error = {err!r}, residual = {fx!r}"')
    level = 0
    if loop.fx_optional:
        put(0, "if fx is not None:")
        level = 1
    put(level, "if fx == 0.0:")
    stop(level + 1, "CONVERGED_EXACT")
    if loop.residual_test:
        put(level, "size = fx if fx >= 0.0 else -fx")
        put(level, "if ftol is not None and size <= ftol:")
        stop(level + 1, "CONVERGED_RESIDUAL")


def _step_test(out: _Emitter) -> None:
    """5. the step test, with the method's plausibility and the open methods' guard."""
    loop, put, stop = out.loop, out.put, out.stop
    put(0, f"ax = {loop.magnitude}")
    put(0, f"limit = {loop.limit}")
    if loop.plausible:
        put(0, f"if err <= limit and not ({loop.plausible}):")
        put(1, "limit = -1.0  # the method's own evidence says the small step is not convergence")
    if loop.guard:
        level = 0
        if loop.fx_optional:
            put(0, "if fx is not None:")
            level = 1
            put(1, "size = fx if fx >= 0.0 else -fx")
        # a small step to a point worse than one already seen, still of the order of the
        # start's |f|, is not convergence: the slope came from far away
        put(level, "if err <= limit and _worse(size, best, start):")
        put(level + 1, "limit = -1.0")
        put(level, "elif size < best:")
        put(level + 1, "best = size")
    put(0, "if err <= limit:")
    if loop.step_test == "converged":
        stop(1, "CONVERGED_STEP")
    elif loop.step_test == "certify":
        if loop.counted:
            put(1, "verdict, why, n = certify(problem, x, fx, limit)")
            put(1, "extra += n")
        else:
            put(1, "verdict, why = certify(x, fx, limit)")
        put(1, "verdict, why, uncertified = _judge(verdict, why, uncertified)")
        put(1, "if verdict is not None:")
        put(2, "status, detail = verdict, why")
        put(2, "break")
    else:  # systems: the step and the residual (linkage.rules.system_converged)
        put(1, f"if fx is not None and {system_converged_source('err', 'fx', 'limit', 'gate')}:")
        stop(2, "CONVERGED_STEP")
        if loop.step_test == "minimizes":
            stop(1, "LOCAL_MINIMUM", 'f"the least-squares residual stalls at {abs(fx or _nan):.3g}, '
                                     'above the tolerance {gate:.3g}"')


def _growth_tests(out: _Emitter) -> None:
    """6. divergence; 7. rounding noise that stops shrinking (8, the cap, is the loop's end)."""
    loop, put, stop = out.loop, out.put, out.stop
    if loop.diverge:
        level = 0
        if loop.diverge_when:
            put(0, f"if {loop.diverge_when}:")
            level = 1
        put(level, "growth = growth + 1 if err > prev_err else 0")
        far = " and ax > runaway" if loop.diverge == "runaway" else ""
        put(level, f"if growth >= _DIVERGE{far}:")
        stop(level + 1, "DIVERGED", 'f"{growth} growing steps, last {err:.3g}"')
    put(0, "if err <= _ROUNDING * ax:")
    put(1, "why, rounding_steps, stalls = _stall(err, prev_err, limit, rounding_steps, stalls)")
    put(1, "if why is not None:")
    stop(2, "PRECISION_LIMIT", "why")
    put(0, "prev_err = err")


def dedent(text: str) -> str:
    """``text`` without the indentation its non-blank lines share (textwrap.dedent's
    result for source fragments, without importing textwrap at a solve's start)."""
    lines = text.splitlines()
    margin = min((len(line) - len(line.lstrip()) for line in lines if line.strip()), default=0)
    end = "\n" if text.endswith("\n") else ""
    return "\n".join(line[margin:] if line.strip() else "" for line in lines) + end


def indent(text: str) -> str:
    """``text`` indented by one level (4 spaces) on its non-blank lines."""
    end = "\n" if text.endswith("\n") else ""
    return "\n".join("    " + line if line.strip() else "" for line in text.splitlines()) + end


def _block(text: str, level: int) -> list[str]:
    """Dedented ``text`` re-indented to ``level`` (4 spaces each)."""
    return [("    " * level + line) if line.strip() else "" for line in dedent(text).splitlines()]


_QUIET_FTOL = "ftol is None and "


def quiet_flag(loop: Loop) -> list[str]:
    """The preamble's line that allows the quiet path: without ``rtol`` and a residual
    test's ``ftol``, as the threshold ``qtol`` of :func:`quiet_path`."""
    allowed = f"{_QUIET_FTOL if loop.residual_test else ''}not rtol"
    lines = [f"    qtol = tol if {allowed} else _inf"]
    if takes_scalar_quiet_path(loop):  # |x| below which test 7 cannot fire (scalar_quiet_path)
        lines += ["    xcap = qtol * _PER_ROUNDING", "    nxcap = -xcap"]
    return lines


def loop_source(loop: Loop) -> str:
    """The source of the function ``loop`` describes: its setup, then for k = 1..max_iter
    its step and the ordered stopping tests, then test 8 (the cap) and its result."""
    lines = [f"def {loop.signature}:", *_block(loop.setup, 1),
             "    prev_err = _BIG",
             "    growth = uncertified = stalls = rounding_steps = k = " + ("extra = " * loop.counted) + "0",
             *(quiet_flag(loop) if loop.quiet else []),
             "    for k in (_STEPS if max_iter is _CAP else range(1, max_iter + 1)):",  # no range made
             "        try:", *_block(loop.step, 3),
             "        except (ArithmeticError, ValueError) as exc:"]
    if loop.failure:
        lines.append("            " + loop.failure)
    else:
        lines += [*_block(loop.on_raise, 3), "            status, detail = _explain(exc)",
                  "            k -= 1", "            break"]
    lines += _block(loop.after, 2)
    lines += [*stopping_tests(loop), "    else:  # test 8, the cap: every other stop breaks",
              '        status, detail = _S.MAX_ITER, ""']
    lines += _block(loop.tail, 1) if loop.tail else [f"    return {loop.result}"]
    return "\n".join(lines) + "\n"


LOOP_CACHE: str | None = os.path.join(os.path.dirname(__file__), "__pycache__")
"""Where the bytecode of the loops whose source this package's code fixes is kept between
runs (:func:`compiled`), beside the package's own; None: nowhere."""


def compiled(source: str, filename: str, fixed_source: bool) -> CodeType:
    """``compile(source, filename, "exec")``; where ``fixed_source`` (the source depends
    only on this package's code, so there are finitely many), kept between runs in
    :data:`LOOP_CACHE` (:func:`~linkage.files.compiled_kept`): compiling a loop takes 0.4 to
    1.3 ms, reading it back about 15 us, and a cold ``linkage solve`` compiles two. A
    source built from a mechanism's numbers (a model's loop) is never kept: there could be
    one per mechanism ever solved."""
    from .files import compiled_kept

    return compiled_kept(source, filename, LOOP_CACHE if fixed_source else None, "loop")


def build_loop(loop: Loop, names: dict[str, Any] | None = None, *,
               fixed_source: bool = False) -> Callable[..., Any]:
    """Compile ``loop``; ``names``: what its step reads besides the stopping tests' own;
    ``fixed_source``: the loop's source depends only on this package's code, and its
    bytecode may be kept between runs (:func:`compiled`)."""
    namespace: dict[str, Any] = {
        "_S": STATUS_MEMBERS, "_inf": math.inf, "_ninf": -math.inf, "_nan": math.nan,
        "_isfinite": math.isfinite, "_explain": explain, "_judge": judge_certificate,
        "_stall": rounding_stall, "_worse": worse_than_seen, "_step_limit": step_limit,
        "_DIVERGE": DIVERGE_STREAK, "_ROUNDING": ROUNDING, "_PER_ROUNDING": 1.0 / ROUNDING,
        "_BIG": sys.float_info.max, "_RUNAWAY": RUNAWAY, "_STEPS": STEPS, "_CAP": STEPS[-1],
        "_counts_after": counts_after, "_state_after": state_after, **(names or {})}
    name = loop.signature.split("(", 1)[0]
    exec(compiled(loop_source(loop), f"<linkage-loop {name}>", fixed_source), namespace)
    return namespace[name]  # type: ignore[no-any-return]


# --- the generic loop -------------------------------------------------------------------------

def generic_loop(can_diverge: bool, needs_residual: bool, minimizes: bool, plausible: bool,
                 certify: bool) -> Loop:
    """The generic loop for a method's flags: its step is ``method.step`` on a state."""
    return Loop(
        signature="generic(step, row, rows, index0, problem, state, tol, rtol, ftol, gate, max_iter, "
                  "plausible, magnitude, certify, best, start, runaway)",
        setup="x, fx, err = state.x, state.fx, state.err",
        step="new = step(problem, state)",
        after="""\
            state = new
            if rows is not None:
                rows.add(row(problem, state, k + index0))
            if state.stop is not None:
                status, detail = state.stop
                break
            x, fx, err = state.x, state.fx, state.err
            """,
        result="state, status, detail, k",
        on_raise="state = _state_after(exc, state)",
        fx_optional=True,
        residual_test=not needs_residual,
        plausible="plausible(state)" if plausible else "",
        guard=can_diverge and not needs_residual,
        step_test=("minimizes" if minimizes else "system") if needs_residual else
                  ("certify" if certify else "converged"),
        diverge=("runaway" if needs_residual else "streak") if can_diverge else "",
        magnitude="magnitude(x)",
    )


_GENERIC: dict[tuple[bool, ...], Callable[..., Any]] = {}


def run(
    method: Any,
    problem: Any,
    state: Any,
    crit: Criteria,
    *,
    record: bool,
    magnitude: Callable[[Any], float] = abs,
    certify: Callable[[float, Any, float], tuple[Status, str]] | None = None,
) -> Outcome:
    """Iterate ``method.step`` from ``state`` until a stopping test fires.

    States are tuples with at least the fields ``x``, ``fx`` (residual, ``None`` when
    not evaluated), ``err`` (the method's error measure, >= 0) and ``stop`` (``None`` or
    a ``(Status, detail)`` pair set by the step). ``certify(x, fx, limit)`` judges an open
    method's small step (test 5).
    """
    rows: Rows | None = None
    if record:
        rows = Rows()
        first = method.initial_row(problem, state)
        if first is not None:
            rows.add(first)
    needs_residual = method.needs_residual
    plausible = getattr(method, "plausible", None)
    flags = (method.can_diverge, needs_residual, getattr(method, "minimizes", False), plausible is not None,
             certify is not None)
    loop = _GENERIC.get(flags)
    if loop is None:
        loop = _GENERIC[flags] = build_loop(generic_loop(*flags), fixed_source=True)
    ftol = crit.ftol
    gate = (ftol if ftol is not None else crit.tol) if needs_residual else math.inf
    seen = [abs(v) for v in (state.fx, getattr(state, "fxp", None)) if isinstance(v, float) and v == v]
    best = min(seen) if seen else math.inf
    start = max(seen) if seen else math.inf
    runaway = RUNAWAY * (1.0 + magnitude(state.x))
    state, status, detail, k = loop(method.step, method.row, rows, method.first_index - 1, problem, state,
                                    crit.tol, crit.rtol, ftol, gate, crit.max_iter, plausible, magnitude,
                                    certify, best, start, runaway)
    return state, status, detail, k, rows
