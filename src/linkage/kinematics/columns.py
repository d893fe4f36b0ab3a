"""A sweep result as columns, one entry per position, for its report.

A batch or closed-form sweep (its positions a lazy :class:`~.batch.BatchPositions` over
a :class:`~.batch.BatchResult`) gives numpy arrays read straight from the engine's
arrays: no :class:`~.positions.Position` is built per row, transmission angles come from
the derivation's numpy twin and joints from :func:`~.rates.place_np`. The one-at-a-time
engine's tuple of positions gives plain lists, without importing numpy (a small sweep's
command stays numpy-free for its cold start).

Rates with a driver speed: ``rates`` gives each position's :class:`~.rates.Rates` (None
where unsolved). A batch result's are a :class:`RateChunks`: computed a chunk of positions
at a time as one block (kinematics.rate_blocks, the one definition over arrays) as they
are read, only the last chunk held, so a table written a block at a time (a
sweep's positions to CSV or parquet) holds one chunk of rates whatever the sweep's length
(docs/performance_loads.md).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

from ..records import NamedTuple
from ..units import degrees, radians
from .positions import SweepResult


class SweepColumns(NamedTuple):
    inputs: Any
    """Driver values, display units."""
    status: Any
    """Text per position: converged, no_solution, failed, off_branch."""
    solution: dict[str, Any]
    """Unknown name -> values (display units; None or NaN where unsolved)."""
    branch: Any
    iterations: Any
    det: Any
    transmission: Any
    """Degrees (None or NaN where unsolved or without a four-bar loop)."""
    joints: dict[str, tuple[Any, Any]]
    """Joint or point name -> (x, y) columns, when the sweep computed joints."""
    rates: Sequence[Any] | None
    """Each position's :class:`~.rates.Rates` (None where unsolved) with a driver speed: a
    list, or for a batch result a :class:`RateChunks` (read in order: one chunk computed at
    a time)."""
    arrays: bool
    """True: numpy arrays (NaN where no value); False: lists (None where no value)."""

    def __len__(self) -> int:  # the positions, not the fields
        return len(self.status)

    def solved(self, i: int) -> bool:
        return self.status[i] == "converged"


def sweep_columns(s: SweepResult) -> SweepColumns:
    """The columns of ``s`` (see the module's description)."""
    batch = getattr(s.positions, "batch", None)
    if batch is None:
        return _list_columns(s)
    return _array_columns(s, batch)


def _list_columns(s: SweepResult) -> SweepColumns:
    ps = s.positions
    joints: dict[str, tuple[Any, Any]] = {}
    names = next((list(p.rates.joints) for p in ps if p.rates is not None), [])
    for j in names:
        xs = [p.rates.joints[j][0] if p.rates is not None and j in p.rates.joints else None for p in ps]
        ys = [p.rates.joints[j][1] if p.rates is not None and j in p.rates.joints else None for p in ps]
        joints[j] = (xs, ys)
    return SweepColumns(
        [p.input for p in ps], [p.status for p in ps],
        {n: [p.solution[n] if p.solution else None for p in ps] for n in s.names},
        [p.branch for p in ps], [p.iterations for p in ps], [p.det for p in ps],
        [p.transmission for p in ps], joints,
        [p.rates for p in ps] if s.motion is not None else None, False)


def _array_columns(s: SweepResult, b: Any) -> SweepColumns:
    import numpy as np

    from ..problems.loops import ANGLE_UNITS
    from .batch import CODE_STATUS, STATUS_CODES

    n = len(b.values)
    solved = b.status == STATUS_CODES["converged"]
    words = np.empty(len(CODE_STATUS), dtype=object)
    for code, word in CODE_STATUS.items():
        words[code] = word
    status = words[b.status.astype(np.intp)]
    nan = np.float64(math.nan)
    solution = {name: np.where(solved, b.solution[:, j], nan) for j, name in enumerate(s.names)}
    branch = np.full(n, None, dtype=object)
    if b.branch is not None:  # one text object shared, not one made per position
        branch[solved] = b.branch
    everywhere = bool(solved.all())
    det = where_solved(solved, b.det, everywhere)
    m = b.source
    transmission = np.full(n, nan)
    joints: dict[str, tuple[Any, Any]] = {}
    rates = None
    if m is not None:
        scale = ANGLE_UNITS[m.driver.unit] if m.driver.kind == "angle" else 1.0
        q = [radians(solution[u.name]) if u.kind == "angle" else solution[u.name] for u in m.unknowns]
        d = np.asarray(b.values, dtype=float) * scale
        placing = b.rates is not None and b.rates[0] is None
        if m.derivation.fourbars:
            # beside place_np's sums when there are joints to place (numpy's sin, cos and
            # arctan2 release the GIL): the same function, so the same bits
            transmission = beside(transmission_column, m, q, d, solved) if placing and n >= BESIDE_FROM \
                else transmission_column(m, q, d, solved)
        if b.rates is not None and b.rates[0] is not None:
            # computed as read, a chunk at a time (the batch's own chunks), never all held
            rates = RateChunks(s.positions)
            first = next((i for i in np.flatnonzero(solved)), None)
            # the joints' names from the first solved position's chunk, as arrays (no Rates built)
            at = None if first is None else int(first) - int(first) % rates.chunk
            names = [] if at is None else list(rates.chunk_block(at).joints)
            joints = {j: (RateColumn(rates, j, 0), RateColumn(rates, j, 1)) for j in names}
        elif placing:
            from .placing import place_np

            placed = place_np(m.model, q, d)
            joints = {k: (where_solved(solved, x, everywhere), where_solved(solved, y, everywhere))
                      for k, (x, y) in placed.items()}
    if callable(transmission):
        transmission = transmission()
    return SweepColumns(np.asarray(b.values, dtype=float), status, solution, branch,
                        np.asarray(b.iterations), det, transmission, joints, rates, True)


BESIDE_FROM = 50_000
"""Positions from which a sweep's transmission angles are computed on a thread beside its
joints (:func:`beside`)."""


def beside(f: Callable[..., Any], *args: Any) -> Callable[[], Any]:
    """``f(*args)`` started on a thread; the call returned gives its value, waiting for it.
    Where the thread failed, ``f(*args)`` is called again there, raising its error in line
    (no thread traceback)."""
    import threading

    out: list[Any] = []

    def run() -> None:
        try:
            out.append(f(*args))
        except Exception:  # left empty: called again in line, where the error is raised
            return

    thread = threading.Thread(target=run, name="linkage-columns")
    thread.start()

    def value() -> Any:
        thread.join()
        return out[0] if out else f(*args)

    return value


def where_solved(solved: Any, x: Any, everywhere: bool) -> Any:
    """``x`` where a position solved, NaN elsewhere: ``x`` itself (a fresh array, read
    only from here on) when every position solved, as ``np.where`` would copy it unchanged
    (ten columns of 360,001 doubles: each copy a new 2.9 MB a fresh process faults in)."""
    import numpy as np

    if everywhere and getattr(x, "shape", None) == solved.shape:
        return x
    return np.where(solved, x, np.float64(math.nan))


def transmission_column(m: Any, q: Sequence[Any], d: Any, solved: Any) -> Any:
    """Each solved position's transmission angle (deg, NaN elsewhere) by the derivation's
    numpy twin of its rule (:meth:`~linkage.problems.derive.Derivation.transmission_np`)."""
    import numpy as np

    with np.errstate(invalid="ignore", divide="ignore"):
        mu = m.derivation.transmission_np(q, d)
    return np.where(solved, degrees(mu), np.nan)


class RateChunks(Sequence):  # type: ignore[type-arg]
    """Each position's rates of a batch sweep with a driver speed (None where unsolved),
    computed a chunk of positions at a time (kinematics.batch.RATES_CHUNK) as one block
    straight from the batch's arrays (:func:`~.rate_blocks.sweep_block`, the block twin of
    the one definition, :func:`~.rates.position_rates`), only the last chunk held.
    :meth:`block` gives rows as arrays (a table's columns, no object per position); an
    item, a position's :class:`~.rates.Rates`. :meth:`listen`: a callback given each chunk
    as it is computed, so a second reader in step (a sweep's loads,
    kinematics.force_sweeps) takes the same rates without computing them again."""

    def __init__(self, positions: Sequence[Any], chunk: int | None = None) -> None:
        from .batch import RATES_CHUNK

        self.positions = positions
        self.batch = positions.batch  # type: ignore[attr-defined]
        self.chunk = RATES_CHUNK if chunk is None else chunk
        self._last: tuple[int, Any, list[Any] | None] = (-1, None, None)
        self._listeners: list[Callable[[int, Any], None]] = []

    def __len__(self) -> int:
        return len(self.positions)

    def __getitem__(self, i: Any) -> Any:
        if isinstance(i, slice):
            return [self[k] for k in range(*i.indices(len(self)))]
        if i < 0:
            i += len(self)
        if not 0 <= i < len(self):
            raise IndexError(i)
        return self.load(i - i % self.chunk)[i % self.chunk]

    def chunk_block(self, start: int) -> Any:
        """The rates of the chunk from ``start`` (a multiple of ``chunk``) as a
        :class:`~.rate_blocks.RateBlock`."""
        if self._last[0] != start:
            from .batch import STATUS_CODES
            from .rate_blocks import sweep_block

            self._last = (-1, None, None)  # the last chunk let go before the next is computed
            b = self.batch
            stop = min(len(self), start + self.chunk)
            speed, accel = b.rates
            block = sweep_block(b.source, b.solution[start:stop], b.values[start:stop],
                                b.status[start:stop] == STATUS_CODES["converged"], speed, accel)
            self._last = (start, block, None)
            for listener in self._listeners:
                listener(start, block)
        return self._last[1]

    def load(self, start: int) -> list[Any]:
        """The rates of the chunk from ``start`` (a multiple of ``chunk``), one
        :class:`~.rates.Rates` per position (None where unsolved)."""
        block = self.chunk_block(start)
        if self._last[2] is None:
            self._last = (start, block, block.rates())
        return self._last[2]  # type: ignore[return-value]

    def block(self, start: int, stop: int) -> Any:
        """Rows ``start:stop`` as one :class:`~.rate_blocks.RateBlock` (the chunks they
        span, in order)."""
        from .rate_blocks import RateBlock

        parts = []
        for a in range(start - start % self.chunk, stop, self.chunk):
            got = self.chunk_block(a)
            lo, hi = max(start, a) - a, min(stop, a + self.chunk) - a
            parts.append(got if (lo, hi) == (0, len(got)) else got.take(slice(lo, hi)))
        return RateBlock.join(parts)

    def listen(self, listener: Callable[[int, Any], None]) -> None:
        """Call ``listener(start, block)`` for every chunk computed from now on."""
        self._listeners.append(listener)


class RateColumn(Sequence):  # type: ignore[type-arg]
    """A joint's x (``part`` 0) or y (1) over a sweep, read from its rates as they are
    read (:class:`RateChunks`); a slice is a numpy array, NaN where there is no value."""

    def __init__(self, rates: Sequence[Any], joint: str, part: int) -> None:
        self.rates, self.joint, self.part = rates, joint, part

    def __len__(self) -> int:
        return len(self.rates)

    def _one(self, i: int) -> float:
        r = self.rates[i]
        xy = r.joints.get(self.joint) if r is not None else None
        return math.nan if xy is None else float(xy[self.part])

    def __getitem__(self, i: Any) -> Any:
        if isinstance(i, slice):
            import numpy as np

            start, stop, step = i.indices(len(self))
            if hasattr(self.rates, "block") and step == 1 and stop > start:  # RateChunks: as arrays
                got = self.rates.block(start, stop).joints.get(self.joint)
                return got[self.part] if got is not None else np.full(stop - start, math.nan)
            idx = range(start, stop, step)
            return np.fromiter((self._one(k) for k in idx), float, len(idx))
        return self._one(i if i >= 0 else i + len(self))
