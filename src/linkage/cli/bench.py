"""linkage bench."""

from pathlib import Path
from typing import Annotated, Any, Optional

import typer

from ..errors import InputError
from .options import PICTURES, FormatOpt, OutputOpt, check_paths, choose_format, emit
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
    problem: Annotated[Optional[list[str]], typer.Option(help="seed002, quadratic, fourbar, rapier "
                       "(repeatable; default: all, or seed002 and fourbar with --quick).")] = None,
    repeats: Annotated[Optional[int], typer.Option(help="Timed batches per measurement "
                       "(default 3, or 5 without --quick).")] = None,
    cold: Annotated[bool, typer.Option("--cold/--no-cold", help="Also time cold starts of the "
                    "CLI in fresh interpreters.")] = True,
    plot: Annotated[Optional[Path], typer.Option(help="Work-precision diagram: log10 error against "
                    "log10 time (.png, .svg or .pdf; needs matplotlib).")] = None,
    fmt: FormatOpt = None,
    output: OutputOpt = None,
) -> None:
    """Run time against achieved error for every method, beside scipy and a hand-written loop.

    Example: linkage bench --quick --plot wp.png
    """
    from ..bench import (
        FULL_TOLERANCES,
        MEASUREMENT_HEADERS,
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
    from ..render.report import Text, table

    out_fmt = choose_format(fmt, output)
    check_paths([], [("--output", output), ("--plot", plot)], {"--plot": (plot, PICTURES)})
    names = problem or (["seed002", "fourbar"] if quick else list(PROBLEMS))
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
    headers = MEASUREMENT_HEADERS
    rows = measurement_rows(results)
    blocks: list[Any] = [Text(f"work-precision benchmark: {len(results)} measurements, {n_repeats} timed "
                              "batches each (median; spread = fastest-slowest batch)", "bold")]
    if not has_scipy():
        blocks.append(Text("scipy is not installed: its rows are skipped "
                           "(pip install 'linkage-kinematics[bench]')"))
    if not has_pylinkage():
        blocks.append(Text("pylinkage is not installed: the sweep comparison is skipped "
                           "(pip install 'pylinkage==1.3.0')"))
    blocks += [Text(""), table("", headers, rows, 4)]
    blocks.append(table("Sweeps (median seconds)", ("sweep", "seconds"), list(sweeps.items()), 4))
    if cold_times:
        blocks.append(table("Cold start (fresh interpreter, median wall time)", ("command", "seconds"),
                            list(cold_times.items()), 4))
    blocks.append(table("Targets (ratios measured in this run)", ("target", "ratio", "measured", "met"),
                        [(t, c, r, "n/a" if r is None or r != r or ok is None else ("yes" if ok else "no"))
                         for t, c, r, ok in target_rows], 3))
    json_obj = {"measurements": [dict(zip(headers, r)) for r in rows], "cold_start": cold_times,
                "sweeps": sweeps,
                "targets": [{"target": t, "ratio": c, "measured": r, "met": ok}
                            for t, c, r, ok in target_rows],
                "scipy": has_scipy()}
    emit(out_fmt, output, blocks=blocks, json_obj=json_obj, csv_table=(headers, rows))
    if plot is not None:
        from ..render.plots import work_precision_plot

        work_precision_plot(results, plot)
        typer.echo(f"wrote {plot}", err=True)
