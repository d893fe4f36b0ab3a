"""Whole-cycle sweeps: continuation, assembly branches, no-solution gaps, limits and toggles.

Each position starts from the previous solution (seed 001, section 3.9). A solve that
fails, or lands on another branch, is retried from the last solved position in 2, 4,
... 64 sub-steps. A position that still fails is ``no_solution`` when the closed form
(or, without one, Levenberg-Marquardt's residual floor) shows the loops cannot close
there; it is never given numbers. After a gap the sweep re-enters on the branch it
started on (from the closed form where there is one). Branches: the closed form's
open/crossed rule for four-bars and slider-cranks, the sign of det J otherwise.
Limit positions (the feasible range ends) and toggles (det J changes sign between
solved positions) are located by bisection to 1e-9 of the driver's unit, or taken from
the closed form where it gives them exactly.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from ..problems.closed_form import (
    arc_limits,
    arcs_within,
    feasible_arcs,
    fourbar_class,
    wrap_degrees,
)
from ..problems.loops import ANGLE_UNITS, LoopModel, Mechanism
from ..result import Status

MAX_HALVINGS = 6
LOCATE_TOL = 1e-9  # driver units (deg for angles)


@dataclass(frozen=True)
class Position:
    input: float
    status: str  # "converged", "no_solution" or "failed"
    solution: dict[str, float] | None
    branch: str | None
    iterations: int
    det: float | None
    transmission: float | None = None
    substeps: int = 0
    note: str = ""


@dataclass(frozen=True)
class SweepResult:
    mechanism: str
    driver: str
    driver_unit: str
    names: tuple[str, ...]
    units: tuple[str, ...]
    positions: tuple[Position, ...]
    feasible_ranges: tuple[tuple[float, float], ...]
    toggles: tuple[float, ...]
    branch: str | None
    classification: dict[str, Any] = field(default_factory=dict)
    method: str = "newton"

    @property
    def summary(self) -> dict[str, int]:
        out: dict[str, int] = {}
        for p in self.positions:
            out[p.status] = out.get(p.status, 0) + 1
        return out

    def column(self, name: str) -> list[float | None]:
        return [p.solution[name] if p.solution else None for p in self.positions]


class _Solver:
    """Solves one position of a mechanism at a driver value, from a guess."""

    def __init__(self, m: Mechanism, method: str, tol: float, max_iter: int) -> None:
        self.m = m
        self.model = LoopModel.compile(m)
        self.method = method
        self.tol = tol
        self.max_iter = max_iter
        self.scale = ANGLE_UNITS[m.driver.unit] if m.driver.kind == "angle" else 1.0
        self.kinds = tuple(u.kind for u in m.unknowns)
        self.names = tuple(u.name for u in m.unknowns)
        from ..problems.closed_form import branch_rule

        self.rule = branch_rule(m) if m.closed_form else None

    def problem(self, value: float, guess: Sequence[float]) -> Any:
        return self.model.problem_at(value * self.scale, tuple(guess))

    def solve(self, value: float, guess: Sequence[float], method: str | None = None) -> tuple[Any, Any]:
        from ..solve import solve_system

        p = self.problem(value, guess)
        r = solve_system(p, method=method or self.method, tol=self.tol, max_iter=self.max_iter,
                         record=False)
        return p, r

    def display(self, q: Sequence[float]) -> dict[str, float]:
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
    solver = _Solver(m, method, tol, max_iter)
    values = list(values)
    lo, hi = (min(values), max(values)) if values else (0.0, 0.0)
    arcs = feasible_arcs(m) if m.closed_form and m.driver.kind == "angle" else None
    have_closed = m.closed_form is not None and m.driver.kind == "angle"
    guess0 = tuple(u.value for u in m.unknowns)
    target = branch
    positions: list[Position] = []
    last_q: tuple[float, ...] | None = None
    last_v: float | None = None
    anchor_q = guess0  # last solution on the target branch, for re-entry without a closed form
    if values and not have_closed:
        # The file's guess belongs to the file's driver value: solve there, then walk to
        # the first sweep value in short steps, so the sweep starts on that branch.
        last_q, last_v = _walk_to(solver, m, values[0], guess0)
        if last_q is not None:
            anchor_q = last_q
            if target is None:
                p0 = solver.problem(last_v, last_q)  # type: ignore[arg-type]
                target = solver.branch(last_q, solver.det(p0, last_q))
    for i, v in enumerate(values):
        pos, q = _solve_position(solver, v, last_q, last_v, anchor_q, target, have_closed)
        if pos.status == "converged":
            if target is None:
                target = pos.branch
            last_q, last_v, anchor_q = q, v, q
        else:
            last_q, last_v = None, None
        positions.append(pos)
        if progress is not None:
            progress(i + 1)
    positions = _continuous_angles(solver, positions)
    toggles = _toggles(solver, positions, arcs, lo, hi, have_closed)
    ranges = (tuple(arcs_within(arcs, lo, hi)) if have_closed else _solved_ranges(positions))
    classification: dict[str, Any] = {}
    if m.closed_form == "fourbar":
        v = {k: q.value for k, q in m.parameters.items()}
        classification = fourbar_class(v["r1"], v["r2"], v["r3"], v["r4"])
    return SweepResult(m.name, m.driver.name, m.driver.unit, solver.names,
                       tuple("deg" if k == "angle" else m.length_unit for k in solver.kinds),
                       tuple(positions), ranges, tuple(toggles), target, classification, method)


def _solve_position(solver: _Solver, v: float, last_q: tuple[float, ...] | None, last_v: float | None,
                    anchor_q: tuple[float, ...], target: str | None,
                    have_closed: bool) -> tuple[Position, tuple[float, ...] | None]:
    def accept(p: Any, r: Any, substeps: int = 0, note: str = "") -> tuple[Position, tuple[float, ...]]:
        q = tuple(r.x)
        det = solver.det(p, q)
        sol = solver.display(q)
        return Position(v, "converged", sol, solver.branch(q, det), r.iterations, det,
                        _transmission(solver, sol), substeps, note), q

    def ok(p: Any, r: Any) -> bool:
        return r.converged and (target is None or solver.branch(r.x, solver.det(p, r.x)) == target)

    # 1. continuation from the previous position
    if last_q is not None:
        p, r = solver.solve(v, last_q)
        if ok(p, r):
            return accept(p, r)
        # 2. the same path in ever smaller sub-steps
        assert last_v is not None
        for h in range(1, MAX_HALVINGS + 1):
            n = 2 ** h
            q = last_q
            good = True
            for k in range(1, n + 1):
                vk = last_v + (v - last_v) * k / n
                p, r = solver.solve(vk, q)
                if not ok(p, r):
                    good = False
                    break
                q = tuple(r.x)
            if good:
                return accept(p, r, n, f"step halved to 1/{n}")
    # 3. re-entry (or first position): the closed form on the target branch, else anchors
    if have_closed:
        ref = solver.problem(v, anchor_q).reference()
        if ref == {}:
            return Position(v, "no_solution", None, None, 0, None,
                            note="the closed form has no real solution"), None
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
                    return accept(p, r, note="re-entered from the closed form")
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


def _continuous_angles(solver: _Solver, positions: list[Position]) -> list[Position]:
    """Report each angle as the representative (mod 360) nearest its previous solved value,
    starting in (-180, 180]: curves stay continuous, across gaps too."""
    from dataclasses import replace

    angles = [n for n, k in zip(solver.names, solver.kinds) if k == "angle"]
    prev: dict[str, float] = {}
    out = []
    for p in positions:
        if p.solution is None:
            out.append(p)
            continue
        sol = dict(p.solution)
        for n in angles:
            v = sol[n]
            ref = prev.get(n)
            sol[n] = wrap_degrees(v) if ref is None else ref + wrap_degrees(v - ref)
            prev[n] = sol[n]
        out.append(replace(p, solution=sol))
    return out


def _walk_to(solver: _Solver, m: Mechanism, v: float,
             guess: tuple[float, ...]) -> tuple[tuple[float, ...] | None, float | None]:
    """Solve at the file's own driver value, then continue to v in steps of <= 2 units."""
    v0 = m.driver.value / solver.scale
    _p, r = solver.solve(v0, guess)
    if not r.converged:
        return None, None
    q = tuple(r.x)
    n = max(1, math.ceil(abs(v - v0) / 2.0))
    for k in range(1, n + 1):
        _p, r = solver.solve(v0 + (v - v0) * k / n, q)
        if not r.converged:
            return None, None
        q = tuple(r.x)
    return q, v


def _transmission(solver: _Solver, sol: dict[str, float]) -> float | None:
    """Four-bars: the transmission angle between coupler and output link, in [0, 180]."""
    if solver.m.closed_form != "fourbar":
        return None
    values = {k: math.degrees(q.value) for k, q in solver.m.parameters.items() if q.kind == "angle"}
    values[solver.m.driver.name] = None  # type: ignore[assignment]
    t3 = sol.get("theta3", values.get("theta3"))
    t4 = sol.get("theta4", values.get("theta4"))
    if t3 is None or t4 is None:
        return None
    return abs(wrap_degrees(t4 - t3))


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


def _toggles(solver: _Solver, positions: Sequence[Position], arcs: Any, lo: float, hi: float,
             have_closed: bool) -> list[float]:
    found: list[float] = []
    if have_closed:
        found += arc_limits(arcs, lo, hi)
    pairs = list(itertools.pairwise(positions))
    for a, b in pairs:
        if a.status == "converged" and b.status == "converged" and a.det and b.det \
                and (a.det > 0) != (b.det > 0):
            found.append(_bisect_det(solver, a, b))
        elif not have_closed and (a.status == "converged") != (b.status == "converged") \
                and "no_solution" in (a.status, b.status):
            found.append(_bisect_limit(solver, a, b))
    return sorted(found)


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
    """One side solves, the other has no solution: bisect on solvability."""
    good, bad = (a, b) if a.status == "converged" else (b, a)
    q = solver_q(solver, good)
    vg, vb = good.input, bad.input
    while abs(vb - vg) > LOCATE_TOL:
        vm = 0.5 * (vg + vb)
        _p, r = solver.solve(vm, q)
        if r.converged:
            vg, q = vm, tuple(r.x)
        else:
            vb = vm
    return 0.5 * (vg + vb)


def solver_q(solver: _Solver, pos: Position) -> tuple[float, ...]:
    assert pos.solution is not None
    return tuple(math.radians(pos.solution[n]) if k == "angle" else pos.solution[n]
                 for n, k in zip(solver.names, solver.kinds))


def driver_values(start: float, stop: float, step: float | None, points: int | None) -> list[float]:
    """The driver values of a sweep: start, start + step, ... <= stop, or ``points`` evenly."""
    if points is not None:
        if points == 1:
            return [start]
        return [start + (stop - start) * k / (points - 1) for k in range(points)]
    assert step is not None
    n = math.floor((stop - start) / step + 1e-9)
    return [start + k * step for k in range(n + 1)]
