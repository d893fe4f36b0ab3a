"""Design-space scans: many variants of one mechanism, each over its whole cycle, reduced to
one flat record per design, filtered, ranked and streamed out chunk by chunk.

Designs come from a grid (``NAME=LO:HI:N`` per parameter, the last varying fastest) or
from ``samples`` random or Latin-hypercube draws (reproducible from ``seed``; design i is
the same whatever the chunk size or the scheduler). They are cut into chunks; each chunk
is one task, :func:`run_chunk`, which runs the design batch engine
(:mod:`linkage.kinematics.designs`) and returns columns. A scan of one chunk runs in
this process; more chunks run on dask: its local threaded scheduler by default
(measured faster here than processes: ``benchmarks/scan.py``), or a dask.distributed
cluster given by address. A task carries the mechanism file's text, never a path, so
workers need only this package installed. Results do not depend on who ran them: every
computation in a chunk is per design.
"""

from __future__ import annotations

import functools
import math
import sys
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .errors import InputError, ParseError
from .kinematics.angles import angle_extent_array, closes_circle, driver_turn
from .kinematics.designs import CONVERGED, DesignSolutions, engine_for, meeting_counts, solve_designs
from .problems.closed_form import grashof_np
from .problems.columns import (
    MEETINGS,
    columns_of,
    extent_columns,
    fourbar_columns,
    fourbar_loops,
    has_meetings,
    path_columns,
)
from .problems.loops import ANGLE_UNITS, Mechanism

MAX_DESIGNS = 10_000_000
MAX_SCAN_POSITIONS = 100_000
CHUNK_POSITIONS = 200_000
"""Designs x positions per task on the closed-form engine: a few tens of MB of arrays."""
CHUNK_DESIGNS_MAX = 20_000
"""At most this many designs per task, whatever the positions: records stay small."""
CHUNK_DESIGNS_SWEEP = 16
"""Designs per task where every design is swept on its own (tens of ms per design)."""
CHUNK_CELLS = 16 * CHUNK_POSITIONS
"""Designs x positions x numbers held per position (unknowns, and two per point) in one
task: about 26 MB of results, whatever the file's size or --chunk."""
MAX_SAMPLE_VALUES = 20_000_000
"""--samples x varied parameters: the drawn designs are held in memory (160 MB)."""
MAX_HELD_VALUES = 50_000_000
"""Designs x record columns a scan may hold at once (400 MB): a sorted file without --top,
or the Python API's returned columns; streamed output holds one chunk."""


@dataclass(frozen=True)
class Vary:
    """One ``--vary NAME=LO:HI[:N]``: file units, N points (None: sampled)."""

    name: str
    lo: float
    hi: float
    n: int | None


def parse_vary(text: str) -> Vary:
    name, eq, spec = text.partition("=")
    name = name.strip()
    parts = spec.split(":")
    if not eq or not name or len(parts) not in (2, 3):
        raise InputError(f"--vary {text!r}: write NAME=LO:HI (sampled) or NAME=LO:HI:N (a grid of N)")
    from .numbers import parse_number

    lo, hi = (parse_number(f"--vary {name} bound", p) for p in parts[:2])
    n = None
    if len(parts) == 3:
        try:
            n = int(parts[2])
        except ValueError:
            raise InputError(f"--vary {name}: N must be a whole number of points, got {parts[2]!r}") from None
        if not 1 <= n <= MAX_DESIGNS:
            raise InputError(f"--vary {name}: N must be between 1 and {MAX_DESIGNS:,}, got {n}")
        if n == 1 and lo != hi:
            raise InputError(f"--vary {name}: one point needs LO = HI (or use --set)")
    if hi < lo:
        raise InputError(f"--vary {name}: HI ({hi:g}) is below LO ({lo:g})")
    return Vary(name, lo, hi, n)


def check_varies(m: Mechanism, varies: Sequence[Vary]) -> None:
    """Each name a parameter of ``m``, once; both bounds valid values for it."""
    seen: set[str] = set()
    for v in varies:
        if v.name in seen:
            raise InputError(f"--vary {v.name} is given twice")
        seen.add(v.name)
        if v.name not in m.parameters:
            what = ("the driver (use --from/--to)" if v.name == m.driver.name else
                    "an unknown" if v.name in {u.name for u in m.unknowns} else "not a parameter")
            raise InputError(f"--vary {v.name}: {what}; the parameters of {m.source} are "
                             f"{', '.join(m.parameters)}")
        for bound in (v.lo, v.hi):
            try:
                m.with_values({v.name: bound}, {})
            except ParseError as exc:
                raise InputError(f"--vary {v.name}: {str(exc).removeprefix('--set ')}") from None


class DesignPlan:
    """Which designs a scan visits: ``chunk(start, stop)`` gives their parameter values
    (file units) as an array of shape (stop - start, parameters)."""

    def __init__(self, varies: Sequence[Vary], samples: int | None, seed: int, method: str) -> None:
        self.names = tuple(v.name for v in varies)
        self.varies = tuple(varies)
        gridded = [v.n is not None for v in varies]
        if samples is None:
            if not all(gridded):
                missing = next(v.name for v in varies if v.n is None)
                raise InputError(f"--vary {missing}: give :N points for a grid, or --samples N "
                                 "for random designs")
            total = math.prod(v.n for v in varies if v.n is not None) if varies else 1
            self.axes = [np.linspace(v.lo, v.hi, v.n) if v.n and v.n > 1 else np.array([v.lo])
                         for v in varies]
            self.samples = None
        else:
            if any(gridded):
                raise InputError("--samples draws random designs: give --vary NAME=LO:HI without :N")
            if not 1 <= samples <= MAX_DESIGNS:
                raise InputError(f"--samples must be between 1 and {MAX_DESIGNS:,}, got {samples}")
            if method not in ("lhs", "random"):
                raise InputError(f"--sampling must be lhs or random, got {method!r}")
            if samples * len(varies) > MAX_SAMPLE_VALUES:
                raise InputError(f"--samples {samples:,} x {len(varies)} varied parameters is "
                                 f"{samples * len(varies):,} values, more than the "
                                 f"{MAX_SAMPLE_VALUES:,} a scan holds; use fewer samples")
            total = samples
            self.samples = _draw(varies, samples, seed, method)
        if total > MAX_DESIGNS:
            raise InputError(f"the grid has {total:,} designs, more than {MAX_DESIGNS:,}; use fewer "
                             "points or --samples")
        self.total = total

    def chunk(self, start: int, stop: int) -> np.ndarray:
        if self.samples is not None:
            return self.samples[start:stop]
        if not self.axes:
            return np.empty((stop - start, 0))
        idx = np.unravel_index(np.arange(start, stop), [len(a) for a in self.axes])
        return np.stack([a[i] for a, i in zip(self.axes, idx)], axis=1)


# --- a joints file's ground joints, moved ----------------------------------------------------

def coordinate_column(joint: str, axis: str) -> str:
    """The record column of a varied coordinate (``--vary O4.x`` -> ``O4_x``): a name
    --where and --sort read (a dot would be an attribute there)."""
    return f"{joint}_{axis}"


@dataclass(frozen=True)
class GroundMove:
    """A ground joint a scan moves: where it is drawn, the plan's columns giving its x and
    y (-1: as drawn) and the derived parameters that place it from the ground's first
    joint (its distance and its angle, deg)."""

    joint: str
    drawn: tuple[float, float]
    columns: tuple[int, int]
    length: str
    angle: str


@dataclass(frozen=True)
class JointMoves:
    """The coordinates of a joints file's ground joints that a scan varies, and how each
    design's coordinates become the derived loops' parameters: the ground is a star from
    its first joint ``root``, so a ground joint at (x, y) is a vector of length
    hypot(x - x0, y - y0) at atan2(y - y0, x - x0) from it. The one home of that rule."""

    root: tuple[float, float]
    moves: tuple[GroundMove, ...]

    @property
    def columns(self) -> frozenset[int]:
        return frozenset(c for g in self.moves for c in g.columns if c >= 0)

    def parameters(self, names: Sequence[str], designs: np.ndarray) -> dict[str, np.ndarray]:
        """The parameter columns (file units) of a chunk of designs (rows of ``names``)."""
        out = {n: designs[:, j] for j, n in enumerate(names) if j not in self.columns}
        rows = designs.shape[0]
        for g in self.moves:
            x, y = (designs[:, c] if c >= 0 else np.full(rows, v) for c, v in zip(g.columns, g.drawn))
            dx, dy = x - self.root[0], y - self.root[1]
            out[g.length] = np.hypot(dx, dy)
            out[g.angle] = np.degrees(np.arctan2(dy, dx))
        return out


def joint_moves(m: Mechanism, doc: Mapping[str, Any] | None, varies: Sequence[Vary],
                fixed: Sequence[str] = ()) -> tuple[list[Vary], JointMoves | None]:
    """``varies`` with each ``JOINT.x``/``JOINT.y`` (a ground joint's coordinate in the
    joints file ``doc``) renamed to its column, and how they move the joints; None when no
    coordinate is varied. ``fixed``: the names given by --set. InputError, one line, for a
    coordinate that cannot be varied."""
    coords = [(k, v) for k, v in enumerate(varies) if v.name not in m.parameters and "." in v.name]
    if not coords:
        return list(varies), None
    from .problems.joints import is_joints_doc

    first = coords[0][1].name
    if doc is None:  # the Python API given a Mechanism: its drawing is gone
        raise InputError(f"vary {first!r}: a joint's coordinate is read from a joints file: give "
                         "its path, not a Mechanism")
    if not is_joints_doc(doc):
        raise InputError(f"--vary {first}: a joint's coordinate is varied in a joints file; "
                         f"{m.source} is in the loops form: vary its parameters "
                         f"({', '.join(m.parameters)})")
    xy = {str(k): (float(p[0]), float(p[1])) for k, p in doc["joints"].items()}
    ground = [str(g) for g in doc["ground"]]
    root, movable = ground[0], ground[1:]
    can = (f"the fixed joints after {root} can move: " + ", ".join(f"{g}.x, {g}.y" for g in movable)
           if movable else f"{root} is this drawing's only fixed joint")
    where = _ground_vectors(m, root)
    names = [v.name for v in varies]
    moved: dict[str, list[int]] = {}
    out = list(varies)
    for k, v in coords:
        if names.index(v.name) != k:
            raise InputError(f"--vary {v.name} is given twice")
        joint, _, axis = v.name.rpartition(".")
        if joint not in xy:
            raise InputError(f"--vary {v.name}: no joint {joint!r} in {m.source}; {can}")
        if axis not in ("x", "y"):
            raise InputError(f"--vary {v.name}: a joint's coordinates are x and y, not {axis!r}")
        if joint == root:
            raise InputError(f"--vary {v.name}: {root} is where the drawing is placed (the ground's "
                             f"first joint): moving it moves the whole drawing; {can}")
        if joint not in ground:
            links = [str(k) for k, js in doc["links"].items() if joint in js]
            lengths = [p for p in m.parameters if p in links or any(p.startswith(f"{k}_") for k in links)]
            raise InputError(f"--vary {v.name}: {joint} moves with {', '.join(links)}: where it is "
                             f"follows from the link lengths; vary those instead ({', '.join(lengths)})")
        if joint not in where:
            raise InputError(f"--vary {v.name}: {joint} is on no loop of {m.source}: moving it "
                             "changes nothing")
        col = coordinate_column(joint, axis)
        if col in m.parameters:
            raise InputError(f"--vary {v.name}: its column {col} is also a parameter of "
                             f"{m.source}; rename that link")
        for other in where[joint]:
            if other in names or other in fixed:
                raise InputError(f"--vary {v.name}: {other} is {joint}'s place too (derived from "
                                 f"it); vary {joint}.x/{joint}.y or {other}, not both")
        out[k] = Vary(col, v.lo, v.hi, v.n)
        moved.setdefault(joint, [-1, -1])[0 if axis == "x" else 1] = k
    moves = JointMoves(xy[root], tuple(GroundMove(j, xy[j], (c[0], c[1]), *where[j])
                                       for j, c in moved.items()))
    _check_moves(m, moves, out, root)
    return out, moves


def _check_moves(m: Mechanism, moves: JointMoves, varies: Sequence[Vary], root: str) -> None:
    """Every design's ground valid, found at the corners of each joint's box (its farthest
    places); a box holding ``root`` would put a joint on it (a ground vector of no length)."""
    for g in moves.moves:
        ranges = [(varies[c].lo, varies[c].hi) if c >= 0 else (v, v) for c, v in zip(g.columns, g.drawn)]
        named = " and ".join(f"{g.joint}.{a}" for a, c in zip("xy", g.columns) if c >= 0)
        if all(lo <= r <= hi for (lo, hi), r in zip(ranges, moves.root)):
            raise InputError(f"--vary {named}: the range puts {g.joint} on {root}, the ground's first "
                             "joint (no ground length); keep it off")
        corners = np.array([(x, y) for x in ranges[0] for y in ranges[1]])
        one = JointMoves(moves.root, (GroundMove(g.joint, g.drawn, (0, 1), g.length, g.angle),))
        for row in range(len(corners)):
            values = {k: float(v[row]) for k, v in one.parameters(("x", "y"), corners).items()}
            try:
                m.with_values(values, {})
            except ParseError as exc:
                raise InputError(f"--vary {named}: {str(exc).removeprefix('--set ')}") from None


def _ground_vectors(m: Mechanism, root: str) -> dict[str, tuple[str, str]]:
    """Each ground joint's (length, angle) parameters, read from the derived loops: the
    vector between ``root`` and it whose angle is a parameter."""
    out: dict[str, tuple[str, str]] = {}
    for loop in m.loops:
        js = loop.joints
        for i, t in enumerate(loop.vectors):
            if not js or not isinstance(t.length, str) or not isinstance(t.angle, str):
                continue
            a, b = js[i], js[(i + 1) % len(js)]
            if t.angle in m.parameters and root in (a, b):
                out[b if a == root else a] = (t.length, t.angle)
    return out


def _draw(varies: Sequence[Vary], n: int, seed: int, method: str) -> np.ndarray:
    rng = np.random.default_rng(seed)
    p = len(varies)
    u = rng.random((n, p))
    if method == "lhs":
        # one draw in each of n equal strata per parameter, strata shuffled independently
        for j in range(p):
            u[:, j] = (rng.permutation(n) + u[:, j]) / n
    lo = np.array([v.lo for v in varies])
    hi = np.array([v.hi for v in varies])
    # in place, the same operations as lo + u * (hi - lo): one array of the designs in memory
    u *= hi - lo
    u += lo
    return u


# --- one task ---------------------------------------------------------------------------------

@dataclass(frozen=True)
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
    from .kinematics.loading import from_text

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


FORCE_BATCH_CELLS = 4_000_000
"""Force-matrix numbers built at once (32 MB): a chunk's positions go through the matrix
method in slices of this many numbers."""


def load_metrics(m: Mechanism, params: Mapping[str, np.ndarray], sol: DesignSolutions, loads: Any,
                 motion: tuple[float, float]) -> dict[str, np.ndarray]:
    """Each design's :data:`~linkage.problems.columns.LOADS` columns: every solved position's
    forces by :func:`~linkage.kinematics.force_sweeps.batch_forces` (the one matrix method), the
    peaks by :func:`~linkage.kinematics.forces.force_peaks` (the one peak rule)."""
    from .kinematics.designs import design_grid
    from .kinematics.force_sweeps import batch_forces
    from .kinematics.forces import force_peaks

    n_designs, n_pos = sol.status.shape
    grid, drv = design_grid(m, params, sol.values, n_designs)
    varied = {k: v for k, v in grid.items() if k in params}
    solved = (sol.status == CONVERGED).reshape(-1)
    q = [(np.radians(sol.solution[:, :, j]) if kind == "angle" else sol.solution[:, :, j]).reshape(-1)
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
               designs: int) -> int:
    """Designs per task: ``chunk`` if given and a task's results (of at most ``designs``)
    fit in CHUNK_CELLS numbers (else an InputError with the numbers), or :func:`chunk_size`."""
    if chunk is None:
        return chunk_size(m, positions, branch)
    cells = min(chunk, designs) * positions * cell_width(m)
    if cells > CHUNK_CELLS:
        raise InputError(f"--chunk {chunk:,}: {min(chunk, designs):,} designs x {positions:,} positions x "
                         f"{cell_width(m)} numbers is {cells:,}, more than {CHUNK_CELLS:,} per "
                         f"task; use --chunk {max(1, CHUNK_CELLS // (positions * cell_width(m))):,} "
                         "or less")
    return chunk


# --- metrics ---------------------------------------------------------------------------------

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
    its transmission angle over the solved positions (steps.fourbar_transmission, folded
    into [0, 90] deg)."""
    from .problems.find_steps import loop_terms
    from .problems.steps import fourbar_transmission

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
    q = [np.radians(sol.solution[:, :, j]) if kind == "angle" else sol.solution[:, :, j]
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
        mu = np.degrees(fourbar_transmission(view, loop, params, drv, q, xp=np))
        mu = np.broadcast_to(mu, (n_designs, n_pos))
        out[lo], out[hi] = _extent(mu, solved)  # folded by fourbar_transmission's one rule
    return out


grashof_class = grashof_np
"""The Grashof class of each four-bar (ground, input, coupler, output): the numpy twin of
:func:`~linkage.problems.closed_form.grashof`."""


# --- running the chunks -------------------------------------------------------------------------

def chunk_bounds(total: int, size: int) -> list[tuple[int, int]]:
    return [(a, min(a + size, total)) for a in range(0, total, size)]


def run_chunks(job: Any, plan: DesignPlan, size: int, *, scheduler: str | None = None,
               workers: int | None = None, task: Callable[..., dict[str, np.ndarray]] | None = None
               ) -> Iterator[dict[str, np.ndarray]]:
    """Every chunk's records, in design order. ``scheduler``: None or "threads" (dask's
    local threads), "processes", "synchronous", or the address of a dask.distributed
    scheduler (tcp://host:port). A scan of one chunk, not sent to a cluster, runs here
    without importing dask. ``task(job, start, designs)`` makes a chunk's records
    (default :func:`run_chunk`; a synthesis search passes its own, a module-level
    function, so it pickles)."""
    task = task or run_chunk
    bounds = chunk_bounds(plan.total, size)
    remote = scheduler is not None and "://" in scheduler
    if remote:
        check_scheduler(scheduler)  # type: ignore[arg-type]
    if not remote and (len(bounds) == 1 or scheduler == "synchronous" or workers == 1):
        for a, b in bounds:
            yield task(job, a, plan.chunk(a, b))
        return
    if remote:
        yield from _distributed(job, plan, bounds, scheduler, task)  # type: ignore[arg-type]
        return
    yield from _local(job, plan, bounds, scheduler or "threads", workers, task)


def _local(job: Any, plan: DesignPlan, bounds: list[tuple[int, int]], kind: str,
           workers: int | None, task: Callable[..., dict[str, np.ndarray]] = run_chunk
           ) -> Iterator[dict[str, np.ndarray]]:
    import os

    if kind not in ("threads", "processes"):
        raise InputError(f"--scheduler must be threads, processes, synchronous or tcp://HOST:PORT, "
                         f"got {kind!r}")
    try:
        if kind == "threads":
            from dask.threaded import get
        else:
            from dask.multiprocessing import get
    except ImportError:
        print("note: dask is not installed, so the chunks run one after another here "
              "(pip install 'linkage-kinematics[scan]' to run them in parallel)", file=sys.stderr)
        for a, b in bounds:
            yield task(job, a, plan.chunk(a, b))
        return
    n = workers or os.cpu_count() or 1
    window = 2 * n  # chunks in flight: memory stays bounded however many designs there are
    for w in range(0, len(bounds), window):
        part = bounds[w:w + window]
        graph = {("chunk", i): (task, job, a, plan.chunk(a, b)) for i, (a, b) in enumerate(part)}
        yield from get(graph, [("chunk", i) for i in range(len(part))], num_workers=n)


def check_scheduler(address: str) -> tuple[str, int]:
    """The host and port of ``tcp://HOST:PORT``, after one quick connection attempt (a
    closed port answers at once, where dask's client retries for its whole timeout);
    anything else an InputError."""
    import socket
    from urllib.parse import urlsplit

    try:
        parts = urlsplit(address)
        host, port = parts.hostname, parts.port
    except ValueError as exc:  # a port beyond 65535 or not a number
        raise InputError(f"--scheduler {address!r}: {exc}; give tcp://HOST:PORT") from None
    if parts.scheme != "tcp" or not host or port is None or parts.path not in ("", "/"):
        raise InputError(f"--scheduler {address!r}: give tcp://HOST:PORT (threads, processes and "
                         "synchronous run here; only tcp:// clusters are supported)")
    try:
        socket.create_connection((host, port), timeout=5.0).close()
    except OSError as exc:
        raise InputError(f"cannot reach the dask scheduler at {address}: "
                         f"{exc.strerror or exc}") from None
    return host, port


def _distributed(job: Any, plan: DesignPlan, bounds: list[tuple[int, int]], address: str,
                 task: Callable[..., dict[str, np.ndarray]] = run_chunk) -> Iterator[dict[str, np.ndarray]]:
    from collections import deque

    try:
        from distributed import Client
    except ImportError:
        raise InputError("--scheduler tcp://... needs dask.distributed: pip install "
                         "'linkage-kinematics[scan]'") from None
    try:
        client = Client(address, timeout="10s")
    except (OSError, TimeoutError, ValueError) as exc:
        raise InputError(f"cannot reach the dask scheduler at {address}: {exc}") from None
    try:
        n = max(1, sum(client.nthreads().values()))
        window = 2 * n
        pending: deque[Any] = deque()
        queue = iter(bounds)
        for a, b in queue:
            pending.append(client.submit(task, job, a, plan.chunk(a, b), pure=False))
            if len(pending) >= window:
                break
        while pending:
            result = pending.popleft().result()
            nxt = next(queue, None)
            if nxt is not None:
                pending.append(client.submit(task, job, nxt[0], plan.chunk(*nxt), pure=False))
            yield result
    finally:
        client.close()


# --- filter, rank, keep ------------------------------------------------------------------------

def take(cols: Mapping[str, np.ndarray], rows: np.ndarray) -> dict[str, np.ndarray]:
    return {k: v[rows] for k, v in cols.items()}


def concat(parts: Sequence[Mapping[str, np.ndarray]]) -> dict[str, np.ndarray]:
    if not parts:
        return {}
    return {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}


def rank(cols: Mapping[str, np.ndarray], key: str, descending: bool) -> np.ndarray:
    """Row order by ``key``: stable, ties in design order, NaN (and, for text, nothing
    else) last whichever the direction."""
    v = cols[key]
    if v.dtype == object:
        order = np.argsort(v.astype(str), kind="stable")
        return order[::-1] if descending else order
    v = v.astype(float)
    missing = np.isnan(v)
    keyed = np.where(missing, np.inf, -v if descending else v)
    return np.lexsort((cols["design"], missing, keyed))


class Keeper:
    """The records a scan keeps: all of them (streamed on to ``sink`` as they come when
    unsorted), or the first ``top`` (by ``sort``), merged chunk by chunk so memory stays
    bounded. ``show`` caps what is held for a table without changing what is counted."""

    def __init__(self, sort: str | None, descending: bool, top: int | None,
                 sink: Callable[[Mapping[str, np.ndarray]], None] | None, show: int | None = None) -> None:
        self.sort, self.descending, self.top, self.sink = sort, descending, top, sink
        self.limit = top if top is not None else show
        self.kept = 0
        self.held: dict[str, np.ndarray] = {}
        self.parts: list[dict[str, np.ndarray]] = []

    @property
    def full(self) -> bool:
        """True once no later design can change the output (unsorted, top reached)."""
        return self.sort is None and self.top is not None and self.kept >= self.top

    def add(self, cols: dict[str, np.ndarray]) -> None:
        if self.sort is None and self.top is not None:
            cols = take(cols, np.arange(min(self.top - self.kept, len(cols["design"]))))
        self.kept += len(cols["design"])
        if self.sink is not None:
            self.sink(cols)
            return
        if self.limit is None:
            self.parts.append(cols)
            return
        merged = concat([self.held, cols]) if self.held else cols
        order = (rank(merged, self.sort, self.descending) if self.sort is not None
                 else np.arange(len(merged["design"])))
        self.held = take(merged, order[: self.limit])

    def result(self) -> dict[str, np.ndarray]:
        """What is held at the end, in order: the rows a table shows, or every row of a
        sorted file."""
        if self.limit is not None:
            return self.held
        rows = concat(self.parts)
        if self.sort is None or not rows:
            return rows
        return take(rows, rank(rows, self.sort, self.descending))


def default_branch(m: Mechanism, branch: str | None, tol: float) -> str | None:
    """The branch every design follows: the one asked for (a name or the signs of the
    derivation's two-way steps, checked here), else (with a closed form) the file's branch
    (:func:`~linkage.kinematics.pose.file_branch`), by name where it has one, else None
    (continuation from the file's guess, design by design)."""
    from .problems.derive import Indeterminate, read_branch, sign_text

    der = m.derivation
    if branch is not None:
        refusal = der.branch_refusal(m.source)  # solve's and sweep's refusal, one home
        if refusal is not None:
            raise InputError(refusal)
        try:
            read_branch(der, branch)
        except ValueError as exc:
            raise InputError(f"--branch {exc}") from None
        return branch
    if not der.complete:
        return None
    from .kinematics.pose import file_branch

    signs = file_branch(m)  # the one home of the file's branch, as a sweep of the file follows it
    if signs is None:
        return sign_text(der.branches[0])
    try:
        named = der.named_solutions(m.driver.value)
    except Indeterminate:
        return signs
    for name, (s, q) in named.items():
        if sign_text(s) == signs:
            # by name, unless the pose is where assemblies meet (its name is rounding's)
            return signs if any(der.meets(q, m.driver.value)) else name
    return signs


@dataclass(frozen=True)
class ScanSetup:
    """A checked scan: the designs, the record columns, the filter and the branch."""

    plan: DesignPlan
    spec: list[tuple[str, str, str]]
    where: Any
    branch: str | None
    values: list[float]
    moves: JointMoves | None = None
    loads: Any = None
    branch_note: str = ""
    """Why the branch is a matter of rounding, where it is (kinematics.sweep.POSE_MEETS)."""


def check_loads(m: Mechanism, names: Sequence[str], loads: Any) -> None:
    """A scan with loads needs links as bodies (the joints form), and a link with a mass
    keeps its drawn shape: its cg and inertia are given for the lengths drawn, so a scan
    varying them (or a --set) would keep a mass where the link no longer is."""
    from .kinematics.bodies import Frame

    Frame.of(m).check_masses(loads, names)


def prepare(m: Mechanism, varies: Sequence[Vary], *, samples: int | None, seed: int, sampling: str,
            values: Sequence[float], branch: str | None, tol: float, where: str | None,
            sort: str | None, doc: Mapping[str, Any] | None = None,
            fixed: Sequence[str] = (), loads: Any = None) -> ScanSetup:
    """Everything checked before any design is solved (one InputError or ParseError).
    ``doc``: the file's document, for a joints file's coordinates (:func:`joint_moves`);
    ``fixed``: the names --set gives; ``loads``: a Loads whose columns the records carry
    (None: none)."""
    from .kinematics.sweep import check_driver_values
    from .problems.where import parse_where

    varies, moves = joint_moves(m, doc, varies, fixed)
    check_varies(m, [v for k, v in enumerate(varies) if moves is None or k not in moves.columns])
    plan = DesignPlan(varies, samples, seed, sampling)
    if len(values) > MAX_SCAN_POSITIONS:
        raise InputError(f"{len(values):,} driver positions per design is more than "
                         f"{MAX_SCAN_POSITIONS:,}; use a larger --step")
    listed = check_driver_values(m, values)
    if loads is not None:
        check_loads(m, plan.names, loads)
    spec = columns_of(m, plan.names, loads is not None)
    known = {c[0]: ("number" if c[1] in ("int", "number") else c[1]) for c in spec}
    test = parse_where(where, known) if where is not None else None
    if sort is not None and sort not in known:
        raise InputError(f"--sort {sort}: no such column; the columns are {', '.join(known)}")
    from .kinematics.pose import POSE_MEETS, pose_meets

    note = POSE_MEETS if branch is None and pose_meets(m) else ""
    return ScanSetup(plan, spec, test, default_branch(m, branch, tol), listed, moves, loads, note)


def scan(mechanism: Mechanism | str, vary: Mapping[str, Sequence[float]], *, samples: int | None = None,
         seed: int = 0, sampling: str = "lhs", values: Sequence[float] | None = None,
         branch: str | None = None, tol: float = 1e-12, where: str | None = None,
         sort: str | None = None, descending: bool = False, top: int | None = None,
         scheduler: str | None = None, workers: int | None = None,
         chunk: int | None = None, loads: Any = None, speed: float | None = None,
         accel: float = 0.0) -> dict[str, np.ndarray]:
    """Scan designs of ``mechanism`` (a Mechanism or a file path); the public
    ``linkage.scan_designs`` (``linkage.scan`` is this module).

    ``vary`` maps parameter names to ``(lo, hi, n)`` (a grid) or ``(lo, hi)`` (with
    ``samples``), in the file's units (of a joints file given by path, also a fixed
    joint's coordinate, ``"O4.x"`` or ``"O4.y"``: columns ``O4_x``, ``O4_y``); ``values``
    are the driver values (default 0..359 deg). Returns the kept records as columns (name
    -> numpy array), in design order or sorted by ``sort``: the columns ``linkage scan``
    writes, with the same ``where``, ``sort``, ``top``, ``scheduler`` and ``workers``.
    Every argument is checked first (:mod:`linkage.arguments`): a misuse raises
    InputError naming it; n, samples, seed, top, chunk and workers are whole numbers
    (workers at most MAX_THREADS threads or MAX_PROCESSES processes), the driver values
    finite reals.

    ``loads``: a :class:`~linkage.Loads` (default: the file's ``[loads]`` and ``[mass]``, if
    any) adds the columns peak_input, max_pin_force, max_shaking_force and forces_flagged
    (:func:`load_metrics`), with the driver at ``speed`` and ``accel`` (rad/s and rad/s^2,
    or the length unit per s and s^2) for the masses' inertia.
    """
    from .arguments import (
        check_flag,
        check_motion,
        check_reals,
        check_scan_options,
        check_text,
        check_vary,
    )
    from .kinematics.loading import mechanism_of
    from .solve import check_criteria

    m = mechanism_of("mechanism", mechanism)
    specs = check_vary(vary, MAX_DESIGNS)
    doc = None
    if not isinstance(mechanism, Mechanism) and any("." in s[0] for s in specs):
        from pathlib import Path

        from .files import parse_toml, read_input

        doc = parse_toml(read_input(Path(mechanism)), str(mechanism))  # a joint's coordinates
    check_scan_options(seed=seed, samples=samples, top=top, chunk=chunk, workers=workers,
                       scheduler=scheduler, max_designs=MAX_DESIGNS)
    check_criteria(tol, 0.0, None, 50)
    for name, text in (("where", where), ("sort", sort), ("branch", branch)):
        check_text(name, text)
    check_text("sampling", sampling, optional=False)
    if sampling not in ("lhs", "random"):
        raise InputError(f"sampling must be lhs or random, got {sampling!r}")
    check_flag("descending", descending)
    varies = [parse_vary(f"{name}={lo!r}:{hi!r}" + (f":{n}" if n is not None else ""))
              for name, lo, hi, n in specs]
    if values is None:
        values = [float(k) for k in range(360)]
    values = check_reals("values", values, most=MAX_SCAN_POSITIONS)
    if not values:
        # a fraction of no positions is no fraction: feasible_fraction would read 0
        raise InputError("values must hold at least one driver value")
    from .kinematics.bodies import checked_loads

    speed, accel = check_motion(speed, accel, m.driver.kind, m.length_unit)
    own = checked_loads(loads, m) if loads is not None else m.extra.get("loads")
    used = own if own is not None and (not own.empty or own.gravity is not None) else None
    if used is None and speed is not None:
        raise InputError("speed in a scan is for the loads' inertia: give loads (a linkage.Loads, or "
                         "[loads] and [mass] in a joints-form file)")
    setup = prepare(m, varies, samples=samples, seed=seed, sampling=sampling, values=list(values),
                    branch=branch, tol=tol, where=where, sort=sort, doc=doc, loads=used)
    check_held(setup.plan.total, len(setup.spec), top, "a scan returned as columns", "top")
    job = ScanJob("", m.source, (), setup.plan.names, tuple(setup.values), setup.branch, tol, m,
                  setup.moves, used, (speed or 0.0, accel))
    keeper = Keeper(sort, descending, top, None)
    feed(keeper, job, setup, pick_chunk(m, len(setup.values), setup.branch, chunk,
                                        setup.plan.total),
         scheduler=scheduler, workers=workers)
    return keeper.result() or {c[0]: np.array([]) for c in setup.spec}


def feed(keeper: Keeper, job: ScanJob, setup: ScanSetup, size: int, *, scheduler: str | None,
         workers: int | None, progress: Callable[[int], None] | None = None) -> int:
    """Run the scan's chunks into ``keeper``, each filtered by the setup's test, until
    every design is done or the keeper is full. Returns the designs scanned."""
    scanned = 0
    for cols in run_chunks(job, setup.plan, size, scheduler=scheduler, workers=workers):
        scanned += len(cols["design"])
        if setup.where is not None:
            cols = take(cols, setup.where(cols, len(cols["design"])))
        keeper.add(cols)
        if progress is not None:
            progress(scanned)
        if keeper.full:
            break
    return scanned
