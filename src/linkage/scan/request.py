"""A scan from request to records: every check made once, in one order, with one message
whoever asks (the Python API, :func:`scan`, or ``linkage scan``: option names spelt as the
asker spells them), then the chunks run and streamed into a keeper, :func:`run_scan`."""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Mapping, Sequence
from contextlib import AbstractContextManager as ContextManager
from typing import Any

import numpy as np

from ..errors import InputError
from ..problems.columns import columns_of
from ..problems.loops import Mechanism
from ..records import frozen
from .designs import MAX_DESIGNS, MAX_SCAN_POSITIONS, DesignPlan, Vary, check_varies, parse_vary
from .engine import run_chunks
from .keep import Keeper, take
from .moves import JointMoves, joint_moves
from .task import ScanJob, check_held, pick_chunk


def default_branch(m: Mechanism, branch: str | None, tol: float) -> str | None:
    """The branch every design follows: the one asked for (a name or the signs of the
    derivation's two-way steps, checked here), else (with a closed form) the file's branch
    (:func:`~linkage.kinematics.pose.file_branch`), by name where it has one, else None
    (continuation from the file's guess, design by design)."""
    from ..problems.derive import Indeterminate, read_branch, sign_text

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
    from ..kinematics.pose import file_branch

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


@frozen
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
    from ..kinematics.bodies import Frame

    Frame.of(m).check_masses(loads, names)


def prepare(m: Mechanism, varies: Sequence[Vary], *, samples: int | None, seed: int, sampling: str,
            values: Sequence[float], branch: str | None, tol: float, where: str | None,
            sort: str | None, doc: Mapping[str, Any] | None = None,
            fixed: Sequence[str] = (), loads: Any = None) -> ScanSetup:
    """Everything checked before any design is solved (one InputError or ParseError).
    ``doc``: the file's document, for a joints file's coordinates (:func:`joint_moves`);
    ``fixed``: the names --set gives; ``loads``: a Loads whose columns the records carry
    (None: none)."""
    from ..kinematics.sweep import check_driver_values
    from ..problems.where import parse_where

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
    from ..kinematics.pose import POSE_MEETS, pose_meets

    note = POSE_MEETS if branch is None and pose_meets(m) else ""
    return ScanSetup(plan, spec, test, default_branch(m, branch, tol), listed, moves, loads, note)




API_NAMES: dict[str, str] = {}
"""The Python API spells every option as its keyword."""
CLI_NAMES = {"descending": "--desc", "values": "--from/--to/--step", "speed": "--speed",
             "loads": "--load/--torque"}
"""``linkage scan``'s spelling where it is not ``--`` and the keyword."""


@frozen
class ScanRequest:
    """A scan as asked, before any check: the mechanism, the varied parameters (file
    units), the driver values, and the options of :func:`scan` / ``linkage scan``.
    ``loads`` is the Loads every design carries (the file's and any given; None: none),
    ``speed`` the driver's speed and ``accel`` its acceleration (internal units; speed
    None: not given); ``doc`` the file's document where a joint's coordinate is varied;
    ``text`` and ``fixed`` the file's text and its --set values (workers parse the text;
    "" sends the mechanism pickled); ``cli`` spells the options as the command line does."""

    mechanism: Mechanism
    varies: tuple[Vary, ...]
    values: tuple[float, ...]
    samples: int | None = None
    seed: int = 0
    sampling: str = "lhs"
    branch: str | None = None
    tol: float = 1e-12
    where: str | None = None
    sort: str | None = None
    descending: bool = False
    top: int | None = None
    scheduler: str | None = None
    workers: int | None = None
    chunk: int | None = None
    loads: Any = None
    speed: float | None = None
    accel: float = 0.0
    doc: Mapping[str, Any] | None = None
    text: str = ""
    fixed: tuple[tuple[str, float], ...] = ()
    cli: bool = False

    def name(self, option: str) -> str:
        """How the asker spells ``option`` (``--sort`` on the command line, ``sort`` in Python)."""
        if self.cli:
            return CLI_NAMES.get(option, f"--{option}")
        return API_NAMES.get(option, option)


@frozen
class OpenScan:
    """A checked scan, ready to run: its setup, the task every chunk carries, designs per task."""

    request: ScanRequest
    setup: ScanSetup
    job: ScanJob
    size: int


def used_loads(loads: Any) -> Any:
    """The loads a scan's records carry: None where there are none (no force, torque, mass
    nor gravity)."""
    return loads if loads is not None and (not loads.empty or loads.gravity is not None) else None


def open_scan(req: ScanRequest) -> OpenScan:
    """Every check of a scan, in one order, before any design is solved: one InputError
    (or ParseError) naming the option as the asker spells it."""
    from ..arguments import check_scan_options
    from ..solve import check_criteria

    m, opt = req.mechanism, req.name
    check_scan_options(seed=req.seed, samples=req.samples, top=req.top, chunk=req.chunk,
                       workers=req.workers, scheduler=req.scheduler, max_designs=MAX_DESIGNS,
                       prefix="--" if req.cli else "")
    check_criteria(req.tol, 0.0, None, 50)
    if req.sampling not in ("lhs", "random"):
        raise InputError(f"{opt('sampling')} must be lhs or random, got {req.sampling!r}")
    if not req.varies:
        raise InputError(f"give at least one {opt('vary')} NAME=LO:HI[:N]")
    both = sorted({v.name for v in req.varies} & {k for k, _ in req.fixed})
    if both:
        raise InputError(f"{both[0]} is given by --set and by --vary; a scanned parameter takes its "
                         "values from --vary only")
    if not req.values:
        # a fraction of no positions is no fraction: feasible_fraction would read 0
        raise InputError(f"{opt('values')} must hold at least one driver value")
    if req.descending and req.sort is None:
        raise InputError(f"{opt('descending')} orders by {opt('sort')}: give {opt('sort')} COLUMN")
    loads = used_loads(req.loads)
    if loads is None and req.speed is not None:
        if m.extra.get("drawing") is None:
            from ..kinematics.bodies import Frame

            Frame.of(m)  # says why: loads need the joints form
        raise InputError(f"{opt('speed')} in a scan is for the loads' inertia: give loads ([loads] or "
                         f"[mass] in a joints-form file, or {opt('loads')})")
    setup = prepare(m, req.varies, samples=req.samples, seed=req.seed, sampling=req.sampling,
                    values=list(req.values), branch=req.branch, tol=req.tol, where=req.where,
                    sort=req.sort, doc=req.doc, fixed=tuple(k for k, _ in req.fixed), loads=loads)
    job = ScanJob(req.text, m.source, req.fixed, setup.plan.names, tuple(setup.values), setup.branch,
                  req.tol, None if req.text else m, setup.moves, loads, (req.speed or 0.0, req.accel))
    size = pick_chunk(m, len(setup.values), setup.branch, req.chunk, setup.plan.total, local_workers(req))
    return OpenScan(req, setup, job, size)


def local_workers(req: ScanRequest) -> int:
    """The workers a scan's chunks run on here: 1 synchronous or on a cluster (its size is
    its own), else --workers or one per core."""
    import os

    if req.scheduler == "synchronous" or (req.scheduler is not None and "://" in req.scheduler):
        return 1
    return req.workers or os.cpu_count() or 1


@frozen
class ScanOutcome:
    """What a scan did: its setup, the designs scanned, the keeper (what it counted and
    kept), the records held at the end, and its wall-clock seconds."""

    setup: ScanSetup
    scanned: int
    keeper: Keeper
    held: dict[str, np.ndarray]
    seconds: float


RecordOutput = Callable[[Mapping[str, np.ndarray]], None]
"""Where streamed records go, a chunk's columns at a time."""


def run_scan(scan_: OpenScan, *, output: ContextManager[RecordOutput] | None = None,
             holding: str = "a scan returned as columns", show: int | None = None,
             progress: Callable[[int, int], ContextManager[Callable[[int], None]]] | None = None,
             ) -> ScanOutcome:
    """Run a checked scan, its records streamed to ``output`` (entered here; a sorted scan
    hands it every kept record once, at the end) or held (``show``: at most that many, for
    a table; else every kept record, refused beforehand where more than a scan holds, the
    refusal saying ``holding``). ``progress(total, size)`` gives a callback of the designs
    scanned so far."""
    req, setup = scan_.request, scan_.setup
    if (output is None and show is None) or (output is not None and req.sort is not None):
        check_held(setup.plan.total, len(setup.spec), req.top, holding, req.name("top"))
    started = time.perf_counter()
    with contextlib.ExitStack() as stack:
        sink = stack.enter_context(output) if output is not None else None
        keeper = Keeper(req.sort, req.descending, req.top, sink if req.sort is None else None, show=show)
        advance = stack.enter_context(progress(setup.plan.total, scan_.size)) if progress else None
        scanned = feed(keeper, scan_.job, setup, scan_.size, scheduler=req.scheduler, workers=req.workers,
                       progress=advance)
        held = keeper.result()
        if sink is not None and req.sort is not None:
            sink(held)
    return ScanOutcome(setup, scanned, keeper, held, time.perf_counter() - started)


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


def scan(mechanism: Mechanism | str, vary: Mapping[str, Sequence[float]], *, samples: int | None = None,
         seed: int = 0, sampling: str = "lhs", values: Sequence[float] | None = None,
         branch: str | None = None, tol: float = 1e-12, where: str | None = None,
         sort: str | None = None, descending: bool = False, top: int | None = None,
         scheduler: str | None = None, workers: int | None = None,
         chunk: int | None = None, loads: Any = None, speed: float | None = None,
         accel: float = 0.0) -> dict[str, np.ndarray]:
    """Scan designs of ``mechanism`` (a Mechanism or a file path); the public
    ``linkage.scan_designs``.

    ``vary`` maps parameter names to ``(lo, hi, n)`` (a grid) or ``(lo, hi)`` (with
    ``samples``), in the file's units (of a joints file given by path, also a fixed
    joint's coordinate, ``"O4.x"`` or ``"O4.y"``: columns ``O4_x``, ``O4_y``); ``values``
    are the driver values (default 0..359 deg). Returns the kept records as columns (name
    -> numpy array), in design order or sorted by ``sort``: the columns ``linkage scan``
    writes, with the same ``where``, ``sort``, ``top``, ``scheduler`` and ``workers``, checked
    by the same code (:func:`open_scan`). Every argument is checked first
    (:mod:`linkage.arguments`): a misuse raises InputError naming it; n, samples, seed, top,
    chunk and workers are whole numbers (workers at most MAX_THREADS threads or
    MAX_PROCESSES processes), the driver values finite reals.

    ``loads``: a :class:`~linkage.Loads` (default: the file's ``[loads]`` and ``[mass]``, if
    any) adds the columns peak_input, max_pin_force, max_shaking_force and forces_flagged
    (:func:`~linkage.scan.task.load_metrics`), with the driver at ``speed`` and ``accel``
    (rad/s and rad/s^2, or the length unit per s and s^2) for the masses' inertia.
    """
    from ..arguments import check_flag, check_motion, check_reals, check_text, check_vary
    from ..kinematics.bodies import checked_loads
    from ..kinematics.loading import mechanism_of

    m = mechanism_of("mechanism", mechanism)
    specs = check_vary(vary, MAX_DESIGNS)
    doc = None
    if not isinstance(mechanism, Mechanism) and any("." in s[0] for s in specs):
        from pathlib import Path

        from ..files import parse_toml, read_input

        doc = parse_toml(read_input(Path(mechanism)), str(mechanism))  # a joint's coordinates
    for name, text in (("where", where), ("sort", sort), ("branch", branch)):
        check_text(name, text)
    check_text("sampling", sampling, optional=False)
    check_flag("descending", descending)
    varies = [parse_vary(f"{name}={lo!r}:{hi!r}" + (f":{n}" if n is not None else ""))
              for name, lo, hi, n in specs]
    values = check_reals("values", [float(k) for k in range(360)] if values is None else values,
                         most=MAX_SCAN_POSITIONS)
    speed, accel = check_motion(speed, accel, m.driver.kind, m.length_unit)
    own = checked_loads(loads, m) if loads is not None else m.extra.get("loads")
    req = ScanRequest(m, tuple(varies), tuple(values), samples=samples, seed=seed, sampling=sampling,
                      branch=branch, tol=tol, where=where, sort=sort, descending=descending, top=top,
                      scheduler=scheduler, workers=workers, chunk=chunk, loads=own, speed=speed,
                      accel=accel, doc=doc)
    out = run_scan(open_scan(req))
    return out.held or {c[0]: np.array([]) for c in out.setup.spec}
