"""The commands, and their modules imported on demand: a run imports the module of the
command it names only (each module's options cost start-up time); help, a misspelt name
and ``linkage.cli.app`` itself load them all."""

import importlib
from collections.abc import Sequence

from .root import app

COMMANDS = ("solve", "sweep", "simulate", "centres", "scan", "tolerance", "assemblies", "draw", "convert",
            "new", "synthesize", "samples", "stress", "bench")
"""In the order ``linkage --help`` lists them."""


def reflow(doc: str) -> str:
    """A docstring as help text: each paragraph one line (rich keeps single line breaks,
    so hard-wrapped source lines would break mid-sentence at any width), and square
    brackets escaped (rich would read "[points]" as a style)."""
    import inspect

    paragraphs = inspect.cleandoc(doc).split("\n\n")
    return "\n\n".join(" ".join(line.strip() for line in p.splitlines()).replace("[", "\\[")
                       for p in paragraphs)


def load(names: Sequence[str] = COMMANDS) -> None:
    """Import these commands' modules (registering each on :data:`app`, its docstring as
    its help), and keep the registered commands in :data:`COMMANDS` order."""
    for name in names:
        before = len(app.registered_commands)
        importlib.import_module(f"{__package__}.{name}")
        for command in app.registered_commands[before:]:
            if command.help is None and command.callback is not None and command.callback.__doc__:
                command.help = reflow(command.callback.__doc__)
    order = {name: i for i, name in enumerate(COMMANDS)}
    app.registered_commands.sort(key=lambda c: order.get(c.name or getattr(c.callback, "__name__", ""),
                                                         len(order)))
