"""The ``linkage`` command line: parses, calls the engine, renders. No numerics here.

Exit codes: 0 converged, 1 ran but did not converge (the rows are still shown),
2 bad input (one line on stderr, never a traceback).

One module per command, imported when a run names it (:mod:`.registry`); ``app`` (every
command registered), ``_app_for`` and ``run_cli`` are loaded on first use, and typer with
them (:func:`main` imports it with the collector paused). No module here has
postponed annotations (typer would evaluate them with ``eval()`` on every start), and
every engine import is inside the function that needs it (start-up time).
"""

from typing import Any

__all__ = ["_app_for", "app", "main", "run_cli"]


def main() -> None:
    """The ``linkage`` command (the console script and ``python -m linkage``). The cyclic
    garbage collector is paused while the command line starts (typer's import, the
    command's module and parser): start-up makes no garbage, yet its tens of thousands of
    objects set off collections that walk every one of them again, about 5 ms of a
    cold ``linkage sweep`` (docs/performance.md). :func:`.entry.main` resumes it before
    the command runs."""
    import gc

    gc.disable()
    from .entry import main as run_main

    run_main(paused_collector=True)


def __getattr__(name: str) -> Any:
    """``app`` with every command registered, ``_app_for`` and ``run_cli``, on first use."""
    if name == "run_cli":
        from .entry import run_cli

        return run_cli
    if name in ("app", "_app_for"):
        from .entry import app_for
        from .registry import load
        from .root import app

        load()
        return app if name == "app" else app_for
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
