"""Many designs at once: a mechanism whose parameters are arrays, solved at every driver
value for every design, vectorised over designs x positions (the engine of ``scan``).

Mechanisms with a closed form (four-bars driven by theta2 or theta4, slider-cranks):

1. The closed form gives every position of every design at once, on the branch asked
   for, or shows that the linkage cannot be assembled there (``no_solution``).
2. Newton-Raphson on the loop equations polishes every assembled position, vectorised,
   with the single solve's stopping rule: max|dq| <= tol (a length step relative to the
   design's size) and max|Phi| <= tol x size. A position counts as solved only when
   Newton converges there, stays within 1e-6 (rad, or of the size) of the closed form
   and lies on the branch; otherwise it is ``failed`` (never given numbers).

Mechanisms without a closed form (six-bars, the rapier drive) follow the sweep's
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
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..methods.newton_system import SINGULAR_RATIO
from ..problems.assembly import (
    fourbar_by_crank_np,
    is_open_np,
    slider_crank_np,
    slider_is_open_np,
)
from ..problems.closed_form import DRIVERS, REQUIRED_NAMES
from ..problems.loops import ANGLE_UNITS, Mechanism, VectorTerm
from ..rules import (
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
    """True when the vectorised closed-form engine can run this mechanism.

    That engine picks each position's assembly by its label, which is right where the two
    solutions at a driver value always carry the two labels (a crank-driven four-bar, a
    slider-crank). A rocker-driven four-bar's two assemblies can share a label (the mirror
    images of A across O2-B), and which one a design is on is then a matter of
    continuity: those designs are swept, as ``linkage sweep`` does."""
    if m.closed_form is None or m.driver.kind != "angle" or m.driver.name not in DRIVERS[m.closed_form]:
        return False
    if m.driver.name == "theta4":
        return False
    expected = set(REQUIRED_NAMES[m.closed_form]) - set(m.parameters) - {m.driver.name}
    return {u.name for u in m.unknowns} == expected


ENGINES = {
    "closed form": "closed form + vectorised Newton",
    "continuation": "vectorised continuation (a design that needs more is swept on its own)",
    "sweep": "continuation, design by design",
}
"""What each engine is called where a person reads it."""


def engine_for(m: Mechanism, branch: str | None) -> str:
    """The engine :func:`solve_designs` runs for ``m``: a key of :data:`ENGINES`."""
    if closed_form_applies(m) and branch is not None:
        return "closed form"
    if branch is None and m.closed_form is None and m.driver.kind == "angle":
        return "continuation"
    return "sweep"


def solve_designs(m: Mechanism, params: Mapping[str, np.ndarray], values: Sequence[float] | np.ndarray,
                  *, branch: str | None, tol: float = 1e-12, max_iter: int = 30,
                  paths: bool = False) -> DesignSolutions:
    """Solve ``m`` with each named parameter taking the values of its array (file units,
    one entry per design) at every driver value in ``values`` (display units).
    ``branch``: open or crossed (mechanisms with a closed form), else None (the branch of
    the file's guess, by continuation)."""
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
    _continuous(m, shown, vals)
    return DesignSolutions(tuple(u.name for u in m.unknowns), kinds, vals,
                           status.reshape(n_designs, len(vals)), feasible.reshape(n_designs, len(vals)),
                           shown, branch, engine,
                           {k: v.reshape(n_designs, len(vals)) for k, v in found_paths.items()})


# --- the closed-form engine ----------------------------------------------------------------

def _grid(m: Mechanism, params: Mapping[str, np.ndarray], vals: np.ndarray,
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


def _closed_form_seeds(m: Mechanism, grid: Mapping[str, Any], drv: np.ndarray,
                       branch: str) -> tuple[dict[str, np.ndarray], np.ndarray, np.ndarray]:
    """Each unknown (internal units) on ``branch`` at every position, from the closed form's
    numpy twins (:mod:`linkage.problems.assembly`); where the linkage can be assembled;
    and where the two branches meet (a limit position: the branch label of a solution
    there is a matter of rounding). The pick is the scalar closed form's
    (closed_form.fourbar_positions): by label. Crank-driven four-bars and slider-cranks
    only (:func:`closed_form_applies`)."""
    want_open = branch == "open"
    if m.closed_form == "slider_crank":
        (open_, crossed), ok = slider_crank_np(grid["r2"], grid["r3"], grid["e"], drv)
        fold = np.abs(math.pi - 2.0 * open_[0]) <= SEED_DISTANCE
        t3, s = open_ if want_open else crossed
        return {"theta3": t3, "s": s}, ok, fold
    r1, r2, r3, r4, t1 = (grid[k] for k in ("r1", "r2", "r3", "r4", "theta1"))
    (first, second), ok = fourbar_by_crank_np(r1, r2, r3, r4, t1, drv)
    pick = is_open_np(*first) == want_open
    fold = _apart((first[0], second[0])) <= SEED_DISTANCE
    return ({"theta3": np.where(pick, first[0], second[0]),
             "theta4": np.where(pick, first[1], second[1])}, ok, fold)


def _on_branch_here(m: Mechanism, q: Sequence[np.ndarray], branch: str) -> np.ndarray:
    """The configuration rule of each solved position (internal units): what
    :func:`~linkage.problems.closed_form.branch_rule` says, over arrays."""
    at = {u.name: c for u, c in zip(m.unknowns, q)}
    if m.closed_form == "slider_crank":
        is_open = slider_is_open_np(at["theta3"])
    else:
        is_open = is_open_np(at["theta3"], at["theta4"])
    return np.asarray(is_open == (branch == "open"))


def _apart(angles: tuple[Any, Any]) -> Any:
    """How far apart two angles are (rad, the short way round)."""
    return np.abs(np.angle(np.exp(1j * (angles[0] - angles[1]))))


def _closed_form_engine(m: Mechanism, params: Mapping[str, np.ndarray], vals: np.ndarray, branch: str,
                        tol: float, max_iter: int, n_designs: int) -> tuple[list[np.ndarray], np.ndarray,
                                                                            np.ndarray, str]:
    grid, drv = _grid(m, params, vals, n_designs)
    seeds, feasible, fold = _closed_form_seeds(m, grid, drv, branch)
    seed = [np.where(feasible, seeds[u.name], 0.0) for u in m.unknowns]
    size = _size(m, grid, drv)
    loops = VectorLoops.of_terms(_terms(m, grid, drv), len(m.unknowns), len(drv))
    q = [c.copy() for c in seed]
    done, _det = _newton(loops, q, np.flatnonzero(feasible), tol, size,
                        [k == "length" for k in (u.kind for u in m.unknowns)], max_iter)
    moved = np.zeros(len(drv))
    for c, s, u in zip(q, seed, m.unknowns):
        np.maximum(moved, np.abs(c - s) / (size if u.kind == "length" else 1.0), out=moved)
    on_branch = _on_branch_here(m, q, branch)
    status = np.where(feasible, FAILED, NO_SOLUTION).astype(np.int8)
    status[done & (moved <= SEED_DISTANCE) & (on_branch | fold) & feasible] = CONVERGED
    return q, status, feasible, "closed form + vectorised Newton"


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


def _newton(loops: VectorLoops, q_all: list[np.ndarray], active: np.ndarray, tol: float, size: np.ndarray,
            is_length: list[bool], max_iter: int, count: bool = False) -> Any:
    """Newton-Raphson at every ``active`` position at once, updating ``q_all`` in place;
    only unconverged positions keep iterating. Returns (converged, det J), and with
    ``count`` the iterations each took as well."""
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
        dq, det = solve_linear(jac, phi, active.size)
        scale = size[active]
        resid = np.abs(phi[0])
        for f in phi[1:]:
            np.maximum(resid, np.abs(f), out=resid)
        singular = ~np.isfinite(det) | (det == 0.0)
        if len(jac) == 2 and len(jac[0]) == 2:
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
    grid, _ = _grid(m, params, np.array([v0]), n_designs)  # one entry per design
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


# --- shared: joints and points, continuous angles ------------------------------------------------

def _paths(m: Mechanism, params: Mapping[str, np.ndarray], vals: np.ndarray, q: list[np.ndarray],
           solved: np.ndarray) -> dict[str, np.ndarray]:
    """Every named joint and point at every solved position (complex, NaN elsewhere), as
    LoopModel.points places them."""
    n_designs = len(solved) // max(len(vals), 1)
    grid, drv = _grid(m, params, vals, n_designs)
    _, value = _resolver(m, grid, drv, q)

    def vec(t: VectorTerm) -> Any:
        return t.sign * value(t.length) * np.exp(1j * (value(t.angle) + t.offset))

    placed: dict[str, Any] = {}
    for loop in m.loops:
        names = loop.joints
        p: Any = placed.get(names[0], 0j) if names and names[0] else 0j
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


def _continuous(m: Mechanism, shown: np.ndarray, vals: np.ndarray) -> None:
    """In place: each angle continuous along the cycle by the rule of
    :mod:`linkage.kinematics.angles` (driver order around the circle), each design's curve
    in the turn within half a turn of the file's guess at the solved position nearest the
    file's driver value."""
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
        shift = turn_shift_array(math.degrees(u.value), at)
        shown[:, :, j] = np.where(solved, continuous(a, turns + shift), np.nan)
