"""The ``linkage`` command line: parses, calls the engine, renders. No numerics here.

Exit codes: 0 converged, 1 ran but did not converge (the rows are still shown),
2 bad input (one line on stderr, never a traceback).

One module per command; importing them registers each on :data:`app`. No module here
has postponed annotations (typer would evaluate them with ``eval()`` on every start),
and every engine import is inside the function that needs it (start-up time).
"""

import importlib

from .app import app
from .entry import app_for, main, reflow, run_cli

# in this order: the order of the commands in `linkage --help`
for _name in ("solve", "sweep", "scan", "draw", "samples", "stress", "bench"):
    importlib.import_module(f".{_name}", __name__)

for _command in app.registered_commands:
    if _command.help is None and _command.callback is not None and _command.callback.__doc__:
        _command.help = reflow(_command.callback.__doc__)

_app_for = app_for  # the name the tests know

__all__ = ["_app_for", "app", "main", "run_cli"]
