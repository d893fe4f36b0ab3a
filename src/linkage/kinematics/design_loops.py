"""The design engines' loops (:mod:`.designs`): a mechanism whose parameters are arrays,
its loop terms resolved per design and position, and Newton-Raphson on all of them at
once (:func:`newton_block`), each position stopped as the single solve's loop stops it
(:class:`~linkage.rules.SystemStops`). Shared by the closed-form engine (:mod:`.designs`)
and the continuation engine (:mod:`.design_continuation`)."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from functools import partial
from typing import Any

import numpy as np

from ..problems.derive import Derivation
from ..problems.loops import ANGLE_UNITS, Mechanism
from ..rules import (
    GOING,
    SystemStops,
    converged_codes,
    residual_gate,
    step_size_array,
)
from .batch import STATUS_CODES
from .vector_loops import VectorLoops, singular_of, solve_linear

CONVERGED, NO_SOLUTION, FAILED, OFF_BRANCH = (STATUS_CODES[k] for k in
                                              ("converged", "no_solution", "failed", "off_branch"))


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


def design_size(m: Mechanism, grid: Mapping[str, Any], drv: np.ndarray) -> Any:
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


def design_resolver(m: Mechanism, grid: Mapping[str, Any], drv: Any,
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


def design_terms(m: Mechanism, grid: Mapping[str, Any], drv: np.ndarray) -> list[list[tuple[Any, ...]]]:
    """The loops' vectors with parameters and driver resolved to floats or flat arrays."""
    index, value = design_resolver(m, grid, drv)

    def ref(r: str | float) -> tuple[Any, int]:
        return (0.0, index[r]) if isinstance(r, str) and r in index else (value(r), -1)

    return [[(t.sign, *ref(t.length), *ref(t.angle), t.offset) for t in loop.vectors] for loop in m.loops]


Linear = Callable[[list[list[Any]], list[np.ndarray], int], tuple[list[Any], Any, Any]]
"""J dq = -Phi at every position: (dq, det J, where J is singular)."""


def stepwise_linear(der: Derivation) -> Linear:
    """J dq = -Phi by the derivation's steps, as the closed form solves the loops: each
    step's two equations (its loop, or its two loops combined with the step's weights)
    hold only its two unknowns and those of earlier steps, so J is block triangular and
    every block is a 2 x 2 solved by Cramer's rule (a Watt six-bar's 4 x 4 at a fifth of
    the cost of a stacked numpy solve). J is singular where a block is, by the 2 x 2 test
    :func:`newton_block` applies to a one-loop J."""
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
                singular |= singular_of([[pa, pb], [pc, pd]], det_s)
                dq[a], dq[b] = (ex * pd - pb * ey) / det_s, (pa * ey - pc * ex) / det_s
                det = det * det_s
        return [np.broadcast_to(d_j, (k,)) for d_j in dq], np.broadcast_to(det, (k,)), singular

    return solve


def newton_block(loops: VectorLoops, q_all: list[np.ndarray], active: np.ndarray, tol: float,
                 size: np.ndarray, is_length: list[bool], max_iter: int, count: bool = False,
                 linear: Linear | None = None) -> Any:
    """Newton-Raphson at every ``active`` position at once, updating ``q_all`` in place;
    each position stops as the single solve's loop stops it (:class:`~linkage.rules.SystemStops`,
    textbook Newton: a singular J leaves q where it is). Returns (converged, det J), and
    with ``count`` the iterations each took as well. ``linear``: how J dq = -Phi is solved
    (default: Cramer's rule for 2 x 2, else a stacked numpy solve)."""
    n_pos = len(size)
    done = np.zeros(n_pos, dtype=bool)
    det_out = np.full(n_pos, np.nan)
    iterations = np.zeros(n_pos, dtype=np.int32)
    stops = SystemStops(tol, residual_gate(tol, size), step_size_array(q_all, None))
    q = [c[active] for c in q_all]
    for _ in range(max_iter):
        if active.size == 0:
            break
        phi, jac = loops.evaluate(q, active)
        if linear is not None:
            dq, det, singular = linear(jac, phi, active.size)
        else:
            dq, det = solve_linear(jac, phi, active.size)
            singular = singular_of(jac, det)
        dq = [np.where(singular, 0.0, d_j) for d_j in dq]
        for j, d_j in enumerate(dq):
            q[j] += d_j
        scale = size[active]
        step = step_size_array(dq, [scale if length else 1.0 for length in is_length])
        codes = stops.judge(step, step_size_array(phi, None), singular, partial(step_size_array, q, None),
                            active)
        for j in range(len(q)):
            q_all[j][active] = q[j]
        det_out[active] = det
        iterations[active] += 1
        done[active[converged_codes(codes)]] = True
        keep = codes == GOING
        active = active[keep]
        q = [c[keep] for c in q]
    return (done, det_out, iterations) if count else (done, det_out)


def det_at(loops: VectorLoops, q: list[np.ndarray], count: int) -> np.ndarray:
    """det J at q (every entry)."""
    _, jac = loops.evaluate(q, None)
    zeros = [np.zeros(count) for _ in q]
    _, det = solve_linear(jac, zeros, count)
    return np.broadcast_to(det, (count,)).astype(float)


def design_tangent(m: Mechanism, loops: VectorLoops, grid: Mapping[str, Any], drv: float,
             q: list[np.ndarray], scale: float) -> list[np.ndarray]:
    """dq/dv (per display unit of the driver) from J dq/dv = -scale dPhi/dv, as
    :func:`~linkage.kinematics.sweep.tangent`; NaN where J is singular. ``grid``: the
    parameters of these designs."""
    count = len(q[0])
    _, value = design_resolver(m, grid, drv, q)

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
