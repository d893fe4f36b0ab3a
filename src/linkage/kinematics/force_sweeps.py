"""Loads over many positions: a sweep's (each position's rates with their bounds, then the
one matrix method for all of them) and a scan's (the numpy twins of the rates, then the
same matrix method), judged by the one status rule (kinematics.forces)."""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping, Sequence
from typing import Any

from ..problems.loads import Loads
from ..records import NamedTuple, frozen
from .bodies import Frame, force_size, metre
from .forces import (
    TOGGLE_COND,
    Forces,
    force_status_np,
    matrix_bound,
    position_forces,
    scaled_to_unit_speed,
    speed_usable,
    undefined_forces,
)
from .load_matrix import ForceArrays, solve_loads


@frozen
class BatchForces:
    """:func:`batch_forces`' answer: the matrix method's arrays (NaN where unsolved or
    undefined), each position's status (FORCE_STATUSES codes), its largest pin force and
    the size of the ground's force (the shaking force), N."""

    arrays: ForceArrays | None
    status: Any
    input: Any
    pin_max: Any
    shaking: Any
    virtual_power: Any
    """The independent answer for ``input`` at every position."""


def batch_forces(mechanism: Any, q: Sequence[Any], d: Any, loads: Loads, *, speed: float = 0.0,
                 accel: float = 0.0, values: Mapping[str, Any] | None = None) -> BatchForces:
    """The forces at many positions at once (a scan's designs x positions, flat): ``q`` one
    array per unknown and ``d`` the driver (internal units, NaN where unsolved),
    ``values`` parameters replaced by arrays (internal units, one per position). The
    kinematics by the numpy twins (kinematics.rates.motions_rates_np, place_motion_np), the
    forces by the one matrix method (:func:`solve_loads`, screened: ``arrays.condition`` is
    a certified upper bound where that is below TOGGLE_COND), judged by
    :func:`force_status_np` with the matrix's bound (no kinematic bounds here: where J is
    singular the forces are undefined)."""
    import numpy as np

    from ..problems.loops import LoopModel
    from .placing import place_motion_np
    from .rates import motions_rates_np

    frame = Frame.of(mechanism)
    d = np.asarray(d, dtype=float)
    n = d.shape[0]
    rows = np.isfinite(d)
    for c in q:
        rows &= np.isfinite(c)
    status = np.full(n, 3, dtype=np.int8)
    inp, pin_max, shaking, vp = (np.full(n, np.nan) for _ in range(4))
    if not rows.any():
        return BatchForces(None, status, inp, pin_max, shaking, vp)
    sub = {k: (v[rows] if isinstance(v, np.ndarray) and v.shape == (n,) else v)
           for k, v in (values or {}).items()}
    model = LoopModel.compile(mechanism, sub)
    qs, ds = [c[rows] for c in q], d[rows]
    moves = bool(speed or accel)
    # the velocities of a unit driver speed: those at the speed over it where it has one
    # (forces.per_unit_speed, as one position's forces get them), else their own rates
    by_speed = speed_usable(speed)
    motions = ((speed, accel),) if by_speed else ((1.0, 0.0), (speed, accel)) if moves else ((1.0, 0.0),)
    # a static load reads positions and the unit speed's velocities, no accelerations
    rates, ok = motions_rates_np(model, qs, ds, motions, accelerations=moves)
    placed = [place_motion_np(model, qs, ds, qd, v, qdd, a) for (qd, qdd), (v, a) in zip(rates, motions)]
    moving, unit = placed[-1], placed[0]
    k = metre(frame.length_unit)

    def xy(which: Mapping[str, Any], part: int, per: float = 1.0) -> dict[str, tuple[Any, Any]]:
        return {j: (v[part].real * per * k, v[part].imag * per * k) for j, v in which.items()}

    zero = np.zeros(len(ds))
    pos = xy(moving, 0)
    vel = xy(moving, 1) if moves else {j: (zero, zero) for j in pos}
    acc = xy(moving, 2) if moves else {j: (zero, zero) for j in pos}
    vstar = xy(moving, 1, 1.0 / speed) if by_speed else xy(unit, 1)
    if sub:  # each design at its own size, as it is judged on its own
        from dataclasses import replace

        frame = replace(frame, size=np.broadcast_to(force_size(mechanism, sub), ds.shape))
    # a scan needs each position's verdict, not its condition number: a certified bound below
    # TOGGLE_COND passes it as ok (as the exact number would) without the inverse
    fa = solve_loads(frame, pos, vel, acc, vstar, loads, mechanism.source, screen_below=TOGGLE_COND)
    got = np.where(ok, fa.input, np.nan)
    status[rows] = force_status_np(got, fa.condition, matrix_bound(fa.condition), ok)
    inp[rows] = got
    vp[rows] = np.where(ok, fa.virtual_power_input, np.nan)
    mags = [np.hypot(fx, fy) for _, _, _, fx, fy in fa.pins]
    if mags:
        pin_max[rows] = np.where(ok, np.max(mags, axis=0), np.nan)
    shaking[rows] = np.where(ok, np.hypot(fa.ground[0], fa.ground[1]), np.nan)
    return BatchForces(fa, status, inp, pin_max, shaking, vp)


LOADS_CHUNK = 4096
"""Positions whose loads a sweep solves at once (as the batch engine computes its rates,
kinematics.batch.RATES_CHUNK): one matrix-method call per chunk, and no more than a chunk
of positions' rates and force matrices held at a time."""


class SolvedPosition(NamedTuple):
    """A solved position as the loads need it: its index in the sweep, the unknowns and the
    driver (internal units) and the sweep's own rates there (None where it has none)."""

    index: int
    q: list[float]
    driver: float
    rates: Any


@frozen
class SolvedRows:
    """A chunk's solved positions as arrays: their indices in the sweep, the unknowns (one
    array each) and the driver, internal units."""

    index: Any
    q: list[Any]
    driver: Any

    def __len__(self) -> int:  # the positions
        return len(self.index)


@frozen
class ChunkForces:
    """The matrix method over a chunk's solved positions (:func:`chunk_forces`)."""

    kept: tuple[int, ...]
    """The index of each position solved (its kinematics defined)."""
    undefined: tuple[int, ...]
    """Positions whose kinematics are undefined (a toggle): no forces."""
    arrays: ForceArrays | None
    """:func:`solve_loads`' answer for ``kept``, in its order (None where none is kept)."""
    actual: Any = None
    """``kept``'s rates at the driver's motion (a :class:`~.rate_blocks.RateBlock`)."""
    unit: Any = None
    """``kept``'s rates at a unit driver speed (the virtual velocities)."""

    def rates(self) -> list[tuple[int, Any, Any]]:
        """(index, rates at the driver's motion, at a unit speed) of each kept position, as
        :class:`~.rates.Rates`."""
        if not self.kept:
            return []
        return list(zip(self.kept, self.actual.rates(), self.unit.rates()))


def chunk_forces(mechanism: Any, frame: Frame, solved: SolvedRows, loads: Loads, speed: float | None,
                 accel: float, given: Any = None) -> ChunkForces:
    """A chunk of a sweep's positions' forces: the positions' rates as one block
    (kinematics.rate_blocks, the one definition over arrays; ``given``, the sweep's own
    block at the driver's motion for these positions, if it has one), the velocities of a
    unit speed from them (:func:`~.forces.per_unit_speed`'s rule) or computed, and the
    matrix method for all of them in one :func:`solve_loads`."""
    import numpy as np

    from .rate_blocks import block_rates

    model = mechanism.model
    moving = speed_usable(speed)
    actual = given if moving and given is not None else block_rates(model, solved.q, solved.driver, speed,
                                                                    accel)
    unit = (scaled_to_unit_speed(actual, speed) if moving and actual.velocities  # type: ignore[arg-type]
            else block_rates(model, solved.q, solved.driver, 1.0, 0.0))
    bad = (actual.status == "undefined") | (unit.status == "undefined")
    index = np.asarray(solved.index)
    undefined = tuple(index[bad].tolist())
    good = np.flatnonzero(~bad)
    if not len(good):
        return ChunkForces((), undefined, None)
    actual, unit = actual.take(good), unit.take(good)
    k = metre(frame.length_unit)

    def scaled(m: Mapping[str, tuple[Any, Any]]) -> dict[str, tuple[Any, Any]]:
        return {j: (x * k, y * k) for j, (x, y) in m.items()}

    zero = np.zeros(len(good))
    still = {j: (zero, zero) for j in actual.joints}
    fa = solve_loads(frame, scaled(actual.joints), scaled(actual.joint_velocities or still),
                     scaled(actual.joint_accelerations or still), scaled(unit.joint_velocities), loads,
                     mechanism.source)
    return ChunkForces(tuple(index[good].tolist()), undefined, fa, actual, unit)


def _display_scale(mechanism: Any) -> float:
    """Internal units of the driver per display unit (a turning driver's degrees or radians)."""
    from ..problems.loops import ANGLE_UNITS

    return ANGLE_UNITS[mechanism.driver.unit] if mechanism.driver.kind == "angle" else 1.0


def solved_positions(mechanism: Any, positions: Sequence[Any], start: int, stop: int) -> SolvedRows:
    """The solved positions among ``positions[start:stop]`` (a sweep's Position objects)."""
    import numpy as np

    from ..units import radians

    scale = _display_scale(mechanism)
    rows = [i for i in range(start, stop)
            if positions[i].status == "converged" and positions[i].solution is not None]
    sols = [positions[i].solution for i in rows]
    q = [np.array([radians(s[u.name]) if u.kind == "angle" else float(s[u.name]) for s in sols], dtype=float)
         for u in mechanism.unknowns]
    return SolvedRows(np.array(rows, dtype=np.intp), q,
                      np.array([positions[i].input for i in rows], dtype=float) * scale)


def solved_columns(mechanism: Any, cols: Any, start: int, stop: int) -> SolvedRows:
    """The solved positions among rows ``start:stop`` of a sweep's columns
    (:class:`~.columns.SweepColumns`), as arrays."""
    import numpy as np

    from ..units import radians

    scale = _display_scale(mechanism)
    status = np.asarray(cols.status[start:stop], dtype=object)
    rows = np.flatnonzero(status == "converged")
    q = []
    for u in mechanism.unknowns:
        v = np.asarray(cols.solution[u.name][start:stop], dtype=float)[rows]
        q.append(radians(v) if u.kind == "angle" else v)
    d = np.asarray(cols.inputs[start:stop], dtype=float)[rows] * scale
    return SolvedRows(rows + start, q, d)


def sweep_forces(mechanism: Any, result: Any, loads: Loads, speed: float, accel: float
                 ) -> list[Forces | None]:
    """Every position of a sweep's forces (None where unsolved): :func:`chunk_forces` a
    chunk of LOADS_CHUNK positions at a time, each position judged by
    :func:`position_forces`."""
    frame = Frame.of(mechanism)
    frame.check_masses(loads)
    n = len(result.positions)
    out: list[Forces | None] = [None] * n
    for a in range(0, n, LOADS_CHUNK):
        cf = chunk_forces(mechanism, frame, solved_positions(mechanism, result.positions, a,
                                                             min(n, a + LOADS_CHUNK)),
                          loads, speed, accel)
        for i in cf.undefined:
            out[i] = undefined_forces(frame, "the kinematics are undefined here")
        for m, (i, actual, unit) in enumerate(cf.rates()):
            out[i] = position_forces(cf.arrays, m, unit, actual.status, loads)  # type: ignore[arg-type]
    return out


FORCE_KEYS = ("input", "virtual_power_input", "max_pin_force", "ground_fx", "ground_fy", "ground_moment",
              "mechanical_advantage", "condition")
"""A sweep's loads columns before each pin's and slider's (SweepResult.force_columns)."""


class LoadChunk(NamedTuple):
    """The loads of positions ``start`` to ``start + len(status)`` as arrays: each
    position's FORCE_STATUSES code (-1: unsolved) and the columns of
    SweepResult.force_columns (NaN where there is no number)."""

    start: int
    status: Any
    columns: dict[str, Any]


def load_chunks(mechanism: Any, cols: Any, loads: Loads, speed: float, accel: float,
                chunk: int = LOADS_CHUNK) -> Iterator[LoadChunk]:
    """A sweep's loads (``cols``: its :class:`~.columns.SweepColumns`) a chunk of
    positions at a time, in order: each chunk by :func:`chunk_forces`, judged by the one
    status rule (:func:`force_status_np` with :func:`matrix_bound` and
    :func:`kinematic_bound`), every number as :func:`position_forces` gives it. Only the
    chunk being solved is held: the caller keeps what it needs of each."""
    frame = Frame.of(mechanism)
    frame.check_masses(loads)
    n = len(cols)
    for a in range(0, n, chunk):
        yield chunk_loads(mechanism, frame, cols, loads, speed, accel, a, min(n, a + chunk))


def chunk_loads(mechanism: Any, frame: Frame, cols: Any, loads: Loads, speed: float, accel: float,
                start: int, stop: int) -> LoadChunk:
    """The loads of rows ``start:stop`` of a sweep's columns (:func:`load_chunks`' chunk)."""
    solved = solved_columns(mechanism, cols, start, stop)
    given = None
    if speed and hasattr(cols.rates, "block"):  # the sweep's own rates (RateChunks), not again
        given = cols.rates.block(start, stop).take(solved.index - start)
    cf = chunk_forces(mechanism, frame, solved, loads, speed, accel, given)
    return _chunk_columns(cf, start, stop - start, loads)


def _chunk_columns(cf: ChunkForces, start: int, size: int, loads: Loads) -> LoadChunk:
    import numpy as np

    from .forces import FORCE_STATUSES, kinematic_bound_np, mechanical_advantage

    status = np.full(size, -1, dtype=np.int8)
    status[[i - start for i in cf.undefined]] = FORCE_STATUSES.index("undefined")
    columns = {key: np.full(size, np.nan) for key in FORCE_KEYS}
    fa = cf.arrays
    if fa is None:
        return LoadChunk(start, status, columns)
    rows = np.array(cf.kept, dtype=np.intp) - start
    cond = fa.condition
    bound = np.maximum(matrix_bound(cond), kinematic_bound_np(cf.unit))
    kin_ok = (cf.actual.status == "ok") & (cf.unit.status == "ok")
    codes = force_status_np(fa.input, cond, bound, kin_ok)
    status[rows] = codes
    number = codes != FORCE_STATUSES.index("undefined")  # flagged forces keep their numbers
    at = rows[number]

    def put(key: str, values: Any) -> None:
        columns.setdefault(key, np.full(size, np.nan))[at] = np.asarray(values, dtype=float)[number]

    inp = fa.input
    # each magnitude as a PinForce's (math.hypot), so the columns equal the Forces' numbers
    mags = [np.fromiter(map(math.hypot, fx.tolist(), fy.tolist()), float, len(rows))
            for *_, fx, fy in fa.pins]
    put("input", inp)
    put("virtual_power_input", fa.virtual_power_input)
    put("max_pin_force", np.max(mags, axis=0) if mags else np.full(len(rows), np.nan))
    put("ground_fx", fa.ground[0])
    put("ground_fy", fa.ground[1])
    put("ground_moment", fa.ground[2])
    ma = [mechanical_advantage(loads, x, fa.input_unit) for x in inp.tolist()]
    put("mechanical_advantage", [math.nan if v is None else v for v in ma])
    put("condition", cond)
    for j, on, _, fx, fy in fa.pins:
        put(f"{j}_on_{on}_fx", fx)
        put(f"{j}_on_{on}_fy", fy)
    for s, _, nn, mm in fa.sliders:
        put(f"{s}_normal", nn)
        put(f"{s}_couple", mm)
    return LoadChunk(start, status, columns)


@frozen
class SweepLoads:
    """A sweep's loads as columns (numpy arrays, one entry per position) and their peaks
    (:func:`sweep_load_columns`)."""

    status: Any
    """FORCE_STATUSES codes; -1 where the position is unsolved."""
    columns: dict[str, Any]
    """SweepResult.force_columns' numbers (NaN where none), each pin's and slider's after
    FORCE_KEYS."""
    peak_input: int
    """The position of the largest |input| by the one peak rule (force_peaks); -1: none."""
    peak_pin: int
    """The position of the largest pin force; -1: none."""
    flagged: int
    """Positions whose forces are flagged (near_toggle, ill_conditioned or undefined)."""

    @property
    def pins(self) -> list[str]:
        """Each pin's and slider's column names, in order."""
        return [k for k in self.columns if k not in FORCE_KEYS]


class LoadColumns:
    """A sweep's loads (``cols``: its :class:`~.columns.SweepColumns`) computed a chunk of
    positions at a time, in order, into columns (a few numbers a position), each chunk
    by :func:`chunk_forces` and judged by the one status rule (:func:`_chunk_columns`), its
    peaks accumulated (:class:`~.forces.PeakTracker`, the one peak rule), the chunk then
    let go. Where the sweep's rates are computed as they are read
    (:class:`~.columns.RateChunks`), each chunk's loads are taken as its rates are
    computed for the positions table, so the rates are computed once for both tables and
    never all held; :meth:`result` computes whatever chunks are left."""

    def __init__(self, mechanism: Any, cols: Any, loads: Loads, speed: float, accel: float,
                 chunk: int | None = None) -> None:
        import numpy as np

        from .forces import PeakTracker

        self.frame = Frame.of(mechanism)
        self.frame.check_masses(loads)
        self.mechanism, self.cols, self.loads, self.speed, self.accel = mechanism, cols, loads, speed, accel
        rates = cols.rates
        # ``chunk`` None: the rates' own chunks where they are computed as read, and
        # followed (each chunk's loads as its rates are computed); else LOADS_CHUNK
        own = getattr(rates, "chunk", None) if hasattr(rates, "listen") else None
        self.chunk = chunk or own or LOADS_CHUNK
        self.n, self.next = len(cols), 0
        self.status = np.full(self.n, -1, dtype=np.int8)
        self.columns: dict[str, Any] = {}
        self.tracker = PeakTracker(2)
        self._done: SweepLoads | None = None
        self.following = own is not None and own == self.chunk
        if self.following:
            rates.listen(self._heard)

    def _heard(self, start: int, _rates: Any) -> None:
        if start == self.next:  # in order only (the peaks are accumulated in order)
            self._take(start)

    def _take(self, a: int) -> None:
        import numpy as np

        b = min(self.n, a + self.chunk)
        c = chunk_loads(self.mechanism, self.frame, self.cols, self.loads, self.speed, self.accel, a, b)
        self.status[a:b] = c.status
        for key, values in c.columns.items():
            self.columns.setdefault(key, np.full(self.n, np.nan))[a:b] = values
        self.tracker.add(c.status, c.columns["input"], c.columns["max_pin_force"])
        self.next = b

    def _step(self) -> None:
        """The next chunk: through the rates (which hand it to :meth:`_heard`), or here."""
        start = self.next
        if self.following:
            self.cols.rates.chunk_block(start)  # computed once, heard by _heard
        if self.next == start:  # not heard (its rates were already at hand)
            self._take(start)

    def pins(self) -> list[str]:
        """Each pin's and slider's column names, in order: known from the first chunk with
        a solved position (the chunks up to it computed here)."""
        while self.next < self.n and not any(k not in FORCE_KEYS for k in self.columns):
            self._step()
        return [k for k in self.columns if k not in FORCE_KEYS]

    def result(self) -> SweepLoads:
        """Every chunk's loads (those not yet taken computed now) and the peaks."""
        if self._done is None:
            import numpy as np

            while self.next < self.n:
                self._step()
            (at_in, at_pin), flagged = self.tracker.peaks()
            for key in FORCE_KEYS:
                self.columns.setdefault(key, np.full(self.n, np.nan))
            ordered = {k: self.columns[k] for k in FORCE_KEYS}
            ordered.update((k, v) for k, v in self.columns.items() if k not in FORCE_KEYS)
            self._done = SweepLoads(self.status, ordered, at_in, at_pin, flagged)
        return self._done


def sweep_load_columns(mechanism: Any, cols: Any, loads: Loads, speed: float, accel: float,
                       chunk: int | None = None) -> SweepLoads:
    """A sweep's loads as columns, every chunk at once (:class:`LoadColumns`)."""
    return LoadColumns(mechanism, cols, loads, speed, accel, chunk).result()


def with_forces(mechanism: Any, result: Any, loads: Loads, speed: float | None, accel: float) -> Any:
    """The sweep ``result`` carrying every position's forces (``result.forces``)."""
    from dataclasses import replace

    return replace(result, forces=tuple(sweep_forces(mechanism, result, loads, speed or 0.0, accel)))
