"""The README's promises: the quick start is what CI runs, and its examples work."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()


def quick_start() -> list[str]:
    block = README.split("## Quick start", 1)[1].split("```bash", 1)[1].split("```", 1)[0]
    return [line for line in block.strip().splitlines() if line.strip()]


def test_quick_start_is_two_commands_and_ci_runs_them_verbatim():
    lines = quick_start()
    assert len(lines) == 2
    assert "linkage solve" in lines[0] and "pytest" in lines[1]
    ci = (ROOT / ".ci" / "run").read_text().splitlines()
    for line in lines:
        assert line in ci


def readme_solve_examples() -> list[tuple[list[str], int]]:
    """Every ``$ linkage solve ...`` line, with the exit code its ``# exit N`` comment
    promises (0 without one)."""
    found = re.findall(r"^\$ (linkage solve[^#\n]*)(#[^\n]*)?", README, flags=re.M)
    out = []
    for command, comment in found:
        code = re.search(r"exit (\d)", comment or "")
        out.append((shlex.split(command)[1:], int(code.group(1)) if code else 0))
    return out


@pytest.mark.parametrize("args,code", readme_solve_examples(), ids=lambda a: " ".join(a) if
                         isinstance(a, list) else str(a))
def test_every_readme_example_runs(cli, args, code, tmp_path, monkeypatch):
    (tmp_path / "sample_inputs").symlink_to(ROOT / "sample_inputs")
    (tmp_path / "docs").symlink_to(ROOT / "docs")  # the files the README shows beside its examples
    monkeypatch.chdir(tmp_path)  # examples that write files write them here
    run = cli(*args)
    assert run.code == code, run.err


def first_console_block() -> tuple[list[str], list[str]]:
    """The README's first figure: its ``$ linkage ...`` command and the lines shown under it."""
    block = README.split("```console\n", 1)[1].split("```", 1)[0]
    command, *shown = block.rstrip("\n").splitlines()
    assert command.startswith("$ linkage "), command
    return shlex.split(command[len("$ linkage "):]), shown


def test_the_readme_first_figure_is_what_linkage_solve_prints(cli):
    """It said R1 = 1.666666667 where linkage solve prints R1 = 1.66666666667: every line of
    the figure (no timing in it: all deterministic) is the command's own, in order."""
    args, shown = first_console_block()
    assert args == ["solve"] and len(shown) > 20
    run = cli(*args)
    assert run.code == 0, run.err
    printed = run.out.rstrip("\n").splitlines()
    assert [line.rstrip() for line in shown] == [line.rstrip() for line in printed]
