"""linkage assemblies."""

from pathlib import Path
from typing import Annotated, Optional

import typer

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
)
from .root import app


@app.command(
    epilog="Examples:  linkage assemblies sample_inputs/watt_sixbar.toml  |  "
    "linkage assemblies sample_inputs/rapier_drive.toml --set theta12=100 --paths",
)
def assemblies(
    file: MechanismFile,
    *,
    set_: SetOpt = None,
    paths: Annotated[bool, typer.Option("--paths", help="Show every homotopy path: its endpoint, "
                     "cycle number, steps, rejected steps and Newton iterations (always in files).")] = False,
    seed: Annotated[int, typer.Option(help="Seed of the homotopy's random gamma and patch.")] = 0,
    sweep: Annotated[bool, typer.Option("--sweep", help="Also follow every real assembly through the "
                     "driver's motion, past limit positions: which assemblies share a circuit (can be "
                     "reached from one another by moving).")] = False,
    plot: Annotated[Optional[Path], typer.Option(help="With --sweep: plot the circuits, each unknown "
                    "against the driver (.png, .svg or .pdf; needs matplotlib).")] = None,
    fmt: FormatOpt = None,
    output: OutputOpt = None,
    columns: ColumnsOpt = None,
    digits: DigitsOpt = 12,
    table: TableOpt = None,
) -> None:
    """Every assembly of a mechanism at its driver value (the file's, or --set), by polynomial
    homotopy continuation: each real one with its unknowns, branch and residual, and the
    complex ones and the paths to infinity counted.

    Example: linkage assemblies sample_inputs/stephenson_sixbar.toml --set theta2=200
    """
    from ..errors import InputError
    from ..kinematics.assemblies import every_assembly
    from ..kinematics.loading import load
    from ..render.assemblies import assemblies_report
    from .options import choose_format, emit_report, note_closed_form, parse_assignments

    out_fmt = choose_format(fmt, output)
    check_paths([file], [("--output", output), ("--plot", plot)], {"--plot": (plot, PICTURES)})
    if plot is not None and not sweep:
        raise InputError("--plot draws the circuits: give --sweep as well")
    mechanism = load(Path(file)).with_values(parse_assignments("--set", set_ or []), {})
    note_closed_form(mechanism)
    result = every_assembly(mechanism, seed=seed)  # its checks name --seed as seed
    if not sweep:
        emit_report(assemblies_report(result, digits, paths), out_fmt, output, columns=columns, table=table)
    else:
        from ..kinematics.circuits import circuits
        from ..render.circuits import circuits_plot, circuits_report

        traced = circuits(result.mechanism, found=result)
        emit_report(circuits_report(traced, digits, paths), out_fmt, output, columns=columns, table=table)
        if plot is not None:
            circuits_plot(traced, plot)
            typer.echo(f"wrote {plot}", err=True)
        if any(c.status != "closed" for c in traced.circuits):
            raise typer.Exit(1)
    if result.failed or result.unresolved or result.continuum or not result.real:
        raise typer.Exit(1)
