"""The repository as a newcomer sees it: what stands at the top level, what the tests are
called, and what the code cites. Each test is named after what a newcomer tripped on."""

from __future__ import annotations

import re
from pathlib import Path

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[1]
TOP_LEVEL = {".ci", ".git", ".gitignore", "LICENSE", "README.md", "benchmarks", "docs",
             "pyproject.toml", "sample_inputs", "src", "tests"}
# what a checkout may hold besides, made by installing or testing it (all in .gitignore)
LOCAL = {".venv", "venv", "build", "dist", ".pytest_cache", ".ruff_cache", ".hypothesis",
         "bertini_output"}
WHERE_CODE_CITES = ("src", "tests", "sample_inputs", "benchmarks", "docs")


def _texts():
    for folder in WHERE_CODE_CITES:
        for p in sorted((ROOT / folder).rglob("*")):
            if p.suffix in (".py", ".toml", ".md") and "__pycache__" not in p.parts:
                yield p, p.read_text(encoding="utf-8")
    yield ROOT / "README.md", (ROOT / "README.md").read_text(encoding="utf-8")


def test_no_stray_output_files_at_the_top_level():
    """A scan's output (out.txt) and an empty err.txt were committed beside README.md."""
    extra = {p.name for p in ROOT.iterdir()} - TOP_LEVEL - LOCAL
    extra = {n for n in extra if not n.endswith(".egg-info")}
    assert not extra, f"unexpected at the top level: {sorted(extra)}"


def test_license_file_is_the_license_pyproject_names():
    """pyproject said MIT and there was no LICENSE file."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert project["license"] == {"text": "MIT"}
    text = (ROOT / "LICENSE").read_text()
    assert text.startswith("MIT License")
    assert "WITHOUT WARRANTY OF ANY KIND" in text


def test_test_files_are_named_by_what_they_test_not_by_review_rounds():
    """test_look_i20, test_review_i22, test_second_reading: names a newcomer cannot place."""
    rounds = re.compile(r"(_i\d+\b|_i\d+_|look|review|second_reading|seed)")
    bad = [p.name for p in (ROOT / "tests").glob("*.py") if rounds.search(p.stem)]
    assert not bad, bad


def test_code_cites_only_what_a_reader_of_the_repository_can_open():
    """35 docstrings cited a reference page and three source documents by names (the page,
    'seed' and a number) that are not in the repository."""
    outside = re.compile("PROBLEMS" + r"\.md|\bseed[ -]?0" + r"0\d", re.IGNORECASE)  # not itself a hit
    hits = [f"{p.relative_to(ROOT)}:{i}" for p, text in _texts()
            for i, line in enumerate(text.splitlines(), 1) if outside.search(line)]
    assert not hits, hits


def test_every_file_the_code_and_docs_cite_exists():
    """A citation is only worth something if the page (or test, or benchmark) is there to
    open: the README's split into docs/ and the tests' new names moved many."""
    cited = re.compile(r"(?<![\w/.])((?:docs|tests|benchmarks)/[\w.-]+\.(?:md|toml|png|py))")
    missing = sorted({f"{p.relative_to(ROOT)} -> {m}" for p, text in _texts()
                      for m in cited.findall(text) if not (ROOT / m).exists()})
    assert not missing, missing


def test_worked_examples_page_restates_every_problem_the_code_names():
    """Code says 'P3' and 'worked example P7': the page must have each of them."""
    page = (ROOT / "docs" / "worked_examples.md").read_text()
    named = {int(n) for _, text in _texts() for n in re.findall(r"worked example P(\d)", text)}
    assert named, "nothing cites the worked examples"
    for n in sorted(named):
        assert re.search(rf"^## P{n}\. ", page, re.MULTILINE), f"P{n} missing"
