"""Fresh processes, as a person runs the command line: cold starts and whole commands.

Timed as an installed package runs: with its bytecode cached. pip compiles it at install
time; an editable install writes it on first import, unless PYTHONDONTWRITEBYTECODE is
set (as on some CI machines), in which case every start would compile our sources again
(about 20 ms). So the variable is dropped for these runs, and each command runs once
untimed first.
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import time
from collections.abc import Callable, Sequence

FLOOR = "python -c 'import rich.table' (floor)"
"""The cold start's floor: what any rich command line pays."""


def process_env() -> dict[str, str]:
    """This environment without PYTHONDONTWRITEBYTECODE (see the module's docstring)."""
    return {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


def linkage_command(*args: str) -> list[str]:
    """``linkage ARGS`` in a fresh interpreter of this one."""
    return [sys.executable, "-m", "linkage", *args]


def python_command(code: str) -> list[str]:
    return [sys.executable, "-c", code]


class ProcessFailed(RuntimeError):
    """A command that failed is no measurement."""


def runner(command: Sequence[str], cpu: list[float] | None = None) -> Callable[[], None]:
    """A call that runs ``command`` to its exit (output discarded) and raises
    :class:`ProcessFailed` with its last stderr line if it did not exit 0; ``cpu`` gets the
    processor seconds (user and system, every thread) of each run."""
    import tempfile

    env = process_env()

    def run() -> None:
        with tempfile.TemporaryFile() as err:
            child = subprocess.Popen(list(command), stdout=subprocess.DEVNULL, stderr=err, env=env)
            _, status, usage = os.wait4(child.pid, 0)
            child.returncode = os.waitstatus_to_exitcode(status)
            if cpu is not None:
                cpu.append(usage.ru_utime + usage.ru_stime)
            if child.returncode != 0:
                err.seek(0)
                last = (err.read().decode(errors="replace").strip().splitlines() or [""])[-1]
                raise ProcessFailed(f"{' '.join(command[2:])}: exit {child.returncode}: {last}")

    return run


def cold_commands() -> dict[str, list[str]]:
    """The cold starts the bench shows, the floor first."""
    from ..samples import sample_path

    return {
        FLOOR: python_command("import rich.table"),
        "linkage solve": linkage_command("solve"),
        "linkage solve FILE": linkage_command("solve", str(sample_path("fourbar_me581.toml"))),
        "linkage sweep crank_rocker.toml": linkage_command("sweep", str(sample_path("crank_rocker.toml"))),
    }


def cold_start(repeats: int = 5, extra: dict[str, list[str]] | None = None) -> dict[str, float]:
    """Median wall time of fresh interpreters running the CLI, and the floor it is
    compared with (``python -c "import rich.table"``), interleaved so that the machine's
    noise hits every command alike."""
    commands = {**cold_commands(), **(extra or {})}
    env = process_env()
    times: dict[str, list[float]] = {label: [] for label in commands}
    for rep in range(repeats + 1):
        for label, cmd in commands.items():
            t0 = time.perf_counter()
            subprocess.run(cmd, capture_output=True, check=False, env=env)
            if rep:
                times[label].append(time.perf_counter() - t0)
    return {label: statistics.median(ts) for label, ts in times.items()}
