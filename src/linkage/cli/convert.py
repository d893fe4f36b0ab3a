"""linkage convert."""

from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import InputError
from .options import MechanismFile, check_paths, stdout_errors
from .root import app


@app.command(
    epilog="Example:  linkage convert my_fourbar.toml -o my_fourbar_loops.toml",
)
def convert(
    file: MechanismFile,
    *,
    output: Annotated[Optional[Path], typer.Option("--output", "-o", help="Write the loops-form file "
                      "here (.toml) instead of standard output.")] = None,
) -> None:
    """Print the vector loops a drawing implies: a joints-and-links file as the loops form,
    each loop under a comment naming its joints.

    Example: linkage convert my_fourbar.toml
    """
    import sys

    from ..files import parse_toml, read_input, write_atomic
    from ..problems.joints import is_joints_doc, loops_text
    from ..problems.loops import parse_mechanism

    if output is not None and str(output) != "-" and output.suffix.lower() != ".toml":
        raise InputError(f"-o {output}: a mechanism file: name it with .toml")
    check_paths([file], [("--output", output)])
    doc = parse_toml(read_input(file), str(file))
    if not is_joints_doc(doc):
        raise InputError(f"{file} is already in the loops form (the joints form from loops is to come)")
    parse_mechanism(doc, str(file))  # refuse here what solve refuses: the printed file solves
    text = loops_text(doc, str(file))
    if output is None or str(output) == "-":
        with stdout_errors():
            sys.stdout.write(text)
            sys.stdout.flush()
        return
    write_atomic(output, text)
    typer.echo(f"wrote {output}", err=True)
