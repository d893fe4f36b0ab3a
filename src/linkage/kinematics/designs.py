"""Many designs at once: a mechanism whose parameters are arrays, solved at every driver
value for every design, vectorised over designs x positions (the engine of ``scan``).

Mechanisms whose every unknown has a closed form derived from the loops
(``m.derivation.complete``: four-bars whichever joint drives, slider-cranks, the Watt
six-bar, any dyadic mechanism):

1. The derivation (:meth:`~linkage.problems.derive.Derivation.solve_np`) gives every
   position of every design at once, designs against positions, on the branch's signs
   (one per two-way step; a branch given by name is the assembly of that name where each
   design's sweep would start: :func:`design_signs`), or shows that the branch cannot be
   assembled there (``off_branch`` if another can, else ``no_solution``).
2. Newton-Raphson on the loop equations polishes every assembled position, vectorised,
   with the single solve's stopping rule: max|dq| <= tol (a length step relative to the
   design's size) and max|Phi| <= tol x size. A position counts as solved only when
   Newton converges there, stays within 1e-6 (rad, or of the size) of the closed form
   and lies on the branch's side of every step; otherwise it is ``failed`` (never given
   numbers).

Mechanisms without one (coupled loops: the offset slider, the rapier drive) follow the sweep's
continuation for every design at once (:func:`_continuation_engine`); a design that
would need more than a plain step anywhere (a halved step, a gap, a fold) is swept on
its own by :func:`~linkage.kinematics.sweep.sweep`. Either way every design gets the
sweep's statuses (tests/test_scan.py compares them).

Either way angles are reported continuously along the driver (each the representative
nearest the previous solved value, across gaps too), and each curve is shifted by whole
turns so that at the position nearest the file's driver value it lies within half a turn
of the file's guess: both engines report the same numbers for the same design.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..problems.derive import Derivation, read_branch
from ..problems.loops import ANGLE_UNITS, LoopModel, Mechanism, VectorTerm
from ..rules import (
    SINGULAR_RATIO,
    continues_array,
    continuity_measures_array,
    residual_gate,
    step_size_array,
    system_converged_array,
)
from .angles import (
    anchor_index_array,
    closes_circle,
    continuous,
    driver_turn,
    turn_shift_array,
    unwrap_turns_array,
)
from .batch import STATUS_CODES, VectorLoops, solve_linear

CONVERGED, NO_SOLUTION, FAILED, OFF_BRANCH = (STATUS_CODES[k] for k in
                                              ("converged", "no_solution", "failed", "off_branch"))
SEED_DISTANCE = 1e-6
"""How far Newton may move a closed-form position (rad, or relative to the size) and
still be that position: further means it went to another assembly."""


@dataclass(frozen=True)
class DesignSolutions:
    """Every design at every driver value. ``status`` and ``feasible`` are (designs,
    positions); ``solution`` is (designs, positions, unknowns) in display units (deg for
    angles), NaN where not solved; ``paths`` maps each joint and named point to its
    complex position (designs, positions), NaN where not solved (only when asked for)."""

    names: tuple[str, ...]
    kinds: tuple[str, ...]
    values: np.ndarray
    status: np.ndarray
    feasible: np.ndarray
    solution: np.ndarray
    branch: str | None
    engine: str
    paths: dict[str, np.ndarray]


def closed_form_applies(m: Mechanism) -> bool:
    """True when the vectorised closed-form engine can run this mechanism: every unknown
    has a closed form derived from its loops (``m.derivation.complete``). Its branches are
    followed by their signs, so a rocker-driven four-bar's two mirror assemblies (which
    may share a name) are two branches like any other."""
    return m.derivation.complete


ENGINES = {
    "closed form": "closed form + vectorised Newton",
    "continuation": "vectorised continuation (a design that needs more is swept on its own)",
    "sweep": "continuation, design by design",
}
"""What each engine is called where a person reads it."""


def engine_for(m: Mechanism, branch: str | None) -> str:
    """The engine :func:`solve_designs` runs for ``m``: a key of :data:`ENGINES`."""
    if closed_form_applies(m):
        # without a branch (the scan always gives one: scan.default_branch), each design
        # is the sweep's from the file's guess
        return "closed form" if branch is not None else "sweep"
    return "continuation" if branch is None and m.driver.kind == "angle" else "sweep"


def solve_designs(m: Mechanism, params: Mapping[str, np.ndarray], values: Sequence[float] | np.ndarray,
                  *, branch: str | None, tol: float = 1e-12, max_iter: int = 30,
                  paths: bool = False) -> DesignSolutions:
    """Solve ``m`` with each named parameter taking the values of its array (file units,
    one entry per design) at every driver value in ``values`` (display units).
    ``branch``: a branch name or sign string (mechanisms with a closed form: see
    :func:`design_signs`), else None (the branch of the file's guess, by continuation)."""
    vals = np.asarray(values, dtype=float)
    sizes = {len(np.atleast_1d(a)) for a in params.values()}
    if len(sizes) > 1:
        raise ValueError("every parameter array needs one value per design")
    n_designs = sizes.pop() if sizes else 1
    which = engine_for(m, branch)
    if which == "closed form":
        assert branch is not None
        q, status, feasible, engine = _closed_form_engine(m, params, vals, branch, tol, max_iter,
                                                          n_designs)
    elif which == "continuation":
        q, status, feasible, engine = _continuation_engine(m, params, vals, tol, n_designs)
    else:
        q, status, feasible, engine = _sweep_engine(m, params, vals, branch, tol, n_designs)
    found_paths = _paths(m, params, vals, q, status == CONVERGED) if paths else {}
    kinds = tuple(u.kind for u in m.unknowns)
    shown = np.stack([np.degrees(c) if k == "angle" else c for c, k in zip(q, kinds)], axis=-1)
    shown[status != CONVERGED] = np.nan
    shown = shown.reshape(n_designs, len(vals), len(kinds))
    _continuous(m, shown, vals, _turn_references(m, params, n_designs, tol))
    return DesignSolutions(tuple(u.name for u in m.unknowns), kinds, vals,
                           status.reshape(n_designs, len(vals)), feasible.reshape(n_designs, len(vals)),
                           shown, branch, engine,
                           {k: v.reshape(n_designs, len(vals)) for k, v in found_paths.items()})


# --- the closed-form engine ----------------------------------------------------------------

def _param_columns(m: Mechanism, params: Mapping[str, np.ndarray]) -> dict[str, Any]:
    """Every parameter in internal units, as the derivation reads them: a float, or (a
    varied one) a column of shape (designs, 1) that broadcasts against a row of positions."""
    out: dict[str, Any] = {}
    for name, q in m.parameters.items():
        if name in params:
            a = np.asarray(params[name], dtype=float).reshape(-1, 1)
            out[name] = a * ANGLE_UNITS[q.unit] if q.kind == "angle" else a
        else:
            out[name] = q.value
    return out


def _rows(columns: Mapping[str, Any], rows: np.ndarray) -> dict[str, Any]:
    """The parameter columns of some designs only."""
    return {k: (v[rows] if isinstance(v, np.ndarray) else v) for k, v in columns.items()}


def design_signs(der: Derivation, text: str, drivers: np.ndarray, columns: Mapping[str, Any],
                 n_designs: int) -> tuple[np.ndarray, np.ndarray]:
    """The sign tuple each design follows on branch ``text`` (designs x two-way steps) and
    which designs have it at all. Signs are the same for every design. A name is each
    design's own: the assembly of that name (:meth:`Derivation.named_solutions`, distinct
    configurations in :attr:`Derivation.branches` order, the second of one name its
    mirror) at the first driver value (internal units, in the order given) where the
    design has one and no two assemblies meet (:meth:`Derivation.meets`), as a sweep of
    that design given ``--branch NAME`` starts on it. Where the name is a function of the
    signs alone (a crank-driven four-bar, a slider-crank, the Watt six-bar's two four-bar
    loops) that is one sign tuple for every design."""
    want = read_branch(der, text)
    count = len(der.two_way)
    if want.signs is not None:
        return np.tile(np.array(want.signs, dtype=float), (n_designs, 1)), np.ones(n_designs, bool)
    branches = np.array(der.branches, dtype=float).reshape(len(der.branches), count)
    out = np.tile(branches[0], (n_designs, 1))
    named = np.zeros(n_designs, dtype=bool)
    todo = np.arange(n_designs)
    # the first driver value for every design (most find the name there), then all the
    # others at once for those that did not
    for cols in (drivers[:1], drivers[1:]):
        if todo.size == 0 or cols.size == 0:
            break
        sub = _rows(columns, todo)
        drv = cols[None, :]
        first = np.full(todo.size, cols.size)  # the first column where a branch has the name
        pick = np.zeros(todo.size, dtype=np.int64)  # which branch
        seen: list[tuple[list[Any], Any, list[Any]]] = []  # (q, distinct, words) of earlier branches
        for b, signs in enumerate(der.branches):
            q, ok = der.solve_np(drv, signs, sub)
            q = [np.broadcast_to(c, ok.shape) for c in q]
            words = [np.broadcast_to(w, ok.shape) for w in der.words_of_np(q, drv, sub)]
            same_name = np.zeros(ok.shape, dtype=np.int64)
            distinct = ok.copy()
            for q_e, distinct_e, words_e in seen:
                equal = np.logical_and.reduce([a == c for a, c in zip(q_e, q)]) if q else ok
                distinct &= ~(distinct_e & equal)
                alike = np.logical_and.reduce([a == c for a, c in zip(words_e, words)]) if words else ok
                same_name += distinct_e & alike
            hit = distinct & (same_name == want.mirrors)
            for meet in der.meets_np(q, drv, sub):
                # where assemblies meet (a change point) the name is a matter of rounding
                hit &= ~np.broadcast_to(meet, ok.shape)
            for w, word in zip(words, want.words):
                hit &= w == word
            col = np.where(hit.any(axis=1), hit.argmax(axis=1), cols.size)
            # names are unique at a driver value: an earlier column wins, never a tie
            earlier = col < first
            first[earlier], pick[earlier] = col[earlier], b
            seen.append((q, distinct, words))
        found = first < cols.size
        out[todo[found]] = branches[pick[found]]
        named[todo[found]] = True
        todo = todo[~found]
        agreed = np.unique(out[named], axis=0)
        if todo.size and len(agreed) == 1 and der.names_are_signs:
            # the name is one sign tuple for every design: the rest need no search
            out[todo], named[todo] = agreed[0], True
            todo = todo[:0]
    return out, named


def design_grid(m: Mechanism, params: Mapping[str, np.ndarray], vals: np.ndarray,
          n_designs: int) -> tuple[dict[str, Any], np.ndarray]:
    """Every parameter (internal units) as a float or a flat array over designs x positions,
    and the driver (internal units) flat the same way."""
    k = len(vals)
    out: dict[str, Any] = {}
    for name, q in m.parameters.items():
        if name in params:
            a = np.asarray(params[name], dtype=float)
            a = a * ANGLE_UNITS[q.unit] if q.kind == "angle" else a
            out[name] = np.repeat(a, k)
        else:
            out[name] = q.value
    scale = ANGLE_UNITS[m.driver.unit] if m.driver.kind == "angle" else 1.0
    return out, np.tile(vals * scale, n_designs)


def _size(m: Mechanism, grid: Mapping[str, Any], drv: np.ndarray) -> Any:
    """The longest length in the loops, per position (as Mechanism.length_scale)."""
    size: Any = 0.0
    for name, q in m.parameters.items():
        if q.kind == "length":
            size = np.maximum(size, np.abs(grid[name]))
    if m.driver.kind == "length":
        size = np.maximum(size, np.abs(drv))
    for loop in m.loops:
        for t in loop.vectors:
            if isinstance(t.length, float):
                size = np.maximum(size, abs(t.length))
    size = np.broadcast_to(np.asarray(size, dtype=float), drv.shape)
    return np.where(size > 0.0, size, 1.0)


def _apart(angles: tuple[Any, Any]) -> Any:
    """How far apart two angles are (rad, the short way round)."""
    d = angles[0] - angles[1]
    return np.abs(d - (2.0 * math.pi) * np.round(d / (2.0 * math.pi)))


def _distance(m: Mechanism, a: Sequence[np.ndarray], b: Sequence[np.ndarray], size: np.ndarray) -> np.ndarray:
    """max over unknowns of how far apart two configurations are (rad, or relative to the
    size); NaN where either is NaN."""
    out = np.zeros(len(size))
    for x, y, u in zip(a, b, m.unknowns):
        far = _apart((x, y)) if u.kind == "angle" else np.abs(x - y) / size
        out = np.maximum(out, far)
    return out


def _closed_form_engine(m: Mechanism, params: Mapping[str, np.ndarray], vals: np.ndarray, branch: str,
                        tol: float, max_iter: int, n_designs: int) -> tuple[list[np.ndarray], np.ndarray,
                                                                            np.ndarray, str]:
    """The derivation's closed form (:meth:`Derivation.solve_np`) for every design at every
    position at once, designs (D, 1) against positions (1, P), on each design's sign tuple
    (:func:`design_signs`); then Newton on the loops polishes every assembled position,
    vectorised, with the single solve's stopping rule (:func:`_newton`). A position counts
    as solved only when Newton converges there, stays within SEED_DISTANCE of the closed
    form and lies on the branch's side of every two-way step (or where the two sides meet
    within SEED_DISTANCE: a limit position, whose side is a matter of rounding). Where the
    branch does not assemble it is ``off_branch`` if another branch does, else
    ``no_solution``."""
    der = m.derivation
    k = len(vals)
    scale = ANGLE_UNITS[m.driver.unit] if m.driver.kind == "angle" else 1.0
    row = (vals * scale)[None, :]
    columns = _param_columns(m, params)
    signs, named = design_signs(der, branch, row[0], columns, n_designs)
    n = len(m.unknowns)
    seed = [np.full((n_designs, k), np.nan) for _ in range(n)]
    ok = np.zeros((n_designs, k), dtype=bool)
    groups, which = np.unique(signs, axis=0, return_inverse=True)
    for g, tup in enumerate(groups):
        rows = np.flatnonzero((which.reshape(-1) == g) & named)
        if rows.size == 0:
            continue
        q, good = der.solve_np(row, tuple(float(s) for s in tup), _rows(columns, rows))
        for j in range(n):
            seed[j][rows] = q[j]
        ok[rows] = good
    seed = [c.reshape(-1) for c in seed]
    ok = ok.reshape(-1)
    grid, drv = design_grid(m, params, vals, n_designs)
    # where the followed branch does not assemble: does any other? (off_branch, not no_solution)
    feasible = ok.copy()
    miss = np.flatnonzero(~ok)
    if miss.size:
        sub = _rows(grid, miss)
        for other in der.branches:
            _, good = der.solve_np(drv[miss], other, sub)
            feasible[miss] |= np.broadcast_to(good, miss.shape)
    size = _size(m, grid, drv)
    loops = VectorLoops.of_terms(_terms(m, grid, drv), n, len(drv))
    q = [np.where(ok, c, 0.0) for c in seed]
    # one loop: Cramer's rule as for every 2 x 2; more: the derivation's blocks
    linear = _stepwise_linear(der) if len(m.loops) > 1 else None
    done, _det = _newton(loops, q, np.flatnonzero(ok), tol, size,
                        [u.kind == "length" for u in m.unknowns], max_iter, linear=linear)
    moved = _distance(m, q, seed, size)
    accept = done & (moved <= SEED_DISTANCE) & ok
    # the side of every two-way step, as the branch says; where Newton landed on another
    # side, only if that side's closed form is the same position (a limit position)
    target = np.repeat(signs, k, axis=0)
    where = np.flatnonzero(accept)
    sides = der.signs_of_np([c[where] for c in q], drv[where], _rows(grid, where))
    landed = target[where].copy()
    for i, side in enumerate(sides):
        side = np.broadcast_to(side, where.shape)
        landed[:, i] = np.where(side != 0.0, side, landed[:, i])
    wrong = (landed != target[where]).any(axis=1)
    if wrong.any():
        rows = where[wrong]
        fold = np.zeros(rows.size, dtype=bool)
        tuples, back = np.unique(landed[wrong], axis=0, return_inverse=True)
        for g, tup in enumerate(tuples):
            part = np.flatnonzero(back.reshape(-1) == g)
            at = rows[part]
            other, _ = der.solve_np(drv[at], tuple(float(s) for s in tup), _rows(grid, at))
            near = _distance(m, [np.broadcast_to(c, at.shape) for c in other], [c[at] for c in seed],
                             size[at])
            fold[part] = near <= SEED_DISTANCE
        accept[rows[~fold]] = False
    status = np.where(feasible, np.where(ok, FAILED, OFF_BRANCH), NO_SOLUTION).astype(np.int8)
    status[accept] = CONVERGED
    return q, status, feasible, ENGINES["closed form"]


def _resolver(m: Mechanism, grid: Mapping[str, Any], drv: Any,
              q: Sequence[np.ndarray] = ()) -> tuple[dict[str, int], Any]:
    """(each unknown's index, the value of a length or angle reference): an unknown from
    ``q``, the driver, a parameter from ``grid`` (a float or an array), or a number."""
    index = {u.name: i for i, u in enumerate(m.unknowns)}

    def value(ref: str | float) -> Any:
        if isinstance(ref, str):
            if ref in index:
                return q[index[ref]]
            return drv if ref == m.driver.name else grid[ref]
        return ref

    return index, value


def _terms(m: Mechanism, grid: Mapping[str, Any], drv: np.ndarray) -> list[list[tuple[Any, ...]]]:
    """The loops' vectors with parameters and driver resolved to floats or flat arrays."""
    index, value = _resolver(m, grid, drv)

    def ref(r: str | float) -> tuple[Any, int]:
        return (0.0, index[r]) if isinstance(r, str) and r in index else (value(r), -1)

    return [[(t.sign, *ref(t.length), *ref(t.angle), t.offset) for t in loop.vectors] for loop in m.loops]


Linear = Callable[[list[list[Any]], list[np.ndarray], int], tuple[list[Any], Any, Any]]
"""J dq = -Phi at every position: (dq, det J, where J is singular)."""


def _stepwise_linear(der: Derivation) -> Linear:
    """J dq = -Phi by the derivation's steps, as the closed form solves the loops: each
    step's two equations (its loop, or its two loops combined with the step's weights)
    hold only its two unknowns and those of earlier steps, so J is block triangular and
    every block is a 2 x 2 solved by Cramer's rule (a Watt six-bar's 4 x 4 at a fifth of
    the cost of a stacked numpy solve). J is singular where a block is, by the 2 x 2 test
    :func:`_newton` applies to a one-loop J."""
    plan = [(tuple(zip(step.loops, step.weights)), step.unknowns) for step in der.steps]

    def solve(jac: list[list[Any]], phi: list[np.ndarray], k: int) -> tuple[list[Any], Any, Any]:
        dq: list[Any] = [None] * len(jac[0])
        det: Any = 1.0
        singular = np.zeros(k, dtype=bool)
        with np.errstate(invalid="ignore", divide="ignore"):
            for rows, (a, b) in plan:
                ex: Any = 0.0
                ey: Any = 0.0
                jx: list[Any] = [0.0] * len(dq)
                jy: list[Any] = [0.0] * len(dq)
                for loop, w in rows:
                    ex, ey = ex - w * phi[2 * loop], ey - w * phi[2 * loop + 1]
                    for j in range(len(dq)):
                        jx[j] = jx[j] + w * jac[2 * loop][j]
                        jy[j] = jy[j] + w * jac[2 * loop + 1][j]
                for j, d_j in enumerate(dq):
                    if d_j is not None:  # an unknown of an earlier step
                        ex, ey = ex - jx[j] * d_j, ey - jy[j] * d_j
                pa, pb, pc, pd = jx[a], jx[b], jy[a], jy[b]
                det_s = pa * pd - pb * pc
                singular |= ~(np.abs(det_s) > SINGULAR_RATIO * (np.abs(pa * pd) + np.abs(pb * pc)))
                dq[a], dq[b] = (ex * pd - pb * ey) / det_s, (pa * ey - pc * ex) / det_s
                det = det * det_s
        return [np.broadcast_to(d_j, (k,)) for d_j in dq], np.broadcast_to(det, (k,)), singular

    return solve


def _newton(loops: VectorLoops, q_all: list[np.ndarray], active: np.ndarray, tol: float, size: np.ndarray,
            is_length: list[bool], max_iter: int, count: bool = False, linear: Linear | None = None) -> Any:
    """Newton-Raphson at every ``active`` position at once, updating ``q_all`` in place;
    only unconverged positions keep iterating. Returns (converged, det J), and with
    ``count`` the iterations each took as well. ``linear``: how J dq = -Phi is solved
    (default: Cramer's rule for 2 x 2, else a stacked numpy solve)."""
    n_pos = len(size)
    done = np.zeros(n_pos, dtype=bool)
    det_out = np.full(n_pos, np.nan)
    iterations = np.zeros(n_pos, dtype=np.int32)
    gate_all = residual_gate(tol, size)
    q = [c[active] for c in q_all]
    for _ in range(max_iter):
        if active.size == 0:
            break
        phi, jac = loops.evaluate(q, active)
        scale = size[active]
        resid = np.abs(phi[0])
        for f in phi[1:]:
            np.maximum(resid, np.abs(f), out=resid)
        if linear is not None:
            dq, det, singular = linear(jac, phi, active.size)
        else:
            dq, det = solve_linear(jac, phi, active.size)
            singular = ~np.isfinite(det) | (det == 0.0)
        if linear is None and len(jac) == 2 and len(jac[0]) == 2:
            (a, b), (c, d) = jac
            with np.errstate(invalid="ignore"):
                singular |= ~(np.abs(det) > SINGULAR_RATIO * (np.abs(a * d) + np.abs(b * c)))
        dq = [np.where(singular, 0.0, d_j) for d_j in dq]
        for j, d_j in enumerate(dq):
            q[j] += d_j
        step = step_size_array(dq, [scale if length else 1.0 for length in is_length])
        gate = gate_all[active]
        with np.errstate(invalid="ignore"):
            # as a single solve: a singular J with max|Phi| already within tolerance is a
            # root to that tolerance (a limit position); otherwise the step test decides
            finished = np.where(singular, resid <= gate, system_converged_array(step, resid, tol, gate))
            keep = ~finished & ~singular & np.isfinite(step)
        for j in range(len(q)):
            q_all[j][active] = q[j]
        det_out[active] = det
        iterations[active] += 1
        done[active[finished]] = True
        active = active[keep]
        q = [c[keep] for c in q]
    return (done, det_out, iterations) if count else (done, det_out)


# --- the continuation engines -----------------------------------------------------------------

SEED_ITERATIONS = 12
"""A design whose seed takes Newton longer than this goes through the one-at-a-time sweep
(whose loop may stop such a run earlier, as diverged or at rounding level)."""


def _continuation_engine(m: Mechanism, params: Mapping[str, np.ndarray], vals: np.ndarray, tol: float,
                         n_designs: int) -> tuple[list[np.ndarray], np.ndarray, np.ndarray, str]:
    """The sweep's continuation for every design at once, where it is plain sailing.

    The seed is Newton from the file's guess at the file's driver value (the branch: the
    sign of det J there); the positions follow in the sweep's order, each from the last
    by the tangent predictor and Newton, with the sweep's tests: converged, det J of the
    same sign, and the correction within the continuity bound. A design that fails any
    test anywhere (it would need a halved step, or reaches a gap or a fold) leaves the
    batch and goes through :func:`~linkage.kinematics.sweep.sweep` on its own, so every
    design gets the sweep's statuses; a design that passes them all is the sweep's
    continuation step for step, vectorised.
    """
    scale = ANGLE_UNITS[m.driver.unit]
    v0 = m.driver.value / scale
    n, k = len(m.unknowns), len(vals)
    is_length = [u.kind == "length" for u in m.unknowns]
    grid, _ = design_grid(m, params, np.array([v0]), n_designs)  # one entry per design
    size = _size(m, grid, np.full(n_designs, v0 * scale))
    clean = np.ones(n_designs, dtype=bool)
    q_out = [np.full((n_designs, k), np.nan) for _ in range(n)]

    def at(v: float, rows: np.ndarray) -> tuple[VectorLoops, dict[str, Any]]:
        sub = {key: (val[rows] if isinstance(val, np.ndarray) else val) for key, val in grid.items()}
        drv = np.full(rows.size, v * scale)
        return VectorLoops.of_terms(_terms(m, sub, drv), n, rows.size), sub

    # the seed
    rows = np.arange(n_designs)
    loops, _ = at(v0, rows)
    seed = [np.full(n_designs, u.value) for u in m.unknowns]
    done, _, iters = _newton(loops, seed, rows, tol, size, is_length, SEED_ITERATIONS, count=True)
    clean &= done & (iters <= SEED_ITERATIONS)
    det0 = _det_at(loops, seed, n_designs)
    clean &= np.isfinite(det0) & (det0 != 0.0)
    positive = det0 > 0.0
    order = np.argsort(vals, kind="stable")
    up = [int(i) for i in order if vals[i] >= v0]
    down = [int(i) for i in order[::-1] if vals[i] < v0]
    full_turn = k > 0 and vals[order[-1]] - vals[order[0]] >= 360.0 - 1e-9
    passes = [[(i, float(vals[i])) for i in up], [(i, float(vals[i])) for i in down]]
    if full_turn:  # as the sweep: each direction carries on around the turn
        passes[0] += [(i, float(vals[i]) + 360.0) for i in down[::-1]]
        passes[1] += [(i, float(vals[i]) - 360.0) for i in up[::-1]]
    reached = np.zeros((n_designs, k), dtype=bool)
    for plan in passes:
        live = np.flatnonzero(clean)
        q_last = [c[live] for c in seed]
        v_last = v0
        here: tuple[VectorLoops, dict[str, Any]] | None = None  # the loops at v_last, while live is unchanged
        for i, v in plan:
            if live.size == 0:
                break
            if reached[live, i].all():
                continue  # found by the other pass: the sweep skips it too
            if abs(v - v_last) > 5.0:  # the sweep walks long intervals in smaller steps
                clean[live] = False
                break
            fresh = ~reached[live, i]
            loops_last, sub = here if here is not None else at(v_last, live)
            t = _tangent(m, loops_last, sub, v_last * scale, q_last, scale)
            pred = [ql + (v - v_last) * tj for ql, tj in zip(q_last, t)]
            loops_v, sub_v = at(v, live)
            q = [c.copy() for c in pred]
            ok, _, _ = _newton(loops_v, q, np.arange(live.size), tol, size[live], is_length, 50, count=True)
            det = _det_at(loops_v, q, live.size)
            ok &= np.isfinite(det) & ((det > 0.0) == positive[live]) & (det != 0.0)
            dv = abs(v - v_last) * scale
            correction, moved, mag = continuity_measures_array(q_last, pred, q)
            with np.errstate(invalid="ignore"):
                ok &= continues_array(correction, moved, dv, mag)
            clean[live[~ok]] = False
            keep = ok
            here = (loops_v, sub_v) if keep.all() else None
            live = live[keep]
            q = [c[keep] for c in q]
            store = fresh[keep]
            for j in range(n):
                q_out[j][live[store], i] = q[j][store]
            reached[live[store], i] = True
            q_last, v_last = q, v
    clean &= reached.all(axis=1)
    status = np.full((n_designs, k), CONVERGED, dtype=np.int8)
    q_flat = [c.reshape(-1) for c in q_out]
    status_flat = status.reshape(-1)
    rest = np.flatnonzero(~clean)
    if rest.size:
        sub = {name: np.atleast_1d(a)[rest] for name, a in params.items()}
        q_rest, st_rest, _, _ = _sweep_engine(m, sub, vals, None, tol, rest.size)
        idx = (rest[:, None] * k + np.arange(k)[None, :]).reshape(-1)
        for j in range(n):
            q_flat[j][idx] = q_rest[j]
        status_flat[idx] = st_rest
    feasible = (status_flat == CONVERGED) | (status_flat == OFF_BRANCH)
    engine = "vectorised continuation" + (f" ({rest.size} designs one at a time)" if rest.size else "")
    return q_flat, status_flat, feasible, engine


def _det_at(loops: VectorLoops, q: list[np.ndarray], count: int) -> np.ndarray:
    """det J at q (every entry)."""
    _, jac = loops.evaluate(q, None)
    zeros = [np.zeros(count) for _ in q]
    _, det = solve_linear(jac, zeros, count)
    return np.broadcast_to(det, (count,)).astype(float)


def _tangent(m: Mechanism, loops: VectorLoops, grid: Mapping[str, Any], drv: float,
             q: list[np.ndarray], scale: float) -> list[np.ndarray]:
    """dq/dv (per display unit of the driver) from J dq/dv = -scale dPhi/dv, as
    :func:`~linkage.kinematics.sweep.tangent`; NaN where J is singular. ``grid``: the
    parameters of these designs."""
    count = len(q[0])
    _, value = _resolver(m, grid, drv, q)

    rhs = []
    for loop in m.loops:
        dx: Any = np.zeros(count)
        dy: Any = np.zeros(count)
        for t in loop.vectors:
            th = value(t.angle) + t.offset
            if t.angle == m.driver.name:
                r = value(t.length)
                dx = dx - t.sign * r * np.sin(th)
                dy = dy + t.sign * r * np.cos(th)
            if t.length == m.driver.name:
                dx = dx + t.sign * np.cos(th)
                dy = dy + t.sign * np.sin(th)
        rhs += [-scale * np.broadcast_to(dx, (count,)), -scale * np.broadcast_to(dy, (count,))]
    _, jac = loops.evaluate(q, None)
    # J t = rhs, i.e. J t + (-rhs) = 0: solve_linear solves J dq = -phi
    dq, _ = solve_linear(jac, [-c for c in rhs], count)
    return [np.asarray(c, dtype=float) for c in dq]


def _sweep_engine(m: Mechanism, params: Mapping[str, np.ndarray], vals: np.ndarray, branch: str | None,
                  tol: float, n_designs: int) -> tuple[list[np.ndarray], np.ndarray, np.ndarray, str]:
    from .stepwise import sweep

    n, k = len(m.unknowns), len(vals)
    q = [np.full(n_designs * k, np.nan) for _ in range(n)]
    status = np.empty(n_designs * k, dtype=np.int8)
    listed = [float(v) for v in vals]
    for d in range(n_designs):
        design = m.with_values({name: float(np.atleast_1d(a)[d]) for name, a in params.items()}, {})
        result = sweep(design, listed, branch=branch, tol=tol)
        for i, p in enumerate(result.positions):
            status[d * k + i] = STATUS_CODES[p.status]
            if p.solution is not None:
                for j, u in enumerate(m.unknowns):
                    v = p.solution[u.name]
                    q[j][d * k + i] = math.radians(v) if u.kind == "angle" else v
    feasible = (status == CONVERGED) | (status == OFF_BRANCH)
    return q, status, feasible, "continuation, design by design"


def meeting_counts(m: Mechanism, params: Mapping[str, np.ndarray], sol: DesignSolutions) -> np.ndarray:
    """Per design, how many solved positions are where two assemblies of a two-way step
    meet to rounding (:meth:`~linkage.problems.derive.Derivation.meets`: a change point, s + l
    = p + q, or a limit exactly on the grid): there the branch is a matter of rounding, as
    a sweep of the design flags it (:attr:`~.positions.SweepResult.meetings`)."""
    der = m.derivation
    solved = sol.status == CONVERGED
    if not der.complete or not der.two_way:
        return np.zeros(len(solved), dtype=np.int64)
    scale = ANGLE_UNITS[m.driver.unit] if m.driver.kind == "angle" else 1.0
    drv = (np.asarray(sol.values, dtype=float) * scale)[None, :]
    q = [np.radians(sol.solution[:, :, j]) if kind == "angle" else sol.solution[:, :, j]
         for j, kind in enumerate(sol.kinds)]
    meet = np.zeros(solved.shape, dtype=bool)
    for m_step in der.meets_np(q, drv, _param_columns(m, params)):
        meet |= np.broadcast_to(m_step, solved.shape)
    return (meet & solved).sum(axis=1).astype(np.int64)


# --- shared: joints and points, continuous angles ------------------------------------------------

def _paths(m: Mechanism, params: Mapping[str, np.ndarray], vals: np.ndarray, q: list[np.ndarray],
           solved: np.ndarray) -> dict[str, np.ndarray]:
    """Every named joint and point at every solved position (complex, NaN elsewhere), as
    LoopModel.points places them."""
    n_designs = len(solved) // max(len(vals), 1)
    grid, drv = design_grid(m, params, vals, n_designs)
    _, value = _resolver(m, grid, drv, q)

    def vec(t: VectorTerm) -> Any:
        return t.sign * value(t.length) * np.exp(1j * (value(t.angle) + t.offset))

    placed: dict[str, Any] = {}
    for loop in m.loops:
        names = loop.joints
        start = complex(*m.origin)
        p: Any = placed.get(names[0], start) if names and names[0] else start
        for name, t in zip(names or [""] * len(loop.vectors), loop.vectors):
            if name:
                placed.setdefault(name, p)
            p = p + vec(t)
    for pname, (origin, vectors) in m.points.items():
        p = placed[origin]
        for t in vectors:
            p = p + vec(t)
        placed[pname] = p
    out = {}
    for name, p in placed.items():
        full = np.broadcast_to(np.asarray(p, dtype=complex), solved.shape).copy()
        full[~solved] = np.nan
        out[name] = full
    return out


def _turn_references(m: Mechanism, params: Mapping[str, np.ndarray], n_designs: int,
                     tol: float) -> np.ndarray:
    """What ``solve FILE`` gives each design at the file's driver value from the file's
    guess (display units, designs x unknowns; NaN where it does not converge): the turn a
    sweep reports its angles in (:func:`~linkage.kinematics.stepwise.sweep`). Newton from
    the guess for every design at once; a design where some whole step would not have
    lowered |Phi|^2 (where the single solve's globalised Newton takes another step) is
    solved by that solve itself."""
    from ..solve import solve_system

    n = len(m.unknowns)
    scale = ANGLE_UNITS[m.driver.unit] if m.driver.kind == "angle" else 1.0
    grid, drv = design_grid(m, params, np.array([m.driver.value / scale]), n_designs)
    loops = VectorLoops.of_terms(_terms(m, grid, drv), n, n_designs)
    size = _size(m, grid, drv)
    is_length = [u.kind == "length" for u in m.unknowns]
    gate = residual_gate(tol, size)
    q = [np.full(n_designs, u.value) for u in m.unknowns]
    plain = np.ones(n_designs, dtype=bool)  # every step so far the globalised solve's too
    done = np.zeros(n_designs, dtype=bool)
    phi, jac = loops.evaluate(q, None)
    with np.errstate(invalid="ignore", over="ignore"):
        for _ in range(50):
            live = plain & ~done
            if not live.any():
                break
            dq, _ = solve_linear(jac, phi, n_designs)
            trial = [c + d for c, d in zip(q, dq)]
            phi_t, jac_t = loops.evaluate(trial, None)
            tiny = _largest(dq) <= 64.0 * np.finfo(float).eps * (1.0 + _largest(q))
            plain &= ~live | (_sumsq(phi_t) <= (1.0 - 1e-4) * _sumsq(phi)) | tiny
            step = step_size_array(dq, [size if length else 1.0 for length in is_length])
            done |= live & plain & system_converged_array(step, _largest(phi), tol, gate)
            q = [np.where(live, t, c) for t, c in zip(trial, q)]
            phi = [np.where(live, t, c) for t, c in zip(phi_t, phi)]
            jac = [[np.where(live, t, c) for t, c in zip(rt, rc)] for rt, rc in zip(jac_t, jac)]
    out = np.stack([np.degrees(c) if u.kind == "angle" else c for c, u in zip(q, m.unknowns)], axis=1)
    out[~done] = np.nan
    rest = ~plain
    if rest.any() and m.derivation.complete:
        # no assembly there on any branch: that solve cannot converge either
        there = np.zeros(n_designs, dtype=bool)
        for signs in m.derivation.branches:
            there |= np.broadcast_to(m.derivation.solve_np(drv, signs, grid)[1], there.shape)
        rest &= there
    for d in np.flatnonzero(rest):
        design = m.with_values({k: float(np.atleast_1d(a)[d]) for k, a in params.items()}, {})
        # its loops walked, not compiled (the same Phi and J; compiling costs more than the solve)
        F, J = LoopModel.compile(design).interpreted_functions(float(drv[d]))
        r = solve_system(F, tuple(u.value for u in m.unknowns), jac=J, tol=tol, record=False)
        if r.converged:
            out[d] = [math.degrees(x) if u.kind == "angle" else x for x, u in zip(r.x, m.unknowns)]
    return out


def _largest(parts: Sequence[Any]) -> Any:
    out = np.abs(parts[0])
    for p in parts[1:]:
        out = np.maximum(out, np.abs(p))
    return out


def _sumsq(parts: Sequence[Any]) -> Any:
    return sum(p * p for p in parts)


def _continuous(m: Mechanism, shown: np.ndarray, vals: np.ndarray, refs: np.ndarray) -> None:
    """In place: each angle continuous along the cycle by the rule of
    :mod:`linkage.kinematics.angles` (driver order around the circle), each design's curve
    shifted by whole turns to the turn ``refs`` gives (:func:`_turn_references`: what
    ``solve FILE`` gives the design) at the solved position nearest the file's driver
    value, as the sweep does; not shifted where that solve does not converge."""
    if shown.size == 0:
        return
    scale = ANGLE_UNITS[m.driver.unit] if m.driver.kind == "angle" else 1.0
    v0 = m.driver.value / scale
    turn = driver_turn(m.driver.unit)
    closes = m.driver.kind == "angle" and closes_circle([float(v) for v in vals], turn)
    for j, u in enumerate(m.unknowns):
        if u.kind != "angle":
            continue
        a = shown[:, :, j]
        solved = np.isfinite(a)
        if not solved.any():
            continue
        turns = unwrap_turns_array(a, closes)
        near = anchor_index_array(vals, solved, v0, closes, turn)[:, None]
        at = continuous(np.take_along_axis(a, near, axis=1), np.take_along_axis(turns, near, axis=1))
        shift = np.nan_to_num(turn_shift_array(refs[:, j:j + 1], at), nan=0.0)
        shown[:, :, j] = np.where(solved, continuous(a, turns + shift), np.nan)
