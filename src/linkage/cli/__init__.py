"""The ``linkage`` command line: parses, calls the engine, renders. No numerics here.

Exit codes: 0 converged, 1 ran but did not converge (the rows are still shown),
2 bad input (one line on stderr, never a traceback).

One module per command, imported when a run names it (:mod:`.registry`); ``app`` (every
command registered) and ``_app_for`` are loaded on first use. No module here has
postponed annotations (typer would evaluate them with ``eval()`` on every start), and
every engine import is inside the function that needs it (start-up time).
"""

from typing import Any

from .entry import main, run_cli

__all__ = ["_app_for", "app", "main", "run_cli"]


def __getattr__(name: str) -> Any:
    """``app`` with every command registered, and ``_app_for``, on first use."""
    if name in ("app", "_app_for"):
        from .entry import app_for
        from .registry import load
        from .root import app

        load()
        return app if name == "app" else app_for
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
