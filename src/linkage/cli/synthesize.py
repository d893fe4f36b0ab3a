"""linkage synthesize."""

from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import InputError
from .options import PICTURES, DigitsOpt, ForceOpt, TableOpt, check_paths, mechanism_output
from .root import app


@app.command(
    epilog="Examples:  linkage synthesize --function 'log10(x)' --x 1:2 --alpha 90:150 --phi 0:90  |  "
    "linkage synthesize --function 'x**2' --x 0:1 --alpha 160:214 --phi 260:322 --spacing optimal "
    "--ground 100 -o design.toml --plot error.png",
)
def synthesize(
    *,
    function: Annotated[Optional[str], typer.Option(
        "--function", metavar="EXPR", show_default=False, help="The function y = f(x) to generate, in x (the "
        "--equation parser: + - * / **, sin, cos, exp, log, log10, sqrt, pi, ...).")] = None,
    x: Annotated[
        Optional[str], typer.Option("--x", metavar="LO:HI", help="The range of x.", show_default=False)
    ] = None,
    alpha: Annotated[
        Optional[str],
        typer.Option(
            "--alpha",
            metavar="A0:A1",
            help="The input angle range (deg, "
            "at O2 from the line O4 -> O2, as in the README's angle conventions): x = LO -> A0, HI -> A1.",
            show_default=False,
        ),
    ] = None,
    phi: Annotated[
        Optional[str],
        typer.Option(
            "--phi",
            metavar="P0:P1",
            help="The output angle range (deg, at O4 from the line O4 -> O2): y = f(LO) -> P0, f(HI) -> P1.",
            show_default=False,
        ),
    ] = None,
    points: Annotated[
        int, typer.Option(help="Precision points: 3 solve R1, R2, R3 exactly, more by least squares.")
    ] = 3,
    spacing: Annotated[
        str, typer.Option(help="chebyshev, uniform (ends included) or optimal (equal ripple, 3 points).")
    ] = "chebyshev",
    at: Annotated[
        Optional[str],
        typer.Option("--at", metavar="X1,X2,...", help="The precision points' x, instead of --spacing."),
    ] = None,
    ground: Annotated[float, typer.Option(help="The ground link's length, in --unit.")] = 1.0,
    unit: Annotated[str, typer.Option(help="The length unit of the links and of -o FILE.toml.")] = "mm",
    min_transmission: Annotated[
        float,
        typer.Option(
            "--min-transmission",
            metavar="DEG",
            help="A transmission angle (folded into 0..90) below this anywhere in the range is a defect.",
        ),
    ] = 30.0,
    rows: Annotated[
        int,
        typer.Option(
            metavar="N",
            help="Rows of the structural-error table (even "
            "steps of x; the extrema are located on a dense grid regardless).",
        ),
    ] = 21,
    search: Annotated[
        bool,
        typer.Option(
            "--search",
            help="Synthesise every candidate of --vary's grid (or --samples random ones) over "
            "alpha0, alpha_span, phi0, phi_span and list those without defects, smallest max "
            "structural error first; with --path, rank the defect-free four-bars of --samples sets.",
        ),
    ] = False,
    vary: Annotated[
        Optional[list[str]],
        typer.Option(
            "--vary",
            metavar="NAME=LO:HI[:N]",
            help="With --search: alpha0, alpha_span, phi0 or phi_span (deg), N points or with "
            "--samples a random range (repeatable).",
        ),
    ] = None,
    samples: Annotated[
        Optional[int], typer.Option(help="With --search: this many random candidates instead of a grid "
                                    "(with --path: sets of extra points, each a nine-point solve).")
    ] = None,
    sampling: Annotated[str, typer.Option(help="With --samples: lhs (default) or random.")] = "lhs",
    seed: Annotated[int, typer.Option(help="With --samples: the random seed.")] = 0,
    top: Annotated[int, typer.Option(metavar="K", help="With --search: keep the best K.")] = 10,
    scheduler: Annotated[
        Optional[str],
        typer.Option(
            help="With --search: threads (default), processes, synchronous or tcp://HOST:PORT "
            "(a dask.distributed scheduler), as linkage scan."
        ),
    ] = None,
    workers: Annotated[Optional[int], typer.Option(help="With --search: local workers.")] = None,
    fmt: Annotated[
        Optional[str],
        typer.Option(
            "--format",
            "-f",
            help="table (default on a terminal), plain, csv, json, xlsx or a tabulate format.",
        ),
    ] = None,
    output: Annotated[
        Optional[Path],
        typer.Option(
            "--output",
            "-o",
            help="FILE.toml: the linkage as a mechanism file (joints form, its driver range the alpha "
            "range), the report still printed, written only for a design without defects (or --design "
            "K's, its defects said) and kept if it exists unless --force; any other suffix: the report "
            "in that format.",
        ),
    ] = None,
    force: ForceOpt = False,
    plot: Annotated[
        Optional[Path],
        typer.Option(
            help="Draw the structural error against x, the precision points marked (.png, .svg, .pdf); "
            "with --motion and 4 poses, the centre-point and circle-point curves."
        ),
    ] = None,
    motion: Annotated[
        bool,
        typer.Option("--motion", help="Motion generation: four-bars that carry a body through 5 poses "
                     "(Burmester) or 3 (with --circle twice), each swept through them and judged; "
                     "4 poses: the centre-point and circle-point curves (docs/motion_synthesis.md)."),
    ] = False,
    pose: Annotated[
        Optional[list[str]],
        typer.Option("--pose", metavar="X,Y,DEG",
                     help="With --motion: a pose of the body (3, 4 or 5 of them)."),
    ] = None,
    poses: Annotated[
        Optional[Path],
        typer.Option("--poses", metavar="FILE", help="With --motion: the poses, one X,Y,DEG a line."),
    ] = None,
    circle: Annotated[
        Optional[list[str]],
        typer.Option("--circle", metavar="X,Y", help="With --motion and 3 poses: a moving pivot at "
                     "pose 1 (twice: three poses leave both free)."),
    ] = None,
    path: Annotated[bool, typer.Option("--path", help="Path generation: every four-bar whose coupler point "
                                       "passes through 5 to 9 --point X,Y, or 5 --point X,Y,DEG with the "
                                       "crank at DEG (docs/path_synthesis.md); with --search, the "
                                       "defect-free ones ranked.")] = False,
    point: Annotated[Optional[list[str]], typer.Option("--point", metavar="X,Y[,DEG]", help="With --path: "
                     "a point of the coupler curve, with DEG the crank's angle there (repeatable).")] = None,
    via: Annotated[Optional[list[str]], typer.Option(
        "--via", metavar="X,Y", help="With --path and n < 9 points: the 9 - n extra points (default: on a "
        "curve through the points; --search --samples K draws K sets).")] = None,
    design_number: Annotated[
        Optional[int],
        typer.Option("--design", metavar="K", help="With --motion and -o FILE.toml: write design K "
                     "(default: the defect-free one with the largest least transmission angle)."),
    ] = None,
    digits: DigitsOpt = 6,
    table: TableOpt = None,
) -> None:
    """Synthesise a four-bar function generator by Freudenstein's equation (run backwards) at precision
    points, then analyse it over the whole range; --motion and --path: motion and path generation.

    Prints the precision points, R1, R2, R3 and the link lengths, the structural error
    (phi generated by the four-bar equation's solver, followed from the first precision point, minus phi
    desired) with its maximum, and the transmission angle. A defect (branch, grashof, order,
    transmission, no_linkage) is printed and the exit code is 1.
    """
    from ..problems.loops import LENGTH_UNITS
    from ..render import writers
    from ..render.synthesis import error_plot, synthesis_report
    from ..synthesis import synthesize as run
    from ..synthesis.request import make_request

    design = output is not None and output.suffix.lower() == ".toml"
    report_out = None if design or output is None or str(output) == "-" else output
    fmt = writers.choose_format(fmt, report_out)
    check_paths([poses], [("--output", output), ("--plot", plot)], {"--plot": (plot, PICTURES)})
    if design:
        mechanism_output(output, force, [poses])
    if unit not in LENGTH_UNITS:
        raise InputError(f"--unit {unit!r} is not a length unit (units: {', '.join(LENGTH_UNITS)})")
    if motion:
        from .motion import motion_command

        if search or function is not None or path:
            raise InputError("--motion takes poses (--pose, --poses): not --function, --search or --path")
        motion_command(pose or [], poses, circle or [], min_transmission=min_transmission,
                       design=design_number, output=output, write_file=design, force=force, unit=unit,
                       fmt=fmt, report_out=report_out, digits=digits, table=table, plot=plot)
        return
    if path:
        from .path import path_command

        if function is not None or plot is not None:
            raise InputError("--path takes 5 to 9 --point X,Y: not --function or --plot")
        path_command(point or [], via or [], search=search, samples=samples, seed=seed, design=design_number,
                     output=output, write_file=design, force=force, fmt=fmt, report_out=report_out,
                     digits=digits, table=table, scheduler=scheduler, workers=workers,
                     min_transmission=min_transmission)
        return
    if pose or poses is not None or circle or design_number is not None or point or via:
        raise InputError("--pose, --poses, --circle and --design are options of --motion; --point of --path "
                         "(and --via)")
    if function is None or x is None:
        raise InputError("give --function and --x (or --motion with poses)")
    if search:
        from .search import search_command

        if design or plot is not None:
            raise InputError(
                "--search lists candidates: run the best one without --search for -o FILE.toml or --plot"
            )
        search_command(function, x, alpha, phi, vary or [], points=points, spacing=spacing, at=at,
                       ground=ground, min_transmission=min_transmission, samples=samples, seed=seed,
                       sampling=sampling, top=top, scheduler=scheduler, workers=workers, fmt=fmt,
                       output=report_out, digits=digits, table=table)
        return
    searching = (("--vary", vary), ("--samples", samples), ("--scheduler", scheduler), ("--workers", workers))
    for option, given in searching:
        if given:
            raise InputError(f"{option} is an option of --search")
    for option, given in (("--alpha", alpha), ("--phi", phi)):
        if given is None:
            raise InputError(f"give {option} (the angle range x and y map onto)")
    req = make_request(function, x, alpha, phi, points=points, spacing=spacing, at=at, ground=ground,
                       min_transmission=min_transmission, table_points=rows)
    result = run(req)
    if design:
        from .synthesis_output import write_chosen

        write_chosen(result, output, unit, force)  # type: ignore[arg-type]
    writers.write(synthesis_report(result, digits, unit), fmt, report_out, table=table)
    if plot is not None and result.linkage is not None and result.curve:
        error_plot(result, plot)
    elif plot is not None:
        typer.echo(f"note: {plot} not drawn: there is no real linkage", err=True)
    if result.defects:
        raise typer.Exit(1)


