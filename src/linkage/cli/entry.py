"""The entry point: one command run, every error one stderr line and an exit code."""

import contextlib
import copy
import sys
from typing import Any

import typer

from ..errors import LinkageError
from .options import NOTED
from .root import app


def app_for(args: list[str]) -> typer.Typer:
    """The app with only the command this run names, whose module alone is imported:
    typer builds the parser of every registered command (signature, type hints, options)
    before it dispatches, and a run uses one. Anything else (no command, an option first,
    a misspelt name) gets the whole app, whose help and "No such command" list them all."""
    from .registry import COMMANDS, load

    if not args or args[0].startswith("-") or args[0] not in COMMANDS:
        load()
        return app
    load((args[0],))
    chosen = [c for c in app.registered_commands if c.callback is not None and
              (c.name or c.callback.__name__) == args[0]]
    lean = copy.copy(app)
    lean.registered_commands = chosen
    return lean


def run_cli(argv: list[str] | None = None) -> int:
    """Run the app and turn every error into one stderr line and an exit code; the notes
    a command made (:func:`note_closed_form`) follow its output when it ran (exit 0 or 1),
    not when it was refused or stopped (the error is then the one line)."""
    from ..files import command_paths

    args = list(sys.argv[1:] if argv is None else argv)
    NOTED.clear()  # each command says its notes once
    with command_paths():  # no output of the run may be a file it read or wrote (files.check_outputs)
        code = _run_command(args)
    if code in (0, 1):
        for note in NOTED:
            typer.echo(_for_stderr(f"note: {note}"), err=True)
    return code


def one_line(text: str) -> str:
    """A message as one line whatever it quotes: a line break in a path or a value (a file
    named ``a<newline>b``) is written as ``\\n`` (``\\r``), so an error stays the one line
    docs/output.md promises."""
    return text.replace("\r", "\\r").replace("\n", "\\n")


def _for_stderr(line: str) -> str:
    """A message as one line, or wrapped at words to a terminal's width (a person's
    terminal would otherwise fold it anywhere, mid-word or mid-path)."""
    line = one_line(line)
    if not sys.stderr.isatty():
        return line
    import shutil
    import textwrap

    width = shutil.get_terminal_size().columns
    return "\n".join(textwrap.wrap(line, width, subsequent_indent="  ", break_long_words=False,
                                    break_on_hyphens=False)) if len(line) > width else line


PAUSED: list[bool] = []
"""True while the collector is paused for start-up (:func:`linkage.cli.main`)."""


def resume_collector() -> None:
    """Start-up is over (the command's module is loaded): if :func:`main` paused the
    collector, what start-up made is frozen (it lives until exit; no collection walks it
    again) and collection resumes for the command's own work. A run in a process of its
    own only: frozen objects are never freed."""
    if PAUSED:
        import gc

        PAUSED.clear()
        gc.freeze()
        gc.enable()


def _run_command(args: list[str]) -> int:
    try:
        app = app_for(args)
        resume_collector()
        rv = app(args=args, prog_name="linkage", standalone_mode=False)
    except typer.Exit as exc:
        return exc.exit_code
    except typer.Abort:
        typer.echo("error: aborted", err=True)
        return 1
    except LinkageError as exc:
        typer.echo(one_line(f"error: {exc}"), err=True)
        return 2
    except KeyboardInterrupt:
        return _interrupted()
    except BrokenPipeError:
        typer.echo("error: cannot write to standard output: the pipe was closed", err=True)
        return 2
    except _StdoutClosed as exc:  # help or version text on a closed standard output
        typer.echo(f"error: cannot write to standard output: {exc.strerror}", err=True)
        return 2
    except RecursionError:
        typer.echo("error: the input is nested too deeply to read", err=True)
        return 2
    except MemoryError:
        typer.echo("error: out of memory: the input asks for more than this machine has", err=True)
        return 2
    except Exception as exc:
        if type(exc).__name__ == "NoArgsIsHelpError":
            return 0  # bare `linkage`: the help was the answer
        if hasattr(exc, "format_message") and hasattr(exc, "exit_code"):
            # A usage error from typer's (or click's) parser: bad option, bad value.
            message = " ".join(exc.format_message().split())
            typer.echo(f"error: {message}", err=True)
            return 2
        typer.echo(one_line(f"internal error: {type(exc).__name__}: {exc} (please report this)"), err=True)
        return 1
    if rv == 130:
        # typer turns Ctrl-C into a silent return of 130 (no command returns a number)
        return _interrupted()
    return rv if isinstance(rv, int) else 0


_terminated: list[int] = []
"""The signal number once SIGTERM arrived (see :func:`_on_sigterm`)."""


def _on_sigterm(signum: int, frame: Any) -> None:
    """SIGTERM is handled as Ctrl-C is: the KeyboardInterrupt unwinds every open output
    (files.atomic_target removes its partial file), then one line and 128 + 15."""
    import signal

    if _terminated:
        return  # a second SIGTERM (timeout(1) signals the child and then its group): already unwinding
    _terminated.append(signum)
    # once: the exit that follows joins the worker threads, and a KeyboardInterrupt raised there
    # is a traceback ("Exception ignored in: <module 'threading'>"), not the one line
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    raise KeyboardInterrupt


def _interrupted() -> int:
    if _terminated:
        typer.echo("error: terminated", err=True)
        return 128 + _terminated[0]
    typer.echo("error: interrupted", err=True)
    return 130


def _standard_streams() -> None:
    """A closed standard stream (``>&-``, ``<&-``) gets /dev/null on its descriptor, so no
    file opened later takes its number; standard output then refuses every write (one
    error line, exit 2) and standard input reads as closed (sys.stdin stays None)."""
    import io
    import os

    for fd in (0, 1, 2):
        try:
            os.fstat(fd)
            continue
        except OSError:
            pass
        null = os.open(os.devnull, os.O_RDWR)
        if null != fd:
            os.dup2(null, fd)
            os.close(null)
        if fd == 1:
            sys.stdout = _ClosedStdout()
        elif fd == 2:
            sys.stderr = io.TextIOWrapper(io.FileIO(2, "w", closefd=False), write_through=True)


class _StdoutClosed(OSError):
    """A write to a standard output that was closed before the run."""


class _ClosedStdout:
    """Standard output that was closed before the run: every write fails as a closed
    descriptor does."""

    def write(self, text: str) -> int:
        import errno
        import os

        raise _StdoutClosed(errno.EBADF, os.strerror(errno.EBADF) + " (standard output is closed)")

    def fileno(self) -> int:
        return self.write("")  # descriptor 1 is /dev/null now: writing there would lose output

    def flush(self) -> None:
        return None

    def isatty(self) -> bool:
        return False


def main(paused_collector: bool = False) -> None:
    """One command run in a process of its own (``linkage.cli.main``, which pauses the
    collector for start-up: ``paused_collector``), then the process exits with its code."""
    import signal

    if paused_collector:
        PAUSED.append(True)
    _standard_streams()
    with contextlib.suppress(ValueError, OSError):  # not the main thread, or no signals
        signal.signal(signal.SIGTERM, _on_sigterm)
    code = run_cli()
    resume_collector()  # start-up failed (an import): resumed here
    try:
        sys.stdout.flush()
    except OSError:
        # stdout is gone (closed pipe, full disk): say nothing more when Python exits
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        if code == 0:
            typer.echo("error: cannot write to standard output", err=True)
            code = 2
    # The objects left (every module's, the run's) are freed by the interpreter's exit as
    # ever, but its last garbage collections no longer walk them: those walks were about a
    # sixth of a cold ``linkage solve`` (10-13 ms of its 70, processor time). Nothing that
    # runs at exit is skipped (atexit, finalizers, flushing); only cyclic garbage made
    # before here is left to the exit.
    import gc

    gc.freeze()
    sys.exit(code)
