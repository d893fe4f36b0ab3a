"""The Typer app, its version option and its root help."""

from typing import Annotated

import typer

app = typer.Typer(
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    context_settings={"help_option_names": ["-h", "--help"]},
    epilog="Example: linkage solve --method all",
)


def _version(value: bool) -> None:
    if value:
        from ..version import __version__

        typer.echo(f"linkage {__version__}")
        raise typer.Exit(0)


@app.callback()
def _root(
    version: Annotated[bool, typer.Option("--version", callback=_version, is_eager=True,
                                          help="Print the version and exit.")] = False,
) -> None:
    """Kinematics of planar mechanisms by numerical root finding: solve one equation or a
    mechanism's loop equations, sweep a whole cycle, with every iteration shown.

    Example: linkage solve --method all
    """
