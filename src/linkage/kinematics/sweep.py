"""Whole-cycle sweeps: continuation, assembly branches, no-solution gaps, limits and toggles.

Each position starts from the previous solution (seed 001, section 3.9). A solve that
fails, or lands on another branch, is retried from the last solved position in 2, 4,
... 64 sub-steps. A position that still fails is ``no_solution`` when the closed form
(or, without one, Levenberg-Marquardt's residual floor) shows the loops cannot close
there; it is never given numbers. After a gap the sweep re-enters on the branch it
started on (from the closed form where there is one). Branches: the closed form's
open/crossed rule for four-bars and slider-cranks, the sign of det J otherwise.
A followed branch also ends at a fold, where det J goes to zero and the driver cannot
advance on that assembly; there continuation would jump to another assembly with no
warning, so each step is checked against the tangent predictor and such positions are
``off_branch`` (another assembly exists, not connected) rather than silently solved.
For a full turn, a backward pass from the start covers the end of the cycle.
Limit positions (where the branch or the feasible range ends) and toggles (det J
changes sign between solved positions) are located by bisection to 1e-9 of the
driver's unit, or taken from the closed form where it gives them exactly.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from ..methods._linalg import SingularMatrix, det_from_lu, lu, lu_solve, lu_two
from ..methods.newton_system import max_abs, newton_system_lean
from ..problems.closed_form import (
    arc_limits,
    arcs_within,
    feasible_arcs,
    fourbar_class,
    transmission,
)
from ..problems.loops import ANGLE_UNITS, Mechanism
from ..problems.system import LeanProblem
from ..result import Status
from ..rules import continues, continuity_measures
from ..solve import system_verdict
from .angles import anchor_index, closes_circle, continuous, driver_turn, turn_shift, unwrap_turns

MAX_HALVINGS = 6
_DEG = 180.0 / math.pi  # math.degrees(x) is x * (180 / pi), bit for bit (CPython's mathmodule)
LOCATE_TOL = 1e-9  # driver units (deg for angles)


@dataclass(frozen=True)
class Position:
    input: float
    status: str  # "converged", "no_solution", "off_branch" or "failed"
    solution: dict[str, float] | None
    branch: str | None
    iterations: int
    det: float | None
    transmission: float | None = None
    substeps: int = 0
    note: str = ""
    rates: Any = None
    """The joints (and with a driver speed, the velocities and accelerations) here: a
    :class:`~linkage.kinematics.rates.Rates`, or None where unsolved."""


@dataclass(frozen=True)
class SweepResult:
    mechanism: str
    driver: str
    driver_unit: str
    names: tuple[str, ...]
    units: tuple[str, ...]
    positions: Sequence[Position]
    """Every position in driver order (a tuple, or built lazily for a batch sweep)."""
    feasible_ranges: tuple[tuple[float, float], ...]
    toggles: tuple[float, ...]
    branch: str | None
    classification: dict[str, Any] = field(default_factory=dict)
    method: str = "newton"
    motion: tuple[float, float] | None = None
    """The driver's (speed, acceleration) in internal units when rates were asked for."""
    length_unit: str = ""

    @property
    def summary(self) -> dict[str, int]:
        if hasattr(self.positions, "summary"):
            return self.positions.summary()  # type: ignore[no-any-return]
        out: dict[str, int] = {}
        for p in self.positions:
            out[p.status] = out.get(p.status, 0) + 1
        return out

    def column(self, name: str) -> Any:
        """One unknown over every position (display units; None or NaN where unsolved)."""
        if hasattr(self.positions, "column"):
            return self.positions.column(name)
        return [p.solution[name] if p.solution else None for p in self.positions]


class _Solver:
    """Solves one position of a mechanism at a driver value, from a guess."""

    def __init__(self, m: Mechanism, method: str, tol: float, max_iter: int) -> None:
        self.m = m
        self.model = m.model
        self.method = method
        self.tol = tol
        self.max_iter = max_iter
        self.scale = ANGLE_UNITS[m.driver.unit] if m.driver.kind == "angle" else 1.0
        self.kinds = tuple(u.kind for u in m.unknowns)
        self.names = tuple(u.name for u in m.unknowns)
        from ..problems.closed_form import branch_rule

        self.rule = branch_rule(m) if m.closed_form else None
        self._problems: dict[float, Any] = {}
        self._compiled: tuple[float, Any] = (math.nan, None)
        size = m.length_scale
        self.gate = tol * size
        self.step_scales = (None if size == 1.0 or "length" not in self.kinds else
                            tuple(size if k == "length" else 1.0 for k in self.kinds))
        # two unknowns measured as they are: the continuation step on scalars (_step_two)
        self.two_angles = self.kinds == ("angle", "angle")
        self.two = len(self.names) == 2 and self.step_scales is None and len(m.loops) == 1
        # (v, q0, q1, LU of J, dPhi/dv) where _step_two last solved: the next tangent
        self.solved_at: tuple[float, float, float, Any, float, float] | None = None
        self.newton_two = self.model.newton_two if self.two else None
        self._fixed_deg: dict[str, float] | None = None
        self.coupler_and_output = "theta3" in self.names and "theta4" in self.names

    def compiled(self, value: float) -> Any:
        """(F, J, dPhi/dv) at a driver value (display units), the last one kept: a
        continuation step's tangent is taken where the previous step solved."""
        d, fns = self._compiled
        if d != value:
            fns = self.model.factory(value * self.scale)
            self._compiled = (value, fns)
        return fns

    def transmission(self, sol: dict[str, float]) -> float | None:
        """Four-bars: the transmission angle between coupler and output link, in [0, 180]."""
        if self.m.closed_form != "fourbar":
            return None
        if self.coupler_and_output:
            return transmission(sol["theta3"], sol["theta4"])
        fixed = self._fixed_deg
        if fixed is None:
            fixed = self._fixed_deg = {k: math.degrees(q.value) for k, q in self.m.parameters.items()
                                       if q.kind == "angle" and k != self.m.driver.name}
        t3 = sol.get("theta3", fixed.get("theta3"))
        t4 = sol.get("theta4", fixed.get("theta4"))
        if t3 is None or t4 is None:
            return None
        return transmission(t3, t4)

    def solve_lean(self, value: float, guess: Sequence[float]) -> tuple[Any, list[float], int] | None:
        """What :meth:`solve` does for textbook Newton, without building a problem or a
        Result: (J, x, iterations) when it converges, None otherwise (the caller then
        takes the full path, which computes the same and says why)."""
        F, J, _ = self.compiled(value)
        try:
            phi0 = F(list(guess))
        except (ArithmeticError, ValueError):
            return None
        light = LeanProblem(F, J, self.step_scales, lambda: self.problem(value))
        q, phi, _err, status, _detail, iterations, _nfev, _njev = newton_system_lean(
            light, tuple(guess), phi0, self.tol, 0.0, self.gate, self.max_iter, False)
        status, _ = system_verdict(status, "", max_abs(phi), self.gate)
        return (J, q, iterations) if status.converged else None

    def problem(self, value: float, guess: Sequence[float] | None = None) -> Any:
        """The compiled problem at a driver value, built once per value (a position asks
        for it several times: tangent, solve, det); its x0 is the file's guess."""
        p = self._problems.get(value)
        if p is None:
            if len(self._problems) > 64:
                self._problems.clear()
            p = self._problems[value] = self.model.problem_at(value * self.scale)
        return p

    def solve(self, value: float, guess: Sequence[float], method: str | None = None,
              damped: bool = False) -> tuple[Any, Any]:
        """Continuation takes the textbook step (``damped=False``): its own step halving
        and continuity check decide which assembly a position belongs to."""
        from ..solve import solve_system

        p = self.problem(value)
        r = solve_system(p, tuple(guess), method=method or self.method, tol=self.tol,
                         max_iter=self.max_iter, record=False, damped=damped)
        return p, r

    def display(self, q: Sequence[float]) -> dict[str, float]:
        if self.two_angles:
            n0, n1 = self.names
            x0, x1 = q
            return {n0: x0 * _DEG, n1: x1 * _DEG}
        return {n: (math.degrees(v) if k == "angle" else v) for n, v, k in zip(self.names, q, self.kinds)}

    def det(self, p: Any, q: Sequence[float]) -> float:
        from ..methods._linalg import SingularMatrix, det_from_lu, lu

        try:
            return det_from_lu(lu(p.J(list(q))))
        except SingularMatrix:
            return 0.0

    def branch(self, q: Sequence[float], det: float) -> str:
        if self.rule is not None:
            return self.rule(self.display(q))
        return "det+" if det > 0 else "det-"


def sweep(
    m: Mechanism,
    values: Sequence[float],
    *,
    method: str = "newton",
    branch: str | None = None,
    tol: float = 1e-12,
    max_iter: int = 50,
    progress: Callable[[int], None] | None = None,
) -> SweepResult:
    """Solve the mechanism at each driver value (display units), by continuation."""
    values = check_driver_values(m, values)
    solver = _Solver(m, method, tol, max_iter)
    lo, hi = (min(values), max(values)) if values else (0.0, 0.0)
    arcs = feasible_arcs(m) if m.closed_form and m.driver.kind == "angle" else None
    have_closed = m.closed_form is not None and m.driver.kind == "angle"
    guess0 = tuple(u.value for u in m.unknowns)
    full_turn = m.driver.kind == "angle" and bool(values) and values[-1] - values[0] >= 360.0 - 1e-9
    done: dict[int, Position] = {}
    target = branch
    anchor_q = guess0
    # The seed: where the branch to follow is known. With a closed form, the first
    # position that can be assembled, on the requested branch (or the guess's);
    # otherwise the file's own driver value, whose guess names the assembly.
    seed: tuple[float, tuple[float, ...]] | None = None
    if have_closed:
        for i, v in enumerate(values):
            pos, q = _solve_position(solver, v, None, None, guess0, target, True)
            if pos.status == "converged" and q is not None:
                seed, target = (v, q), pos.branch
                done[i] = pos
                break
            done[i] = pos
    else:
        v0 = m.driver.value / solver.scale
        p0, r0 = solver.solve(v0, guess0)
        if r0.converged:
            q0 = tuple(r0.x)
            seed = (v0, q0)
            target = solver.branch(q0, solver.det(p0, q0))
    if seed is not None:
        anchor_q = seed[1]
        for i, pos in _follow(solver, values, seed, target, full_turn, progress, done).items():
            done[i] = pos
    # The rest: re-entry on the same branch where a closed form names it; otherwise the
    # position is no_solution (no assembly at all) or off_branch (one not connected),
    # trying the last other assembly found first (continuation along it).
    other: tuple[float, ...] | None = None
    for j, v in enumerate(values):
        if j in done:
            continue
        prev = done.get(j - 1)
        if have_closed:
            last = (_q_of(solver, prev), values[j - 1]) if prev else (None, None)
            pos, q = _solve_position(solver, v, last[0], last[1], anchor_q, target, True)
        else:
            tries = [g for g in (other, anchor_q, guess0) if g is not None]
            pos, found = _classify_gap(solver, v, tries)
            other = found or other
        if target is None and pos.status == "converged":
            target = pos.branch
        done[j] = pos
        if progress is not None:
            progress(len(done))
    positions = [done[j] for j in range(len(values))]
    positions = _continuous_angles(solver, positions)
    toggles = _toggles(solver, positions, arcs, lo, hi, have_closed)
    ranges = (tuple(arcs_within(arcs, lo, hi)) if have_closed else _solved_ranges(positions))
    classification: dict[str, Any] = {}
    if m.closed_form == "fourbar":
        v = {k: q.value for k, q in m.parameters.items()}
        classification = fourbar_class(v["r1"], v["r2"], v["r3"], v["r4"])
    return SweepResult(m.name, m.driver.name, m.driver.unit, solver.names,
                       tuple("deg" if k == "angle" else m.length_unit for k in solver.kinds),
                       tuple(positions), ranges, tuple(toggles), target, classification, method,
                       length_unit=m.length_unit)


BATCH_ABOVE = 20_000
"""Sweeps of more positions than this run on the batch engine (numpy) by default."""


def sweep_mechanism(
    mechanism: Mechanism | str | Any,
    values: Sequence[float] | Any,
    *,
    branch: str | None = None,
    method: str = "newton",
    tol: float = 1e-12,
    max_iter: int = 50,
    batch: bool | None = None,
    progress: Callable[[int], None] | None = None,
    speed: float | None = None,
    accel: float = 0.0,
    joints: bool = False,
) -> SweepResult:
    """Solve a mechanism over driver values (display units: degrees for an angle), each
    position from the previous one; the public ``linkage.sweep``.

    ``mechanism``: a :class:`~linkage.problems.loops.Mechanism` or a path to a file.
    ``values``: a list or a numpy array. ``branch``: "open" or "crossed" for a mechanism
    with a closed form, else the branch of the file's guess. More than ``BATCH_ABOVE``
    values with Newton go through the numpy batch engine (``batch`` forces the choice);
    its result keeps columns and builds a position only when one is read.

    Each position has ``.input``, ``.status`` ("converged", "no_solution", "off_branch",
    "failed"), ``.solution`` (unknown name -> value, display units), ``.branch``,
    ``.iterations`` and ``.det``; ``result.column(name)`` gives one unknown throughout.
    With a driver ``speed`` (rad/s, or length unit/s for a linear driver) and ``accel``, or
    with ``joints=True``, every solved position also has ``.rates``: its joints and named
    points and, with a speed, the velocity and acceleration of every unknown, joint and
    point (:class:`~linkage.kinematics.rates.Rates`; a batch sweep computes it as positions
    are read). Without them the sweep does not pay for it. ``speed`` and ``accel`` are
    numbers in those internal units; a unit string such as "10rpm" is the command line's,
    and is refused here. ``values`` must be finite reals in a sequence (not a generator).
    Every argument is checked first (:mod:`linkage.arguments`): a misuse raises
    :class:`~linkage.errors.InputError` naming the argument.
    """
    from ..arguments import check_callable, check_flag, check_mechanism, check_rate, check_reals, check_text
    from ..errors import InputError
    from ..solve import check_criteria

    # the front door: every argument checked once, InputError naming it
    m = check_mechanism("mechanism", mechanism)
    values = check_reals("values", values, most=MAX_POSITIONS)
    check_criteria(tol, 0.0, None, max_iter)
    check_text("branch", branch)
    check_callable("progress", progress)
    check_flag("joints", joints)
    if batch is not None:
        check_flag("batch", batch)
    per_s = "rad/s" if m.driver.kind == "angle" else f"{m.length_unit or 'length unit'}/s"
    if speed is not None:
        speed = check_rate("speed", speed, per_s)
    accel = check_rate("accel", accel, f"{per_s}^2")
    if speed is None and accel != 0.0:
        raise InputError("accel needs speed (the driver's velocity)")
    if method not in ("newton", "newton-fd", "lm"):
        raise InputError(f"unknown method {method!r}; choose from newton, newton-fd, lm")
    if branch is not None:
        if branch not in ("open", "crossed"):
            raise InputError(f"--branch must be open or crossed, got {branch!r}")
        if m.closed_form is None:
            raise InputError(f"--branch needs a mechanism with a closed form; {m.source} has none "
                             "(its branch follows the file's guess)")
    n = len(values)
    use_batch = batch if batch is not None else (n > BATCH_ABOVE and method == "newton")
    if use_batch:
        if method != "newton":
            raise InputError("--batch runs Newton-Raphson; drop --method or --batch")
        from dataclasses import replace

        from .batch import batch_sweep

        return replace(batch_sweep(m, values, branch=branch, tol=tol, max_iter=max_iter, speed=speed,
                                   accel=accel, joints=joints).to_sweep(), method="newton (batch)")
    result = sweep(m, check_driver_values(m, values), method=method, branch=branch, tol=tol,
                   max_iter=max_iter, progress=progress)
    return with_rates(m, result, speed, accel) if speed is not None or joints else result


def with_rates(m: Mechanism, result: SweepResult, speed: float | None, accel: float) -> SweepResult:
    """Joints, and with a driver speed velocities and accelerations, at every solved position."""
    from dataclasses import replace

    from .rates import position_rates

    model = m.model
    scale = ANGLE_UNITS[m.driver.unit] if m.driver.kind == "angle" else 1.0
    kinds = [u.kind for u in m.unknowns]
    positions = []
    for p in result.positions:
        if p.solution is None:
            positions.append(p)
            continue
        q = [math.radians(p.solution[u.name]) if k == "angle" else p.solution[u.name]
             for u, k in zip(m.unknowns, kinds)]
        positions.append(replace(p, rates=position_rates(model, q, p.input * scale, speed, accel)))
    motion = (speed, accel) if speed is not None else None
    return replace(result, positions=tuple(positions), motion=motion)


def check_driver_values(m: Mechanism, values: Sequence[float]) -> list[float]:
    """The values as floats, or InputError: too many, not finite, or beyond what the
    driver's kind can represent (see :func:`~linkage.problems.loops.magnitude_problem`)."""
    from ..errors import InputError
    from ..problems.loops import magnitude_problem

    if len(values) > MAX_POSITIONS:
        raise InputError(f"{len(values):,} driver values is more than {MAX_POSITIONS:,}; sweep in parts")
    out = [float(v) for v in values]
    if not out:
        return out
    lo, hi = min(out), max(out)
    scale = math.pi / 180.0 if m.driver.kind == "angle" else 1.0
    for v in (lo, hi):
        why = magnitude_problem(v * scale, m.driver.kind, m.length_unit) if math.isfinite(v) else \
            "the driver values must be finite"
        if why:
            raise InputError(f"driver {m.driver.name}: {why}")
    return out


def _solve_position(solver: _Solver, v: float, last_q: tuple[float, ...] | None, last_v: float | None,
                    anchor_q: tuple[float, ...], target: str | None,
                    have_closed: bool) -> tuple[Position, tuple[float, ...] | None]:
    def accept(p: Any, r: Any, substeps: int = 0, note: str = "") -> tuple[Position, tuple[float, ...]]:
        q = tuple(r.x)
        det = solver.det(p, q)
        sol = solver.display(q)
        return Position(v, "converged", sol, solver.branch(q, det), r.iterations, det,
                        solver.transmission(sol), substeps, note), q

    def ok(p: Any, r: Any) -> bool:
        return r.converged and (target is None or solver.branch(r.x, solver.det(p, r.x)) == target)

    ref = solver.problem(v, anchor_q).reference() if have_closed else None
    if have_closed and ref == {}:
        return Position(v, "no_solution", None, None, 0, None,
                        note="the closed form has no real solution"), None
    # 1. continuation from the previous position (with its own step halving)
    if last_q is not None and last_v is not None:
        pos, q = _continue(solver, v, [(last_v, last_q)], target)
        if pos.status == "converged":
            return pos, q
    # 3. re-entry (or first position): the closed form on the target branch, else anchors
    if have_closed:
        if ref:
            want = target if target is not None else solver.branch(anchor_q, 1.0)
            if target is None:
                # first position: keep the branch nearest the file's guess
                p, r = solver.solve(v, anchor_q)
                if r.converged:
                    return accept(p, r)
            sol = ref.get(want) if want else None
            if sol is not None:
                guess = tuple(math.radians(sol[n]) if k == "angle" else sol[n]
                              for n, k in zip(solver.names, solver.kinds))
                p, r = solver.solve(v, guess)
                if ok(p, r):
                    return accept(p, r, note=REENTERED)
            elif want:
                # a rocker-driven four-bar: both assemblies here carry the other label
                return Position(v, "off_branch", None, None, 0, None,
                                note=f"every assembly here is {', '.join(ref)}"), None
    else:
        for guess in (anchor_q, tuple(u.value for u in solver.m.unknowns)):
            p, r = solver.solve(v, guess)
            if ok(p, r):
                return accept(p, r)
        p, r = solver.solve(v, anchor_q, method="lm")
        if r.status is Status.NO_SOLUTION:
            return Position(v, "no_solution", None, None, r.iterations, None,
                            note="least squares: the loops cannot close here"), None
    return Position(v, "failed", None, None, 0, None, note="no convergence on the branch"), None


REENTERED = "re-entered from the closed form"


def _q_of(solver: _Solver, pos: Position | None) -> tuple[float, ...] | None:
    return solver_q(solver, pos) if pos is not None and pos.solution is not None else None


def _continue(solver: _Solver, v: float, history: list[tuple[float, tuple[float, ...]]],
              target: str | None) -> tuple[Position, tuple[float, ...] | None]:
    """One continuation step to v from the branch's last solved position.

    Predictor: the tangent dq/dv = -J^-1 dPhi/dv at the last solution. Corrector: Newton
    from the prediction. The result is accepted only on the target branch and close to
    the prediction: the correction may be at most half the predicted change plus a term
    in dv^2 (the path's curvature) and rounding. Anything else, a jump to another
    assembly included, halves the step, down to 1/64. A branch that cannot be followed
    further ends here; the caller decides what the position is.
    """
    v_last, q_last = history[-1]
    if solver.method == "newton":
        fast = (_step_two(solver, v, v_last, q_last, target) if solver.two else
                _lean_step(solver, v, v_last, q_last, target))
        if fast is not None:
            return fast
    for h in range(0, MAX_HALVINGS + 1):
        n = 2 ** h
        vq = (v_last, q_last)
        ok = True
        r = p = None
        for k in range(1, n + 1):
            vk = v_last + (v - v_last) * k / n
            pred = _predict(solver, vq[0], vq[1], vk)
            if pred is None:
                ok = False
                break
            p, r = solver.solve(vk, pred)
            if not r.converged:
                ok = False
                break
            q = tuple(r.x)
            det = solver.det(p, q)
            if target is not None and solver.branch(q, det) != target:
                ok = False
                break
            dv = abs(vk - vq[0]) * solver.scale
            correction, moved, size = continuity_measures(vq[1], pred, q)
            if not continues(correction, moved, dv, size):
                ok = False
                break
            vq = (vk, q)
        if ok and r is not None:
            q = tuple(r.x)
            sol = solver.display(q)
            note = f"step halved to 1/{n}" if n > 1 else ""
            return Position(v, "converged", sol, solver.branch(q, det), r.iterations, det,
                            solver.transmission(sol), n if n > 1 else 0, note), q
    return Position(v, "failed", None, None, 0, None, note="the branch could not be continued"), None


def _lean_step(solver: _Solver, v: float, v_last: float, q_last: tuple[float, ...],
               target: str | None) -> tuple[Position, tuple[float, ...]] | None:
    """The whole step of :func:`_continue` (no halving) with the same predictor, Newton
    run, det, branch and continuity tests, on compiled functions only; None wherever
    that step would not be accepted, so the full loop decides (and computes the same)."""
    pred = _predict(solver, v_last, q_last, v)
    if pred is None:
        return None
    got = solver.solve_lean(v, pred)
    if got is None:
        return None
    J, x, iterations = got
    q = tuple(x)
    try:
        det = det_from_lu(lu(J(list(q))))
    except SingularMatrix:
        det = 0.0
    branch = solver.branch(q, det)
    if target is not None and branch != target:
        return None
    dv = abs(v - v_last) * solver.scale
    correction, moved, size = continuity_measures(q_last, pred, q)
    if not continues(correction, moved, dv, size):
        return None
    sol = solver.display(q)
    return Position(v, "converged", sol, branch, iterations, det, solver.transmission(sol)), q


def _step_two(solver: _Solver, v: float, v_last: float, q_last: tuple[float, ...],
              target: str | None) -> tuple[Position, tuple[float, ...]] | None:
    """:func:`_lean_step` for two unknowns measured as they are (every four-bar), on
    scalars: the tangent's LU and det J written out, and Newton run by the model's compiled
    ``newton_two`` (:mod:`linkage.codegen`), the same operations in the same order as the
    general path, so the same predictor, iterates, counts, det and branch
    (tests/test_compile.py). J and dPhi/dv at a solved position serve its det and the
    next step's tangent. None wherever that step would not be accepted, so the full loop
    decides (and computes the same)."""
    x0, x1 = q_last
    cached = solver.solved_at
    if cached is not None and cached[0] == v_last and cached[1] == x0 and cached[2] == x1:
        factors, w0, w1 = cached[3], cached[4], cached[5]
    else:
        _, J, V = solver.compiled(v_last)
        (a, b), (c, d) = J([x0, x1])
        w0, w1 = V([x0, x1])
        factors = lu_two(a, b, c, d)
    if factors is None:
        return None
    m00, m01, m10, m11, swapped = factors
    neg = -solver.scale
    y0, y1 = (neg * w1, neg * w0) if swapped else (neg * w0, neg * w1)
    y1 = (y1 - m10 * y0) / m11
    y0 = (y0 - m01 * y1) / m00
    dv = v - v_last
    pred0, pred1 = x0 + dv * y0, x1 + dv * y1
    try:
        got = solver.newton_two(v * solver.scale, pred0, pred1, solver.tol, solver.gate, solver.max_iter)
    except (ArithmeticError, ValueError):
        return None
    if got is None:
        return None
    k, x0, x1, a, b, c, d, w0, w1 = got
    factors = lu_two(a, b, c, d)
    det = 0.0 if factors is None else (-1.0 if factors[4] else 1.0) * factors[0] * factors[3]
    solver.solved_at = (v, x0, x1, factors, w0, w1)
    q = (x0, x1)
    sol = solver.display(q)
    branch = solver.rule(sol) if solver.rule is not None else ("det+" if det > 0 else "det-")
    if target is not None and branch != target:
        return None
    dv = abs(dv) * solver.scale
    e0, e1 = abs(x0), abs(x1)
    size = 1.0 + (e0 if e0 >= e1 else e1)
    e0, e1 = abs(pred0 - q_last[0]), abs(pred1 - q_last[1])
    moved = e0 if e0 >= e1 else e1
    e0, e1 = abs(x0 - pred0), abs(x1 - pred1)
    correction = e0 if e0 >= e1 else e1
    if not continues(correction, moved, dv, size):
        return None
    return _converged(v, sol, branch, k, det, solver.transmission(sol)), q


_new = object.__new__


def _converged(v: float, sol: dict[str, float], branch: str, iterations: int, det: float,
               transmission: float | None) -> Position:
    """``Position(v, "converged", ...)`` for the hot loop, without the frozen dataclass's
    ``__init__``, which sets each of its ten fields through ``object.__setattr__`` (1.5 us
    against 0.6 us; a sweep makes one per position). tests/test_compile.py checks that
    both give equal positions and that the fields are still these."""
    p = _new(Position)
    p.__dict__.update(input=v, status="converged", solution=sol, branch=branch, iterations=iterations,
                      det=det, transmission=transmission, substeps=0, note="", rates=None)
    return p


def tangent(solver: _Solver, v0: float, q0: Sequence[float]) -> list[float] | None:
    """dq/dv on the branch at (v0, q0), from J dq/dv = -dPhi/dv with the compiled, exact
    dPhi/dv; q in internal units, v in display units. None where J is singular."""
    _, J, V = solver.compiled(v0)
    try:
        return lu_solve(lu(J(list(q0))), [-solver.scale * c for c in V(list(q0))])
    except SingularMatrix:
        return None


def _predict(solver: _Solver, v0: float, q0: tuple[float, ...], v: float) -> tuple[float, ...] | None:
    """q0 + (v - v0) dq/dv: the tangent predictor."""
    t = tangent(solver, v0, q0)
    if t is None:
        return None
    return tuple(q + (v - v0) * ti for q, ti in zip(q0, t))


def _classify_gap(solver: _Solver, v: float, guesses: Sequence[tuple[float, ...]]
                  ) -> tuple[Position, tuple[float, ...] | None]:
    """A position the followed branch does not reach, for a mechanism without a closed
    form: off_branch if Newton or least squares closes the loops from any guess (another
    assembly exists; its solution is returned so the next position can start from it),
    no_solution if neither does from any of them."""
    for method, damped in ((None, False), (None, True), ("lm", True)):
        for g in guesses:
            _p, r = solver.solve(v, g, method=method, damped=damped)
            if r.converged:
                return Position(v, "off_branch", None, None, r.iterations, None,
                                note="an assembly exists here, but the followed branch does not "
                                     "reach it"), tuple(r.x)
    return Position(v, "no_solution", None, None, 0, None,
                    note="least squares: the loops cannot close here"), None


def _continuous_angles(solver: _Solver, positions: list[Position]) -> list[Position]:
    """Report each angle continuously along the cycle, in driver order around the circle
    (an arc across the grid's end is one piece), in the turn ``solve FILE`` gives at the
    file's driver value: the rule of :mod:`linkage.kinematics.angles`."""
    angles = [n for n, k in zip(solver.names, solver.kinds) if k == "angle"]
    if not angles:
        return positions
    closes = _closes(solver, positions)
    solved = {n: [p.solution[n] if p.solution else None for p in positions] for n in angles}
    turns = {n: unwrap_turns(solved[n], closes) for n in angles}
    shift = _anchor(solver, positions, angles, turns, closes)
    for i, p in enumerate(positions):
        sol = p.solution
        if sol is None:
            continue
        # in place: each position and its solution dict were made by this sweep and are
        # not yet anybody else's (a new Position per position cost 1.5 us each); from the
        # values as solved, so writing twice would write the same
        for n in angles:
            sol[n] = continuous(solved[n][i], turns[n][i] + shift[n])  # type: ignore[arg-type,operator]
    return positions


def _closes(solver: _Solver, positions: Sequence[Position]) -> bool:
    """Whether the sweep's driver values close the circle (angles.closes_circle)."""
    if solver.m.driver.kind != "angle":
        return False
    return closes_circle([p.input for p in positions], driver_turn(solver.m.driver.unit))


def _anchor(solver: _Solver, positions: list[Position], angles: list[str],
            turns: dict[str, list[int | None]], closes: bool) -> dict[str, int]:
    """Whole turns to add to each angle's curve so that at the position nearest the file's
    own driver value it reads as `solve FILE` reports it there (Newton from the file's
    guess): a sweep and a solve never disagree by a turn."""
    none = dict.fromkeys(angles, 0)
    m = solver.m
    v0 = m.driver.value / solver.scale
    near = anchor_index([p.input for p in positions], [p.solution is not None for p in positions], v0,
                        closes, driver_turn(m.driver.unit))
    if near is None:
        return none
    from ..solve import solve_system

    r = solve_system(solver.problem(v0), tuple(u.value for u in m.unknowns), tol=solver.tol, record=False)
    if not r.converged:
        return none
    ref = solver.display(r.x)
    sol = positions[near].solution
    assert sol is not None
    return {n: turn_shift(ref[n], continuous(sol[n], turns[n][near])) for n in angles}  # type: ignore[arg-type]


def _follow(solver: _Solver, values: Sequence[float], seed: tuple[float, tuple[float, ...]],
            target: str | None, full_turn: bool, progress: Callable[[int], None] | None,
            done: dict[int, Position]) -> dict[int, Position]:
    """Continuation from the seed, up through the values above it and down through those
    below, each direction until the branch ends; over a full turn a direction that
    reaches the end of the range carries on around (v + 360 is the same position)."""
    from dataclasses import replace

    found: dict[int, Position] = {}
    two = solver.two and solver.method == "newton"
    v_seed = seed[0]
    order = sorted(range(len(values)), key=lambda i: values[i])
    up = [i for i in order if values[i] >= v_seed]
    down = [i for i in reversed(order) if values[i] < v_seed]
    for first, second, shift in ((up, down[::-1], 360.0), (down, up[::-1], -360.0)):
        hist = [seed]
        plan = [(i, values[i]) for i in first]
        if full_turn:
            plan += [(i, values[i] + shift) for i in second]
        for i, v in plan:
            if i in found or i in done:
                if i in found:
                    continue
            v_last, q_last = hist[-1]
            step = _step_two(solver, v, v_last, q_last, target) if two and abs(v - v_last) <= 5.0 \
                else None
            if step is not None:
                # the common case, first: what _continue would return (it tries this first)
                found[i] = step[0] if step[0].input == values[i] else replace(step[0], input=values[i])
                hist = [(v, step[1])]
                if progress is not None:
                    progress(len(found) + len(done))
                continue
            pos, q = _continue(solver, v, hist, target) if abs(v - v_last) <= 5.0 else \
                _walk(solver, v, hist, target)
            if pos.status != "converged" or q is None:
                break
            found[i] = pos if pos.input == values[i] else replace(pos, input=values[i])
            hist = [(v, q)]
            if progress is not None:
                progress(len(found) + len(done))
    return found


def _walk(solver: _Solver, v: float, hist: list[tuple[float, tuple[float, ...]]],
          target: str | None) -> tuple[Position, tuple[float, ...] | None]:
    """Continuation over a long interval in steps of at most 2 driver units."""
    v0 = hist[-1][0]
    n = max(1, math.ceil(abs(v - v0) / 2.0))
    pos, q = Position(v, "failed", None, None, 0, None), None
    for k in range(1, n + 1):
        pos, q = _continue(solver, v0 + (v - v0) * k / n, hist, target)
        if pos.status != "converged" or q is None:
            return pos, None
        hist = [(v0 + (v - v0) * k / n, q)]
    return Position(v, pos.status, pos.solution, pos.branch, pos.iterations, pos.det,
                    pos.transmission, pos.substeps, pos.note), q


def _solved_ranges(positions: Sequence[Position]) -> tuple[tuple[float, float], ...]:
    out = []
    start = None
    prev = None
    for p in positions:
        if p.status == "converged":
            if start is None:
                start = p.input
            prev = p.input
        elif start is not None:
            out.append((start, prev))
            start = None
    if start is not None:
        out.append((start, prev))
    return tuple(out)  # type: ignore[arg-type]


def solved_ranges_array(values: Any, converged: Any) -> tuple[tuple[float, float], ...]:
    """:func:`_solved_ranges` over arrays (the batch engine's): each run of converged
    positions as (first driver value, last driver value), in position order."""
    import numpy as np

    c = np.asarray(converged, dtype=bool)
    if not c.size:
        return ()
    edges = np.diff(c.astype(np.int8))
    starts, ends = np.flatnonzero(edges == 1) + 1, np.flatnonzero(edges == -1)
    if c[0]:
        starts = np.concatenate(([0], starts))
    if c[-1]:
        ends = np.concatenate((ends, [len(c) - 1]))
    return tuple((float(values[a]), float(values[b])) for a, b in zip(starts, ends))


def _toggles(solver: _Solver, positions: Sequence[Position], arcs: Any, lo: float, hi: float,
             have_closed: bool) -> list[float]:
    found: list[float] = []
    if have_closed:
        found += arc_limits(arcs, lo, hi)
    pairs = list(itertools.pairwise(positions))
    for a, b in pairs:
        if a.status == "converged" and b.status == "converged" and a.det and b.det \
                and (a.det > 0) != (b.det > 0):
            if REENTERED in (a.note, b.note):
                continue  # not one assembly moving: the sweep re-entered on the other one
            found.append(_bisect_det(solver, a, b))
        elif not have_closed and (a.status == "converged") != (b.status == "converged"):
            found.append(_bisect_limit(solver, a, b))
    # det J can also touch zero without changing sign (two assemblies crossing, as an
    # in-line slider-crank with r3 = r2 at 90 deg): a local minimum of |det J| over the
    # solved positions is refined, and is a toggle where J is singular there
    for a, b, c in zip(positions, positions[1:], positions[2:]):
        if a.det is not None and b.det is not None and c.det is not None \
                and a.status == b.status == c.status == "converged" \
                and (a.det > 0) == (b.det > 0) == (c.det > 0) \
                and abs(b.det) <= abs(a.det) and abs(b.det) <= abs(c.det):
            touch = _touch_det(solver, a, b, c)
            if touch is not None and not any(abs(touch - t) <= 2 * LOCATE_TOL for t in found):
                found.append(touch)
    return sorted(found)


TOUCH_RATIO = 1e-5
"""A minimum of |det J| / (its columns' lengths) at most this is a toggle (see hadamard_ratio)."""

TOUCH_CANDIDATE = 0.1
"""A local minimum of |det J| over the solved positions is searched only where
hadamard_ratio is below this there (a transmission angle under 5.7 deg): near a touch it
falls like the distance to it (0.017 a degree on the in-line slider-crank), while an
ordinary mechanism's smallest transmission angle is far above, and costs nothing."""


def _touch_det(solver: _Solver, a: Position, b: Position, c: Position) -> float | None:
    """The driver value in [a, c] where the branch's J is nearest singular (golden-section
    search on hadamard_ratio, to LOCATE_TOL), if J is singular there; else None."""
    from ..methods._linalg import hadamard_ratio

    q_b = solver_q(solver, b)
    if not hadamard_ratio(solver.problem(b.input).J(list(q_b))) <= TOUCH_CANDIDATE:
        return None
    ends = ((a.input, solver_q(solver, a)), (c.input, solver_q(solver, c)))
    cache: dict[float, float] = {}

    def ratio(v: float) -> float:
        if v not in cache:
            # from the nearer end, where J is regular (not from b: J may be singular there)
            v0, q0 = min(ends, key=lambda e: abs(e[0] - v))
            # damped: next to a singular J the textbook step can jump to another assembly
            p, r = solver.solve(v, _predict(solver, v0, q0, v) or q0, damped=True)
            x = list(r.x)
            # there Newton converges only linearly and may stop at max_iter short of tol:
            # its last iterate still places the minimum when it nearly closes the loops
            close = r.converged or (all(map(math.isfinite, x)) and
                                    max_abs(p.F(x)) <= 1e-6 * solver.m.length_scale)
            cache[v] = hadamard_ratio(p.J(x)) if close else math.inf
        return cache[v]

    lo, hi = a.input, c.input
    g = (math.sqrt(5.0) - 1.0) / 2.0
    x1, x2 = hi - g * (hi - lo), lo + g * (hi - lo)
    while abs(hi - lo) > LOCATE_TOL:
        if ratio(x1) <= ratio(x2):
            hi, x2 = x2, x1
            x1 = hi - g * (hi - lo)
        else:
            lo, x1 = x1, x2
            x2 = lo + g * (hi - lo)
    best = min(cache, key=cache.__getitem__, default=None)
    if best is None or not cache[best] <= TOUCH_RATIO:
        return None
    return best


def _bisect_det(solver: _Solver, a: Position, b: Position) -> float:
    """det J changes sign between two solved positions: bisect on its sign."""
    qa = solver_q(solver, a)
    va, vb, det_a = a.input, b.input, a.det or 0.0
    while abs(vb - va) > LOCATE_TOL:
        vm = 0.5 * (va + vb)
        p, r = solver.solve(vm, qa)
        if not r.converged:
            break
        d = solver.det(p, r.x)
        if (d > 0) == (det_a > 0):
            va, qa = vm, tuple(r.x)
        else:
            vb = vm
    return 0.5 * (va + vb)


def _bisect_limit(solver: _Solver, a: Position, b: Position) -> float:
    """One side is on the branch, the other is not (no solution, or another assembly):
    bisect on "Newton from the branch's nearest solution stays on it" (see _reaches)."""
    good, bad = (a, b) if a.status == "converged" else (b, a)
    q = solver_q(solver, good)
    vg, vb = good.input, bad.input
    while abs(vb - vg) > 1e-6:
        vm = 0.5 * (vg + vb)
        qm = _reaches(solver, vm, vg, q, good.branch)
        if qm is not None:
            vg, q = vm, qm
        else:
            vb = vm
    refined = _refine_limit(solver, vg, q)
    if refined is not None and min(good.input, bad.input) <= refined <= max(good.input, bad.input):
        return refined
    return 0.5 * (vg + vb)


def _refine_limit(solver: _Solver, v0: float, q0: tuple[float, ...]) -> float | None:
    """The limit exactly: Newton on Phi(q, v) = 0, det J(q, v) = 0 for (q, v), from a
    point near it (the fold or assembly limit is where det J vanishes on the branch)."""
    from ..methods._linalg import SingularMatrix, det_from_lu, lu, lu_solve

    def g(x: list[float]) -> list[float]:
        *q, v = x
        p = solver.problem(v, tuple(q))
        try:
            d = det_from_lu(lu(p.J(q)))
        except SingularMatrix:
            d = 0.0
        return [*p.F(q), d]

    x = [*q0, v0]
    for _ in range(30):
        gx = g(x)
        cols = []
        for j in range(len(x)):
            h = 1e-7 * max(1.0, abs(x[j]))
            xj = list(x)
            xj[j] += h
            cols.append([(a - b) / h for a, b in zip(g(xj), gx)])
        jac = [[cols[j][i] for j in range(len(x))] for i in range(len(x))]
        try:
            dx = lu_solve(lu(jac), [-c for c in gx])
        except SingularMatrix:
            return None
        x = [a + b for a, b in zip(x, dx)]
        if not all(math.isfinite(c) for c in x):
            return None
        if abs(dx[-1]) <= 1e-12 * max(1.0, abs(x[-1])) and max(abs(c) for c in dx[:-1]) <= 1e-12:
            return x[-1]
    return None


def _reaches(solver: _Solver, v: float, v_good: float, q_good: tuple[float, ...],
             branch: str | None) -> tuple[float, ...] | None:
    """The solution at v on the branch through (v_good, q_good), or None.

    Near a limit or a fold the branch moves like sqrt(v* - v), so a solution within
    2 sqrt(|v - v_good|) (radians, scaled by the size of q) counts as the same branch;
    a jump to another assembly is larger once the interval is small.
    """
    p, r = solver.solve(v, q_good)
    if not r.converged:
        return None
    q = tuple(r.x)
    if branch is not None and solver.branch(q, solver.det(p, q)) != branch:
        return None
    dist = max(abs(x - y) for x, y in zip(q, q_good))
    allow = 2.0 * math.sqrt(abs(v - v_good) * solver.scale) * (1.0 + max(abs(c) for c in q_good))
    return q if dist <= allow + 1e-12 else None


def solver_q(solver: _Solver, pos: Position) -> tuple[float, ...]:
    assert pos.solution is not None
    return tuple(math.radians(pos.solution[n]) if k == "angle" else pos.solution[n]
                 for n, k in zip(solver.names, solver.kinds))


MAX_POSITIONS = 2_000_000
"""The most positions one sweep may ask for (the batch engine holds them all in memory)."""


def driver_values(start: float, stop: float, step: float | None, points: int | None) -> list[float]:
    """The driver values of a sweep: start, start + step, ... <= stop, or ``points`` evenly.

    Refuses (InputError) more than MAX_POSITIONS values, and ranges whose values double
    precision cannot tell apart at that spacing (``--from 1e26 --step 1``)."""
    from ..errors import InputError

    for name, v in (("--from", start), ("--to", stop)):
        if not math.isfinite(v):
            raise InputError(f"{name} must be finite, got {v!r}")
    if points is not None:
        if points < 1:
            raise InputError(f"--points must be >= 1, got {points}")
        if points > MAX_POSITIONS:
            raise InputError(f"--points {points} is more than {MAX_POSITIONS:,} positions; "
                             "sweep in parts or use fewer points")
        spacing = (stop - start) / (points - 1) if points > 1 else math.inf
    else:
        assert step is not None
        if not (math.isfinite(step) and step > 0.0):
            raise InputError(f"--step must be > 0 and finite, got {step!r}")
        count = (stop - start) / step
        if count + 1 > MAX_POSITIONS:
            raise InputError(f"--from {start:g} --to {stop:g} --step {step:g} is more than "
                             f"{MAX_POSITIONS:,} positions; use a larger --step")
        spacing = step
    ulp = math.ulp(max(abs(start), abs(stop)))
    if points != 1 and not spacing >= 1e6 * ulp:
        raise InputError(f"--from {start:g} and --to {stop:g} are too large for a spacing of "
                         f"{spacing:g}: double precision resolves only {ulp:.3g} there")
    if points is not None:
        if points == 1:
            return [start]
        return [start + (stop - start) * k / (points - 1) for k in range(points)]
    n = math.floor((stop - start) / step + 1e-9)
    return [start + k * step for k in range(n + 1)]
