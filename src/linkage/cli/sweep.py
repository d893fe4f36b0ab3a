"""linkage sweep."""

from pathlib import Path
from typing import Annotated, Any, Optional

import typer

from ..errors import InputError
from ..methods import SCALAR_METHODS
from ..solve import SYSTEM_METHODS  # (a sweep imports it in any case: kinematics.sweep's criteria)
from .options import (
    PICTURES,
    AccelOpt,
    ColumnsOpt,
    DigitsOpt,
    FormatOpt,
    GravityOpt,
    LoadOpt,
    OutputOpt,
    SetOpt,
    SpeedOpt,
    TableOpt,
    TorqueOpt,
    check_paths,
    choose_format,
    emit_report,
    note_closed_form,
    parse_assignments,
)
from .progress import progress_bar
from .root import app


@app.command(
    epilog="Examples:  linkage sweep sample_inputs/fourbar_me581.toml --from 0 --to 359 --step 1  |  "
    "linkage sweep sample_inputs/crank_rocker.toml --branch crossed --format csv -o cycle.csv",
)
def sweep(
    file: Annotated[Optional[Path], typer.Argument(
        metavar="[FILE]", help="A mechanism file (TOML, see sample_inputs/; - reads standard input); "
        "without it, the four-bar input-output equation over alpha.", show_default=False)] = None,
    *,
    start: Annotated[Optional[float], typer.Option("--from", help="First driver value (driver's "
                     "unit; default 0).")] = None,
    stop: Annotated[Optional[float], typer.Option("--to", help="Last driver value (default 360, or "
                    "the file's [driver] range).")] = None,
    r1: Annotated[Optional[str], typer.Option("--r1", help="Without FILE: R1 (default 5/3).")] = None,
    r2: Annotated[Optional[str], typer.Option("--r2", help="Without FILE: R2 (default 5/2).")] = None,
    r3: Annotated[Optional[str], typer.Option("--r3", help="Without FILE: R3 (default 11/6).")] = None,
    links: Annotated[Optional[tuple[str, str, str, str]], typer.Option(
        metavar="A B C D", help="Without FILE: link lengths input, coupler, output, ground.")] = None,
    step: Annotated[Optional[float], typer.Option(help="Driver increment (default 1).")] = None,
    points: Annotated[Optional[int], typer.Option(help="Number of evenly spaced positions "
                      "instead of --step.")] = None,
    method: Annotated[str, typer.Option("--method", "-m", help=f"With FILE: {', '.join(SYSTEM_METHODS)}; "
                      f"without (the four-bar equation): {', '.join(SCALAR_METHODS)}.")] = "newton",
    branch: Annotated[Optional[str], typer.Option(help="Assembly branch to follow (mechanisms "
                      "whose loops have a closed form), by name or signs as in solve --branch: open, "
                      "crossed, open/crossed for a six-bar, 'open (mirror)', +-; default: the "
                      "assembly of the file's pose (its guesses solved at its driver value: a "
                      "drawing's assembly as drawn).")] = None,
    set_: SetOpt = None,
    tol: Annotated[float, typer.Option(help="Step and residual tolerance per position.")] = 1e-12,
    batch: Annotated[Optional[bool], typer.Option("--batch/--no-batch", help="Use the numpy "
                     "batch engine (default: above 20,000 positions; newton only).")] = None,
    plot: Annotated[Optional[Path], typer.Option(help="Also plot the outputs against the driver "
                    "(.png, .svg or .pdf; needs matplotlib).")] = None,
    path: Annotated[Optional[list[str]], typer.Option(
        "--path", metavar="JOINT", help="With --plot: draw the path of this joint or named "
        "point over the sweep instead (a coupler curve; repeatable).")] = None,
    speed: SpeedOpt = None,
    accel: AccelOpt = None,
    force: LoadOpt = None,
    torque: TorqueOpt = None,
    gravity: GravityOpt = None,
    torque_plot: Annotated[Optional[Path], typer.Option("--torque-plot", help="With loads: plot the "
                           "input torque (or force) over the sweep, its peak marked.")] = None,
    fmt: FormatOpt = None,
    output: OutputOpt = None,
    digits: DigitsOpt = 10,
    columns: ColumnsOpt = None,
    table: TableOpt = None,
) -> None:
    """Solve a mechanism over a range of its driver, each position from the previous one.

    Reports every position (converged; no_solution where the linkage cannot be assembled;
    off_branch where it can, but not on the followed branch), the branch, det J, a
    four-bar's transmission angle, the feasible ranges and the limit/toggle positions
    (with --speed, each unknown's rates too). Without FILE:
    the four-bar input-output equation (solve's --r1/--r2/--r3/--links and --method) at
    each alpha from --from to --to, each from the previous root.

    Example: linkage sweep sample_inputs/rapier_drive.toml --step 5

    Example: linkage sweep --from 10 --to 160 --step 30
    """
    from ..arguments import check_method, check_number, driver_span, parse_motion
    from ..kinematics.loading import load
    from ..kinematics.positions import check_assembles_somewhere, driver_range_text
    from ..kinematics.sweep import BATCH_ABOVE, driver_values, sweep_mechanism
    from ..render.sweep import sweep_report
    from ..render.writers import data_formats, is_data, prefetch
    from ..solve import check_criteria

    out_fmt = choose_format(fmt, output)
    check_paths([file], [("--output", output), ("--plot", plot), ("--torque-plot", torque_plot)],
                {"--plot": (plot, PICTURES), "--torque-plot": (torque_plot, PICTURES)})
    check_criteria(tol, 0.0, None, 50)
    equation_only = {"--r1": r1, "--r2": r2, "--r3": r3, "--links": links}
    if file is None:
        given = [k for k, v in {"--branch": branch, "--set": set_, "--batch": batch, "--path": path,
                                "--speed": speed, "--accel": accel, "--load": force, "--torque": torque,
                                "--gravity": gravity, "--torque-plot": torque_plot}.items() if v or v == ""]
        if given:
            raise InputError(f"{', '.join(given)} apply to a mechanism FILE")
        a = check_number("--from", 0.0 if start is None else start)
        b = check_number("--to", 360.0 if stop is None else stop)
        sweep_equation(a, b, step, points, method, r1, r2, r3, links, tol, out_fmt, output, digits, plot)
        return
    given = [k for k, v in equation_only.items() if v is not None]
    if given:
        raise InputError(f"{', '.join(given)} belong to the four-bar equation (sweep without FILE)")
    if step is not None and points is not None:
        raise InputError("give --step or --points, not both")
    if step is not None:
        check_number("--step", step)
    check_method("--method", method, SYSTEM_METHODS, "for a mechanism file")
    mechanism = load(file).with_values(parse_assignments("--set", set_ or []), {})
    a, b = driver_span(mechanism, start, stop)
    if points is None and step is None:
        step = 1.0
    values = driver_values(a, b, step, points, array_above=BATCH_ABOVE)
    note_closed_form(mechanism)
    w, a_ = parse_motion(speed, accel, mechanism)
    motion = (speed, accel)
    # loads from the file or the options, or none (their engine is not imported: start-up time)
    loads = None
    if force or torque or gravity is not None or mechanism.extra.get("loads"):
        from ..kinematics.bodies import command_loads

        loads = command_loads(mechanism, force or [], torque or [], gravity)
    named = check_path_names(mechanism, path, plot, file)
    if batch is None and len(values) <= BATCH_ABOVE:
        # the numpy engines (closed form, batch) cost a fresh process numpy's import, more
        # than the one-at-a-time sweep of this many positions (the cold-start target)
        batch = False
    n = len(values)
    data = is_data(out_fmt)
    if data:
        prefetch(out_fmt, n)  # the writer's imports beside the solving
    # one bar for solving and writing (n positions each), on screen until the file is complete
    with progress_bar(2 * n if data else n, minimum=4000 if data else 2000) as advance:
        result = sweep_mechanism(mechanism, values, method=method, branch=branch, tol=tol, batch=batch,
                                 progress=advance, speed=w, accel=a_, joints=data or bool(path))
        check_assembles_somewhere(result.summary, str(file), lambda: driver_range_text(result))
        if advance is not None and data:
            advance(n, f"writing {out_fmt}")
        note = "" if data or not named else \
            f"joints and points (x, y): with --format {data_formats()}"
        from ..kinematics.columns import sweep_columns

        cols = sweep_columns(result)  # read once: a batch sweep's rates for its table and its loads
        report = sweep_report(result, digits, joints_note=note, cols=cols)
        report, draw_torque = with_loads(report, mechanism, result, loads, (w, a_), digits, torque_plot, cols)
        emit_report(report, out_fmt, output, columns=columns, table=table,
                    progress=None if advance is None else (lambda rows: advance(n + rows)))
        if draw_torque is not None:
            draw_torque()
    if plot is not None:
        draw_sweep(result, mechanism, path, plot, motion)
    if result.summary.get("failed"):
        raise typer.Exit(1)


def with_loads(report: Any, mechanism: Any, result: Any, loads: Any, motion: tuple[Any, Any], digits: int,
               torque_plot: Path | None, cols: Any) -> tuple[Any, Any]:
    """The report with its loads table where the run has loads (cli.loads.sweep_loads), and
    the call that draws --torque-plot once the report is written (None without it)."""
    if loads is not None and (not loads.empty or loads.gravity is not None):
        from .loads import sweep_loads

        return sweep_loads(report, mechanism, result, loads, *motion, digits, torque_plot, cols)
    if torque_plot is not None:
        raise InputError("--torque-plot needs loads: [loads] or [mass] in the file, or --load/--torque")
    return report, None


def check_path_names(mechanism: Any, path: list[str] | None, plot: Path | None, file: Path) -> list[str]:
    """The mechanism's named joints and points; each --path one of them, drawn into --plot."""
    named = [j for loop in mechanism.loops for j in loop.joints if j] + list(mechanism.points)
    if path:
        if plot is None:
            raise InputError("--path draws into the --plot file: give --plot PATH.png as well")
        for name in path:
            if name not in named:
                raise InputError(f"--path {name}: no joint or point of that name in {file} "
                                 f"(named: {', '.join(dict.fromkeys(named)) or 'none'})")
    return named


def draw_sweep(result: Any, mechanism: Any, path: list[str] | None, plot: Path,
               motion: tuple[str | None, str | None]) -> None:
    """--plot: the --path joints' paths, else the sweep's unknowns (with the --speed/--accel
    they were computed at)."""
    from ..arguments import motion_text
    from ..render.plots import path_plot, sweep_plot

    if path:
        path_plot(result, mechanism, path, plot)
    else:
        sweep_plot(result, plot, motion_text(motion[0], motion[1], mechanism))
    typer.echo(f"wrote {plot}", err=True)


def sweep_equation(a: float, b: float, step: float | None, points: int | None, method: str,
                   r1: str | None, r2: str | None, r3: str | None, links: Any, tol: float, out_fmt: str,
                   output: Path | None, digits: int, plot: Path | None) -> None:
    """The four-bar input-output equation over alpha (the student report's table,
    docs/worked_examples.md P2): the options
    checked here, the walk in :func:`linkage.kinematics.equation_sweep.equation_sweep`."""
    from ..arguments import check_method
    from ..kinematics.equation_sweep import equation_sweep
    from ..kinematics.positions import check_assembles_somewhere
    from ..kinematics.sweep import driver_values
    from ..methods import METHODS
    from ..problems.seed_equation import fourbar_coefficients, scalar_problem
    from ..render.sweep import equation_report

    check_method("--method", method, METHODS, "for the four-bar equation (sweep without FILE)")
    if plot is not None:
        raise InputError("--plot draws mechanism sweeps; without FILE use --format csv")
    if step is not None and points is not None:
        raise InputError("give --step or --points, not both")
    if b < a:
        raise InputError(f"--to ({b:g}) must not be below --from ({a:g})")
    values = driver_values(a, b, step if step is not None or points is not None else 1.0, points)
    if len(values) > 100_000:
        raise InputError(f"{len(values):,} values of alpha is more than 100,000; use a larger --step")
    first = scalar_problem(None, None, values[0], r1, r2, r3, links)
    coeffs = first.title  # "..., R1 = ..., R2 = ..., R3 = ..." for the table's heading
    rs, _ = fourbar_coefficients(r1, r2, r3, links)
    rows = equation_sweep(values, rs, method, tol)
    heading = coeffs.split(', ', 2)[2] if coeffs.count(', ') >= 2 else coeffs
    statuses = [r[1] for r in rows]
    check_assembles_somewhere({s: statuses.count(s) for s in set(statuses)}, f"the four-bar of {heading}",
                              lambda: f"alpha from {values[0]:.12g} to {values[-1]:.12g} deg")
    emit_report(equation_report(rows, method, tol, heading, digits), out_fmt, output)
    # as a mechanism sweep: where the linkage cannot be assembled is an answer, not a failure
    if any(r[2] is None and r[1] != "no_solution" for r in rows):
        raise typer.Exit(1)
