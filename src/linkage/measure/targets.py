"""The speed targets (docs/performance.md; issue 33's table, row for row), each a ratio of
two timings taken in this run as interleaved pairs (:func:`.timing.interleaved_pairs`): the
library through its public API or its command line against the same work written by hand
(:mod:`.hand`).

Rows whose runs take seconds (whole command-line processes, a million positions) are
``long``: measured with ``linkage bench --full``, listed as not measured otherwise.
"""

from __future__ import annotations

import os
import statistics
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from ..records import frozen
from .processes import FLOOR, ProcessFailed, cold_commands, linkage_command, python_command, runner
from .timing import Pairs, interleaved_pairs

Target = tuple[str, str, "float | None", "bool | None"]
"""(target, comparison, measured ratio, met): None where this run could not judge it."""


@frozen
class Row:
    """One target: ``name`` as issue 33's table names the measure, met when the ratio is at
    most ``bound`` (at least, where ``at_least``); ``part`` tells two targets of one
    measure apart (the cold starts of solve and sweep)."""

    name: str
    comparison: str
    bound: float
    at_least: bool = False
    long: bool = False
    cold: bool = False
    """A cold start: not measured with ``--no-cold``."""
    part: str = ""

    @property
    def label(self) -> str:
        part = f" ({self.part})" if self.part else ""
        return f"{self.name}{part}: {'>=' if self.at_least else '<='} {self.bound:g}x"

    def met(self, ratio: float) -> bool:
        return ratio >= self.bound if self.at_least else ratio <= self.bound


ROWS = (
    Row("scalar Newton, history off / hand loop", "linkage / hand", 2.0),
    Row("scalar Newton, history on / hand loop", "linkage / hand", 3.0),
    Row("system Newton off / hand 2x2", "linkage / hand", 2.0),
    Row("scipy hybr / ours", "scipy / linkage", 3.0, at_least=True),
    Row("361-position linkage.sweep / numpy closed form", "linkage / numpy", 3.0),
    Row("10^6 positions / the same numpy closed form, written tight", "linkage / numpy", 1.5, long=True),
    Row("360,001 positions to CSV, CLI / API process", "cli / api", 2.0, long=True),
    Row("the same to parquet", "cli / api", 1.5, long=True),
    Row("36,001 positions to CSV with --speed 10 / without (rates, joint velocities)",
        "with / without", 2.0, long=True),
    Row("loaded scan / a hand-written numpy 9x9 batched solve", "linkage / hand", 1.5, long=True),
    Row("synthesize --search / hand numpy, one thread", "cli / hand", 1.2, long=True),
    Row("cold start solve, sweep / import rich.table", "linkage / import", 1.5, cold=True, part="solve"),
    Row("cold start solve, sweep / import rich.table", "linkage / import", 1.8, cold=True, part="sweep"),
)
"""In the order of issue 33's table."""

EARLIER = (
    Row("issue 10: scalar Newton at least 10x faster than scipy root_scalar newton", "scipy / linkage", 10.0,
        at_least=True),
)
"""The earlier targets measured the same way (the sweeps' and the scan's: :mod:`.sweeps`)."""


@frozen
class Settings:
    """How hard to measure: ``repeats`` pairs, in-process batches of about ``budget`` s."""

    repeats: int
    budget: float
    work: Path
    """A scratch directory for the files the commands write."""


class Skipped(Exception):
    """This run cannot measure the row (an optional package is missing); the reason."""


@frozen
class Measured:
    """Pairs, and what else the row's target asks (cores used): ``detail`` says it,
    ``also_met`` judges it."""

    pairs: Pairs
    detail: str = ""
    also_met: bool = True


Measure = Callable[[Settings], "Pairs | Measured"]


def short_pairs(s: Settings) -> int:
    """Pairs of a row whose calls take microseconds to a fraction of a second (the cold
    starts): three times the repeats, at least 9 (cheap, and a shared machine's
    preemptions then hit a few pairs only)."""
    return max(9, 3 * s.repeats)


def tolerance() -> float:
    """The tolerance the solver rows are compared at (issue 10's targets: 1e-12)."""
    return 1e-12


def scalar_newton(record: bool) -> Measure:
    def measure(s: Settings) -> Pairs:
        from . import api
        from .hand import hand_newton
        from .precision import scalar_problem

        spec = scalar_problem("freudenstein")
        p, x0, tol = spec["problem"], spec["x0"], tolerance()
        return interleaved_pairs(
            lambda: api.solve_scalar(p, method="newton", x0=x0, tol=tol, record=record),
            lambda: hand_newton(p.f, p.fprime, x0, tol), short_pairs(s), s.budget)

    return measure


def scipy_newton(s: Settings) -> Pairs:
    try:
        from scipy.optimize import root_scalar
    except ImportError:
        raise Skipped("scipy is not installed") from None
    from . import api
    from .precision import scalar_problem

    spec = scalar_problem("freudenstein")
    p, x0, tol = spec["problem"], spec["x0"], tolerance()
    return interleaved_pairs(
        lambda: root_scalar(p.f, method="newton", x0=x0, fprime=p.fprime, xtol=tol),
        lambda: api.solve_scalar(p, method="newton", x0=x0, tol=tol, record=False), short_pairs(s), s.budget)


def fourbar_system() -> tuple[Any, tuple[float, ...]]:
    from .precision import system_problem

    spec = system_problem("fourbar")
    return spec["problem"], tuple(float(v) for v in spec["x0"])


def system_newton(s: Settings) -> Pairs:
    """User callables F and J, as the hand loop gets them."""
    from . import api
    from .hand import hand_newton_2x2

    p, x0 = fourbar_system()
    tol = tolerance()
    return interleaved_pairs(
        lambda: api.solve_system(p.F, x0, jac=p.J, tol=tol, max_iter=100, record=False),
        lambda: hand_newton_2x2(p.F, p.J, x0, tol), short_pairs(s), s.budget)


def scipy_hybr(s: Settings) -> Pairs:
    try:
        from scipy.optimize import root
    except ImportError:
        raise Skipped("scipy is not installed") from None
    from . import api
    p, x0 = fourbar_system()
    tol = tolerance()
    return interleaved_pairs(
        lambda: root(p.F, x0, jac=p.J, method="hybr", options={"xtol": tol}),
        lambda: api.solve_system(p.F, x0, jac=p.J, tol=tol, max_iter=100, record=False),
        short_pairs(s), s.budget)


def crank_rocker() -> tuple[Any, tuple[float, float, float, float]]:
    """crank_rocker.toml (the public API's Mechanism) and its links r1..r4."""
    from ..samples import sample_path
    from . import api

    m = api.load_mechanism(sample_path("crank_rocker.toml"))
    v = {k: q.value for k, q in m.parameters.items()}
    return m, (v["r1"], v["r2"], v["r3"], v["r4"])


def sweep_against_closed_form(positions: int) -> Measure:
    """``linkage.sweep`` of crank_rocker.toml over 0..360 deg (the engine it picks) against
    :func:`.hand.fourbar_open` on the same crank angles. The short row also times the floor
    (:func:`.hand.fourbar_open_certified`: the closed form with the evidence the single
    solve's promise needs, by hand) against the same closed form, and says it: the least
    the row's ratio can be."""

    def measure(s: Settings) -> Pairs | Measured:
        import numpy as np

        from ..kinematics.closed import MARGIN_FLOOR
        from ..rules import residual_gate
        from ..units import radians
        from . import api
        from .hand import fourbar_open, fourbar_open_certified

        m, links = crank_rocker()
        grid = np.linspace(0.0, 360.0, positions)
        values = grid if positions > 1_000 else [float(v) for v in grid]
        short = positions <= 1_000
        pairs = interleaved_pairs(lambda: api.sweep(m, values), lambda: fourbar_open(radians(grid), *links),
                                  short_pairs(s) if short else s.repeats, s.budget if short else 0.0)
        if not short:
            return pairs
        tol = tolerance()
        gate = residual_gate(tol, m.length_scale)
        floor = interleaved_pairs(
            lambda: fourbar_open_certified(values, *links, tol, gate, MARGIN_FLOOR),
            lambda: fourbar_open(radians(grid), *links), short_pairs(s), s.budget)
        return Measured(pairs, f"the floor (closed form and its evidence by hand) {floor.ratio:.2f}x; "
                               f"linkage / floor {pairs.ratio / floor.ratio:.2f}x")

    return measure


SWEEP_FILE_POSITIONS = 360_001
"""Issue 20's output rows: crank_rocker.toml over 0..360 step 0.001."""


def sweep_to_file(suffix: str) -> Measure:
    """``linkage sweep crank_rocker.toml --step 0.001 --to 360 -o FILE`` against a process
    that runs ``linkage.sweep`` of the same positions through the API (and writes nothing).
    Also times the floor against the same API process, and says it: that process, then the
    file's varying columns computed and written by hand through pyarrow
    (:func:`.hand.write_sweep_file`): the row's ratio as plain code with the writers the
    package has would make it."""

    def measure(s: Settings) -> Measured:
        if suffix == "parquet":
            try:
                import pyarrow.parquet  # noqa: F401
            except ImportError:
                raise Skipped("pyarrow is not installed") from None
        from ..samples import sample_path

        path = str(sample_path("crank_rocker.toml"))
        cli = runner(linkage_command("sweep", path, "--step", "0.001", "--to", "360",
                                     "-o", str(s.work / f"sweep.{suffix}")))
        sweep = (f"import linkage; v = [k * 0.001 for k in range({SWEEP_FILE_POSITIONS})]; "
                 f"r = linkage.sweep(linkage.load_mechanism({path!r}), v)")
        api = runner(python_command(sweep))
        pairs = interleaved_pairs(cli, api, s.repeats)
        _, links = crank_rocker()
        by_hand = runner(python_command(
            f"{sweep}; import numpy as np; from linkage.measure.hand import write_sweep_file; "
            f"write_sweep_file(np.asarray(v), r.column('theta3'), r.column('theta4'), {links!r}, "
            f"{str(s.work / f'floor.{suffix}')!r}, {suffix!r})"))
        floor = interleaved_pairs(by_hand, api, s.repeats)
        return Measured(pairs, f"by hand (the API process, then the file's varying columns through "
                               f"pyarrow) {floor.ratio:.2f}x")

    return measure


def sweep_with_speed(s: Settings) -> Pairs:
    """36,001 positions of crank_rocker.toml to CSV, with --speed 10 (rates and joint
    velocities) and without."""
    from ..samples import sample_path

    path = str(sample_path("crank_rocker.toml"))

    def command(*extra: str) -> Callable[[], None]:
        return runner(linkage_command("sweep", path, "--step", "0.01", "--to", "360", *extra,
                                      "-o", str(s.work / f"speed{len(extra)}.csv")))

    return interleaved_pairs(command("--speed", "10"), command(), s.repeats)


LOADED_DESIGNS = 200
"""Designs of the loaded scan row (O4 moved along x), each over 0..359 deg."""


def loaded_scan(s: Settings) -> Pairs:
    """``linkage.scan_designs`` of crank_rocker_joints.toml with O4.x sampled in 90..110 mm,
    a 20 N weight at the coupler point P and a -2 N m torque on the rocker (static loads),
    with its default scheduler, against :func:`.hand.loaded_scan` of the same designs."""
    import numpy as np
    import tomllib

    from ..samples import sample_path
    from . import api
    from .hand import DrawnFourbar
    from .hand import loaded_scan as by_hand

    path = sample_path("crank_rocker_joints.toml")
    joints = tomllib.loads(path.read_text())["joints"]
    drawn = DrawnFourbar(tuple(joints["A"]), tuple(joints["B"]), joints["O4"][0], tuple(joints["P"]))
    weight, torque = (0.0, -20.0), -2.0
    loads = api.Loads(forces={"P": weight}, torques={"rocker": torque})
    vary = {"O4.x": (90.0, 110.0)}
    o4x = api.scan_designs(str(path), vary, samples=LOADED_DESIGNS, loads=loads)["O4_x"]
    positions = np.arange(360.0)
    return interleaved_pairs(lambda: api.scan_designs(str(path), vary, samples=LOADED_DESIGNS, loads=loads),
                             lambda: by_hand(drawn, o4x, weight, torque, positions), s.repeats)


SEARCH = ("alpha0=0:350:18", "alpha_span=40:120:4", "phi0=0:350:18", "phi_span=60:120:4")
"""The search row's grid (5,184 candidates) for y = log10(x), x 1..2, 3 Chebyshev points."""
EVERY_CORE = 0.75
"""Cores used (processor time over wall time) of at least this share of the cores this
process may run on count as every core (the machine is shared)."""


def function_search(s: Settings) -> Measured:
    """``linkage synthesize --search`` of :data:`SEARCH` (transmission >= 40 deg, every
    candidate kept, to CSV) against :func:`.hand.function_search` of the same candidates in
    a process of its own, one thread; and the processor time over the wall time of the
    command (the cores it used)."""
    varies = [a for v in SEARCH for a in ("--vary", v)]
    cpu: list[float] = []
    cli = runner(linkage_command("synthesize", "--search", "--function", "log10(x)", "--x", "1:2", *varies,
                                 "--min-transmission", "40", "--top", "100000",
                                 "-o", str(s.work / "search.csv")), cpu)
    grids = ", ".join(f"np.linspace({v.split('=')[1].replace(':', ', ')})" for v in SEARCH)
    hand = runner(python_command(
        "import math, numpy as np; from linkage.measure.hand import function_search; "
        "xs = [1.5 - 0.5 * math.cos((2 * j - 1) * math.pi / 6) for j in (1, 2, 3)]; "
        "gx = np.linspace(1.0, 2.0, 2001); "
        f"c = np.stack([g.ravel() for g in np.meshgrid({grids}, indexing='ij')], axis=1); "
        "function_search(xs, [math.log10(x) for x in xs], gx, np.log10(gx), c, 40.0)"))
    pairs = interleaved_pairs(cli, hand, s.repeats)
    used = statistics.median(c / w for c, w in zip(cpu[1:], pairs.a))
    return Measured(pairs, f"{used:.2f} of {cores()} cores", used >= EVERY_CORE * cores())


def cold_start(which: str) -> Measure:
    """A fresh ``linkage solve`` (its default problem) or ``linkage sweep crank_rocker.toml``
    against ``python -c "import rich.table"``."""

    def measure(s: Settings) -> Pairs:
        commands = cold_commands()
        key = "linkage solve" if which == "solve" else "linkage sweep crank_rocker.toml"
        return interleaved_pairs(runner(commands[key]), runner(commands[FLOOR]), short_pairs(s))

    return measure


MEASURES: dict[Row, Measure] = dict(zip(ROWS + EARLIER, (
    scalar_newton(False), scalar_newton(True), system_newton, scipy_hybr,
    sweep_against_closed_form(361), sweep_against_closed_form(1_000_000),
    sweep_to_file("csv"), sweep_to_file("parquet"), sweep_with_speed,
    loaded_scan, function_search,
    cold_start("solve"), cold_start("sweep"), scipy_newton,
)))
"""How each row (issue 33's, then the earlier ones) is measured."""


@frozen
class Outcome:
    row: Row
    pairs: Pairs | None
    note: str = ""
    """Why there are no pairs: skipped (and why), or not measured (long, without --full);
    with pairs, what else was measured (cores used)."""
    also_met: bool = True

    @property
    def target(self) -> Target:
        if self.pairs is None:
            return (self.row.label, f"{self.row.comparison}: {self.note}", None, None)
        r = self.pairs.ratio
        a, b = self.pairs.a_median, self.pairs.b_median
        shown = f"{self.row.comparison}: {seconds(a)} / {seconds(b)}, {len(self.pairs.a)} pairs"
        return (self.row.label, shown + (f"; {self.note}" if self.note else ""), r,
                self.row.met(r) and self.also_met)


def seconds(t: float) -> str:
    """A median as a person reads it: us, ms or s, three figures."""
    if t < 1e-3:
        return f"{t * 1e6:.3g} us"
    if t < 1.0:
        return f"{t * 1e3:.3g} ms"
    return f"{t:.3g} s"


@contextmanager
def settings(repeats: int, budget: float) -> Iterator[Settings]:
    with tempfile.TemporaryDirectory(prefix="linkage-bench-") as tmp:
        yield Settings(repeats, budget, Path(tmp))


def run_rows(full: bool, repeats: int, budget: float, *, cold: bool = True,
             progress: Callable[[str], None] | None = None,
             measures: dict[Row, Measure] | None = None) -> list[Outcome]:
    """Every row of :data:`ROWS` and :data:`EARLIER`, measured (the long ones only when
    ``full``, the cold starts only when ``cold``)."""
    out = []
    with settings(repeats, budget) as s:
        for row, measure in (measures or MEASURES).items():
            if progress:
                progress(row.label)
            if row.long and not full:
                out.append(Outcome(row, None, "not measured (long: linkage bench --full)"))
                continue
            if row.cold and not cold:
                out.append(Outcome(row, None, "not measured (--no-cold)"))
                continue
            try:
                got = measure(s)
                out.append(Outcome(row, got.pairs, got.detail, got.also_met) if isinstance(got, Measured)
                           else Outcome(row, got))
            except Skipped as why:
                out.append(Outcome(row, None, f"skipped: {why}"))
            except ProcessFailed as failed:
                out.append(Outcome(row, None, f"failed: {failed}"))
    return out


def cores() -> int:
    """The cores this process may run on."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
