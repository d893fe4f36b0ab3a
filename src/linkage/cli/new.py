"""linkage new: every kind, its help and its defaults from the one registry
(:data:`linkage.problems.templates.KINDS`)."""

from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import InputError
from ..problems.templates import KINDS, angles, branch_help, kind_names, kind_titles, links_order
from .options import ForceOpt
from .root import app

OPTIONS = {"links": "--links", "angle_deg": "--angle", "branch": "--branch", "unit": "--unit",
           "name": "--name", "form": "--form"}
"""templates' argument names, as this command's options."""


@app.command(
    help=f"Start a mechanism file from its link lengths ({kind_titles()}), drawn as a commented "
    "joints file.\n\nThe file solves and sweeps as written: the crank at --angle, each dyad closed on "
    "--branch. Move its joints to change the design; --form loops writes the vector loops the drawing "
    "implies instead.\n\nExample: linkage new fourbar --links 40 120 80 100 -o my_fourbar.toml",
    epilog="Examples:  linkage new fourbar --links 40 120 80 100 -o my_fourbar.toml  |  "
    "linkage new slider-crank --links 40 120 -5 --angle 90 --branch crossed  |  "
    "linkage new watt --form loops",
    context_settings={"ignore_unknown_options": True},  # a negative offset in --links
)
def new(
    kind: Annotated[str, typer.Argument(metavar="KIND", help=f"{kind_names()}.", show_default=False)],
    lengths: Annotated[Optional[list[str]], typer.Argument(metavar="[--links LENGTH...]", help="The "
                       "lengths, in the file's unit.", show_default=False, hidden=True)] = None,
    *,
    links: Annotated[bool, typer.Option("--links", help="The lengths follow, in this order: "
                     f"{links_order()} (offset: a slider line's, any sign). Default: the sample's "
                     "(linkage samples).")] = False,
    angle: Annotated[Optional[float], typer.Option("--angle", metavar="DEG", help="The crank's angle "
                     f"in the drawing, degrees (default: the sample's: {angles()}).",
                     show_default=False)] = None,
    branch: Annotated[str, typer.Option("--branch", help=branch_help())] = "open",
    unit: Annotated[str, typer.Option("--unit", help="The file's length_unit: mm, cm, m, in or ft.")] = "mm",
    name: Annotated[Optional[str], typer.Option("--name", help="The mechanism's name "
                    "(default: its kind's).", show_default=False)] = None,
    form: Annotated[str, typer.Option("--form", help="joints (the drawing) or loops (the vector loops "
                    "it implies, as linkage convert prints them).")] = "joints",
    output: Annotated[Optional[Path], typer.Option("--output", "-o", help="Write the file here (.toml) "
                      "instead of standard output; an existing file is kept unless --force.")] = None,
    force: ForceOpt = False,
) -> None:
    """linkage new: a file of one of the kinds of :data:`linkage.problems.templates.KINDS`
    (its help, choices and defaults come from there)."""
    import sys

    from ..numbers import parse_number
    from ..problems.templates import text
    from .options import mechanism_output, stdout_errors, write_mechanism

    given = list(lengths or [])
    kinds = [item for item in given if item in KINDS]
    if kinds:
        raise InputError(f"give KIND first: linkage new {kinds[0]} --links ...")
    for item in given:
        if item.startswith("-") and not item[1:2].isdigit() and item[1:2] != ".":
            raise InputError(f"no such option: {item} (see linkage new --help)")
    if given and not links:
        raise InputError(f"{given[0]!r}: give the lengths after --links, e.g. linkage new {kind} "
                         f"--links {' '.join(given)}")
    if links and not given:
        raise InputError(f"--links: give the lengths after it ({links_order(kind) or links_order()})")
    values = [parse_number(f"--links {item}", item) for item in given]
    target = mechanism_output(output, force)
    try:
        content = text(kind, values or None, angle, branch, unit, name, form)
    except InputError as exc:  # the library names its arguments; say them as options
        word, sep, rest = str(exc).partition(" " if str(exc).startswith("links ") else ":")
        raise InputError(f"{OPTIONS.get(word, word)}{sep}{rest}") from None
    if target is None:
        with stdout_errors():
            sys.stdout.write(content)
            sys.stdout.flush()
        return
    write_mechanism(target, content, force)
