"""linkage assemblies."""

from pathlib import Path
from typing import Annotated

import typer

from .options import (
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
    from ..kinematics.assemblies import every_assembly
    from ..kinematics.loading import load
    from ..render.assemblies import assemblies_report
    from .options import choose_format, emit_report, note_closed_form, parse_assignments

    out_fmt = choose_format(fmt, output)
    check_paths([file], [("--output", output)])
    mechanism = load(Path(file)).with_values(parse_assignments("--set", set_ or []), {})
    note_closed_form(mechanism)
    result = every_assembly(mechanism, seed=seed)  # its checks name --seed as seed
    emit_report(assemblies_report(result, digits, paths), out_fmt, output, columns=columns, table=table)
    if result.failed or result.unresolved or result.continuum or not result.real:
        raise typer.Exit(1)
