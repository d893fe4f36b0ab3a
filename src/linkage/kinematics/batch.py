"""The batch engine: many positions at once with numpy, for large sweeps.

1. A coarse continuation pass (the one-at-a-time sweep on at most ``coarse`` points)
   fixes statuses, the branch and warm starts.
2. Each position's guess is interpolated from its coarse neighbours (angles reported
   continuously, so interpolation is safe).
3. Newton-Raphson runs vectorised over every position whose coarse neighbours both
   solved, iterating only the unconverged ones; two unknowns use Cramer's rule, more
   a stacked ``numpy.linalg.solve``. Same stopping rule as a single solve
   (:mod:`linkage.rules`): the step (lengths relative to the mechanism's size) within
   ``tol`` and max|Phi| within ``tol`` x size.
4. Positions it cannot settle (next to a gap, unconverged, or on another branch) go
   through the one-at-a-time path. No per-iteration history is recorded.

The answers equal the one-at-a-time sweep's to about 1e-12 (tests check it).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import replace
from functools import partial
from typing import Any

import numpy as np

from ..errors import InputError
from ..problems.loops import ANGLE_UNITS, LoopModel, Mechanism
from ..records import frozen
from ..rules import GOING, SystemStops, converged_codes, residual_gate, step_scales, step_size_array
from ..units import RAD_PER_DEG, degrees, radians
from .angles import nearest_turn, nearest_turn_array
from .continuation import Solver, classify_gap, continue_step, solve_position, solver_q
from .half_angle import cos_sin
from .limits import solved_ranges_array
from .positions import MAX_POSITIONS, Position, SweepResult, check_driver_values, driver_values, sweep_result
from .stepwise import sweep
from .vector_loops import LoopPlan, VectorLoops, loop_plan, singular_of, solve_linear
from .warm_starts import Coarse, coarse_intervals, warm_starts

STATUS_CODES = {"converged": 0, "no_solution": 1, "failed": 2, "off_branch": 3}
CODE_STATUS = {v: k for k, v in STATUS_CODES.items()}


@frozen
class BatchResult:
    """Arrays, one entry per position: driver values, status codes, solutions (display
    units, shape (N, n)), det J and Newton iterations; the branch they are all on."""

    values: np.ndarray
    status: np.ndarray
    solution: np.ndarray
    det: np.ndarray
    iterations: np.ndarray
    branch: str | None  # every converged position is on this branch
    coarse: SweepResult
    fallback: int
    source: Mechanism | None = None
    rates: tuple[float | None, float] | None = None
    """(driver speed or None, acceleration) when each position's joints (and with a speed
    its rates) were asked for: computed by the one-at-a-time sweep's own
    :func:`~linkage.kinematics.sweep.with_rates` as positions are read."""

    def __getattr__(self, name: str) -> Any:
        """``solution`` of a result made by :func:`batch_result_to_show`: its work done at the
        first read and kept (a result whose columns no one reads does not unwrap and anchor
        them, as its positions are built only when read). Called only where the instance has
        no such attribute."""
        if name == "solution":
            work = self.__dict__.get("solution_work")
            if work is not None:
                value = self.__dict__["solution"] = work()
                self.__dict__.pop("solution_work", None)  # (its inputs freed)
                return value
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def __getstate__(self) -> dict[str, Any]:
        """The fields, ``solution`` done first (its work is a closure: not pickled)."""
        self.solution  # noqa: B018 (done and kept by __getattr__ where it is pending)
        return {k: v for k, v in self.__dict__.items() if k != "solution_work"}

    def to_sweep(self) -> SweepResult:
        """The same result as a SweepResult whose positions are built only when read
        (a million positions cost nothing until a caller asks for one)."""
        c = self.coarse
        motion = self.rates if self.rates is not None and self.rates[0] is not None else None
        return sweep_result(c.mechanism, c.driver, c.driver_unit, c.names, c.units, BatchPositions(self),
                            c.feasible_ranges, c.toggles, c.branch, c.classification, c.method, motion,
                            c.length_unit, BatchMeetings(self))

    def meetings(self) -> tuple[float, ...]:
        """The driver values of solved positions where two assemblies meet to rounding
        (:meth:`~linkage.problems.derive.Derivation.meets_np`), as the one-at-a-time engine
        lists them (:attr:`~.positions.SweepResult.meetings`)."""
        m = self.source
        if m is None or not m.derivation.complete or not m.derivation.two_way or not len(self.values):
            return ()
        scale = ANGLE_UNITS[m.driver.unit] if m.driver.kind == "angle" else 1.0
        q = [radians(self.solution[:, j]) if u.kind == "angle" else self.solution[:, j]
             for j, u in enumerate(m.unknowns)]
        meet = self.status == STATUS_CODES["converged"]
        hit = np.zeros(len(self.values), dtype=bool)
        for step in m.derivation.meets_np(q, self.values * scale):
            hit |= np.broadcast_to(step, hit.shape)
        return tuple(float(v) for v in self.values[meet & hit])


def batch_result_to_show(values: np.ndarray, status: np.ndarray, solution: Callable[[], np.ndarray],
                         det: np.ndarray, iterations: np.ndarray, branch: str | None, coarse: SweepResult,
                         fallback: int, source: Mechanism | None,
                         rates: tuple[float | None, float] | None) -> BatchResult:
    """``BatchResult(values, status, solution(), ...)`` with ``solution()`` called when the
    field is first read (:meth:`BatchResult.__getattr__`), and without the frozen
    dataclass's ``__init__`` (as :func:`~.positions.sweep_result`). ``solution`` must give
    the same array whenever it is called (a function of its arguments alone)."""
    out = _new(BatchResult)
    out.__dict__.update(values=values, status=status, solution_work=solution, det=det, iterations=iterations,
                        branch=branch, coarse=coarse, fallback=fallback, source=source, rates=rates)
    return out


_new = object.__new__


class BatchMeetings(Sequence):  # type: ignore[type-arg]
    """A batch result's :meth:`BatchResult.meetings`, computed when first read: a sweep
    whose meetings no one reads does not test every position for them (as its positions
    are built only when read). Equal to, hashed, shown and pickled as the tuple."""

    def __init__(self, batch: BatchResult) -> None:
        self.batch = batch
        self.found: tuple[float, ...] | None = None

    def values(self) -> tuple[float, ...]:
        if self.found is None:
            self.found = self.batch.meetings()
        return self.found

    def __len__(self) -> int:
        return len(self.values())

    def __getitem__(self, i: Any) -> Any:
        return self.values()[i]

    def __iter__(self) -> Any:
        return iter(self.values())

    def __eq__(self, other: object) -> bool:
        if isinstance(other, BatchMeetings):
            other = other.values()
        return self.values() == other

    def __hash__(self) -> int:
        return hash(self.values())

    def __repr__(self) -> str:
        return repr(self.values())

    def __reduce__(self) -> tuple[Any, ...]:
        return (tuple, (self.values(),))


RATES_CHUNK = 4096
"""Positions whose rates a batch result computes at once when one of them is read."""


class BatchPositions(Sequence):  # type: ignore[type-arg]
    """The positions of a batch sweep as a sequence: columns (arrays) inside, a
    :class:`Position` built for each entry that is read."""

    def __init__(self, batch: BatchResult) -> None:
        self.batch = batch
        self._chunk: tuple[int, Sequence[Position]] = (-1, ())  # the last chunk with rates
        self._angles: tuple[int, np.ndarray] = (-1, np.zeros(0))  # the last chunk's transmission

    def __len__(self) -> int:
        return len(self.batch.values)

    def __repr__(self) -> str:
        """The positions, as a tuple of them shows them (the first and last of a long
        sweep): one sweep's repr is the same in every process, as the one-at-a-time
        engine's tuple is."""
        n = len(self)
        if n <= 100:
            return f"BatchPositions({tuple(self)!r})"
        return f"BatchPositions({n:,} positions: {self[0]!r}, ..., {self[n - 1]!r})"

    def __getitem__(self, i: Any) -> Any:
        if isinstance(i, slice):
            return [self[k] for k in range(*i.indices(len(self)))]
        if i < 0:
            i += len(self)
        if not 0 <= i < len(self):
            raise IndexError(i)
        if self.batch.rates is None:
            return self._position(i)
        # the rates a chunk at a time, by the one definition (with_rates), the last chunk
        # kept: reading in order costs one with_rates call per RATES_CHUNK positions, and
        # memory stays bounded whatever the sweep's size
        start = i - i % RATES_CHUNK
        if self._chunk[0] != start:
            from .rate_blocks import with_rates  # a batch without rates (a scan's) never loads them

            b = self.batch
            assert b.source is not None
            part = tuple(self._position(k) for k in range(start, min(len(self), start + RATES_CHUNK)))
            speed, accel = b.rates  # type: ignore[misc]
            self._chunk = (start, with_rates(b.source, replace(b.coarse, positions=part), speed,
                                             accel).positions)
        return self._chunk[1][i - start]

    def _position(self, i: int) -> Position:
        b = self.batch
        st = CODE_STATUS[int(b.status[i])]
        sol = ({n: float(b.solution[i, j]) for j, n in enumerate(b.coarse.names)}
               if st == "converged" else None)
        return Position(float(b.values[i]), st, sol, b.branch if sol else None, int(b.iterations[i]),
                        float(b.det[i]) if sol else None, self._transmission(i) if sol else None)

    def _transmission(self, i: int) -> float | None:
        """The transmission angle of solved position ``i`` (deg), by the derivation's rule as
        this sweep's columns compute it (its numpy twin,
        :meth:`~linkage.problems.derive.Derivation.transmission_np`, as
        :func:`~.columns.transmission_column` reads it): a position read and its row in a
        written table are the same number, bit for bit. A chunk of positions at a time
        (RATES_CHUNK), the last chunk kept."""
        b = self.batch
        m = b.source
        if m is None or not m.derivation.fourbars:
            return None
        start = i - i % RATES_CHUNK
        if self._angles[0] != start:
            stop = min(len(self), start + RATES_CHUNK)
            scale = ANGLE_UNITS[m.driver.unit] if m.driver.kind == "angle" else 1.0
            q = [radians(b.solution[start:stop, j]) if u.kind == "angle" else b.solution[start:stop, j]
                 for j, u in enumerate(m.unknowns)]
            with np.errstate(invalid="ignore", divide="ignore"):
                mu = m.derivation.transmission_np(q, b.values[start:stop] * scale)
            self._angles = (start, degrees(np.broadcast_to(mu, (stop - start,))))
        return float(self._angles[1][i - start])

    def summary(self) -> dict[str, int]:
        codes, counts = np.unique(self.batch.status, return_counts=True)
        return {CODE_STATUS[int(c)]: int(k) for c, k in zip(codes, counts)}

    def column(self, name: str) -> np.ndarray:
        """One unknown over every position (NaN where not converged), without objects."""
        j = self.batch.coarse.names.index(name)
        out = self.batch.solution[:, j].copy()
        out[self.batch.status != STATUS_CODES["converged"]] = np.nan
        return out


def batch_sweep(m: Mechanism, values: Sequence[float] | np.ndarray, *, branch: str | None = None,
                tol: float = 1e-12, max_iter: int = 50, coarse: int = 361, speed: float | None = None,
                accel: float = 0.0, joints: bool = False,
                coarse_engine: Callable[..., BatchResult | None] | None = None) -> BatchResult:
    """Solve ``m`` at every driver value in ``values`` (display units, ascending). With a
    driver ``speed`` (and ``accel``) or ``joints``, every solved position read from the
    result carries ``.rates`` as the one-at-a-time sweep's do. ``max_iter`` caps every
    Newton run, as in the one-at-a-time sweep (the vectorised one at VECTOR_ITER at most:
    a position slower than that goes the one-at-a-time way). ``coarse_engine``: an engine
    that sweeps the coarse grid as the one-at-a-time sweep does, or gives None where it
    does not apply (the front door passes the closed form, :func:`~.closed.closed_sweep`,
    which this module may not import: it imports this one)."""
    rates = (speed, accel) if speed is not None or joints else None
    vals = np.asarray(values, dtype=float)
    if vals.ndim != 1:
        raise InputError("the driver values must be a one-dimensional sequence")
    if len(vals) > MAX_POSITIONS:
        raise InputError(f"{len(vals):,} driver values is more than {MAX_POSITIONS:,}; sweep in parts")
    if len(vals):
        if not np.isfinite(vals).all():
            raise InputError("the driver values must be finite")
        check_driver_values(m, [float(vals.min()), float(vals.max())])
    n_pos = len(vals)
    if n_pos == 0:
        rough = sweep(m, [], branch=branch, tol=tol)
        empty = np.zeros(0)
        return BatchResult(vals, np.zeros(0, dtype=np.int8), np.zeros((0, len(m.unknowns))), empty,
                           np.zeros(0, dtype=np.int32), rough.branch, rough, 0, m, rates)
    lo, hi = float(vals[0]), float(vals[-1])
    grid = driver_values(lo, hi, None, min(coarse, n_pos))
    fast = None if coarse_engine is None else coarse_engine(m, grid, branch=branch, tol=tol,
                                                            max_iter=max_iter)
    rough = sweep(m, grid, branch=branch, tol=tol, max_iter=max_iter) if fast is None else fast.to_sweep()
    solver = Solver(m, "newton", tol, max_iter)
    names, kinds = solver.names, solver.kinds
    n = len(names)
    scale = [RAD_PER_DEG if k == "angle" else 1.0 for k in kinds]
    coarse = _coarse_pass(solver, rough, grid, scale, fast)
    grid_arr = coarse.grid
    drv_scale = ANGLE_UNITS[m.driver.unit] if m.driver.kind == "angle" else 1.0
    code = STATUS_CODES
    status = np.full(n_pos, code["failed"], dtype=np.int8)
    iters = np.zeros(n_pos, dtype=np.int32)
    det_out = np.full(n_pos, np.nan)
    shown = np.empty((n_pos, n))
    ref = np.empty((n_pos, n))  # the guesses, written where a position is left for step 4
    # Steps 2 and 3 a block of positions at a time: every temporary array then stays in
    # the processor's cache (1,000,000 positions at once made each one 8 MB, and the
    # engine waited on memory).
    for lo_i in range(0, n_pos, BLOCK):
        hi_i = min(n_pos, lo_i + BLOCK)
        _settle(m, solver.model, coarse, names, kinds, scale, vals[lo_i:hi_i], drv_scale, tol,
                min(max_iter, VECTOR_ITER),
                rough.branch, status[lo_i:hi_i], iters[lo_i:hi_i], det_out[lo_i:hi_i],
                shown[lo_i:hi_i], ref[lo_i:hi_i])

    # 4. everything else, one at a time
    todo = np.flatnonzero(status != code["converged"])
    have_closed = _have_closed(m, solver, lo)
    _one_at_a_time(m, solver, rough, grid_arr, vals, todo, have_closed, status, iters, shown, det_out)
    # report angles continuously, as the one-at-a-time sweep does (where a position has
    # a guess; the blocks did the others)
    for i in todo:
        for j, k in enumerate(kinds):
            if k == "angle" and math.isfinite(ref[i, j]):
                r = ref[i, j]
                shown[i, j] = nearest_turn(r, shown[i, j])
    shown[status != code["converged"]] = np.nan
    if not have_closed:
        # the ranges the positions themselves solved on, as the one-at-a-time sweep reports
        # them (the coarse pass's are only as fine as its grid)
        rough = replace(rough, feasible_ranges=solved_ranges_array(vals, status == code["converged"]))
    return BatchResult(vals, status, shown, det_out, iters, rough.branch, rough, len(todo), m, rates)


def _coarse_pass(solver: Solver, rough: SweepResult, grid: Sequence[float],
                 scale: Sequence[float], fast: BatchResult | None = None) -> Coarse:
    """The coarse sweep as the blocks read it: its solutions and their exact first and
    second derivatives dq/dv and d2q/dv2 there (display units), by the acceleration
    analysis of :func:`~.rates.solve_rates_np` at unit driver speed and no driver
    acceleration, at every coarse point at once; a position where J is singular (no
    tangent) is no end of a usable interval."""
    from .rates import solve_rates_np  # (a small sweep, which imports this module, never loads it)

    names, kinds = solver.names, solver.kinds
    grid_arr = np.array(grid)
    if fast is not None:  # its columns, without a Position built per point
        ok_coarse = fast.status == STATUS_CODES["converged"]
        coarse_sol = np.where(ok_coarse[:, None], fast.solution, np.nan)
    else:
        ok_coarse = np.array([p.status == "converged" for p in rough.positions])
        coarse_sol = np.array([[p.solution[nm] if p.solution else np.nan for nm in names]
                               for p in rough.positions])
    drv_scale = solver.scale
    q = [coarse_sol[:, j] * sc for j, sc in enumerate(scale)]
    with np.errstate(all="ignore"):
        qd, qdd, solved = solve_rates_np(solver.model, q, grid_arr * drv_scale, 1.0, 0.0)
        # d(q / sc) / d(v / drv_scale) and the second derivative likewise
        slopes = np.stack([np.asarray(a, dtype=float) * (drv_scale / sc) for a, sc in zip(qd, scale)], axis=1)
        bends = np.stack([np.asarray(a, dtype=float) * (drv_scale * drv_scale / sc)
                          for a, sc in zip(qdd, scale)], axis=1)
    usable = ok_coarse & np.broadcast_to(solved, ok_coarse.shape) & np.isfinite(slopes).all(axis=1)
    usable &= np.isfinite(bends).all(axis=1)
    return coarse_intervals(grid_arr, usable, coarse_sol, np.where(usable[:, None], slopes, 0.0),
                            np.where(usable[:, None], bends, 0.0), kinds)


def _one_at_a_time(m: Mechanism, solver: Solver, rough: SweepResult, grid_arr: np.ndarray, vals: np.ndarray,
                   todo: np.ndarray, have_closed: bool, status: np.ndarray, iters: np.ndarray,
                   shown: np.ndarray, det_out: np.ndarray) -> None:
    """Step 4, in place: each position the blocks left, by continuation from the nearer
    solved coarse neighbour; failing that, the status the one-at-a-time sweep gives it."""
    code = STATUS_CODES
    right = np.clip(np.searchsorted(grid_arr, vals[todo], side="right"), 1, len(grid_arr) - 1)
    target = rough.branch
    for i, r in zip(todo, right):
        v = float(vals[i])
        near = sorted((int(r) - 1, int(r)), key=lambda c: abs(grid_arr[c] - v))
        pos = None
        for c in near:
            cp = rough.positions[c]
            if cp.status == "converged":
                qc = solver_q(solver, cp)
                if have_closed:
                    pos, _ = solve_position(solver, v, qc, cp.input, qc, target, True)
                else:
                    pos, _ = continue_step(solver, v, [(cp.input, qc)], target)
                if pos.status == "converged":
                    break
        if pos is None or pos.status != "converged":
            status[i] = code[_gap_status(m, solver, rough, near, v, pos, have_closed)]
            continue
        status[i] = code["converged"]
        iters[i] = pos.iterations
        shown[i] = [pos.solution[nm] for nm in solver.names]
        det_out[i] = pos.det if pos.det is not None else np.nan


def _gap_status(m: Mechanism, solver: Solver, rough: SweepResult, near: Sequence[int], v: float,
                pos: Position | None, have_closed: bool) -> str:
    """The status of a position that continuation did not solve, as the one-at-a-time
    sweep gives it: the closed form's verdict where there is one, else that of the coarse
    neighbours that did not solve (classified afresh where they differ)."""
    target = rough.branch
    others = [rough.positions[c].status for c in near if rough.positions[c].status != "converged"]
    if have_closed and pos is not None and pos.status in ("no_solution", "off_branch"):
        return pos.status  # solve_position read the closed form already
    closed = solver.problem(v).reference() if have_closed else None
    if closed is not None and (closed == {} or target not in closed):
        # as the one-at-a-time sweep: no assembly at all, or none with the label
        return "no_solution" if closed == {} else "off_branch"
    if len(set(others)) > 1 and not have_closed:
        # a boundary between two kinds of gap falls in this coarse interval
        anchor = next((solver_q(solver, p) for p in rough.positions if p.solution), None)
        tries = [g for g in (anchor, tuple(u.value for u in m.unknowns)) if g is not None]
        return classify_gap(solver, v, tries)[0].status
    return others[0] if others else "failed"


VECTOR_ITER = 30
"""The most iterations of the vectorised Newton (the few slower positions go one at a time)."""

FULL_ITERATIONS = 1
"""Newton iterations of the vectorised Newton over every position of a block at once;
the later ones gather the positions still going."""

BLOCK = 16_384
"""Positions per block of the batch engine's vectorised steps (temporaries of 128 kB)."""


def _settle(m: Mechanism, model: LoopModel, coarse: Coarse, names: Sequence[str], kinds: Sequence[str],
            scale: Sequence[float], vals: np.ndarray, drv_scale: float, tol: float, max_iter: int,
            branch: str | None, status: np.ndarray, iters: np.ndarray, det_out: np.ndarray,
            shown: np.ndarray, ref: np.ndarray) -> None:
    """Steps 2 and 3 for one block of positions, written into the output slices: the warm
    start, vectorised Newton, the continuity and branch checks and continuous angles.
    A position left "failed" goes to the one-at-a-time path. Columns are contiguous 1-D
    arrays, written into the (N, n) outputs once (reading a strided column costs
    several times more)."""
    n, code = len(kinds), STATUS_CODES
    refs, left, usable = warm_starts(coarse, vals)
    drivers = vals * drv_scale
    # the driver's cosine and sine, taken once for the loop equations and the branch rule;
    # every cosine and sine here from the half-angle tangent (a fifth of the time of np.cos
    # and np.sin, within half_angle.ABS_ERROR of them)
    plan = loop_plan(m) if model is m.model else LoopPlan.of(model)
    trig = cos_sin(drivers) if plan.driver_angle else None
    loops = VectorLoops(plan, drivers, trig, cos_sin)
    q_all = [r * sc for r, sc in zip(refs, scale)]
    done = _vector_newton(loops, q_all, usable, m.length_scale, kinds, tol, max_iter, iters, det_out)
    status[done] = code["converged"]
    cols = [c / sc for c, sc in zip(q_all, scale)]
    # Continuity: a position must stay near its interpolated guess. Near a nearly
    # singular configuration Newton can jump to another assembly with the same det J
    # sign; such positions go to the one-at-a-time path.
    gaps = [np.abs(c - r) for c, r in zip(cols, refs)]  # each unknown's move from its guess
    moved = gaps[0] if n == 1 else np.maximum(gaps[0], gaps[1])
    for j in range(2, n):
        np.maximum(moved, gaps[j], out=moved)
    status[done & (moved > np.take(coarse.allowed, left))] = code["failed"]
    status[done & ~_on_branch_columns(m, cols, names, det_out, branch, drivers, trig)] = code["failed"]
    # angles reported continuously with the guess (the one-at-a-time sweep's convention):
    # a solution within half a turn of its guess is already the representative nearest it
    for j, k in enumerate(kinds):
        if k == "angle":
            far = ~(gaps[j] < 180.0)  # (NaN included)
            if far.any():
                cols[j][far] = nearest_turn_array(refs[j][far], cols[j][far])
    for j in range(n):
        shown[:, j] = cols[j]
    # the guesses, read afterwards only where the one-at-a-time path takes over
    left_over = np.flatnonzero(status != code["converged"])
    if left_over.size:
        for j in range(n):
            ref[left_over, j] = refs[j][left_over]


def _vector_newton(loops: VectorLoops, q_all: list[np.ndarray], live: np.ndarray, size: float,
                   kinds: Sequence[str], tol: float, max_iter: int, iters: np.ndarray,
                   det_out: np.ndarray) -> np.ndarray:
    """Step 3, textbook Newton at the ``live`` positions (q_all updated in place, internal
    units), each stopped as the single solve's loop stops it (:class:`~linkage.rules.SystemStops`,
    with its scales: a length step relative to the mechanism's size, max|Phi| within
    tol x size); where each converged. The first iteration (all most positions need from
    the quintic warm start) evaluates every position and moves only the live ones (no
    gathers); later ones gather the few left. Position by position the iterates do not
    depend on the block: every evaluation takes its cosines and sines directly."""
    n, n_pos = len(kinds), len(live)
    steps = step_scales(kinds, size)
    stops = SystemStops(tol, residual_gate(tol, size), step_size_array(q_all, None))
    live = live.copy()
    done = np.zeros(n_pos, dtype=bool)
    it = 0
    while it < min(FULL_ITERATIONS, max_iter) and live.any():
        it += 1
        phi, jac = loops.evaluate(q_all, None)
        dq, det = solve_linear(jac, phi, n_pos)
        singular = singular_of(jac, det)
        step = step_size_array(dq, steps)
        moving = live & ~singular & np.isfinite(step)
        for j in range(n):
            np.add(q_all[j], dq[j], out=q_all[j], where=moving)
        codes = stops.judge(step, step_size_array(phi, None), singular, partial(step_size_array, q_all, None))
        np.copyto(iters, it, where=live)  # (a masked copy: no gather of the live positions)
        np.copyto(det_out, det, where=live)
        done |= live & converged_codes(codes)
        live &= codes == GOING
    active = np.flatnonzero(live)
    q = [c[active] for c in q_all]
    while it < max_iter and active.size:
        it += 1
        phi, jac = loops.evaluate(q, active)
        dq, det = solve_linear(jac, phi, active.size)
        singular = singular_of(jac, det)
        for j in range(n):
            q[j] += np.where(singular, 0.0, dq[j])
        codes = stops.judge(step_size_array(dq, steps), step_size_array(phi, None), singular,
                            partial(step_size_array, q, None), active)
        for j in range(n):
            q_all[j][active] = q[j]
        iters[active] = it
        det_out[active] = det
        done[active[converged_codes(codes)]] = True
        keep = codes == GOING
        active = active[keep]
        q = [c[keep] for c in q]
    return done


def _have_closed(m: Mechanism, solver: Solver, value: float) -> bool:
    """Whether the one-at-a-time sweep re-enters gaps from the closed form and classifies
    them by it, so the fallback here does too: an angle-driven mechanism whose loops have
    a closed form (``m.derivation.complete``) that its problem carries as the reference."""
    return (m.driver.kind == "angle" and m.derivation.complete
            and solver.problem(value).reference is not None)


def _on_branch_columns(m: Mechanism, cols: Sequence[np.ndarray], names: Sequence[str], det: np.ndarray,
                       target: str | None, drivers: np.ndarray,
                       driver_trig: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
    """True where a solution (one array per unknown, display units, at ``drivers`` in
    internal units) lies on the target branch: a branch of the derivation (its signs, or
    its name: each two-way step's word by the derivation's own rule, as
    :func:`~linkage.kinematics.designs.design_signs` reads them), else the sign of det J
    (``det+``, ``det-``). ``driver_trig``: np.cos and np.sin of ``drivers`` where the
    caller took them (:meth:`~linkage.problems.derive.Derivation.on_branch_np`)."""
    if target is None:
        return np.ones(len(det), dtype=bool)
    der = m.derivation
    if not der.complete or target in ("det+", "det-"):
        return (det > 0) == (target == "det+")
    from ..problems.derive import read_branch

    want = read_branch(der, target)
    kinds = {u.name: u.kind for u in m.unknowns}
    q = [radians(c) if kinds[n] == "angle" else c for n, c in zip(names, cols)]
    # the derivation's one rule (a name's mirror: the continuity test has already decided)
    return np.broadcast_to(der.on_branch_np(q, drivers, want, driver_trig=driver_trig), (len(det),))
