"""``solve_system``: Phi(q) = 0 for n unknowns, validated once at the front door, with
short front doors for two unknowns (user callables, or a compiled mechanism)."""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any

from ..arguments import check_callable, check_fd_step, check_method, check_reals, real_vector
from ..errors import InputError
from ..iterate import Criteria, run
from ..result import FAST_NAMES, History, Raw, Result, Status, fast_source, given
from ..rules import residual_gate
from .criteria import MAX_RELATIVE_TOL, RecentCriteria, check_criteria
from .diagnose import names_bad_callables

# The system solvers load with the first system solve, never with a scalar one
# (python -X importtime: about 20 ms of every `linkage solve` otherwise).

# --- systems ------------------------------------------------------------------------------

SYSTEM_METHODS: tuple[str, ...] = ("newton", "newton-fd", "lm")


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
    if method == "newton" and not record and fd_step is None:
        ready = _ready
        if (ready[0] is F and ready[1] is jac and ready[2] is tol and ready[3] is rtol and ready[4] is ftol
                and ready[5] is max_iter and ready[6] is damped and (type(x0) is tuple or type(x0) is list)
                and len(x0) == 2):
            a, b = x0
            if type(a) is float and type(b) is float and a - a == 0.0 and b - b == 0.0:
                try:
                    return ready[7](ready, a, b)  # type: ignore[no-any-return]
                except (TypeError, IndexError, RecursionError):
                    return solve_general(F, x0, jac=jac, method=method, tol=tol, rtol=rtol, ftol=ftol,
                                         max_iter=max_iter, record=record, fd_step=fd_step, damped=damped,
                                         show_jacobian=show_jacobian)
        fast = fast_newton(F, x0, jac, tol, rtol, ftol, max_iter, damped)
        if fast is not None:
            return fast
    return solve_general(F, x0, jac=jac, method=method, tol=tol, rtol=rtol, ftol=ftol, max_iter=max_iter,
                         record=record, fd_step=fd_step, damped=damped, show_jacobian=show_jacobian)


_recent = RecentCriteria()
"""The criteria the system front door checked last (read by identity)."""


def fast_newton(F: Any, x0: Any, jac: Any, tol: float, rtol: float, ftol: float | None, max_iter: int,
                damped: bool) -> Result | None:
    """Newton with recording off by a short front door, where one applies: user callables
    of two unknowns from a start of two finite floats, a tuple or a list (judged and packaged
    in the loop's own call, :func:`user_two_entry`), or a compiled problem of two unknowns
    that converges (:func:`_mechanism_two`); the same Result as the general path
    (tests/test_compile.py). None for anything else, and where a user function returned the
    wrong kind of value: the general path then runs and names it. User callables solved
    with criteria of immutable values are remembered (:data:`_ready`): solving the same
    functions at the same criteria again goes from :func:`solve_system` straight to the loop."""
    global _ready
    seen = _recent.seen
    if seen[0] is tol and seen[1] is rtol and seen[2] is ftol and seen[3] is max_iter:
        crit = seen[4]
    else:
        crit = _recent.check(tol, rtol, ftol, max_iter)
    try:
        if (jac is not None and (type(x0) is tuple or type(x0) is list) and len(x0) == 2
                and type(x0[0]) is float and type(x0[1]) is float and x0[0] - x0[0] == 0.0
                and x0[1] - x0[1] == 0.0 and callable(F)):
            entries, (names, kinds, _), _, _ = _user_two or _user_two_entry()
            on = 1 if damped else 0  # the entry for damped's truth (user_two_loop)
            entry = entries[on] or user_two_compiled(on)
            last = _last_two
            problem = last[2] if last[0] is F and last[1] is jac else user_two_problem(F, jac)
            c_tol, c_rtol, c_ftol, c_max = crit
            gate = c_ftol if c_ftol is not None else c_tol
            meta = (user_two_meta, crit, gate, names, kinds)
            ready = (F, jac, tol, rtol, ftol, max_iter, damped,
                     entry, problem, c_tol, c_rtol, gate, c_max, meta)
            if _recent.seen[4] is crit and (damped is True or damped is False):
                _ready = ready
            return entry(ready, x0[0], x0[1])  # type: ignore[no-any-return]
        SystemProblem = _system_solvers()[3]
        if (jac is None and type(F) is SystemProblem and len(F.names) == 2 and F.J is not None
                and F.step_scales is None):
            return _mechanism_two(F, x0, crit, damped)
    except (TypeError, IndexError, RecursionError):
        pass
    return None


_ready: tuple[Any, ...] = (None,) * 14
"""The user callables (F, jac), the criteria objects (tol, rtol, ftol, max_iter) and
``damped`` :func:`fast_newton` last solved, then what it solved them with (the entry, the
problem, the checked criteria, the gate, the raw meta): read by identity in
:func:`solve_system`, which hands the whole record to the entry (three arguments, not nine);
one assignment, so a reader sees all or none. Only criteria that
:class:`~.criteria.RecentCriteria` remembers (floats, ints, None) and a bool ``damped``,
which cannot change under the same identity."""

USER_TWO_SIGNATURE = "newton_2x2_user(ready, x0, x1)"
"""The entry takes :data:`_ready`'s record (or one like it) and the start; ``damped`` is
its own (:func:`user_two_loop`), not read from the record."""

USER_TWO_START = """\
_, _, _, _, _, _, _, _, problem, tol, rtol, gate, max_iter, meta = ready
F, Jf = problem.F, problem.J
try:
    phi0 = F([x0, x1])
except (ArithmeticError, ValueError) as exc:
    raise _unevaluable(exc) from None
if not (type(phi0) is list and len(phi0) == 2 and type(phi0[0]) is float and type(phi0[1]) is float):
    _residual_checked(phi0, 2)
p0, p1 = phi0
"""
"""The user entry's start: Phi at x0, checked as :func:`residual_at_start` checks it (a
list of two floats passes on sight)."""

USER_TWO_TAIL = """\
if type(p0) is float and type(p1) is float:
    a0 = p0 if p0 > 0.0 else 0.0 - p0
    a1 = p1 if p1 > 0.0 else 0.0 - p1
    residual = """ + "{larger}" + """
else:
    residual = _max_abs((p0, p1))
# system_verdict leaves a converged step within the gate as it is: the common case, no call
if status is not _S.CONVERGED_STEP or not residual <= gate:
    status, detail = _verdict(status, detail, residual, gate)
""" + "\n".join(fast_source('"newton"', "(x0, x1)", "status", "k", "nfev", "err", "residual", "detail",
                            "meta", None, "njev")) + "\n"
"""The user entry's tail: max|Phi| at the end (:func:`~linkage.methods.newton_system.max_abs`,
for two floats as its bits by ``larger_of``), :func:`system_verdict` and the Result, as
:func:`_two_unknown_result` makes them (built in the entry's frame, :func:`~linkage.result.fast_source`:
the statements of :meth:`Result.fast`)."""

_user_two: tuple[Any, ...] = ()
"""What :func:`_user_two_entry` built, read as a module global on the hot path."""


def _user_two_entry() -> tuple[Any, ...]:
    """The entries for user callables of two unknowns (Newton's two-unknown loop judged and
    packaged in its own call; one for each truth of ``damped``, compiled on its first use by
    :func:`user_two_compiled`), the generic labels of two unknowns and what
    :func:`user_two_problem` builds with, imported once."""
    global _user_two
    if not _user_two:
        from ..problems.system import LeanProblem, generic_labels, generic_system

        _user_two = ([None, None], generic_labels(2), LeanProblem, generic_system)
    return _user_two


def user_two_compiled(on: int) -> Any:
    """The entry for user callables of two unknowns with ``damped`` true (``on`` 1) or false
    (0), compiled and kept in :data:`_user_two`."""
    from ..methods.newton_system import compile_newton_2x2_entry, max_abs

    entry = compile_newton_2x2_entry(user_two_loop(bool(on)), {
        "_unevaluable": unevaluable_start, "_residual_checked": residual_checked,
        "_verdict": system_verdict, "_max_abs": max_abs, **FAST_NAMES})
    (_user_two or _user_two_entry())[0][on] = entry
    return entry


def user_two_loop(damped: bool) -> Any:
    """The loop of the entry for user callables of two unknowns (a
    :class:`~linkage.iterate.Loop`): Newton's two-unknown loop, its start and tail these,
    ``damped`` written in (:func:`~linkage.methods.newton_system.with_damping`)."""
    from ..methods.newton_system import larger_of, newton_2x2_entry, with_damping

    return with_damping(newton_2x2_entry(USER_TWO_SIGNATURE, USER_TWO_START,
                                         USER_TWO_TAIL.replace("{larger}", larger_of("a0", "a1"))), damped)


@names_bad_callables
def solve_general(F: Any, x0: Any, *, jac: Any, method: str, tol: float, rtol: float, ftol: float | None,
                  max_iter: int, record: bool, fd_step: float | None, damped: bool,
                  show_jacobian: bool) -> Result:
    """:func:`solve_system` by the general path, every argument checked; a TypeError or
    IndexError from F or jac is named (:func:`~linkage.solve.diagnose.names_bad_callables`)."""
    NewtonSystem, max_abs, newton_system, SystemProblem, generic_system = _system_solvers()
    check_method("method", method, SYSTEM_METHODS, "for a system")
    crit = check_criteria(tol, rtol, ftol, max_iter)
    if fd_step is not None:
        fd_step = check_fd_step("fd_step", fd_step)
    problem, q0 = system_problem(F, x0, jac, crit, SystemProblem, generic_system)
    if method == "newton" and problem.J is None:
        raise InputError("newton needs the Jacobian jac; use method='newton-fd' to difference it")
    kind = "fd" if method == "newton-fd" or problem.J is None else "analytic"
    if method == "lm":
        from ..methods.least_squares import LevenbergMarquardt

        m: Any = LevenbergMarquardt(kind, fd_step, diagnostics=record)
    else:
        m = NewtonSystem(kind, fd_step, damped, diagnostics=record)
    phi0 = residual_at_start(problem, q0)
    gate = residual_gate(crit.ftol if crit.ftol is not None else crit.tol, problem.length_scale)
    rows = None
    if method == "newton" and kind == "analytic" and not record:
        q, phi, err, status, detail, iterations, nfev, njev = newton_system.newton_system_lean(
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
    return packaged(m, problem, crit, gate, (x, status, detail, iterations, nfev, njev, err, residual),
                    rows, record, show_jacobian)


def system_problem(F: Any, x0: Any, jac: Any, crit: Criteria, SystemProblem: Any,
                   generic_system: Any) -> tuple[Any, tuple[float, ...]]:
    """The problem to solve and its checked start (InputError naming what is wrong)."""
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
    if problem.length_scale != 1.0 or "length" in problem.kinds or problem.length_unit:
        for name, value in (("tol", crit.tol), ("ftol", crit.ftol)):
            if value is not None and value > MAX_RELATIVE_TOL:
                raise InputError(f"{name} = {value:g} is too loose to mean anything: for a mechanism "
                                 f"it is relative to its size ({problem.length_scale:g} "
                                 f"{problem.length_unit}); use at most {MAX_RELATIVE_TOL:g}")
    return problem, tuple(checked)


def residual_at_start(problem: Any, q0: tuple[float, ...]) -> Any:
    """Phi(q0), checked: a list of n real numbers (InputError otherwise)."""
    try:
        phi0 = problem.F(list(q0))
    except (ArithmeticError, ValueError) as exc:
        raise unevaluable_start(exc) from None
    residual_checked(phi0, problem.n)
    return phi0


def unevaluable_start(exc: BaseException) -> InputError:
    """The error for a residual that raised ``exc`` at x0."""
    return InputError(f"the residual cannot be evaluated at x0: {exc}")


def residual_checked(phi0: Any, n: int) -> None:
    """InputError unless ``phi0``, Phi at x0, is a sequence of n real numbers."""
    real_vector("F", phi0, n, "at x0")
    if len(phi0) != n:
        raise InputError(f"the system has {len(phi0)} equations for {n} unknowns")


def packaged(m: Any, problem: Any, crit: Criteria, gate: float, outcome: tuple[Any, ...], rows: Any,
             record: bool, show_jacobian: bool) -> Result:
    """The Result of a system solve from its judged outcome (x, status, detail, iterations,
    nfev, njev, err, residual), with the closed form's verdict where it has one."""
    x, status, detail, iterations, nfev, njev, err, residual = outcome
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
            status, detail = Status.NO_SOLUTION, f"{unassembled_text(problem)}; {m.name}: {reason}"
    history = None
    if rows is not None:
        history = system_history(m, problem, rows, show_jacobian, reference, x)
    return Result.fast(m.name, x, status, iterations, nfev, err, residual, detail, njev, (given, meta),
                       None if history is None else (given, history))


def unassembled_text(problem: Any) -> str:
    """What a mechanism's problem whose closed form has no real solution at its driver value
    is: the verdict on a failed solve there (:func:`packaged`) and the refusal of one
    (:func:`check_assembles`)."""
    meta = problem.meta
    return (f"the linkage cannot be assembled at {meta.get('driver')} = {meta.get('driver_value'):.12g} "
            f"{meta.get('driver_unit', '')} (the closed form has no real solution)")


def check_assembles(problem: Any, source: str) -> None:
    """InputError where the closed form of a mechanism's ``problem`` (where one is derived)
    has no real solution at its driver value: the linkage cannot be assembled there, so no
    method can converge (``solve FILE`` refuses it as bad input, exit 2). Without a closed
    form, or where it has a solution, nothing is refused."""
    if problem.reference is not None and problem.reference() == {}:
        raise InputError(f"{source}: {unassembled_text(problem)}")


@functools.lru_cache(maxsize=1)
def _system_solvers() -> tuple[Any, ...]:
    """The system solvers, imported on the first system solve (never by a scalar one;
    Levenberg-Marquardt only when asked for; the lean loop read from its module where
    it runs, compiled on its first use)."""
    from ..methods import newton_system
    from ..methods.newton_system import NewtonSystem, max_abs
    from ..problems.system import SystemProblem, generic_system

    return NewtonSystem, max_abs, newton_system, SystemProblem, generic_system


_two_loaded: tuple[Any, ...] = ()
"""What :func:`_two_unknowns` loaded, read as a module global on the hot path."""


def _two_unknowns() -> tuple[Any, ...]:
    """What :func:`fast_newton` needs, imported once (a scalar solve never pays for it)."""
    global _two_loaded
    if not _two_loaded:
        from ..methods.newton_system import max_abs, newton_2x2

        _two_loaded = (newton_2x2, max_abs)
    return _two_loaded


def system_verdict(status: Status, detail: str, residual: float, gate: float,
                   stopped: bool = True) -> tuple[Status, str]:
    """The verdict on a system solve from its loop's outcome and its final max|Phi|: a run
    the method stopped (no step lowers |Phi|, or J is singular) with |Phi| already within
    tolerance is a root to that tolerance (ill-conditioned, so the step test could not
    pass); a converged status with |Phi| above it is not."""
    if residual <= gate:
        if stopped and status in _STOPPED:  # a tuple: found by identity, no Enum hash (about 0.1 us)
            return Status.CONVERGED_RESIDUAL, f"max|Phi| = {residual:.3g} <= {gate:.3g}; {detail}"
        return status, detail
    if status.converged:
        return Status.STALLED, f"max|Phi| = {residual:.3g} at the end, above {gate:.3g}"
    return status, detail


_STOPPED = (Status.LOCAL_MINIMUM, Status.SINGULAR_JACOBIAN)


def _two_unknown_result(problem: Any, q0: tuple[float, ...], phi0: Any, crit: Criteria, gate: float,
                        damped: bool, meta: Raw, loaded: tuple[Any, ...]) -> Result:
    """Newton on two unknowns by :func:`~linkage.methods.newton_system.newton_2x2`,
    judged and packaged as :func:`solve_system` does (``loaded``: :func:`_two_unknowns`)."""
    newton_2x2, max_abs = loaded[0], loaded[1]
    q, phi, err, status, detail, iterations, nfev, njev = newton_2x2(
        problem, q0, phi0, crit.tol, crit.rtol, gate, crit.max_iter, damped)
    residual = max_abs(phi)
    status, detail = system_verdict(status, detail, residual, gate)
    return Result.fast("newton", tuple(q), status, iterations, nfev, err, residual, detail, njev, meta)


_last_two: tuple[Any, Any, Any] = (None, None, None)
"""The user functions (F, jac) :func:`fast_newton` last solved, with their problem: solving
the same functions again (from another start, at other tolerances) builds none."""


def user_two_problem(F: Callable[..., Any], jac: Callable[..., Any]) -> Any:
    """The problem :func:`fast_newton` hands user callables of two unknowns to: none built
    unless a step is refused; kept, so the same functions solved again reuse it."""
    global _last_two
    _, _, LeanProblem, generic_system = _user_two  # loaded by fast_newton before it calls this

    problem = LeanProblem(F, jac, None, lambda: generic_system(F, 2, jac))
    _last_two = (F, jac, problem)
    return problem


def user_two_meta(crit: Criteria, gate: float, names: tuple[str, ...],
                  kinds: tuple[str, ...]) -> dict[str, Any]:
    """``Result.meta`` of a solve on user callables of two unknowns, built when first read."""
    return {"tol": crit.tol, "rtol": crit.rtol, "ftol": gate, "names": names, "kinds": kinds, "title": ""}


def mechanism_meta(problem: Any, crit: Criteria, gate: float) -> dict[str, Any]:
    """``Result.meta`` of a solve of a compiled problem, built when first read."""
    return {"tol": crit.tol, "rtol": crit.rtol, "ftol": gate, "names": problem.names, "kinds": problem.kinds,
            "title": problem.title, **problem.meta}


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
    result = _two_unknown_result(problem, q0, phi0, crit, gate, damped, (mechanism_meta, problem, crit, gate),
                                 _two_unknowns())
    return result if result.converged else None


def system_history(m: Any, problem: Any, rows: list[tuple[Any, ...]], show_jacobian: bool,
                    reference: dict[str, dict[str, float]] | None, x: tuple[float, ...]) -> History:
    from ..problems.closed_form import wrap_degrees

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
    from ..problems.closed_form import wrap_degrees

    shown = problem.to_display(x)

    def distance(sol: dict[str, float]) -> float:
        return max(abs(wrap_degrees(v - sol[n])) if k == "angle" else abs(v - sol[n])
                   for v, n, k in zip(shown, problem.names, problem.kinds))

    return min(reference, key=lambda b: distance(reference[b]))
