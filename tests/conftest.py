"""Shared test helpers: compare with printed digits, run the CLI in-process or as a process."""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
from dataclasses import dataclass

import pytest

from linkage.cli import run_cli


def decimals(printed: str) -> int:
    return len(printed.split(".")[1]) if "." in printed else 0


def matches(value: float | None, printed: str | None, slack: float = 0.0) -> bool:
    """True when ``value`` rounds to ``printed`` (within half a unit in its last digit).

    ``slack`` widens that by a rounding bound where the printed digit lies below what
    double precision determines (e.g. a difference quotient of nearly equal values).
    """
    if printed is None:
        return True
    if printed == "NaN":
        return value is None or (isinstance(value, float) and math.isnan(value))
    if value is None:
        return False
    half_unit = 0.5 * 10.0 ** -decimals(printed)
    return abs(value - float(printed)) <= half_unit * (1 + 1e-9) + 4 * math.ulp(value) + slack


def assert_rows(actual: list[tuple], expected: tuple[tuple[str | None, ...], ...], *, label: str,
                slack: dict[int, list[float]] | None = None) -> None:
    """Every cell rounds to the printed one; ``slack[column][row]`` widens single cells."""
    assert len(actual) == len(expected), f"{label}: {len(actual)} rows, expected {len(expected)}"
    for got, want in zip(actual, expected):
        assert len(got) == len(want), f"{label}: row {want[0]} has {len(got)} columns"
        k = expected.index(want)
        for j, (g, w) in enumerate(zip(got, want)):
            extra = slack[j][k] if slack and j in slack else 0.0
            assert matches(g, w, extra), f"{label}: row {want[0]} column {j}: got {g!r}, printed {w!r}"


@dataclass
class CliRun:
    code: int
    out: str
    err: str


@pytest.fixture
def cli(capsys):
    """Run ``linkage ARGS`` in-process through the real entry point's error handling."""

    def invoke(*args: str) -> CliRun:
        code = run_cli(list(args))
        captured = capsys.readouterr()
        return CliRun(code, captured.out, captured.err)

    return invoke


def run_process(*args: str, code: str | None = None) -> subprocess.CompletedProcess:
    """Run ``python -m linkage ARGS`` (or ``python -c CODE``) in a fresh interpreter."""
    cmd = [sys.executable, "-c", code] if code else [sys.executable, "-m", "linkage", *args]
    env = dict(os.environ, COLUMNS="200")
    return subprocess.run(cmd, capture_output=True, text=True, timeout=120, env=env)


@pytest.fixture(scope="session")
def crank_rocker_search():
    """The suite's one complete nine-point solve (1,442 paths, about 35 s of two cores):
    ``search_path`` on six of a Grashof crank-rocker's nine coupler points with the other
    three as via points (tests/test_path_search.py). Shared for the session by the search's
    tests and by tests/test_nine_point.py's known four-bar, so that it is tracked once."""
    from test_path_search import search_the_crank_rocker

    return search_the_crank_rocker()


def sigint_as_at_a_terminal() -> None:
    """The child's SIGINT at its default, as a terminal's foreground job has it: a test run
    started as a background job (``pytest &``) has it ignored, POSIX shells' rule for
    background jobs, which Python and so the child keep (the signal would then be lost)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
