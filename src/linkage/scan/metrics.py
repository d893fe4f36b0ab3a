"""A chunk's records: one flat row per design (the columns of
:func:`~linkage.problems.columns.columns_of`), reduced from its solved positions."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..kinematics.angles import angle_extent_array, closes_circle, driver_turn
from ..kinematics.designs import CONVERGED, DesignSolutions, meeting_counts
from ..problems.closed_form import grashof_np
from ..problems.columns import (
    MEETINGS,
    extent_columns,
    fourbar_columns,
    fourbar_loops,
    has_meetings,
    path_columns,
)
from ..problems.loops import ANGLE_UNITS, Mechanism
from ..units import degrees, radians


def design_metrics(m: Mechanism, names: Sequence[str], designs: np.ndarray, sol: DesignSolutions,
                   start: int, params: Mapping[str, np.ndarray] | None = None) -> dict[str, np.ndarray]:
    """The records of a chunk: ``names`` the varied columns (``designs``' columns),
    ``params`` the parameter columns solved (default: the same)."""
    n_designs, n_pos = sol.status.shape
    solved = sol.status == CONVERGED
    out: dict[str, np.ndarray] = {"design": np.arange(start, start + n_designs, dtype=np.int64)}
    for j, n in enumerate(names):
        out[n] = np.array(designs[:, j], dtype=float)
    out["feasible_fraction"] = sol.feasible.mean(axis=1) if n_pos else np.zeros(n_designs)
    out["solved_fraction"] = solved.mean(axis=1) if n_pos else np.zeros(n_designs)
    out["full_cycle"] = solved.all(axis=1) & (n_pos > 0)
    if has_meetings(m):
        given = params if params is not None else {n: designs[:, j] for j, n in enumerate(names)}
        out[MEETINGS[0]] = meeting_counts(m, given, sol)
    # angles by the range rule of kinematics.angles (continuous around the circle, a full
    # turn at most); lengths from their extremes
    closes = m.driver.kind == "angle" and closes_circle([float(v) for v in sol.values],
                                                        driver_turn(m.driver.unit))
    with np.errstate(invalid="ignore"):
        for j, u in enumerate(m.unknowns):
            if u.kind == "angle":
                lo, hi, span = angle_extent_array(np.where(solved, sol.solution[:, :, j], np.nan), closes)
            else:
                lo, hi = _extent(sol.solution[:, :, j], solved)
                span = hi - lo
            for key, col in zip(extent_columns(u.name), (lo, hi, span)):
                out[key] = col
        out.update(fourbar_metrics(m, names, designs, sol, params))
        for p in m.points:
            z = sol.paths[p]
            for axis, part in (("x", z.real), ("y", z.imag)):
                for key, col in zip(path_columns(p, axis), _extent(part, solved)):
                    out[key] = col
    return out


def _extent(values: np.ndarray, solved: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per design (row): min and max over solved positions; NaN where none is solved."""
    any_solved = solved.any(axis=1)
    lo = np.where(solved, values, np.inf).min(axis=1, initial=np.inf)
    hi = np.where(solved, values, -np.inf).max(axis=1, initial=-np.inf)
    return np.where(any_solved, lo, np.nan), np.where(any_solved, hi, np.nan)


def fourbar_metrics(m: Mechanism, names: Sequence[str], designs: np.ndarray,
                    sol: DesignSolutions, given: Mapping[str, np.ndarray] | None = None,
                    ) -> dict[str, np.ndarray]:
    """For every four-bar loop of the derivation (columns named by
    :func:`~linkage.problems.columns.fourbar_loops`): its Grashof class, from the lengths
    of its ground, input, coupler and output as each design has them, and the extremes of
    its transmission angle over the solved positions (derive.fourbar_transmission, folded
    into [0, 90] deg)."""
    from ..problems.find_steps import loop_terms
    from ..problems.steps import fourbar_transmission

    views = fourbar_loops(m)
    if not views:
        return {}
    n_designs, n_pos = sol.status.shape
    solved = sol.status == CONVERGED
    varied = ({n: np.asarray(c, dtype=float) for n, c in given.items()} if given is not None else
              {n: np.asarray(designs[:, j], dtype=float) for j, n in enumerate(names)})
    # the derivation's parameters (internal units): a varied one a column per design
    params: dict[str, Any] = {k: q.value for k, q in m.parameters.items()}
    for k, col in varied.items():
        q = m.parameters[k]
        params[k] = (col * ANGLE_UNITS[q.unit] if q.kind == "angle" else col)[:, None]
    scale = ANGLE_UNITS[m.driver.unit] if m.driver.kind == "angle" else 1.0
    drv = (np.asarray(sol.values, dtype=float) * scale)[None, :]
    q = [radians(sol.solution[:, :, j]) if kind == "angle" else sol.solution[:, :, j]
         for j, kind in enumerate(sol.kinds)]
    terms = loop_terms(m)
    out: dict[str, np.ndarray] = {}
    for view, suffix in views:
        loop = terms[view.loop]

        lengths = []
        for i in (view.ground, view.input, view.coupler, view.output):
            ref = loop[i][1]
            v = params[ref] if isinstance(ref, str) else ref
            lengths.append(np.broadcast_to(np.abs(np.asarray(v, dtype=float)).reshape(-1), (n_designs,)))
        (g, lo, hi) = (c for c, _, _ in fourbar_columns(suffix))
        out[g] = grashof_class(*lengths)
        mu = degrees(fourbar_transmission(view, loop, params, drv, q, xp=np))
        mu = np.broadcast_to(mu, (n_designs, n_pos))
        out[lo], out[hi] = _extent(mu, solved)  # folded by fourbar_transmission's one rule
    return out


grashof_class = grashof_np
"""The Grashof class of each four-bar (ground, input, coupler, output): the numpy twin of
:func:`~linkage.problems.closed_form.grashof`."""

