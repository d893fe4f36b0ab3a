"""linkage samples."""

import sys
from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import InputError
from .options import check_paths, emit, stdout_errors
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
                      "new file (an existing file is never replaced).")] = None,
) -> None:
    """List the mechanism files shipped with linkage, or copy one out to start your own.

    Example: linkage samples crank_rocker -o my_linkage.toml
    """
    from ..samples import find_sample
    from ..samples import samples as shipped

    if name is None:
        if output is not None:
            raise InputError("give the NAME of the sample to write with -o")
        from ..render.report import Text

        listing = shipped()
        width = max((len(k) for k in listing), default=0)
        emit("table" if sys.stdout.isatty() else "plain", None,
             blocks=[*(Text(f"{k.ljust(width)}  {v}") for k, v in listing.items()), Text(""),
                     Text("print one with `linkage samples NAME`, or copy it with "
                          "`linkage samples NAME -o FILE`")],
             json_obj=listing, csv_table=(("sample", "what it is"), list(listing.items())))
        return
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
