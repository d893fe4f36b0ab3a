"""The scan's engines for mechanisms without a closed form (coupled loops: the offset
slider, the rapier drive): the sweep's continuation for every design at once
(:func:`continuation_engine`), design by design where a design needs more
(:func:`sweep_engine`), and the turn each design's angles are reported in
(:func:`turn_references`). :mod:`.designs` chooses the engine."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from functools import partial
from typing import Any

import numpy as np

from ..problems.loops import ANGLE_UNITS, LoopModel, Mechanism
from ..rules import (
    GOING,
    SystemStops,
    continues_array,
    continuity_measures_array,
    converged_codes,
    residual_gate,
    step_size_array,
)
from ..units import degrees, radians
from .batch import STATUS_CODES
from .design_loops import (
    CONVERGED,
    OFF_BRANCH,
    design_grid,
    design_size,
    design_tangent,
    design_terms,
    det_at,
    newton_block,
)
from .vector_loops import VectorLoops, solve_linear

SEED_ITERATIONS = 12
"""A design whose seed takes Newton longer than this goes through the one-at-a-time sweep
(whose loop may stop such a run earlier, as diverged or at rounding level)."""


def continuation_engine(m: Mechanism, params: Mapping[str, np.ndarray], vals: np.ndarray, tol: float,
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
    size = design_size(m, grid, np.full(n_designs, v0 * scale))
    clean = np.ones(n_designs, dtype=bool)
    q_out = [np.full((n_designs, k), np.nan) for _ in range(n)]

    def at(v: float, rows: np.ndarray) -> tuple[VectorLoops, dict[str, Any]]:
        sub = {key: (val[rows] if isinstance(val, np.ndarray) else val) for key, val in grid.items()}
        drv = np.full(rows.size, v * scale)
        return VectorLoops.of_terms(design_terms(m, sub, drv), n, rows.size), sub

    # the seed
    rows = np.arange(n_designs)
    loops, _ = at(v0, rows)
    seed = [np.full(n_designs, u.value) for u in m.unknowns]
    done, _, iters = newton_block(loops, seed, rows, tol, size, is_length, SEED_ITERATIONS, count=True)
    clean &= done & (iters <= SEED_ITERATIONS)
    det0 = det_at(loops, seed, n_designs)
    clean &= np.isfinite(det0) & (det0 != 0.0)
    positive = det0 > 0.0
    passes = sweep_passes(vals, v0)
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
            t = design_tangent(m, loops_last, sub, v_last * scale, q_last, scale)
            pred = [ql + (v - v_last) * tj for ql, tj in zip(q_last, t)]
            loops_v, sub_v = at(v, live)
            q = [c.copy() for c in pred]
            ok, _, _ = newton_block(loops_v, q, np.arange(live.size), tol, size[live], is_length, 50,
                                    count=True)
            det = det_at(loops_v, q, live.size)
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
    return _with_the_rest(m, params, vals, tol, clean, q_out)


def sweep_passes(vals: np.ndarray, v0: float) -> list[list[tuple[int, float]]]:
    """The order the sweep visits ``vals`` from the file's driver value ``v0``: up from it,
    then down from it, as (index, value); over a full turn each direction carries on
    around the turn (the value shifted by a turn), as the sweep does."""
    order = np.argsort(vals, kind="stable")
    up = [int(i) for i in order if vals[i] >= v0]
    down = [int(i) for i in order[::-1] if vals[i] < v0]
    full_turn = len(vals) > 0 and vals[order[-1]] - vals[order[0]] >= 360.0 - 1e-9
    passes = [[(i, float(vals[i])) for i in up], [(i, float(vals[i])) for i in down]]
    if full_turn:
        passes[0] += [(i, float(vals[i]) + 360.0) for i in down[::-1]]
        passes[1] += [(i, float(vals[i]) - 360.0) for i in up[::-1]]
    return passes


def _with_the_rest(m: Mechanism, params: Mapping[str, np.ndarray], vals: np.ndarray, tol: float,
                   clean: np.ndarray, q_out: list[np.ndarray]) -> tuple[list[np.ndarray], np.ndarray,
                                                                        np.ndarray, str]:
    """The engine's result: the ``clean`` designs' positions as continued, every other
    design swept on its own (:func:`sweep_engine`)."""
    n_designs, k = q_out[0].shape
    n = len(q_out)
    status = np.full((n_designs, k), CONVERGED, dtype=np.int8)
    q_flat = [c.reshape(-1) for c in q_out]
    status_flat = status.reshape(-1)
    rest = np.flatnonzero(~clean)
    if rest.size:
        sub = {name: np.atleast_1d(a)[rest] for name, a in params.items()}
        q_rest, st_rest, _, _ = sweep_engine(m, sub, vals, None, tol, rest.size)
        idx = (rest[:, None] * k + np.arange(k)[None, :]).reshape(-1)
        for j in range(n):
            q_flat[j][idx] = q_rest[j]
        status_flat[idx] = st_rest
    feasible = (status_flat == CONVERGED) | (status_flat == OFF_BRANCH)
    engine = "vectorised continuation" + (f" ({rest.size} designs one at a time)" if rest.size else "")
    return q_flat, status_flat, feasible, engine


def sweep_engine(m: Mechanism, params: Mapping[str, np.ndarray], vals: np.ndarray, branch: str | None,
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
                    q[j][d * k + i] = radians(v) if u.kind == "angle" else v
    feasible = (status == CONVERGED) | (status == OFF_BRANCH)
    return q, status, feasible, "continuation, design by design"


def turn_references(m: Mechanism, params: Mapping[str, np.ndarray], n_designs: int,
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
    loops = VectorLoops.of_terms(design_terms(m, grid, drv), n, n_designs)
    size = design_size(m, grid, drv)
    is_length = [u.kind == "length" for u in m.unknowns]
    gate = residual_gate(tol, size)
    q = [np.full(n_designs, u.value) for u in m.unknowns]
    plain = np.ones(n_designs, dtype=bool)  # every step so far the globalised solve's too
    done = np.zeros(n_designs, dtype=bool)
    stopped = np.zeros(n_designs, dtype=bool)
    # the globalised solve's stopping order (no divergence test: it lowers |Phi| every step)
    stops = SystemStops(tol, gate, step_size_array(q, None), can_diverge=False)
    phi, jac = loops.evaluate(q, None)
    with np.errstate(invalid="ignore", over="ignore"):
        for _ in range(50):
            live = plain & ~done & ~stopped
            if not live.any():
                break
            dq, _ = solve_linear(jac, phi, n_designs)
            trial = [c + d for c, d in zip(q, dq)]
            phi_t, jac_t = loops.evaluate(trial, None)
            tiny = step_size_array(dq, None) <= 64.0 * np.finfo(float).eps * (1.0 + step_size_array(q, None))
            plain &= ~live | (_sumsq(phi_t) <= (1.0 - 1e-4) * _sumsq(phi)) | tiny
            step = step_size_array(dq, [size if length else 1.0 for length in is_length])
            codes = stops.judge(step, step_size_array(phi, None), None, partial(step_size_array, trial, None))
            done |= live & plain & converged_codes(codes)
            stopped |= live & plain & (codes != GOING)
            q = [np.where(live, t, c) for t, c in zip(trial, q)]
            phi = [np.where(live, t, c) for t, c in zip(phi_t, phi)]
            jac = [[np.where(live, t, c) for t, c in zip(rt, rc)] for rt, rc in zip(jac_t, jac)]
    out = np.stack([degrees(c) if u.kind == "angle" else c for c, u in zip(q, m.unknowns)], axis=1)
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
            out[d] = [degrees(x) if u.kind == "angle" else x for x, u in zip(r.x, m.unknowns)]
    return out


def _sumsq(parts: Sequence[Any]) -> Any:
    return sum(p * p for p in parts)
