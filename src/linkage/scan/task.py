"""One task of a scan: a chunk of designs solved by the design batch engine
(:mod:`linkage.kinematics.designs`) and reduced to their records; and how many designs a
task holds."""

from __future__ import annotations

import functools
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..errors import InputError
from ..kinematics.designs import CONVERGED, DesignSolutions, engine_for, solve_designs
from ..problems.loops import Mechanism
from ..records import frozen
from ..units import radians
from .metrics import design_metrics
from .moves import JointMoves

CHUNK_POSITIONS = 200_000
"""Designs x positions per task on the closed-form engine: a few tens of MB of arrays."""
CHUNK_DESIGNS_MAX = 20_000
"""At most this many designs per task, whatever the positions: records stay small."""
CHUNK_DESIGNS_SWEEP = 16
"""Designs per task where every design is swept on its own (tens of ms per design)."""
CHUNK_CELLS = 16 * CHUNK_POSITIONS
"""Designs x positions x numbers held per position (unknowns, and two per point) in one
task: about 26 MB of results, whatever the file's size or --chunk."""
MAX_HELD_VALUES = 50_000_000
"""Designs x record columns a scan may hold at once (400 MB): a sorted file without --top,
or the Python API's returned columns; streamed output holds one chunk."""


# --- one task ---------------------------------------------------------------------------------

@frozen
class ScanJob:
    """What every task needs, small and picklable: the mechanism as text (workers need no
    file), the --set overrides, the varied names, the driver values and the options."""

    text: str
    source: str
    overrides: tuple[tuple[str, float], ...]
    names: tuple[str, ...]
    values: tuple[float, ...]
    branch: str | None
    tol: float
    mechanism: Mechanism | None = None
    """A mechanism object given directly (the Python API); it travels pickled."""
    moves: JointMoves | None = None
    """The ground joints a scan of a joints file moves (their coordinates among names)."""
    loads: Any = None
    """A :class:`~linkage.problems.loads.Loads` whose forces each design's records carry
    (:func:`load_metrics`), or None."""
    motion: tuple[float, float] = (0.0, 0.0)
    """The driver's speed and acceleration (internal units) for the loads' inertia."""


@functools.lru_cache(maxsize=8)
def job_mechanism(text: str, source: str, overrides: tuple[tuple[str, float], ...]) -> Mechanism:
    from ..kinematics.loading import from_text

    return from_text(text, source).with_values(dict(overrides), {})


def run_chunk(job: ScanJob, start: int, designs: np.ndarray) -> dict[str, np.ndarray]:
    """One task: the records of designs ``start, start + 1, ...`` as columns."""
    m = job.mechanism or job_mechanism(job.text, job.source, job.overrides)
    params = (job.moves.parameters(job.names, designs) if job.moves is not None else
              {name: designs[:, j] for j, name in enumerate(job.names)})
    sol = solve_designs(m, params, np.array(job.values), branch=job.branch, tol=job.tol,
                        paths=bool(m.points))
    out = design_metrics(m, job.names, designs, sol, start, params)
    if job.loads is not None:
        out.update(load_metrics(m, params, sol, job.loads, job.motion))
    return out


FORCE_BATCH_CELLS = 2_000_000
"""Force-matrix numbers built at once (16 MB): a chunk's positions go through the matrix
method in slices of this many numbers. On dask's threads each numpy call of a slice is a
hand-over of the GIL between the workers, so fewer, larger calls use both cores better
(benchmarks/loaded_scan.py, two workers, interleaved: 1,000,000 took 10% more wall time
than this, 250,000 twice as much; 6,000,000, its arrays beyond the caches, 15% more)."""


def load_metrics(m: Mechanism, params: Mapping[str, np.ndarray], sol: DesignSolutions, loads: Any,
                 motion: tuple[float, float]) -> dict[str, np.ndarray]:
    """Each design's :data:`~linkage.problems.columns.LOADS` columns: every solved position's
    forces by :func:`~linkage.kinematics.force_sweeps.batch_forces` (the one matrix method), the
    peaks by :func:`~linkage.kinematics.forces.force_peaks` (the one peak rule)."""
    from ..kinematics.designs import design_grid
    from ..kinematics.force_sweeps import batch_forces
    from ..kinematics.forces import force_peaks

    n_designs, n_pos = sol.status.shape
    grid, drv = design_grid(m, params, sol.values, n_designs)
    varied = {k: v for k, v in grid.items() if k in params}
    solved = (sol.status == CONVERGED).reshape(-1)
    q = [(radians(sol.solution[:, :, j]) if kind == "angle" else sol.solution[:, :, j]).reshape(-1)
         for j, kind in enumerate(sol.kinds)]
    d = np.where(solved, drv, np.nan)
    total = n_designs * n_pos
    status = np.full(total, -1, dtype=np.int8)
    inp, pin, shaking = np.full(total, np.nan), np.full(total, np.nan), np.full(total, np.nan)
    width = 3 * sum(1 for b in m.extra["drawing"].bodies if b != "ground")
    step = max(1, FORCE_BATCH_CELLS // (width * width + 8 * width))
    for a in range(0, total, step):
        b = min(a + step, total)
        part = slice(a, b)
        bf = batch_forces(m, [c[part] for c in q], d[part], loads, speed=motion[0], accel=motion[1],
                          values={k: v[part] for k, v in varied.items()})
        status[part], inp[part], pin[part], shaking[part] = bf.status, bf.input, bf.pin_max, bf.shaking
    status[~solved] = -1  # unsolved: neither counted nor flagged
    shape = (n_designs, n_pos)
    status, inp, pin, shaking = (x.reshape(shape) for x in (status, inp, pin, shaking))
    (at_in, at_pin, at_ground), flagged = force_peaks(status, inp, pin, shaking)
    rows = np.arange(n_designs)
    none = at_in < 0  # the same positions count for every column
    return {
        "peak_input": np.where(none, np.nan, np.abs(inp[rows, at_in])),
        "max_pin_force": np.where(none, np.nan, pin[rows, at_pin]),
        "max_shaking_force": np.where(none, np.nan, shaking[rows, at_ground]),
        "forces_flagged": flagged.astype(np.int64),
    }


def chunk_size(m: Mechanism, positions: int, branch: str | None) -> int:
    most = max(1, CHUNK_CELLS // (max(positions, 1) * cell_width(m)))
    if engine_for(m, branch) != "sweep":
        return max(1, min(CHUNK_DESIGNS_MAX, CHUNK_POSITIONS // max(positions, 1), most))
    return min(CHUNK_DESIGNS_SWEEP, most)


TASKS_PER_WORKER = 2
"""Chunks per worker a scan is cut into at least, where its designs allow: 900 designs in
chunks of 555 kept one of two cores idle for 40% of the scan."""
MIN_TASK_POSITIONS = 20_000
"""Designs x positions a task keeps at least when cut for the workers: enough for numpy's
array work to outweigh a task's fixed cost."""


def balanced(size: int, designs: int, positions: int, workers: int) -> int:
    """``size`` designs per task, or fewer so that ``designs`` make at least
    TASKS_PER_WORKER tasks per worker, of nearly equal size (each at least
    MIN_TASK_POSITIONS positions), as many as a whole number of rounds of the workers
    where there are enough for one: every worker busy to the end on a local scheduler
    (three equal tasks on two workers kept one idle for the last third of the scan)."""
    if workers <= 1:
        return size
    tasks = max(1, min(TASKS_PER_WORKER * workers, designs * max(positions, 1) // MIN_TASK_POSITIONS))
    if tasks > workers:
        tasks -= tasks % workers
    return max(1, min(size, -(-designs // tasks)))


def cell_width(m: Mechanism) -> int:
    """Numbers a task holds per design and position: status, each unknown, x and y of each
    point."""
    return 1 + len(m.unknowns) + 2 * len(m.points)


def check_held(designs: int, columns: int, top: int | None, what: str, option: str = "--top") -> None:
    """Refuse, before any design is solved, a scan that would hold more than MAX_HELD_VALUES
    record values at once (``what`` says why they are held, ``option`` names top)."""
    held = min(designs, top if top is not None else designs) * columns
    if held > MAX_HELD_VALUES:
        raise InputError(f"{what} holds every record: {designs:,} designs x {columns} columns is "
                         f"{held:,} values, more than {MAX_HELD_VALUES:,}; give {option} "
                         f"of at most {MAX_HELD_VALUES // columns:,} designs, or fewer designs")


def pick_chunk(m: Mechanism, positions: int, branch: str | None, chunk: int | None,
               designs: int, workers: int = 1) -> int:
    """Designs per task: ``chunk`` if given and a task's results (of at most ``designs``)
    fit in CHUNK_CELLS numbers (else an InputError with the numbers), or :func:`chunk_size`,
    cut smaller where that would leave some of ``workers`` idle (:func:`balanced`)."""
    if chunk is None:
        return balanced(chunk_size(m, positions, branch), designs, positions, workers)
    cells = min(chunk, designs) * positions * cell_width(m)
    if cells > CHUNK_CELLS:
        raise InputError(f"--chunk {chunk:,}: {min(chunk, designs):,} designs x {positions:,} positions x "
                         f"{cell_width(m)} numbers is {cells:,}, more than {CHUNK_CELLS:,} per "
                         f"task; use --chunk {max(1, CHUNK_CELLS // (positions * cell_width(m))):,} "
                         "or less")
    return chunk

