"""linkage bench."""

from pathlib import Path
from typing import Annotated, Any, Optional

import typer

from ..errors import InputError
from .early import refuse_csv_to_stdout
from .options import PICTURES, FormatOpt, OutputOpt, TableOpt, check_paths, choose_format, emit_report
from .progress import progress_bar
from .root import app

BENCH_TABLES = ("measurements", "sweeps", "cold_start", "targets", "continuation", "certified")
"""The tables of bench's report (render.tools.bench_report, then issue 34's:
measure.continuation_targets), known before it runs."""


MAX_REPEATS = 1000
"""Timed batches per measurement at most: each batch times every method on every problem, so
a thousand already runs for hours; more was accepted and ran until killed."""


@app.command(
    epilog="Examples:  linkage bench --quick  |  linkage bench --full  |  "
    "linkage bench --problem fourbar --plot wp.png  |  linkage bench --format csv -o bench.csv",
)
def bench(
    *,
    quick: Annotated[bool, typer.Option("--quick", help="Two problems, three tolerances, short "
                     "timings (about 20 seconds).")] = False,
    full: Annotated[bool, typer.Option("--full", help="Also the long targets: whole command-line "
                    "sweeps of 36,001 and 360,001 positions, a million positions in process, "
                    "nine-point Problem 3 and its 1,442 roots checked at 50 digits (minutes).")] = False,
    problem: Annotated[Optional[list[str]], typer.Option(help="freudenstein, quadratic, fourbar, rapier "
                       "(repeatable; default: all, or freudenstein and fourbar with --quick).")] = None,
    repeats: Annotated[Optional[int], typer.Option(help="Timed batches per measurement, and pairs "
                       "per target (default 3, or 5 without --quick).")] = None,
    cold: Annotated[bool, typer.Option("--cold/--no-cold", help="Also time cold starts of the "
                    "CLI in fresh interpreters.")] = True,
    plot: Annotated[Optional[Path], typer.Option(help="Work-precision diagram: log10 error against "
                    "log10 time (.png, .svg or .pdf; needs matplotlib).")] = None,
    fmt: FormatOpt = None,
    output: OutputOpt = None,
    table: TableOpt = None,
) -> None:
    """Run time against achieved error for every method, beside scipy and a hand-written loop,
    and every speed target, each a ratio of interleaved pairs timed in this run; then issue
    34's targets, seconds against their bounds, with their roots checked at 50 digits.

    Example: linkage bench --quick --plot wp.png
    """
    from ..measure.precision import PROBLEMS

    out_fmt = choose_format(fmt, output)
    check_paths([], [("--output", output), ("--plot", plot)], {"--plot": (plot, PICTURES)})
    refuse_csv_to_stdout(out_fmt, output, table, BENCH_TABLES)
    names = problem or (["freudenstein", "fourbar"] if quick else list(PROBLEMS))
    for name in names:
        if name not in PROBLEMS:
            raise InputError(f"unknown problem {name!r}; choose from {', '.join(PROBLEMS)}")
    n_repeats = repeats if repeats is not None else (3 if quick else 5)
    if not 1 <= n_repeats <= MAX_REPEATS:
        raise InputError(f"--repeats must be a whole number from 1 to {MAX_REPEATS:,}, got {n_repeats}")
    try:
        import mpmath  # noqa: F401
    except ImportError:
        raise InputError("the benchmark needs mpmath for its references: "
                         "pip install 'linkage-kinematics[bench]'") from None
    results = work_precision(names, quick, n_repeats)
    report = run_targets(results, quick=quick, full=full, cold=cold, repeats=n_repeats)
    emit_report(report, out_fmt, output, table=table)
    if plot is not None:
        from ..render.plots import work_precision_plot

        work_precision_plot(results, plot)
        typer.echo(f"wrote {plot}", err=True)


def work_precision(names: list[str], quick: bool, repeats: int) -> list[Any]:
    """The work-precision measurements, with a progress bar on a terminal."""
    from ..measure.precision import FULL_TOLERANCES, QUICK_TOLERANCES, count_measurements, measure

    tolerances = QUICK_TOLERANCES if quick else FULL_TOLERANCES
    with progress_bar(count_measurements(names, tolerances), minimum=1) as advance:
        done = [0]

        def step(_: str) -> None:
            done[0] += 1
            if advance is not None:
                advance(done[0])

        return measure(names, tolerances, repeats, 0.01 if quick else 0.015, progress=step)


def run_targets(results: list[Any], *, quick: bool, full: bool, cold: bool, repeats: int) -> Any:
    """Issue 33's rows, the earlier targets, the sweeps and the cold starts, then issue 34's
    rows, as the report."""
    from ..measure import continuation_targets as continuation
    from ..measure.precision import has_pylinkage, has_scipy, measurement_rows
    from ..measure.processes import cold_start
    from ..measure.sweeps import SCAN_DESIGNS, sweep_times, targets
    from ..measure.targets import ROWS, run_rows
    from ..render.tools import bench_report

    with progress_bar(len(ROWS) + len(continuation.ROWS), minimum=1, label="targets") as advance:
        done = [0]

        def step(_: str) -> None:
            done[0] += 1
            if advance is not None:
                advance(done[0])

        outcomes = run_rows(full, repeats, 0.005, cold=cold, progress=step)
        found = continuation.run_rows(full, repeats, progress=step)
    sweeps = sweep_times(repeats, SCAN_DESIGNS // 10 if quick else SCAN_DESIGNS)
    cold_times = cold_start(3 if quick else 5) if cold else {}
    target_rows = [o.target for o in outcomes] + targets(sweeps)
    notes = []
    if not has_scipy():
        notes.append("scipy is not installed: its rows are skipped (pip install 'linkage-kinematics[bench]')")
    if not has_pylinkage():
        notes.append("pylinkage is not installed: the sweep comparison is skipped "
                     "(pip install 'pylinkage==1.3.0')")
    if not full:
        notes.append("the long targets are measured with --full")
    report = bench_report(measurement_rows(results), sweeps, cold_times, target_rows, repeats, notes,
                          has_scipy())
    return continuation.with_continuation(report, found)
