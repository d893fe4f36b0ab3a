"""linkage tolerance."""

from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import InputError
from .options import (
    PICTURES,
    ColumnsOpt,
    DigitsOpt,
    FormatOpt,
    MechanismFile,
    OutputOpt,
    SetOpt,
    TableOpt,
    check_paths,
    choose_format,
    emit_report,
    note_closed_form,
    parse_assignments,
)
from .progress import progress_bar
from .root import app


@app.command(
    epilog="Examples:  linkage tolerance sample_inputs/crank_rocker.toml --tol r2=±0.05 --tol r3=±0.05 "
    "--step 30  |  linkage tolerance sample_inputs/crank_rocker_joints.toml --tol coupler=0.1 "
    "--tol O4.x=0.1 --samples 10000 --plot bands.png",
)
def tolerance(
    file: MechanismFile,
    *,
    tols: Annotated[Optional[list[str]], typer.Option(
        "--tol", metavar="NAME=±D", help="A tolerance ±D on a length, in the file's units (repeatable; "
        "NAME=D means the same): a parameter of a loops file, a derived length of a joints file "
        "(as linkage convert names it), or a fixed joint's coordinate such as O4.x.")] = None,
    samples: Annotated[int, typer.Option(help="Monte Carlo designs.")] = 1000,
    seed: Annotated[int, typer.Option(help="The Monte Carlo's random seed (same seed, same "
                    "samples).")] = 0,
    distribution: Annotated[str, typer.Option(help="How each ±D is drawn: normal (sigma D/3: ±D is "
                            "3 sigma) or uniform (within ±D).")] = "normal",
    start: Annotated[Optional[float], typer.Option("--from", help="First driver value (default 0, or "
                     "the file's driver range).")] = None,
    stop: Annotated[Optional[float], typer.Option("--to", help="Last driver value (default 359, or "
                    "the file's driver range).")] = None,
    step: Annotated[float, typer.Option(help="Driver increment (default 1).", show_default=False)] = 1.0,
    branch: Annotated[Optional[str], typer.Option(help="The assembly every design follows (open, "
                      "crossed, ...); default: the file's guess's.")] = None,
    set_: SetOpt = None,
    tol: Annotated[float, typer.Option("--solve-tol", help="Step and residual tolerance per "
                   "position.")] = 1e-12,
    scheduler: Annotated[Optional[str], typer.Option(help="Where the Monte Carlo's chunks run, as "
                         "linkage scan: threads (default), processes, synchronous, or "
                         "tcp://HOST:PORT.")] = None,
    workers: Annotated[Optional[int], typer.Option(help="Local workers (default: one per "
                       "core).")] = None,
    plot: Annotated[Optional[Path], typer.Option(help="Draw one output's nominal curve with its "
                    "worst-case, RSS and Monte Carlo bands (.png, .svg or .pdf; needs matplotlib).")] = None,
    plot_output: Annotated[Optional[str], typer.Option("--plot-output", metavar="NAME", help="With "
                           "--plot: the output drawn (an unknown, or P.x / P.y of a point; default the "
                           "last unknown).")] = None,
    fmt: FormatOpt = None,
    output: OutputOpt = None,
    digits: DigitsOpt = 6,
    table: TableOpt = None,
    columns: ColumnsOpt = None,
) -> None:
    """How manufacturing tolerances spread a mechanism's outputs over its cycle.

    Linear: the sensitivity of every unknown and named point to each toleranced length,
    dq/dp = -J^-1 dPhi/dp, at every driver value; the worst case (sum |dq/dp D|), the RSS
    (sqrt(sum (dq/dp D)^2), the 3-sigma band with ±D read as 3 sigma) and each tolerance's
    contribution. Each position's band is checked against the exact solutions at ±D: status
    near_limit where a limit or toggle is within reach (the band is not to be trusted
    there). Monte Carlo: --samples designs run as a scan (on dask: --workers,
    --scheduler), their 0.135, 50 and 99.865 percentiles and sigma at every driver value,
    and the share that cannot be assembled. See docs/tolerance.md.

    Example: linkage tolerance sample_inputs/crank_rocker.toml --tol r2=0.05 --tol r4=0.05 --step 30
    """
    from collections import Counter

    from ..arguments import check_scan_options, driver_span
    from ..files import parse_toml, read_input
    from ..kinematics.loading import from_text
    from ..kinematics.positions import check_assembles_somewhere, span_text
    from ..kinematics.sweep import driver_values
    from ..render.tolerance import tolerance_report
    from ..scan.tolerance import MAX_SAMPLES, outputs_of, parse_tolerance, prepare, study
    from ..solve import check_criteria

    if output is not None and str(output) == "-":
        output = None
    out_fmt = choose_format(fmt, output)
    check_paths([file], [("--output", output), ("--plot", plot)], {"--plot": (plot, PICTURES)})
    check_criteria(tol, 0.0, None, 50)
    check_scan_options(seed=seed, samples=samples, workers=workers, scheduler=scheduler,
                       max_designs=MAX_SAMPLES, prefix="--")
    if plot_output is not None and plot is None:
        raise InputError("--plot-output names the output --plot draws: give --plot FILE.png as well")
    tolerances = [parse_tolerance(t) for t in tols or []]
    text = read_input(file)
    fixed = parse_assignments("--set", set_ or [])
    mechanism = from_text(text, str(file)).with_values(fixed, {})
    note_closed_form(mechanism)
    a, b = driver_span(mechanism, start, stop, turn_end=359.0)
    values = driver_values(a, b, step, None)
    doc = parse_toml(text, str(file)) if any("." in t.name for t in tolerances) else None
    names = [o.name for o in outputs_of(mechanism)]
    if plot_output is not None and plot_output not in names:
        raise InputError(f"--plot-output {plot_output}: no such output; the outputs are {', '.join(names)}")
    plan, job = prepare(mechanism, tolerances, values, branch=branch, tol=tol, doc=doc, text=text,
                        overrides=tuple((k, float(v)) for k, v in fixed.items()), samples=samples,
                        distribution=distribution)
    with progress_bar(samples, minimum=2000) as advance:
        result = study(mechanism, plan, values, branch=job.branch, tol=tol, samples=samples, seed=seed,
                       distribution=distribution, job=job, scheduler=scheduler, workers=workers,
                       progress=advance)
    # the one rule of a linkage that assembles at no position of the range (the nominal's)
    driver = mechanism.driver
    check_assembles_somewhere(Counter("no_solution" if s == "not_assembled" else s for s in result.status),
                              str(file), lambda: span_text(driver.name, a, b, driver.unit))
    emit_report(tolerance_report(result, digits), out_fmt, output, columns=columns, table=table)
    if plot is not None:
        from ..render.tolerance import tolerance_plot

        tolerance_plot(result, plot_output, plot)
        typer.echo(f"wrote {plot}", err=True)
