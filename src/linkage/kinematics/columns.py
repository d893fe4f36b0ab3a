"""A sweep result as columns, one entry per position, for its report.

A batch or closed-form sweep (its positions a lazy :class:`~.batch.BatchPositions` over
a :class:`~.batch.BatchResult`) gives numpy arrays read straight from the engine's
arrays: no :class:`~.positions.Position` is built per row, transmission angles come from
the derivation's numpy twin and joints from :func:`~.rates.place_np`. The one-at-a-time
engine's tuple of positions gives plain lists, without importing numpy (a small sweep's
command stays numpy-free for its cold start).

Rates with a driver speed stay on the scalar definition (each position's
:class:`~.rates.Rates`, read a chunk at a time for a batch result): ``rates`` then holds
them, one per position (None where unsolved).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, NamedTuple

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
    """Each position's :class:`~.rates.Rates` (None where unsolved) with a driver speed."""
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
    branch = np.where(solved, b.branch, None) if b.branch is not None else np.full(n, None, dtype=object)
    det = np.where(solved, b.det, nan)
    m = b.source
    transmission = np.full(n, nan)
    joints: dict[str, tuple[Any, Any]] = {}
    rates = None
    if m is not None:
        scale = ANGLE_UNITS[m.driver.unit] if m.driver.kind == "angle" else 1.0
        q = [np.radians(solution[u.name]) if u.kind == "angle" else solution[u.name] for u in m.unknowns]
        d = np.asarray(b.values, dtype=float) * scale
        if m.derivation.fourbars:
            transmission = transmission_column(m, q, d, solved)
        if b.rates is not None and b.rates[0] is not None:
            # read once, in order (the batch computes them a chunk at a time)
            rates = [p.rates for p in s.positions]
            joints = _joints_of_rates(rates, n)
        elif b.rates is not None:
            from .rates import place_np

            placed = place_np(m.model, q, d)
            joints = {k: (np.where(solved, x, nan), np.where(solved, y, nan)) for k, (x, y) in placed.items()}
    return SweepColumns(np.asarray(b.values, dtype=float), status, solution, branch,
                        np.asarray(b.iterations), det, transmission, joints, rates, True)


def transmission_column(m: Any, q: Sequence[Any], d: Any, solved: Any) -> Any:
    """Each solved position's transmission angle (deg, NaN elsewhere) by the derivation's
    numpy twin of its rule (:meth:`~linkage.problems.derive.Derivation.transmission_np`)."""
    import numpy as np

    with np.errstate(invalid="ignore", divide="ignore"):
        mu = m.derivation.transmission_np(q, d)
    return np.where(solved, np.degrees(mu), np.nan)


def _joints_of_rates(rates: Sequence[Any], n: int) -> dict[str, tuple[Any, Any]]:
    import numpy as np

    names = next((list(r.joints) for r in rates if r is not None), [])
    out = {j: (np.full(n, np.nan), np.full(n, np.nan)) for j in names}
    for i, r in enumerate(rates):
        if r is None:
            continue
        for j, (x, y) in r.joints.items():
            out[j][0][i] = x
            out[j][1][i] = y
    return out
