"""linkage samples."""

import sys
from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import InputError
from .options import check_paths, choose_format, emit_report, stdout_errors
from .root import app


@app.command(
    epilog="Examples:  linkage samples  |  linkage samples crank_rocker -o my_linkage.toml  |  "
    "linkage samples watt_sixbar | linkage solve -",
)
def samples(
    name: Annotated[Optional[str], typer.Argument(metavar="[NAME]", help="A sample to print (or write "
                    "with -o), e.g. crank_rocker.", show_default=False)] = None,
    *,
    output: Annotated[Optional[Path], typer.Option("--output", "-o", help="Write the sample to this "
                      "new .toml file (an existing file is never replaced).")] = None,
    fmt: Annotated[Optional[str], typer.Option("--format", "-f", help="The list's format, to "
                   "standard output: table (rich, default on a terminal), plain (default when "
                   "piped), csv, json or any tabulate format (github, grid, latex, ...).")] = None,
) -> None:
    """List the mechanism files shipped with linkage, or copy one out to start your own.

    Example: linkage samples crank_rocker -o my_linkage.toml
    """
    from ..samples import find_sample
    from ..samples import samples as shipped

    if name is None:
        if output is not None:
            raise InputError("give the NAME of the sample to write with -o")
        from ..render.tools import samples_report
        from ..render.writers import is_binary

        if fmt is not None and is_binary(fmt.strip().lower()):  # the registry would ask for -o FILE
            raise InputError(f"--format {fmt}: the list of samples goes to standard output; "
                             "use table, plain, csv, json or a tabulate format")
        emit_report(samples_report(shipped()), choose_format(fmt, None), None)
        return
    if fmt is not None:
        raise InputError("--format applies to the list of samples; a sample is printed as its TOML text")
    if output is not None and str(output) != "-" and output.suffix.lower() != ".toml":
        raise InputError(f"-o {output}: a sample is a mechanism file: name it with .toml")
    text = find_sample(name).read_text(encoding="utf-8")
    if output is None or str(output) == "-":
        with stdout_errors():
            sys.stdout.write(text)
            sys.stdout.flush()
        return
    if output.exists() or output.is_symlink():
        raise InputError(f"{output} exists; choose a new file name (samples never replace a file)")
    check_paths([], [("--output", output)])
    from ..files import write_atomic

    write_atomic(output, text)
    typer.echo(f"wrote {output}", err=True)
