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
continuation for every design at once (:func:`.design_continuation.continuation_engine`); a design that
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
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..problems.derive import Derivation, read_branch
from ..problems.loops import ANGLE_UNITS, Mechanism
from ..records import frozen
from ..units import degrees, radians
from .angles import (
    anchor_index_array,
    closes_circle,
    continuous,
    driver_turn,
    turn_shift_array,
    unwrap_turns_array,
)
from .design_continuation import continuation_engine, sweep_engine, turn_references
from .design_loops import (
    CONVERGED,
    FAILED,
    NO_SOLUTION,
    OFF_BRANCH,
    design_grid,
    design_size,
    design_terms,
    newton_block,
    stepwise_linear,
)
from .vector_loops import VectorLoops

SEED_DISTANCE = 1e-6
"""How far Newton may move a closed-form position (rad, or relative to the size) and
still be that position: further means it went to another assembly."""


@frozen
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
        q, status, feasible, engine = continuation_engine(m, params, vals, tol, n_designs)
    else:
        q, status, feasible, engine = sweep_engine(m, params, vals, branch, tol, n_designs)
    found_paths = design_paths(m, params, vals, q, status == CONVERGED) if paths else {}
    kinds = tuple(u.kind for u in m.unknowns)
    shown = np.stack([degrees(c) if k == "angle" else c for c, k in zip(q, kinds)], axis=-1)
    shown[status != CONVERGED] = np.nan
    shown = shown.reshape(n_designs, len(vals), len(kinds))
    _continuous(m, shown, vals, turn_references(m, params, n_designs, tol))
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
    vectorised, with the single solve's stopping rule (:func:`.design_loops.newton_block`). A position counts
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
    size = design_size(m, grid, drv)
    loops = VectorLoops.of_terms(design_terms(m, grid, drv), n, len(drv))
    q = [np.where(ok, c, 0.0) for c in seed]
    # one loop: Cramer's rule as for every 2 x 2; more: the derivation's blocks
    linear = stepwise_linear(der) if len(m.loops) > 1 else None
    done, _det = newton_block(loops, q, np.flatnonzero(ok), tol, size,
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
    q = [radians(sol.solution[:, :, j]) if kind == "angle" else sol.solution[:, :, j]
         for j, kind in enumerate(sol.kinds)]
    meet = np.zeros(solved.shape, dtype=bool)
    for m_step in der.meets_np(q, drv, _param_columns(m, params)):
        meet |= np.broadcast_to(m_step, solved.shape)
    return (meet & solved).sum(axis=1).astype(np.int64)


# --- shared: joints and points, continuous angles ------------------------------------------------

def design_paths(m: Mechanism, params: Mapping[str, np.ndarray], vals: np.ndarray, q: list[np.ndarray],
           solved: np.ndarray) -> dict[str, np.ndarray]:
    """Every named joint and point at every solved position (complex, NaN elsewhere), by the
    one placing rule (:func:`~.placing.place_np`, as a sweep places them) on each design's
    own parameters."""
    from ..problems.loops import LoopModel
    from .placing import place_np

    n_designs = len(solved) // max(len(vals), 1)
    grid, drv = design_grid(m, params, vals, n_designs)
    model = LoopModel.compile(m, {k: v for k, v in grid.items() if k in params})
    out = {}
    for name, (x, y) in place_np(model, q, drv).items():
        full = np.empty(solved.shape, dtype=complex)
        full.real, full.imag = x, y
        full[~solved] = np.nan
        out[name] = full
    return out


def _continuous(m: Mechanism, shown: np.ndarray, vals: np.ndarray, refs: np.ndarray) -> None:
    """In place: each angle continuous along the cycle by the rule of
    :mod:`linkage.kinematics.angles` (driver order around the circle), each design's curve
    shifted by whole turns to the turn ``refs`` gives (:func:`.design_continuation.turn_references`: what
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
