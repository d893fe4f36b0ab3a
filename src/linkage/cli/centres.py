"""linkage centres."""

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
from .root import app


@app.command(
    epilog="Examples:  linkage centres sample_inputs/slider_crank_joints.toml --set theta_crank=60  |  "
    "linkage centres sample_inputs/crank_rocker_joints.toml --centrodes --plot centrodes.png",
)
def centres(
    file: MechanismFile,
    *,
    set_: SetOpt = None,
    centrodes: Annotated[bool, typer.Option("--centrodes", help="Also the fixed and moving centrodes "
                         "over a sweep of the driver (--from, --to, --step): the path of the centre of "
                         "--body relative to the ground, in the ground's frame and in the body's.")] = False,
    body: Annotated[Optional[str], typer.Option(help="With --centrodes: the link whose centrodes "
                    "(default: the coupler, the first link with no ground joint).")] = None,
    start: Annotated[Optional[float], typer.Option("--from", help="With --centrodes: first driver value "
                     "(default 0, or the file's [driver] range).")] = None,
    stop: Annotated[Optional[float], typer.Option("--to", help="With --centrodes: last driver value "
                    "(default 360, or the file's [driver] range).")] = None,
    step: Annotated[Optional[float], typer.Option(help="With --centrodes: the driver's increment "
                    "(default 1).")] = None,
    branch: Annotated[Optional[str], typer.Option(help="The assembly, by name or signs as in solve "
                      "--branch (open, crossed, open/crossed for a six-bar, +-); default: the file's "
                      "pose's (a drawing's drawn pose). --centrodes follows it.")] = None,
    plot: Annotated[Optional[Path], typer.Option(help="Draw the mechanism with its centres (and with "
                    "--centrodes the centrodes) into this picture (.png, .svg or .pdf; needs "
                    "matplotlib).")] = None,
    fmt: FormatOpt = None,
    output: OutputOpt = None,
    digits: DigitsOpt = 10,
    table: TableOpt = None,
    columns: ColumnsOpt = None,
) -> None:
    """All n(n-1)/2 instant centres of a mechanism at a pose (the file's driver value, or
    --set): the primary ones from the joints (pins; a slider's at infinity, perpendicular to
    its line), the rest by Kennedy's theorem, each finite or at infinity, and each checked
    against the velocities (v = omega x r about it). A loops-form file is drawn as joints
    and links first, as linkage convert --form joints draws it. Exit 1 where a centre is
    undefined, the velocities are (a toggle), or the check fails.

    Example: linkage centres sample_inputs/fourbar_me581_joints.toml --set theta_crank=80
    """
    from ..kinematics.centres import as_given, at_driver, centres_at
    from ..kinematics.loading import load
    from ..render.centres import centres_report

    out_fmt = choose_format(fmt, output)
    check_paths([file], [("--output", output), ("--plot", plot)], {"--plot": (plot, PICTURES)})
    sweep_only = {"--body": body, "--from": start, "--to": stop, "--step": step}
    given = [k for k, v in sweep_only.items() if v is not None]
    if given and not centrodes:
        raise InputError(f"{', '.join(given)} set the centrodes' sweep: give --centrodes as well")
    mechanism = load(file).with_values(parse_assignments("--set", set_ or []), {})
    note_closed_form(mechanism)
    mechanism, pose, converted = at_driver(mechanism, branch=branch)
    ic = as_given(centres_at(pose), mechanism, converted)
    cd = None
    if centrodes:
        from collections import Counter

        from ..arguments import check_number, driver_span
        from ..kinematics.centrodes import centrodes as run_centrodes
        from ..kinematics.positions import check_assembles_somewhere, span_text
        from ..kinematics.sweep import driver_values

        a, b = driver_span(mechanism, start, stop)
        if step is not None and not check_number("--step", step) > 0:
            raise InputError("--step must be > 0")
        values = driver_values(a, b, 1.0 if step is None else step, None)
        cd = run_centrodes(mechanism, values, body, branch=branch)
        # the one rule of a linkage that assembles at no position of the range
        check_assembles_somewhere(Counter(p.status for p in cd.points), str(file),
                                  lambda: span_text(mechanism.driver.name, a, b, mechanism.driver.unit))
    emit_report(centres_report(ic, digits, cd), out_fmt, output, columns=columns, table=table)
    if plot is not None:
        from ..render.centres import centres_plot

        centres_plot(pose, ic, plot, cd)
        typer.echo(f"wrote {plot}", err=True)
    if ic.status != "ok":
        raise typer.Exit(1)
