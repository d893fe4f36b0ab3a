"""The documents' promises: the quick start is what CI runs, and every example in the README
and docs/ prints what the page shows.

A fenced block whose lines start with ``$ linkage`` is an example. Each command runs, in
order, in a scratch folder of its page holding copies of sample_inputs/ and docs/ (so an
example that writes a file writes it there, and a later one on the page can read it), and
must exit as its ``# exit N`` comment says (0 without one). The lines
after a command are what it prints to standard output, compared line for line, except:
- a line ``...`` stands for any number of lines, and a line ending in ``...`` for any line
  that starts with what comes before it;
- a time (a number followed by s, ms or us) matches any time.
A block that cannot be run in a test (timings, minutes of work) says so with
``<!-- not run: REASON -->`` on the line before its fence.
"""

from __future__ import annotations

import re
import shlex
import shutil
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"^(?P<indent> *)```(?P<info>[^\n]*)\n(?P<body>.*?)^(?P=indent)```", re.M | re.S)
NOT_RUN = re.compile(r"<!-- not run: (?P<why>[^>]*\S) -->\s*$")
TIME = re.compile(r"\b\d[\d,]*(\.\d+)?(e-?\d+)? ?(s|ms|us)\b")


@dataclass(frozen=True)
class Example:
    page: str
    line: int
    command: str
    code: int
    shown: tuple[str, ...]  # the output lines the page shows (empty: only the exit code counts)

    def __str__(self) -> str:
        return f"{self.page}:{self.line}: {self.command}"


def _blocks(path: Path):
    """(line number, body, reason not run or None) of every fenced block with a command."""
    text = path.read_text()
    for m in FENCE.finditer(text):
        body = "\n".join(line[len(m["indent"]):] for line in m["body"].splitlines())
        if not re.search(r"^\$ ", body, re.M):
            continue
        before = text[: m.start()].rstrip("\n").rsplit("\n", 1)[-1]
        why = NOT_RUN.search(before)
        yield text.count("\n", 0, m.start()) + 1, body, why["why"] if why else None


def _examples(path: Path) -> list[Example]:
    out = []
    for line, body, why in _blocks(path):
        if why:
            continue
        lines = body.splitlines()
        i = 0
        while i < len(lines):
            start = i
            command = lines[i][2:]
            while command.endswith("\\"):
                i += 1
                command = command[:-1] + " " + lines[i].strip()
            i += 1
            shown = []
            while i < len(lines) and not lines[i].startswith("$ "):
                shown.append(lines[i])
                i += 1
            comment = re.search(r"#.*\bexit (\d+)", command)
            out.append(Example(path.name, line + 1 + start, command.strip(),
                               int(comment.group(1)) if comment else 0, tuple(shown)))
    return out


EXAMPLES = [e for page in PAGES for e in _examples(page)]


def _matches(actual: list[str], shown: list[str]) -> bool:
    """Whether ``actual`` is what ``shown`` shows (``...`` lines, times as any time)."""
    def same(a: str, s: str) -> bool:
        a, s = TIME.sub("<time>", a.rstrip()), TIME.sub("<time>", s.rstrip())
        return a.startswith(s[:-3].rstrip()) if s.endswith("...") else a == s

    # a small matcher with backtracking over the "..." lines
    memo: dict[tuple[int, int], bool] = {}

    def go(i: int, j: int) -> bool:
        if (i, j) not in memo:
            if j == len(shown):
                ok = i == len(actual)
            elif shown[j].strip() == "...":
                ok = any(go(k, j + 1) for k in range(i, len(actual) + 1))
            else:
                ok = i < len(actual) and same(actual[i], shown[j]) and go(i + 1, j + 1)
            memo[(i, j)] = ok
        return memo[(i, j)]

    return go(0, 0)


def _trim(lines: list[str]) -> list[str]:
    lines = [line.rstrip() for line in lines]
    while lines and not lines[0]:
        lines.pop(0)
    while lines and not lines[-1]:
        lines.pop()
    return lines


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


def test_the_readme_is_a_short_guide_that_links_every_docs_page():
    """The README was 1,695 lines mixing usage, test names, benchmarks and fix history. A
    tour of every command with one example each (and a picture for the synthesis and
    continuation commands: issue 34) fits in 450."""
    assert len(README.splitlines()) <= 450
    for page in PAGES[1:]:
        if page.name.endswith(".md"):
            assert f"docs/{page.name}" in README, f"the README does not link docs/{page.name}"


def test_every_command_example_runs_or_says_why_not():
    """Each page's examples are found (a block that is not run gives its reason)."""
    for page in PAGES:
        for _, body, why in _blocks(page):
            commands = [line for line in body.splitlines() if line.startswith("$ ")]
            if why is None:
                strays = [c for c in commands if not c.startswith("$ linkage ")]
                assert not strays, f"{page.name}: only linkage commands can be checked: {strays}"
    assert len(EXAMPLES) >= 30
    assert any(e.page == "README.md" and e.shown for e in EXAMPLES)


@pytest.fixture(scope="module")
def scratch(tmp_path_factory):
    """One folder per page, made on first use."""
    folders: dict[str, Path] = {}

    def folder(page: str) -> Path:
        if page not in folders:
            folders[page] = tmp_path_factory.mktemp(page.replace(".", "_"))
            for name in ("sample_inputs", "docs"):
                shutil.copytree(ROOT / name, folders[page] / name)
        return folders[page]

    return folder


@pytest.mark.parametrize("example", EXAMPLES, ids=str)
def test_every_example_prints_what_its_page_shows(cli, example, scratch, monkeypatch):
    monkeypatch.chdir(scratch(example.page))
    args = shlex.split(example.command, comments=True)
    assert args[0] == "linkage"
    run = cli(*args[1:])
    assert run.code == example.code, f"{example}: exit {run.code}\n{run.err}"
    shown = _trim(list(example.shown))
    if shown:
        actual = _trim(run.out.splitlines())
        assert _matches(actual, shown), (
            f"{example}\n--- the page shows ---\n" + "\n".join(shown)
            + "\n--- the command prints ---\n" + "\n".join(actual))


def test_the_quick_start_names_every_test_extra():
    """The quick start says what its second line installs: every package of the test extra."""
    import re as _re

    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        import tomli as tomllib
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]["test"]
    said = " ".join(README.split("## Quick start", 1)[1].split("## ", 1)[0].split())
    for requirement in extras:
        name = _re.split(r"[\[<>=!~ ]", requirement, maxsplit=1)[0]
        assert name in said, f"the quick start does not name {name}"


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
