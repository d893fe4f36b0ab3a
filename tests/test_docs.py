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


def readme_solve_examples() -> list[list[str]]:
    found = re.findall(r"^\$ (linkage solve[^#\n]*)", README, flags=re.M)
    return [shlex.split(c)[1:] for c in found]


@pytest.mark.parametrize("args", readme_solve_examples(), ids=" ".join)
def test_every_readme_example_runs(cli, args, tmp_path, monkeypatch):
    (tmp_path / "sample_inputs").symlink_to(ROOT / "sample_inputs")
    monkeypatch.chdir(tmp_path)  # examples that write files write them here
    run = cli(*args)
    assert run.code == 0, run.err
