"""linkage stress."""

from typing import Annotated, Optional

import typer

from ..errors import InputError
from .early import refuse_csv_to_stdout
from .options import FormatOpt, OutputOpt, TableOpt, check_paths, choose_format, emit_report
from .root import app


@app.command(
    epilog="Examples:  linkage stress --quick  |  linkage stress --seed 7 --method hybrid --format json",
)
def stress(
    *,
    quick: Annotated[bool, typer.Option("--quick", help="A third of the classic cases and fewer "
                     "random mechanisms (seconds instead of minutes).")] = False,
    seed: Annotated[int, typer.Option(help="Seed for the random families (runs are "
                    "deterministic for a seed).")] = 0,
    method: Annotated[Optional[list[str]], typer.Option("--method", "-m", help="Only these "
                      "methods (repeatable).")] = None,
    fmt: FormatOpt = None,
    output: OutputOpt = None,
    table: TableOpt = None,
) -> None:
    """Try to break every method (test functions, random four-bars, bad starts, tiny tolerances).

    Runs classic test functions, random four-bars, the MGH systems, bad starts, tiny
    tolerances and non-finite values; a claimed root that is not one fails the run.

    Example: linkage stress --quick
    """
    from ..arguments import MAX_SEED, check_method, check_whole
    from ..measure.stress import SUMMARY_HEADERS, run, stress_tables, summary_rows, totals
    from ..methods import SCALAR_METHODS
    from ..solve import SYSTEM_METHODS

    known = tuple(dict.fromkeys((*SCALAR_METHODS, *SYSTEM_METHODS)))  # scalar's, then the systems' new ones
    for m in method or []:
        check_method("--method", m, known)
    check_whole("--seed", seed, 0, MAX_SEED)  # every --seed's range (arguments.check_scan_options)
    out_fmt = choose_format(fmt, output)
    check_paths([], [("--output", output)])
    methods = method or None
    refuse_csv_to_stdout(out_fmt, output, table, stress_tables(methods))
    try:
        import mpmath  # noqa: F401
    except ImportError:
        raise InputError("the stress suite needs mpmath for its references: "
                         "pip install 'linkage-kinematics[stress]'") from None
    report = run(quick=quick, seed=seed, methods=methods)
    rows = summary_rows(report)
    false, crashes = totals(rows)
    from ..render.tools import stress_report

    emit_report(stress_report(report, rows, SUMMARY_HEADERS, quick, seed, false, crashes), out_fmt, output,
                table=table)
    if false or crashes:
        raise typer.Exit(1)
