"""Newton-Raphson for loop-closure systems: solve J(q_k) dq = -Phi(q_k), q_k+1 = q_k + dq.

Quadratic convergence near a solution where J is nonsingular (the textbook section 3.9, eq. 7; worked
example P3, docs/worked_examples.md). One residual and one Jacobian evaluation per step; with the
Jacobian by forward differences (``newton-fd``, the course notes' recipe, docs/worked_examples.md P3:
perturb one coordinate by h, take (Phi(q + h e_j) - Phi(q)) / h as column j, restore it), n + 1
residual evaluations and order falling toward linear as h grows. By default the step
is globalised (``damped``, see :class:`NewtonSystem`): taken whole when it lowers
|Phi|^2, else shortened, else replaced by a Levenberg-Marquardt step. The textbook
iteration (``damped=False``) fails where det J = 0 (toggle or dead-centre positions, a
start such as theta3 = theta4): a named ``singular_jacobian`` stop with det and
condition number. Rows follow P3: k, q_k, Phi(q_k), max|Phi|, dq (rad and deg), det J, cond J.
"""

from __future__ import annotations

import math
import operator
import sys
from typing import Any, ClassVar

from ..iterate import QUIET_RESIDUAL, Loop, build_loop, dedent, indent
from ..linalg import SingularMatrix, cond1, det_from_lu, lu, lu_solve, pivot_ratio
from ..problems.system import SystemProblem
from ..records import NamedTuple, frozen
from ..result import Column, Status
from ..rules import COUNTS_ON_RAISE, counts_made, invertible, invertible_source, pivots_invertible, step_size
from ..units import degrees
from .common import new_state

EPS = sys.float_info.epsilon

def max_abs(v: Any) -> float:
    """max |v_i|, NaN if any entry is NaN (the builtin max would silently skip it)."""
    m = 0.0
    for c in v:
        a = abs(c)
        if a > m or a != a:
            if a != a:
                return math.nan
            m = a
    return m


def larger_of(u: str, v: str) -> str:
    """Source of max(u, v) for two magnitudes named ``u`` and ``v`` (each >= 0 or NaN), NaN
    (``_nan``) if either is NaN, as :func:`max_abs` of two values: ``u`` when ``u >= v``,
    else ``v`` when ``v >= u``, else one is NaN. Two comparisons at most, where testing
    both for NaN first takes four (the generated 2x2 loops write it three times a step)."""
    return f"({u} if {u} >= {v} else {v} if {v} >= {u} else _nan)"


def invertible_2x2_source(ad: str, bc: str, det: str) -> str:
    """Source of :func:`~linkage.rules.invertible` for a 2x2 J, ``invertible(det, |ad| + |bc|)``
    with ``det`` = ``ad - bc`` (three names): where ``ad`` and ``bc`` have opposite signs,
    ``|det|`` is ``fl(|ad| + |bc|)`` itself (rounding is symmetric in sign), which is above
    SINGULAR_RATIO times itself exactly when it is finite (and it is above 0): the rule's verdict is
    then "det is finite", two or three comparisons and no float made (the rule's own form
    makes up to five; ``_ninf`` is minus infinity, :func:`~linkage.iterate.build_loop`'s name);
    any other case (and an infinite det) takes the rule's own source
    (:func:`~linkage.rules.invertible_source`). A four-bar's ``ad`` and ``bc`` have opposite
    signs wherever the sines of theta3 and theta4 do, or their cosines do (the bench's case);
    tests/test_newton_system_loops.py holds the verdicts to the rule's."""
    size = f"({ad} if {ad} > 0.0 else 0.0 - {ad}) + ({bc} if {bc} > 0.0 else 0.0 - {bc})"
    return (f"({ad} < 0.0 and {bc} > 0.0 and {det} > _ninf or {ad} > 0.0 and {bc} < 0.0 and {det} < _inf"
            f" or {invertible_source(det, size)})")


def fd_jacobian(problem: SystemProblem, q: list[float], phi: list[float],
                h: float | None) -> list[list[float]]:
    """Forward differences, one coordinate at a time; columns as in the course notes
    (docs/worked_examples.md P3)."""
    n = len(q)
    cols = []
    for j in range(n):
        step = h if h is not None else math.sqrt(sys.float_info.epsilon) * max(1.0, abs(q[j]))
        qj = list(q)
        qj[j] = q[j] + step
        pj = problem.F(qj)
        cols.append([(pj[i] - phi[i]) / step for i in range(len(phi))])
    return [[cols[j][i] for j in range(n)] for i in range(len(phi))]


class NewtonSystemState(NamedTuple):
    x: tuple[float, ...]
    fx: float | None
    err: float
    stop: tuple[Status, str] | None
    q: tuple[float, ...]
    phi: tuple[float, ...]
    jac: tuple[tuple[float, ...], ...]
    dq: tuple[float, ...]
    det: float
    cond: float
    alpha: float
    nfev: int
    njev: int
    phi_x: tuple[float, ...]  # Phi at x (the next step's residual, computed by the trial)


def singular_detail(det: float, cond: float) -> str:
    return f"det J = {det:.6g}, cond J = {cond:.3g}"


def equilibrate(jac: list[list[float]]) -> tuple[list[list[float]], list[float], list[float]]:
    """R J C with row scales R and column scales C making every row's and column's largest
    entry 1: a singularity test on the result reacts to singularity, not to units or to
    one equation being written 1e6 times larger than another."""
    n = len(jac)
    r = []
    for row in jac:
        big = max(abs(v) for v in row)
        r.append(1.0 / big if big > 0.0 and math.isfinite(big) else 1.0)
    c = []
    for j in range(n):
        big = max(abs(jac[i][j]) * r[i] for i in range(n))
        c.append(1.0 / big if big > 0.0 and math.isfinite(big) else 1.0)
    return [[jac[i][j] * r[i] * c[j] for j in range(n)] for i in range(n)], r, c


def newton_direction(jac: list[list[float]], phi: list[float]) -> tuple[list[float] | None, float, float]:
    """Solve J dq = -Phi on the equilibrated matrix: (dq or None when singular, det J,
    smallest/largest pivot of the equilibrated LU)."""
    n = len(phi)
    if n == 2:
        (a, b), (c, d) = jac
        det = a * d - b * c
        size = abs(a * d) + abs(b * c)  # invariant under row and column scaling
        if invertible(det, size):
            return [(b * phi[1] - d * phi[0]) / det, (c * phi[0] - a * phi[1]) / det], det, abs(det) / size
        return None, det, (abs(det) / size if size > 0.0 else 0.0)
    scaled, _, _ = equilibrate(jac)
    try:
        ratio = pivot_ratio(lu(scaled))
        f = lu(jac)
    except SingularMatrix:
        return None, 0.0, 0.0
    det = det_from_lu(f)
    if not pivots_invertible(ratio):
        return None, det, ratio
    # the solve itself uses J as given: equilibration decides singularity only
    return lu_solve(f, [-v for v in phi]), det, ratio


def normal_equations(jac: list[list[float]], phi: list[float]) -> tuple[list[list[float]], list[float]]:
    """(J^T J, J^T Phi), each entry summed over the rows in order; formed once per step,
    whatever the number of damping values tried (a 24-unknown mechanism spent most of a
    sweep forming it again for each)."""
    cols = [list(c) for c in zip(*jac)]
    n = len(cols)
    jtj = [[0.0] * n for _ in range(n)]
    for i in range(n):
        ci, row = cols[i], jtj[i]
        for j in range(i, n):
            row[j] = jtj[j][i] = sum(map(operator.mul, ci, cols[j]))
    return jtj, [sum(map(operator.mul, c, phi)) for c in cols]


def lm_direction(normal: tuple[list[list[float]], list[float]], mu: float) -> list[float] | None:
    """(J^T J + mu diag(J^T J)) dq = -J^T Phi: a step between Newton's (mu -> 0) and a
    scaled steepest descent (mu large), defined where J is singular; ``normal`` is
    :func:`normal_equations`' (J^T J, J^T Phi)."""
    jtj = [list(row) for row in normal[0]]
    g = normal[1]
    n = len(g)
    top = max((jtj[i][i] for i in range(n)), default=0.0)
    for i in range(n):
        jtj[i][i] += mu * max(jtj[i][i], 1e-12 * top, 1e-300)
    try:
        return lu_solve(lu(jtj), [-v for v in g])
    except (SingularMatrix, ArithmeticError):
        return None


step_measure = step_size
"""max |dq_i| / scale_i: angles in rad, lengths relative to the mechanism's size
(:func:`linkage.rules.step_size`, the one definition)."""


def _sumsq(v: Any) -> float:
    total = 0.0
    for c in v:
        total += c * c
    return total


@frozen
class NewtonSystem:
    """``jacobian``: "analytic" or "fd"; ``fd_step``: h for "fd" (None: sqrt(eps) max(1, |q|));
    ``damped``: globalised (the default; False for the textbook iteration); ``diagnostics``:
    compute cond J every step.

    Globalised: the Newton step is taken whole when it lowers |Phi|^2 (so a good start
    gives the textbook table, P3 row for row); otherwise it is halved down to 1/64; when
    that fails, or J is singular after equilibration, a Levenberg-Marquardt step with a
    growing damping looks for any decrease. When none exists the iterate sits at a
    stationary point of |Phi|^2 that is not a root: ``local_minimum``.
    """

    jacobian: str = "analytic"
    fd_step: float | None = None
    damped: bool = True
    diagnostics: bool = True

    bracketing: ClassVar[bool] = False
    needs_residual: ClassVar[bool] = True
    minimizes: ClassVar[bool] = False
    first_index: ClassVar[int] = 1

    @property
    def can_diverge(self) -> bool:  # type: ignore[override]
        # a globalised run lowers |Phi| every step: growing steps are no evidence
        return not self.damped

    @property
    def name(self) -> str:
        return "newton-fd" if self.jacobian == "fd" else "newton"

    def columns(self, problem: SystemProblem, show_jacobian: bool = False) -> tuple[Column, ...]:
        return system_columns(problem, show_jacobian, step_label="dq")

    def init(self, problem: SystemProblem, q0: tuple[float, ...],
             phi0: Any = None) -> NewtonSystemState:
        nan = math.nan
        phi0 = tuple(problem.F(list(q0)) if phi0 is None else phi0)
        return NewtonSystemState(tuple(q0), None, math.inf, None, tuple(q0), (), (), (), nan, nan,
                                 1.0, 1, 0, phi0)

    def step(self, problem: SystemProblem, s: NewtonSystemState) -> NewtonSystemState:
        q = list(s.x)
        phi = list(s.phi_x)
        nfev, njev = s.nfev, s.njev
        if self.jacobian == "fd":
            jac = fd_jacobian(problem, q, phi, self.fd_step)
            nfev += len(q)
        else:
            jac = problem.J(q)  # type: ignore[misc]
            njev += 1
        try:  # an evaluation counts once it returned, in a step that raises too (iterate.counts_made)
            resid = max_abs(phi)
            scales = problem.step_scales
            dq, det, _ = newton_direction(jac, phi)
            cond = (cond1(jac) if dq is None or self.diagnostics else math.nan)
            tjac = tuple(map(tuple, jac))

            def state(step: list[float], alpha: float, phi_new: Any, stop: Any = None) -> NewtonSystemState:
                x = tuple(qi + di for qi, di in zip(q, step))
                err = step_measure(step, scales)
                return new_state(NewtonSystemState, (
                    x, resid, err if stop is None else math.nan, stop, tuple(q), tuple(phi), tjac,
                    tuple(step), det, cond, alpha, nfev, njev, tuple(phi_new)))

            if not self.damped:
                if dq is None:
                    return state([0.0] * len(q), 1.0, phi,
                                 (Status.SINGULAR_JACOBIAN, singular_detail(det, cond)))
                trial = [qi + di for qi, di in zip(q, dq)]
                phi_t = problem.F(trial)
                nfev += 1
                return state(dq, 1.0, phi_t)

            base = _sumsq(phi)
            if dq is not None and max_abs(dq) <= 64.0 * EPS * (1.0 + max_abs(q)):
                # a step at rounding level: |Phi| is noise there, no decrease can be asked of it
                phi_t = problem.F([qi + di for qi, di in zip(q, dq)])
                nfev += 1
                return state(dq, 1.0, phi_t)
            if dq is not None:
                alpha = 1.0
                while alpha >= 1.0 / 64.0:
                    step = dq if alpha == 1.0 else [alpha * d for d in dq]
                    phi_t = problem.F([qi + di for qi, di in zip(q, step)])
                    nfev += 1
                    if _sumsq(phi_t) <= (1.0 - 1e-4 * alpha) * base:
                        return state(step, alpha, phi_t)
                    alpha *= 0.5
            # Newton's direction failed (or J is singular): damped steps toward lower |Phi|^2
            mu = 1e-3
            normal = normal_equations(jac, phi)
            while mu <= 1e12:
                d = lm_direction(normal, mu)
                if d is not None and all(map(math.isfinite, d)):
                    phi_t = problem.F([qi + di for qi, di in zip(q, d)])
                    nfev += 1
                    if _sumsq(phi_t) < base:
                        return state(d, 0.0, phi_t)
                    if max(abs(di) for di in d) <= 1e-15 * (1.0 + max_abs(q)):
                        break  # the steps no longer move q: nothing lower is reachable
                mu *= 10.0
            grad = max(abs(v) for v in normal[1])
            if dq is None:
                why = (Status.SINGULAR_JACOBIAN, f"{singular_detail(det, cond)}; no damped step lowers "
                                                 f"max|Phi| = {resid:.3g}")
            else:
                why = (Status.LOCAL_MINIMUM, f"max|Phi| = {resid:.3g} cannot be lowered from here "
                                             f"(|J^T Phi| = {grad:.3g}); try another start")
            return state([0.0] * len(q), 0.0, phi, why)
        except (ArithmeticError, ValueError) as exc:
            raise counts_made(exc, nfev, njev)  # noqa: B904 (the same exception, its traceback kept)

    def initial_row(self, problem: SystemProblem, s: NewtonSystemState) -> None:
        return None

    def row(self, problem: SystemProblem, s: NewtonSystemState, i: int) -> tuple[Any, ...]:
        return system_row(problem, i, s.q, s.phi, s.dq, s.det, s.cond, s.jac, s.err)


def system_columns(problem: SystemProblem, show_jacobian: bool, step_label: str) -> tuple[Column, ...]:
    """P3's layout, generated from the unknowns' names and kinds (the error column last)."""
    L = problem.length_unit
    cols = [Column("k", "index")]
    for i, name in enumerate(problem.names):
        cols.append(Column(f"{name} ({problem.unit(i)})" if problem.unit(i) else name, "text"))
    for r in range(len(problem.equation_names)):
        cols.append(Column(f"Phi{r + 1} ({L})" if L else f"Phi{r + 1}", "text"))
    cols.append(Column(f"max|Phi| ({L})" if L else "max|Phi|", "text"))
    for i, name in enumerate(problem.names):
        unit = problem.step_unit(i)
        cols.append(Column(f"d{name} ({unit})" if unit else f"d{name}", "text"))
        if problem.kinds[i] == "angle":
            cols.append(Column(f"d{name} (deg)", "text"))
    cols.append(Column(f"det J ({det_unit(problem)})" if det_unit(problem) else "det J", "text"))
    cols.append(Column("cond J", "text"))
    if show_jacobian:
        for r in range(len(problem.equation_names)):
            for c, name in enumerate(problem.names):
                unit = jac_unit(problem, c)
                label = f"dPhi{r + 1}/d{name}"
                cols.append(Column(f"{label} ({unit})" if unit else label, "text"))
    units = sorted({problem.step_unit(i) for i in range(problem.n)} - {""})
    cols.append(Column(f"max|{step_label}| ({', '.join(units)})" if units else f"max|{step_label}|", "text"))
    return tuple(cols)


def jac_unit(problem: SystemProblem, col: int) -> str:
    L = problem.length_unit
    if problem.kinds[col] == "angle":
        return f"{L}/rad" if L else "1/rad"
    return ""


def det_unit(problem: SystemProblem) -> str:
    if not problem.length_unit:
        return ""
    n_len = problem.n - sum(k == "length" for k in problem.kinds)
    n_ang = sum(k == "angle" for k in problem.kinds)
    top = f"{problem.length_unit}^{n_len}" if n_len > 1 else (problem.length_unit if n_len == 1 else "1")
    bottom = f"rad^{n_ang}" if n_ang > 1 else ("rad" if n_ang == 1 else "")
    return f"{top}/{bottom}" if bottom else top


def system_row(problem: SystemProblem, k: int, q: Any, phi: Any, dq: Any, det: float, cond: float,
               jac: Any, err: float, show_jacobian: bool = False) -> tuple[Any, ...]:
    row: list[Any] = [k, *problem.to_display(q), *phi, max_abs(phi) if phi else None]
    for i, kind in enumerate(problem.kinds):
        d = dq[i] if dq else None
        row.append(d)
        if kind == "angle":
            row.append(degrees(d) if d is not None else None)
    row += [det, cond]
    row.append(jac)  # expanded (or dropped) by the solve function: see solve_system
    row.append(err)
    return tuple(row)


_FALLBACK = """\
njev -= 1  # the method evaluates J again
s = _NewtonSystem("analytic", None, damped, diagnostics=False).step(problem, _State(
    {q}, None, err, None, (), (), (), (), _nan, _nan, 1.0, nfev, njev, {phi}))
nfev, njev = s.nfev, s.njev
if s.stop is not None:
    {stopped}
    err = s.err
    status, detail = s.stop
    break
"""
"""An iteration whose whole step is refused (a line search, a damped or singular step)
goes to :meth:`NewtonSystem.step`: one implementation of globalisation. A stop it names
ends the loop with its point (``stopped``: the assignment of its x and Phi) as the
iterate, to the loop's result or tail."""

NEWTON_SYSTEM_LOOP = Loop(
    signature="newton_system_lean(problem, q0, phi0, tol, rtol, gate, max_iter, damped)",
    setup="""\
        F, Jf = problem.F, problem.J
        scales = problem.step_scales
        if scales is None and len(q0) == 2 and len(phi0) == 2:
            return _newton_2x2(problem, q0, phi0, tol, rtol, gate, max_iter, damped)
        q = list(q0)
        phi = list(phi0)
        n = len(q)
        nfev, njev = 1, 0
        err = fx = _inf
        runaway = _RUNAWAY * (1.0 + _max_abs(q))
        """,
    step=dedent("""\
        jac = Jf(q)
        njev += 1
        dq = None
        if n == 2:
            p0, p1 = phi
            a0, a1 = abs(p0), abs(p1)
            fx = """ + larger_of("a0", "a1") + """
            (a, b), (c, d) = jac
            det = a * d - b * c
            if _invertible(det, abs(a * d) + abs(b * c)):
                dq = [(b * p1 - d * p0) / det, (c * p0 - a * p1) / det]
        else:
            fx = _max_abs(phi)
            dq = _direction(jac, phi)[0]
        phi_t = None
        if dq is not None:
            trial = [qi + di for qi, di in zip(q, dq)]
            phi_t = F(trial)
            nfev += 1
            if damped and not _sumsq(phi_t) <= (1.0 - 1e-4) * _sumsq(phi) and \\
                    not _max_abs(dq) <= 64.0 * _EPS * (1.0 + _max_abs(q)):
                phi_t = None  # the whole step does not lower |Phi|: the method decides
                nfev -= 1
        if phi_t is None:
        """) + indent(_FALLBACK.format(
            q="tuple(q)", phi="tuple(phi)", stopped="q, phi = list(s.x), list(s.phi_x)")) + dedent("""\
            step, trial, phi_t = list(s.dq), list(s.x), list(s.phi_x)
        else:
            step = dq
        """),
    after="""\
        if scales is None and n == 2:
            e0, e1 = abs(step[0]), abs(step[1])
            err = """ + larger_of("e0", "e1") + """
        else:
            err = _step_size(step, scales)
        q, phi = trial, phi_t
        size_q = _max_abs(q)
        """,
    result="q, phi, err, status, detail, k, nfev, njev", on_raise=COUNTS_ON_RAISE,
    residual_test=False, step_test="system", diverge="runaway", diverge_when="not damped",
    magnitude="size_q", quiet=True)
"""Newton-Raphson for a system with recording off: the stopping rule of
:mod:`linkage.iterate` for systems around the whole Newton step (Cramer's rule for two
unknowns), handing a refused step to :meth:`NewtonSystem.step`. The outcome equals the
generic loop's (status, root, iterations; tests/test_compile.py). Returns (x, Phi(x),
last error, status, detail, iterations, nfev, njev)."""

_2X2_STOPPED = "x0, x1 = s.x\n    p0, p1 = s.phi_x"
"""The iterate a stop named by :meth:`NewtonSystem.step` leaves to the two-unknown loops."""

_2X2_START = """\
F, Jf = problem.F, problem.J
x0, x1 = q0
p0, p1 = phi0
"""
"""How :data:`NEWTON_2X2_LOOP` starts: F, Jf, the start x0, x1 and Phi there p0, p1 (an
entry of its own, :func:`newton_2x2_entry`, sets them its own way)."""

_2X2_RESIDUAL = """\
# |v| written "v if v > 0.0 else 0.0 - v": the same bits as abs (-0.0 included), no call
a0 = {p0} if {p0} > 0.0 else 0.0 - {p0}
a1 = {p1} if {p1} > 0.0 else 0.0 - {p1}
fx = """ + larger_of("a0", "a1") + """
"""
"""max|Phi| of the two-unknown loops, ``fx``, from the entries of Phi {p0} and {p1}."""

_2X2_SETUP = dedent("""\
    ss = st = p0 * p0 + p1 * p1  # _sumsq(phi), carried from the step that produced phi
    nfev, njev = 1, 0
    err = fx = _inf
    if not damped:  # read by the divergence test only, which a damped run does not take
        a0, a1 = abs(x0), abs(x1)
        runaway = _RUNAWAY * (1.0 + """ + larger_of("a0", "a1") + """)
    shrink = 1.0 - 1e-4
    tiny = 64.0 * _EPS
    high_x = tol / _ROUNDING  # the quiet path's bound on |x| (quiet_rounding)
    low_x = -high_x
    """)

_2X2_REFUSED = _FALLBACK.format(q="(x0, x1)", phi="(p0, p1)", stopped=_2X2_STOPPED) + """\
d0, d1 = s.dq
t0, t1 = s.x
f0, f1 = s.phi_x
st = f0 * f0 + f1 * f1
"""
"""A refused step in the two-unknown loops (a singular J, or a whole step that does not
lower |Phi|): :meth:`NewtonSystem.step` decides, and the loop goes on from its step."""

NEWTON_2X2_LOOP = Loop(
    signature="newton_2x2(problem, q0, phi0, tol, rtol, gate, max_iter, damped)",
    setup=_2X2_START + _2X2_SETUP,
    step=dedent("""\
        (a, b), (c, d) = Jf([x0, x1])
        njev += 1
        if not damped:  # max|Phi| where the step is taken from (damped: only where the tests read it)
        """) + indent(_2X2_RESIDUAL.format(p0="p0", p1="p1")) + dedent("""\
        ad = a * d
        bc = b * c
        det = ad - bc
        # a refused step written in both places it is refused: no flag set and tested each step
        if """ + invertible_2x2_source("ad", "bc", "det") + """:
            d0, d1 = (b * p1 - d * p0) / det, (c * p0 - a * p1) / det
            t0, t1 = x0 + d0, x1 + d1
            f0, f1 = F([t0, t1])
            nfev += 1
            if damped:
                st = f0 * f0 + f1 * f1
                if not st <= shrink * ss:
                    e0, e1 = abs(d0), abs(d1)
                    step_size = """ + larger_of("e0", "e1") + """
                    e0, e1 = abs(x0), abs(x1)
                    q_size = """ + larger_of("e0", "e1") + """
                    if not step_size <= tiny * (1.0 + q_size):
                        nfev -= 1  # the whole step does not lower |Phi|: the method decides
        """) + indent(indent(indent(indent(_2X2_REFUSED)))) + "else:\n" + indent(_2X2_REFUSED),
    after="""\
        e0 = d0 if d0 > 0.0 else 0.0 - d0
        e1 = d1 if d1 > 0.0 else 0.0 - d1
        err = """ + larger_of("e0", "e1") + """
        # one name at a time: six names in one assignment build and unpack a tuple every step
        o0 = p0
        o1 = p1
        x0 = t0
        x1 = t1
        p0 = f0
        p1 = f1
        fs, ss = ss, st  # the sums of squares of the old and the new phi (each read only when damped)
        """,
    late="if damped:\n" + indent(_2X2_RESIDUAL.format(p0="o0", p1="o1")) + dedent("""\
        e0 = x0 if x0 > 0.0 else 0.0 - x0
        e1 = x1 if x1 > 0.0 else 0.0 - x1
        size_q = """ + larger_of("e0", "e1") + """
        """),
    result="[x0, x1], [p0, p1], err, status, detail, k, nfev, njev", on_raise=COUNTS_ON_RAISE,
    residual_test=False, step_test="system", diverge="runaway", diverge_when="not damped",
    magnitude="size_q", quiet=True,
    # damped: the old phi's sum of squares finite and positive says max|Phi| is (it may be
    # finite and positive where the sum under- or overflows: the tests then decide)
    quiet_residual=f"(fs > 0.0 and fs < _inf if damped else {QUIET_RESIDUAL})",
    # |x0|, |x1| below tol / _ROUNDING, with err above tol (qtol), says err > _ROUNDING max(|x0|, |x1|):
    # _ROUNDING is a power of two, so _ROUNDING * (tol / _ROUNDING) is tol exactly, and rounding
    # is monotonic (it may fail where the rounding test passes: the tests then decide)
    # (single comparisons, no chains: iterate.quiet_path says why)
    quiet_rounding="x0 > low_x and x0 < high_x and x1 > low_x and x1 < high_x")
""":data:`NEWTON_SYSTEM_LOOP` for two unknowns measured as they are (every four-bar), on
scalars: the same operations in the same order, so the same iterates, status and counts
(tests/test_compile.py), without the per-iteration lists and helper calls."""

def newton_2x2_entry(signature: str, start: str, tail: str) -> Loop:
    """:data:`NEWTON_2X2_LOOP` with its own ``signature``, ``start`` (source that sets F, Jf,
    x0, x1 and Phi there p0, p1, in place of reading them from ``problem``, ``q0`` and
    ``phi0``) and ``tail`` (source after the loop, in place of returning its result): the
    same iterations, so the same iterates, status and counts, for a front door that judges
    and packages them in the same call (:func:`linkage.solve.system.fast_newton`)."""
    return NEWTON_2X2_LOOP._replace(signature=signature, setup=dedent(start) + _2X2_SETUP, tail=tail)


def with_damping(loop: Loop, damped: bool) -> Loop:
    """``loop`` (an entry, :func:`newton_2x2_entry`, whose start does not read ``damped``) for
    one value of ``damped``: the name written as the constant it is, so the compiler drops
    the branches it rules out instead of the loop testing it at every step. A loop that tests
    its truth only (every test here is ``if damped``, ``if not damped`` or ``x if damped else
    y``; :class:`NewtonSystem` too) takes the same branches, so the same iterations."""
    import re

    word = "True" if damped else "False"

    def written(text: str) -> str:  # the code of each line, not its comment
        lines = []
        for line in text.split("\n"):
            code, mark, comment = line.partition("  #") if "  #" in line else line.partition("#") \
                if line.lstrip().startswith("#") else (line, "", "")
            lines.append(re.sub(r"\bdamped\b", word, code) + mark + comment)
        return "\n".join(lines)

    fields = ("setup", "step", "after", "late", "tail", "quiet_residual", "diverge_when")
    return loop._replace(**{name: written(getattr(loop, name)) for name in fields})


def compile_newton_2x2_entry(loop: Loop, names: dict[str, Any]) -> Any:
    """An entry (:func:`newton_2x2_entry`) compiled with ``names`` beside the loop's own."""
    return build_loop(loop, {**_LOOP_NAMES, **names}, fixed_source=True)


_LOOP_NAMES = {"_NewtonSystem": NewtonSystem, "_State": NewtonSystemState, "_max_abs": max_abs,
               "_direction": newton_direction, "_sumsq": _sumsq, "_EPS": EPS, "_invertible": invertible,
               "_step_size": step_measure}


def __getattr__(name: str) -> Any:
    """``newton_2x2`` and ``newton_system_lean``, compiled on their first use (PEP 562), not
    at import: a cold start that solves no system does not pay about 2.7 ms for them. Each
    is compiled once and kept as the module's attribute (a race compiles the same source
    twice: either result is the same function)."""
    if name == "newton_2x2":
        loop = build_loop(NEWTON_2X2_LOOP, _LOOP_NAMES, fixed_source=True)
    elif name == "newton_system_lean":
        two = globals().get("newton_2x2") or __getattr__("newton_2x2")
        loop = build_loop(NEWTON_SYSTEM_LOOP, {**_LOOP_NAMES, "_newton_2x2": two}, fixed_source=True)
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = loop
    return loop
