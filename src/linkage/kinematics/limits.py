"""Limit positions and toggles of a swept branch, and the driver ranges it solved on.

Limits (where the branch or the feasible range ends) and toggles (det J changes sign
between solved positions, or touches zero between them) are located by bisection to
``LOCATE_TOL`` of the driver's unit; where the loops have a derived closed form, the limits
and the feasible ranges come from its margins instead (:func:`closed_form_limits`), to a few
ulps of the driver.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from typing import Any

from ..linalg import SingularMatrix, det_from_lu, lu, lu_solve
from ..methods.golden import golden_min
from ..methods.newton_system import max_abs
from ..problems.derive import Derivation, sign_text
from ..problems.derive_limits import (
    Signs,
    assembles,
    assembles_np,
    limit_between,
    limits_between_np,
)
from ..units import radians
from .angles import closes_circle, driver_turn
from .continuation import REENTERED, Solver, predict, solver_q
from .positions import Position

LOCATE_TOL = 1e-9  # driver units (deg for angles)


def dip_between(d: Derivation, a: float, c: float, branches: Sequence[Signs], scale: float = 1.0,
                params: Mapping[str, float] | None = None) -> tuple[float, float] | None:
    """Where :func:`assembles` is >= 0 at both ``a`` and ``c`` but dips below zero between
    (an unassembled sliver narrower than the grid): its two limits, else None. Golden-section
    search (:func:`linkage.methods.golden.golden_min`) for the smallest value, then
    :func:`limit_between` on each side. It lives here, a layer above the margins
    (:mod:`linkage.problems.derive_limits`), because the golden-section loop is a method."""
    def g(x: float) -> float:
        return assembles(d, x, branches, scale, params)

    _, x1, g1, x2, g2, _ = golden_min(g, a, c, 200, lambda k: k[2] < 0.0 or k[4] < 0.0 or not k[1] < k[3])
    inside = x1 if g1 < 0.0 else x2 if g2 < 0.0 else None
    if inside is None:
        return None
    return limit_between(d, a, inside, branches, scale, params), limit_between(d, inside, c, branches,
                                                                              scale, params)


def solved_ranges(positions: Sequence[Position]) -> tuple[tuple[float, float], ...]:
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
    """:func:`solved_ranges` over arrays (the batch engine's): each run of converged
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


def followed_branches(solver: Solver, positions: Sequence[Position], target: str | None) -> list[Signs]:
    """The sign tuples of the assemblies a sweep solved (one for a branch followed by its
    signs, or by a name that is one sign branch; both mirror assemblies of a rocker-driven
    four-bar followed by name); with none solved, the target's signs or every branch."""
    d = solver.derivation
    assert d is not None
    solved = [p for p in positions if p.solution is not None]
    out: list[Signs] = []
    if len(solved) > SCALAR_GRID:
        import numpy as np

        # every position at once, by the numpy twin of signs_of
        q = [radians(np.array([p.solution[n] for p in solved])) if k == "angle" else  # type: ignore[index]
             np.array([p.solution[n] for p in solved]) for n, k in zip(solver.names, solver.kinds)]  # type: ignore[index]
        signs = np.stack(d.signs_of_np(q, np.array([p.input for p in solved]) * solver.scale), axis=-1)
        for row in np.unique(signs[(signs != 0.0).all(axis=-1)], axis=0)[::-1]:  # "+" first
            out.append(tuple(float(s) for s in row))
    elif solved:
        # a command-line sweep: the scalar rule (no numpy import)
        seen = {d.signs_of(solver_q(solver, p), p.input * solver.scale) for p in solved}
        out = sorted((s for s in seen if 0.0 not in s), reverse=True)  # "+" first
    if out:
        return out
    if target is not None:
        wanted = [b for b in d.branches if sign_text(b) == target]
        if wanted:
            return wanted
    return list(d.branches)


FEW_BRACKETS = 8
"""Up to this many limits between grid points are bisected by the scalar function, more by
its numpy twin (the same halvings, every bracket at once)."""


LIMIT_CANDIDATE = 0.1
"""A local minimum of the margin over the grid is searched for an unassembled sliver between
grid points only where it is below this (a tenth of the loop's size)."""


SCALAR_GRID = 4096
"""Grids up to this many driver values are scanned for limits by the scalar rule, larger
ones by its numpy twin (the two agree: tests/test_derived_sweep.py)."""


def closed_form_limits(solver: Solver, positions: Sequence[Position], lo: float, hi: float,
                       target: str | None) -> tuple[list[float], tuple[tuple[float, float], ...]]:
    """The limit positions in [lo, hi] and the feasible ranges of the followed branches,
    from the derived closed form's margins (:mod:`linkage.problems.derive_limits`): each
    sign change of :func:`~linkage.problems.derive_limits.assembles` between neighbouring
    driver values (across the grid's end where it closes the circle) is bisected to
    adjacent doubles, and a dip below zero between two that assemble is found by its
    minimum."""
    d = solver.derivation
    assert d is not None
    branches = followed_branches(solver, positions, target)
    grid = sorted({p.input for p in positions})
    if not grid:
        return [], ()
    scale = solver.scale
    turn = driver_turn(solver.m.driver.unit) if solver.m.driver.kind == "angle" else 0.0
    ring = list(grid)
    if turn and len(grid) > 2 and closes_circle(grid, turn):
        ring.append(grid[0] + turn)
    if len(ring) > SCALAR_GRID:
        import numpy as np

        x = np.array(ring)
        g = assembles_np(d, x, branches, scale)
        ok = g >= 0.0
        change = np.flatnonzero(ok[:-1] != ok[1:])
    else:
        # a command-line sweep's grid: the scalar rule, so the sweep does not import numpy
        # (its import costs a fresh process more than the whole sweep)
        g = [assembles(d, v, branches, scale) for v in ring]
        ok = [v >= 0.0 for v in g]
        change = [i for i in range(len(ring) - 1) if ok[i] != ok[i + 1]]
    if len(change) > FEW_BRACKETS:  # all at once; a few are quicker one by one (no array overhead)
        import numpy as np

        x = np.array(ring)
        at = np.asarray(change)
        found = [float(t) for t in limits_between_np(d, x[at], x[at + 1], branches, scale)]
    else:
        found = [limit_between(d, float(ring[i]), float(ring[i + 1]), branches, scale) for i in change]
    for i in range(1, len(ring) - 1):
        # a sliver between grid points that all three assemble at: where the middle one does not,
        # its sign changes were bracketed above, and a "dip" would end at that grid point
        if ok[i - 1] and ok[i] and ok[i + 1] and g[i] <= g[i - 1] and g[i] <= g[i + 1] \
                and g[i] < LIMIT_CANDIDATE:
            for a, c in ((ring[i - 1], ring[i]), (ring[i], ring[i + 1])):
                dip = dip_between(d, a, c, branches, scale)
                if dip is not None:
                    found += dip
    limits = sorted({t - turn if t > hi else t for t in found})
    limits = [t for t in limits if lo <= t <= hi]
    cuts = [lo, *(t for t in limits if lo < t < hi), hi]
    ranges: list[tuple[float, float]] = []
    for a, b in itertools.pairwise(cuts):
        if b > a and assembles(d, 0.5 * (a + b), branches, scale) >= 0.0:
            if ranges and ranges[-1][1] == a:
                ranges[-1] = (ranges[-1][0], b)
            else:
                ranges.append((a, b))
    if lo == hi and assembles(d, lo, branches, scale) >= 0.0:
        ranges.append((lo, hi))
    return limits, tuple(ranges)


def toggles(solver: Solver, positions: Sequence[Position], limits: Sequence[float] | None, lo: float,
            hi: float, have_closed: bool) -> list[float]:
    """The limit positions (``limits``, from the closed form where there is one) and the
    toggles of a swept branch, sorted, each once."""
    found: list[float] = list(limits or ())
    n = len(positions)
    ring = _around(solver, positions)
    # pairs and triples across the grid's end too, where the grid closes the circle: a
    # toggle at 0 of a 0..359 sweep has neighbours at 359 and 1
    last_pair = max(n - 1 if len(ring) == n + 2 else n - 2, -1)
    for a, b in itertools.islice(itertools.pairwise(ring), last_pair + 1):
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
    # (each position's det read once: this scan runs on every sweep)
    dets = [p.det if p.status == "converged" else None for p in ring]
    for i in range(1, len(dets) - 1):
        ad, bd, cd = dets[i - 1], dets[i], dets[i + 1]
        if ad is None or bd is None or cd is None:
            continue
        if bd == 0.0:
            touch: float | None = ring[i].input  # J singular at the grid point itself
        elif abs(bd) <= abs(ad) and abs(bd) <= abs(cd) and (ad > 0) == (bd > 0) == (cd > 0):
            if _near_a_limit(solver, limits, ring[i - 1].input, ring[i + 1].input):
                continue  # |det J| falls towards the branch's end, located exactly already
            touch = _touch_det(solver, ring[i - 1], ring[i], ring[i + 1])
        else:
            continue
        if touch is not None:
            found.append(touch)
    # back onto the grid's own turn, each toggle once
    turn = driver_turn(solver.m.driver.unit) if solver.m.driver.kind == "angle" else 0.0
    out: list[float] = []
    for t in sorted(t - turn if t > hi + LOCATE_TOL and len(ring) > n else t for t in found):
        if not any(abs(t - u) <= 2 * LOCATE_TOL for u in out):
            out.append(t)
    return out


def _near_a_limit(solver: Solver, limits: Sequence[float] | None, a: float, c: float) -> bool:
    """Whether a closed-form limit lies in [a, c] (or a turn on: the ring's last pairs)."""
    turn = driver_turn(solver.m.driver.unit) if solver.m.driver.kind == "angle" else 0.0
    return any(a <= t <= c or (turn and a <= t + turn <= c) for t in limits or ())


def _around(solver: Solver, positions: Sequence[Position]) -> list[Position]:
    """The positions in driver order and, where the driver is an angle whose grid closes the
    circle, continued a turn on by the first ones (the first two; or the second, where the
    last position is the first one a turn on): every position then has neighbours."""
    from dataclasses import replace

    ring = list(positions)
    if solver.m.driver.kind != "angle" or len(ring) < 3 or not ring[1].input > ring[0].input:
        return ring
    turn = driver_turn(solver.m.driver.unit)
    if not closes_circle([p.input for p in ring], turn):
        return ring
    first, second = ring[0], ring[1]
    if ring[-1].input - first.input >= turn - LOCATE_TOL:
        return [*ring, replace(second, input=second.input + turn)]
    return [*ring, replace(first, input=first.input + turn), replace(second, input=second.input + turn)]


TOUCH_RATIO = 1e-5
"""A minimum of |det J| / (its columns' lengths) at most this is a toggle (see hadamard_ratio)."""


TOUCH_CANDIDATE = 0.1
"""A local minimum of |det J| over the solved positions is searched only where
hadamard_ratio is below this there (a transmission angle under 5.7 deg): near a touch it
falls like the distance to it (0.017 a degree on the in-line slider-crank), while an
ordinary mechanism's smallest transmission angle is far above, and costs nothing."""


def _touch_det(solver: Solver, a: Position, b: Position, c: Position) -> float | None:
    """The driver value in [a, c] where the branch's J is nearest singular (golden-section
    search on hadamard_ratio, to LOCATE_TOL), if J is singular there; else None."""
    from ..linalg import hadamard_ratio

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
            p, r = solver.solve(v, predict(solver, v0, q0, v) or q0, damped=True)
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


def _bisect_det(solver: Solver, a: Position, b: Position) -> float:
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


def _bisect_limit(solver: Solver, a: Position, b: Position) -> float:
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


def _refine_limit(solver: Solver, v0: float, q0: tuple[float, ...]) -> float | None:
    """The limit exactly: Newton on Phi(q, v) = 0, det J(q, v) = 0 for (q, v), from a
    point near it (the fold or assembly limit is where det J vanishes on the branch)."""

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


def _reaches(solver: Solver, v: float, v_good: float, q_good: tuple[float, ...],
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
    if not solver.on_target(q, solver.det(p, q), v, branch):
        return None
    dist = max(abs(x - y) for x, y in zip(q, q_good))
    allow = 2.0 * math.sqrt(abs(v - v_good) * solver.scale) * (1.0 + max(abs(c) for c in q_good))
    return q if dist <= allow + 1e-12 else None
