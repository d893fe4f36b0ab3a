"""linkage bench."""

from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import InputError
from .options import PICTURES, FormatOpt, OutputOpt, TableOpt, check_paths, choose_format, emit_report
from .progress import progress_bar
from .root import app


@app.command(
    epilog="Examples:  linkage bench --quick  |  linkage bench --problem fourbar --plot wp.png  |  "
    "linkage bench --format csv -o bench.csv",
)
def bench(
    *,
    quick: Annotated[bool, typer.Option("--quick", help="Two problems, three tolerances, short "
                     "timings (about 10 seconds).")] = False,
    problem: Annotated[Optional[list[str]], typer.Option(help="freudenstein, quadratic, fourbar, rapier "
                       "(repeatable; default: all, or freudenstein and fourbar with --quick).")] = None,
    repeats: Annotated[Optional[int], typer.Option(help="Timed batches per measurement "
                       "(default 3, or 5 without --quick).")] = None,
    cold: Annotated[bool, typer.Option("--cold/--no-cold", help="Also time cold starts of the "
                    "CLI in fresh interpreters.")] = True,
    plot: Annotated[Optional[Path], typer.Option(help="Work-precision diagram: log10 error against "
                    "log10 time (.png, .svg or .pdf; needs matplotlib).")] = None,
    fmt: FormatOpt = None,
    output: OutputOpt = None,
    table: TableOpt = None,
) -> None:
    """Run time against achieved error for every method, beside scipy and a hand-written loop.

    Example: linkage bench --quick --plot wp.png
    """
    from ..bench import (
        FULL_TOLERANCES,
        PROBLEMS,
        QUICK_TOLERANCES,
        cold_start,
        has_pylinkage,
        has_scipy,
        measure,
        measurement_rows,
        sweep_times,
        targets,
    )

    out_fmt = choose_format(fmt, output)
    check_paths([], [("--output", output), ("--plot", plot)], {"--plot": (plot, PICTURES)})
    names = problem or (["freudenstein", "fourbar"] if quick else list(PROBLEMS))
    for name in names:
        if name not in PROBLEMS:
            raise InputError(f"unknown problem {name!r}; choose from {', '.join(PROBLEMS)}")
    n_repeats = repeats if repeats is not None else (3 if quick else 5)
    if n_repeats < 1:
        raise InputError(f"--repeats must be >= 1, got {n_repeats}")
    try:
        import mpmath  # noqa: F401
    except ImportError:
        raise InputError("the benchmark needs mpmath for its references: "
                         "pip install 'linkage-kinematics[bench]'") from None
    tolerances = QUICK_TOLERANCES if quick else FULL_TOLERANCES
    budget = 0.01 if quick else 0.015
    from ..bench import count_measurements

    with progress_bar(count_measurements(names, tolerances), minimum=1) as advance:
        done = [0]

        def step(_: str) -> None:
            done[0] += 1
            if advance is not None:
                advance(done[0])

        results = measure(names, tolerances, n_repeats, budget, progress=step)
    cold_times = cold_start(3 if quick else 5) if cold else {}
    sweeps = sweep_times(n_repeats, 100_000 if quick else 1_000_000)
    target_rows = targets(results, cold_times, sweeps)
    if cold:  # the CLI in fresh processes, as the cold start
        from ..bench import sweep_output_targets

        target_rows += sweep_output_targets(2 if quick else 3)
    from ..render.tools import bench_report

    notes = []
    if not has_scipy():
        notes.append("scipy is not installed: its rows are skipped (pip install 'linkage-kinematics[bench]')")
    if not has_pylinkage():
        notes.append("pylinkage is not installed: the sweep comparison is skipped "
                     "(pip install 'pylinkage==1.3.0')")
    emit_report(bench_report(measurement_rows(results), sweeps, cold_times, target_rows, n_repeats, notes,
                             has_scipy()), out_fmt, output, table=table)
    if plot is not None:
        from ..render.plots import work_precision_plot

        work_precision_plot(results, plot)
        typer.echo(f"wrote {plot}", err=True)
