"""Continuation: one position of a sweep from the last, on one assembly branch.

Each position starts from the previous solution (the textbook section, section 3.9): the tangent
predictor dq/dv = -J^-1 dPhi/dv, then Newton. A solve that fails, or lands on another
branch, is retried from the last solved position in 2, 4, ... 64 sub-steps; a step is
accepted only on the target branch and close to the prediction
(:func:`linkage.rules.continues`). Branches: where the loops have a derived closed form
(``m.derivation``, complete), each position is labelled with its configuration's name
(open/crossed per four-bar or slider-crank loop, + or - per other two-way step) and a
branch given as a sign string (``+-``) is followed by the configurations' signs, one given
as a name by their names (the same thing for a crank-driven loop; a rocker-driven
four-bar's two mirror assemblies can share a name, and the sweep takes whichever carries
it); otherwise by the sign of det J. A followed branch also ends at
a fold, where det J goes to zero and the driver cannot advance on that assembly; there
continuation would jump to another assembly with no warning, so such positions are
``off_branch`` (another assembly exists, not connected) rather than silently solved. A
position that still fails is ``no_solution`` when the closed form (or, without one,
Levenberg-Marquardt's residual floor) shows the loops cannot close there; it is never
given numbers. After a gap the sweep re-enters on the branch it started on (from the
closed form on the branch's signs, or the first assembly of its name, where there is one).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

from ..linalg import SingularMatrix, det_from_lu, lu, lu_solve, lu_two
from ..methods import newton_system
from ..methods.newton_system import max_abs
from ..methods.newton_two import newton_two_of
from ..problems.derive import parse_signs, read_branch
from ..problems.loops import ANGLE_UNITS, Mechanism
from ..problems.system import LeanProblem
from ..result import Status
from ..rules import continues, continuity_measures, residual_gate, step_scales
from ..solve import system_verdict
from ..units import DEG_PER_RAD, degrees, radians
from .positions import Position, converged_position

MAX_HALVINGS = 6


class Solver:
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
        d = m.derivation
        # the derived closed form names each position's branch and re-enters it (None:
        # the sign of det J labels it, and Newton from the anchors re-enters it)
        self.derivation = d if d.complete and d.two_way else None
        self.count = len(d.two_way)
        self._params = {k: q.value for k, q in m.parameters.items()}
        self._wanted: dict[str, Any] = {}  # a target read as a BranchText (derive.read_branch)
        self._problems: dict[float, Any] = {}
        self._compiled: tuple[float, Any] = (math.nan, None)
        self.gate = residual_gate(tol, m.length_scale)
        self.step_scales = step_scales(self.kinds, m.length_scale)
        # two unknowns measured as they are: the continuation step on scalars (step_two)
        self.two_angles = self.kinds == ("angle", "angle")
        self.two = len(self.names) == 2 and self.step_scales is None and len(m.loops) == 1
        # (v, q0, q1, LU of J, dPhi/dv) where step_two last solved: the next tangent
        self.solved_at: tuple[float, float, float, Any, float, float] | None = None
        self.newton_two = newton_two_of(self.model) if self.two else None

    def compiled(self, value: float) -> Any:
        """(F, J, dPhi/dv) at a driver value (display units), the last one kept: a
        continuation step's tangent is taken where the previous step solved."""
        d, fns = self._compiled
        if d != value:
            fns = self.model.factory(value * self.scale)
            self._compiled = (value, fns)
        return fns

    def transmission(self, q: Sequence[float], value: float) -> float | None:
        """The transmission angle (deg, folded into [0, 90]) of a mechanism whose loops include
        four-bars (:func:`~linkage.problems.steps.fourbar_transmission`: the coupler as
        traversed against the output link from its pivot), at unknowns ``q`` (internal
        units) and the driver's ``value`` (display units). With several four-bar loops, the
        one farthest from 90 deg: the loop that transmits worst."""
        if not self.m.derivation.fourbars:
            return None
        mu = self.m.derivation.transmission(q, value * self.scale, self._params)
        return None if mu is None else mu * DEG_PER_RAD

    def solve_lean(self, value: float, guess: Sequence[float],
                   damped: bool = False) -> tuple[Any, list[float], int] | None:
        """What :meth:`solve` does for textbook Newton, without building a problem or a
        Result: (J, x, iterations) when it converges, None otherwise (the caller then
        takes the full path, which computes the same and says why)."""
        F, J, _ = self.compiled(value)
        try:
            phi0 = F(list(guess))
        except (ArithmeticError, ValueError):
            return None
        light = LeanProblem(F, J, self.step_scales, lambda: self.problem(value))
        # read from the module: the loop is compiled on its first use, not at import
        q, phi, _err, status, _detail, iterations, _nfev, _njev = newton_system.newton_system_lean(
            light, tuple(guess), phi0, self.tol, 0.0, self.gate, self.max_iter, damped)
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
            return {n0: x0 * DEG_PER_RAD, n1: x1 * DEG_PER_RAD}
        return {n: (degrees(v) if k == "angle" else v) for n, v, k in zip(self.names, q, self.kinds)}

    def det(self, p: Any, q: Sequence[float]) -> float:
        from ..linalg import SingularMatrix, det_from_lu, lu

        try:
            return det_from_lu(lu(p.J(list(q))))
        except SingularMatrix:
            return 0.0

    def branch(self, q: Sequence[float], det: float, value: float | None = None) -> str:
        """A position's branch label: the derivation's name for its configuration
        (:meth:`~linkage.problems.derive.Derivation.name_of`) at the driver's ``value``
        (display units; default the file's), else the sign of det J."""
        d = self.derivation
        if d is not None:
            return d.name_of(q, self.m.driver.value if value is None else value * self.scale)
        if self.m.derivation.complete:
            # a linear closed form has one assembly: solve's name for it, not det J's sign
            from ..problems.loops import ONLY

            return ONLY
        return "det+" if det > 0 else "det-"

    def on_target(self, q: Sequence[float], det: float, value: float, target: str | None,
                  label: str | None = None) -> bool:
        """Whether a configuration is on the followed branch: a sign string (``+-``) is
        followed by the configuration's signs, a name (or det+/det-) by its label."""
        if target is None:
            return True
        d = self.derivation
        if d is not None:
            if target not in self._wanted:
                try:
                    self._wanted[target] = read_branch(d, target)
                except ValueError:
                    self._wanted[target] = None  # no branch of this mechanism: no position is on it
            want = self._wanted[target]
            # the derivation's one rule: a step whose assemblies meet here is on either
            # (``label``, where given, is :meth:`branch` here: the words name_of joined)
            return want is not None and d.on_branch(q, value * self.scale, want,
                                                    words=None if label is None else label.split("/"))
        return (label if label is not None else self.branch(q, det, value)) == target


def solver_q(solver: Solver, pos: Position) -> tuple[float, ...]:
    assert pos.solution is not None
    return tuple(radians(pos.solution[n]) if k == "angle" else pos.solution[n]
                 for n, k in zip(solver.names, solver.kinds))


def q_of(solver: Solver, pos: Position | None) -> tuple[float, ...] | None:
    return solver_q(solver, pos) if pos is not None and pos.solution is not None else None


REENTERED = "re-entered from the closed form"


def assemblies(solver: Solver, v: float) -> dict[str, tuple[tuple[float, ...], list[float]]] | None:
    """Every assembly at driver value ``v`` (display units) from the derived closed form,
    keyed by name (:meth:`~linkage.problems.derive.Derivation.named_solutions`); None
    where it says nothing (no derivation, or a change point)."""
    from ..problems.derive import Indeterminate

    d = solver.derivation
    if d is None:
        return None
    try:
        return d.named_solutions(v * solver.scale)
    except Indeterminate:
        return None


def on_branch_guess(solver: Solver, v: float, target: str,
                    found: dict[str, tuple[tuple[float, ...], list[float]]]) -> list[float] | None:
    """The closed form's configuration on the followed branch at ``v``: by its signs for a
    sign string, else the first assembly carrying the name (the plain key before its
    mirror)."""
    from ..problems.derive import Indeterminate

    d = solver.derivation
    assert d is not None
    signs = parse_signs(target, solver.count)
    if signs is not None:
        try:
            return d.solve(v * solver.scale, signs)
        except Indeterminate:
            return None
    got = found.get(target)
    if got is None:
        # where the assemblies meet (a change point) the one configuration is on both
        # branches, whichever name rounding gave it
        return next((q for _, q in found.values() if solver.on_target(q, 1.0, v, target)), None)
    return got[1]


CLOSED_FORM_KEPT = "the closed form: Newton's step cannot settle here (J nearly singular)"


def closed_form_kept(solver: Solver, p: Any, v: float, q: Sequence[float],
                     target: str | None) -> Position | None:
    """The closed form's own position where Newton from it cannot meet the step test
    (within a hair of a limit, J is so nearly singular that its steps bounce at the
    rounding of Phi): kept when its residual is within the single solve's gate and it is
    on the branch. Its error is a few ulps of the answer's own sensitivity (tests hold it
    to 50-digit references), which is all any method can deliver there."""
    F, _, _ = solver.compiled(v)
    if not max_abs(F(q)) <= solver.gate:
        return None
    det = solver.det(p, q)
    if not solver.on_target(q, det, v, target):
        return None
    return Position(v, "converged", solver.display(q), solver.branch(q, det, v), 0, det,
                    solver.transmission(q, v), 0, CLOSED_FORM_KEPT)


def solve_position(solver: Solver, v: float, last_q: tuple[float, ...] | None, last_v: float | None,
                    anchor_q: tuple[float, ...], target: str | None,
                    have_closed: bool) -> tuple[Position, tuple[float, ...] | None]:
    def accept(p: Any, r: Any, substeps: int = 0, note: str = "") -> tuple[Position, tuple[float, ...]]:
        q = tuple(r.x)
        det = solver.det(p, q)
        sol = solver.display(q)
        return Position(v, "converged", sol, solver.branch(q, det, v), r.iterations, det,
                        solver.transmission(q, v), substeps, note), q

    def ok(p: Any, r: Any) -> bool:
        return r.converged and solver.on_target(r.x, solver.det(p, r.x), v, target)

    ref = assemblies(solver, v) if have_closed else None
    if have_closed and ref == {}:
        return Position(v, "no_solution", None, None, 0, None,
                        note="the closed form has no real solution"), None
    # 1. continuation from the previous position (with its own step halving)
    if last_q is not None and last_v is not None:
        pos, q = continue_step(solver, v, [(last_v, last_q)], target)
        if pos.status == "converged":
            return pos, q
    # 3. re-entry (or first position): the closed form on the target branch, else anchors
    # (also where the closed form is indeterminate, ref None: a change point where every
    # value of an unknown closes a loop, so Newton from the branch's anchor picks one)
    if have_closed and ref is not None:
        if ref:
            if target is None:
                # first position: keep the branch nearest the file's guess
                p, r = solver.solve(v, anchor_q)
                if r.converged:
                    return accept(p, r)
                target = solver.branch(anchor_q, 1.0, v)
            guess = on_branch_guess(solver, v, target, ref)
            if guess is not None:
                p, r = solver.solve(v, guess)
                if ok(p, r):
                    return accept(p, r, note=REENTERED)
                kept = closed_form_kept(solver, p, v, guess, target)
                if kept is not None:
                    return kept, tuple(guess)
            else:
                # no assembly here is on the branch (a rocker-driven four-bar's mirror
                # assemblies can both carry the other name)
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


def continue_step(solver: Solver, v: float, history: list[tuple[float, tuple[float, ...]]],
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
        fast = (step_two(solver, v, v_last, q_last, target) if solver.two else
                lean_step(solver, v, v_last, q_last, target))
        if fast is not None:
            return fast
    for h in range(0, MAX_HALVINGS + 1):
        n = 2 ** h
        vq = (v_last, q_last)
        ok = True
        r = p = None
        for k in range(1, n + 1):
            vk = v_last + (v - v_last) * k / n
            pred = predict(solver, vq[0], vq[1], vk)
            if pred is None:
                ok = False
                break
            p, r = solver.solve(vk, pred)
            if not r.converged:
                ok = False
                break
            q = tuple(r.x)
            det = solver.det(p, q)
            if not solver.on_target(q, det, vk, target):
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
            return Position(v, "converged", sol, solver.branch(q, det, v), r.iterations, det,
                            solver.transmission(q, v), n if n > 1 else 0, note), q
    return Position(v, "failed", None, None, 0, None, note="the branch could not be continued"), None


def lean_step(solver: Solver, v: float, v_last: float, q_last: tuple[float, ...],
               target: str | None) -> tuple[Position, tuple[float, ...]] | None:
    """The whole step of :func:`continue_step` (no halving) with the same predictor, Newton
    run, det, branch and continuity tests, on compiled functions only; None wherever
    that step would not be accepted, so the full loop decides (and computes the same)."""
    pred = predict(solver, v_last, q_last, v)
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
    branch = solver.branch(q, det, v)
    if not solver.on_target(q, det, v, target, branch):
        return None
    dv = abs(v - v_last) * solver.scale
    correction, moved, size = continuity_measures(q_last, pred, q)
    if not continues(correction, moved, dv, size):
        return None
    sol = solver.display(q)
    return Position(v, "converged", sol, branch, iterations, det, solver.transmission(q, v)), q


def step_two(solver: Solver, v: float, v_last: float, q_last: tuple[float, ...],
              target: str | None) -> tuple[Position, tuple[float, ...]] | None:
    """:func:`lean_step` for two unknowns measured as they are (every four-bar), on
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
    branch = solver.branch(q, det, v)
    if not solver.on_target(q, det, v, target, branch):
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
    return converged_position(v, sol, branch, k, det, solver.transmission(q, v)), q


def tangent(solver: Solver, v0: float, q0: Sequence[float]) -> list[float] | None:
    """dq/dv on the branch at (v0, q0), from J dq/dv = -dPhi/dv with the compiled, exact
    dPhi/dv; q in internal units, v in display units. None where J is singular."""
    _, J, V = solver.compiled(v0)
    try:
        return lu_solve(lu(J(list(q0))), [-solver.scale * c for c in V(list(q0))])
    except SingularMatrix:
        return None


def predict(solver: Solver, v0: float, q0: tuple[float, ...], v: float) -> tuple[float, ...] | None:
    """q0 + (v - v0) dq/dv: the tangent predictor."""
    t = tangent(solver, v0, q0)
    if t is None:
        return None
    return tuple(q + (v - v0) * ti for q, ti in zip(q0, t))


def classify_gap(solver: Solver, v: float, guesses: Sequence[tuple[float, ...]]
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


def follow(solver: Solver, values: Sequence[float], seed: tuple[float, tuple[float, ...]],
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
            step = step_two(solver, v, v_last, q_last, target) if two and abs(v - v_last) <= 5.0 \
                else None
            if step is not None:
                # the common case, first: what continue_step would return (it tries this first)
                found[i] = step[0] if step[0].input == values[i] else replace(step[0], input=values[i])
                hist = [(v, step[1])]
                if progress is not None:
                    progress(len(found) + len(done))
                continue
            pos, q = continue_step(solver, v, hist, target) if abs(v - v_last) <= 5.0 else \
                walk(solver, v, hist, target)
            if pos.status != "converged" or q is None:
                break
            found[i] = pos if pos.input == values[i] else replace(pos, input=values[i])
            hist = [(v, q)]
            if progress is not None:
                progress(len(found) + len(done))
    return found


def walk(solver: Solver, v: float, hist: list[tuple[float, tuple[float, ...]]],
          target: str | None) -> tuple[Position, tuple[float, ...] | None]:
    """Continuation over a long interval in steps of at most 2 driver units."""
    v0 = hist[-1][0]
    n = max(1, math.ceil(abs(v - v0) / 2.0))
    pos, q = Position(v, "failed", None, None, 0, None), None
    for k in range(1, n + 1):
        pos, q = continue_step(solver, v0 + (v - v0) * k / n, hist, target)
        if pos.status != "converged" or q is None:
            return pos, None
        hist = [(v0 + (v - v0) * k / n, q)]
    return Position(v, pos.status, pos.solution, pos.branch, pos.iterations, pos.det,
                    pos.transmission, pos.substeps, pos.note), q
