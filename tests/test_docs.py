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


def test_ci_reruns_the_numerics_sensitive_tests_with_numpys_simd_dispatch_off():
    """After the quick start, .ci/run runs NUMERICS again under NPY_DISABLE_CPU_FEATURES set to
    numpy's dispatch targets: every test file that holds a numpy twin to a bound in ulps
    (tests/ulps.py) is among them, and each exists."""
    ci = (ROOT / ".ci" / "run").read_text()
    after = ci.split(quick_start()[1], 1)[1]
    numerics = re.search(r'^NUMERICS="([^"]+)"', after, flags=re.M)
    assert numerics, "no NUMERICS= line after the quick start"
    files = numerics.group(1).split()
    assert all((ROOT / f).is_file() for f in files), files
    using = sorted(f"tests/{p.name}" for p in (ROOT / "tests").glob("test_*.py")
                   if re.search(r"^from ulps import", p.read_text(), flags=re.M))
    assert using and set(using) <= set(files), (using, files)
    assert re.search(r'^NPY_DISABLE_CPU_FEATURES="\$targets" python -m pytest \$NUMERICS$', after, flags=re.M)
    assert "__cpu_dispatch__" in after


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


def readme_method_all_table() -> list[str]:
    """The ```text block after "`--method all` runs every method": its lines."""
    block = README.split("`--method all` runs every method", 1)[1].split("```text", 1)[1].split("```", 1)[0]
    return [line for line in block.strip().splitlines() if line.strip()]


def deterministic(lines: list[str]) -> list[list[str]]:
    """A --method all table without its last column (time per solve, which is measured):
    the lines down to the header's rule whole, each row after it split into cells."""
    rule = next(k for k, line in enumerate(lines) if line.lstrip().startswith("---"))
    return [line.split() for line in lines[:rule]] + [line.split()[:-1] for line in lines[rule + 1:]]


def test_readme_method_all_table_is_what_the_command_prints(cli):
    """Every column but the time is deterministic arithmetic: the README's table shows
    what `linkage solve --method all` prints now (it showed 10 fixed-point evaluations,
    from before the roots were certified, where the command printed 19)."""
    run = cli("solve", "--method", "all")
    assert run.code == 0, run.err
    printed = [line for line in run.out.strip().splitlines() if line.strip()]
    want = deterministic(readme_method_all_table())
    assert deterministic(printed) == want
    assert [row[0] for row in want[3:]] == ["bisection", "regula-falsi", "hybrid", "secant", "newton",
                                            "fixed-point"]
