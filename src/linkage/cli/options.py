"""What every command shares: the options, the output format and writer, path checks,
--set/--guess parsing and the closed-form notes."""

from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Annotated, Any, Optional

import typer

from ..errors import InputError
from ..numbers import parse_number
from ..render.writers import data_formats, format_help, output_help

FormatOpt = Annotated[Optional[str], typer.Option("--format", "-f", help=format_help())]
"""--format: its choices and help from the one registry of formats (render.formats)."""
OutputOpt = Annotated[Optional[Path], typer.Option("--output", "-o", help=output_help())]
TableOpt = Annotated[
    Optional[str],
    typer.Option("--table", metavar="NAME", help=f"Write only this table of the report ({data_formats()}). "
                 "CSV holds one table: a report of several needs it on standard "
                 "output; to -o FILE.csv the others go beside it as FILE.NAME.csv."),
]
MechanismFile = Annotated[
    Path, typer.Argument(metavar="FILE", help="A mechanism file (TOML, see `linkage samples`).",
                         show_default=False)
]
SetOpt = Annotated[
    Optional[list[str]],
    typer.Option("--set", metavar="NAME=VALUE", help="Override a parameter or the driver, in "
                 "the file's units (repeatable)."),
]
ColumnsOpt = Annotated[
    Optional[str],
    typer.Option("--columns", metavar="NAMES", help="Show only these columns, on screen and in "
                 "every file: comma-separated names or their beginnings, e.g. theta3,theta4,det "
                 "(the first column always stays)."),
]
def _digits(value: int) -> int:
    """--digits: checked here, not by a click range, whose "<int range> [3<=x<=17]" label
    widened every help page's type column until the help text wrapped at 23 characters."""
    if not 3 <= value <= 17:
        raise typer.BadParameter(f"{value} is not from 3 to 17")
    return value


DigitsOpt = Annotated[
    int, typer.Option("--digits", metavar="N", callback=_digits,
                      help="Significant digits printed in tables (3 to 17).")
]


SpeedOpt = Annotated[
    Optional[str],
    typer.Option("--speed", metavar="SPEED", help="Driver speed, for velocities and "
                 "accelerations of every unknown, joint and point: a number in rad/s (or the "
                 "file's length unit per second for a sliding driver), or with a unit: 600rpm, "
                 "10rad/s, 90deg/s, 250mm/s. Every rate has an error bound: near a toggle or "
                 "limit a rate is ill_conditioned (printed to the digits its bound leaves), at "
                 "one undefined (no number)."),
]
AccelOpt = Annotated[
    Optional[str],
    typer.Option("--accel", metavar="ACCEL", help="Driver acceleration (with --speed; "
                 "default 0): rad/s^2, or 5rad/s^2, 90deg/s^2, 100rpm/s, 20mm/s^2."),
]

LoadOpt = Annotated[
    Optional[list[str]],
    typer.Option("--load", metavar="P=FX,FY", help="With FILE (joints form): a force in N at a joint or "
                 "point, ground frame (repeatable; adds to or overrides the file's [loads])."),
]
TorqueOpt = Annotated[
    Optional[list[str]],
    typer.Option("--torque", metavar="LINK=T", help="With FILE: a torque in N m on a link, "
                 "counterclockwise positive (repeatable)."),
]
GravityOpt = Annotated[
    Optional[str],
    typer.Option("--gravity", metavar="G", help="With FILE: gravity on the [mass] links, G m/s^2 in -y "
                 "(e.g. 9.81) or GX,GY."),
]


def choose_format(fmt: str | None, output: Path | None) -> str:
    """The run's format, by the one registry (render.writers): --format, else -o's suffix
    (an unknown suffix refused, naming those that work), else table or plain."""
    from ..render.writers import choose_format as choose

    return choose(fmt, output)


def emit_report(report: Any, fmt: str, output: Path | None, *, columns: str | None = None,
                progress: Any = None, table: str | None = None) -> None:
    """Write a command's report (render.data.Report) through the one writer registry;
    ``columns`` (--columns) keeps only those columns, ``table`` (--table) that table."""
    from ..render.writers import pick_columns, write

    if columns:
        report = pick_columns(report, columns)
    write(report, fmt, output, progress=progress, table=table)


class stdout_errors:
    """A failed write to standard output (full disk, closed pipe) becomes one error line."""

    def __enter__(self) -> None:
        return None

    def __exit__(self, kind: Any, exc: Any, tb: Any) -> bool:
        if isinstance(exc, OSError):
            from ..errors import OutputError

            raise OutputError(f"cannot write to standard output: {exc.strerror or exc}") from None
        return False


ForceOpt = Annotated[
    bool, typer.Option("--force", help="With -o FILE.toml: replace an existing file (never the input).")
]


def mechanism_output(output: Path | None, force: bool, inputs: Sequence[Path | None] = ()) -> Path | None:
    """The one rule for -o FILE.toml of every command that writes a mechanism file (new,
    convert, synthesize), checked before any work: None for standard output; else a .toml
    path that is not an input (not even with --force) and, without --force, not an existing
    file."""
    if output is None or str(output) == "-":
        return None
    if output.suffix.lower() != ".toml":
        raise InputError(f"-o {output}: a mechanism file: name it with .toml")
    check_paths(list(inputs), [("--output", output)])
    if (output.exists() or output.is_symlink()) and not force:
        raise InputError(f"-o {output} exists; choose a new name, or --force to replace it")
    return output


def write_mechanism(output: Path, text: str, force: bool, inputs: Sequence[Path | None] = (),
                    said: str = "") -> None:
    """Write a mechanism file by :func:`mechanism_output`'s rule, checked again (a file may
    have appeared while the command worked) and atomically (files.write_atomic: a temporary
    file renamed over the target). A command calls it only once it has succeeded, so a
    failing command leaves the old file as it was. ``said``: what the "wrote" line adds."""
    from ..files import write_atomic

    mechanism_output(output, force, inputs)
    write_atomic(output, text)
    typer.echo(f"wrote {output}{said}", err=True)


PICTURES = (".png", ".svg", ".pdf")


def check_paths(inputs: list[Path | None], outputs: list[tuple[str, Path | None]],
                pictures: dict[str, tuple[Path | None, tuple[str, ...]]] | None = None) -> None:
    """Every output path checked before any work: not an input, not shared, its folder
    exists; pictures have a suffix the plotter can write."""
    from ..files import check_outputs

    for opt, (path, suffixes) in (pictures or {}).items():
        if path is not None and path.suffix.lower() not in suffixes:
            raise InputError(f"{opt} {path}: use one of {', '.join(suffixes)} for the picture")
    check_outputs(inputs, outputs)


def parse_assignments(option: str, items: list[str]) -> dict[str, float]:
    out = {}
    for item in items:
        name, sep, value = item.partition("=")
        if not sep or not name.strip():
            raise InputError(f"{option} expects name=value, got {item!r}")
        out[name.strip()] = parse_number(f"{option} {name.strip()}", value)
    return out


def note_closed_form(mechanism: Any) -> None:
    """Once per command, a one-line note on standard error for a file that still says
    ``closed_form = ...`` (read and checked, but derived from the loops now), and for a
    drawing solved at a [driver] value other than the drawn one (where it was drawn): kept
    here, printed by :func:`run_cli` when the command ends."""
    for note in (mechanism.closed_form_note, mechanism.drawing_note):
        if note is not None and note not in NOTED:
            NOTED.append(note)


NOTED: list[str] = []
"""The notes of this command, printed by :func:`run_cli` after its output (emptied as each
command starts: tests run many commands in one process)."""


def note_exit_reasons(fmt: str, reasons: Iterable[str]) -> None:
    """The reasons a command exits 1, as notes where its output is a table format (csv,
    parquet, xlsx): the tables hold the rows, not the verdict, which would be nowhere."""
    from ..render.writers import is_data

    if is_data(fmt) and fmt != "json":
        NOTED.extend(reasons)
