"""A scalar method is its module, its registry entry and its test (issue 33: "adding
Halley's method touches at most 3 files"): no other file in the repository names the last
method added, and a method registered at run time, with no file of the repository edited,
runs through ``linkage solve`` with its own table and in ``--method all``."""

from __future__ import annotations

import json
import textwrap
from pathlib import Path

import mpmath
import pytest

from conftest import run_process

ROOT = Path(__file__).resolve().parents[1]
SEARCHED = ("src", "tests", "docs", "README.md", "benchmarks")
SKIPPED_PARTS = {"__pycache__", ".venv", ".git", ".pytest_cache", ".ruff_cache"}


def files_naming(word: str) -> set[str]:
    """Like ``grep -ril WORD src tests docs README.md benchmarks``: the text files whose
    text holds ``word`` in any case, relative to the repository, this test file excepted
    (it names the method to look for)."""
    here = Path(__file__).resolve()
    found = set()
    for top in SEARCHED:
        path = ROOT / top
        for f in [path] if path.is_file() else sorted(path.rglob("*")):
            if not f.is_file() or SKIPPED_PARTS & set(f.parts) or f.resolve() == here:
                continue
            try:
                text = f.read_text()
            except (UnicodeDecodeError, OSError):
                continue
            if word.lower() in text.lower():
                found.add(f.relative_to(ROOT).as_posix())
    return found


def test_the_last_method_added_is_named_in_its_module_its_entry_and_its_test_only():
    assert files_naming("halley") == {"src/linkage/methods/halley.py", "src/linkage/methods/__init__.py",
                                      "tests/test_halley.py"}


def test_the_search_finds_what_grep_finds():
    # a word every engine names, so the search cannot pass by finding nothing
    assert {"src/linkage/methods/newton.py", "docs/solving.md", "README.md"} <= files_naming("NEWTON")


# Steffensen's method: x - f(x)^2 / (f(x + f(x)) - f(x)), order 2 without a derivative
# (e.g. Dahlquist & Bjorck, Numerical Methods, section 6.2; the Wikipedia article
# "Steffensen's method"). Written here as a method outside the package would be.
TOY = '''
from dataclasses import dataclass
from typing import Any, ClassVar, NamedTuple

from linkage.methods.common import new_state, start_stop
from linkage.result import Column, Status


class SteffensenState(NamedTuple):
    x: float
    fx: float
    err: float
    stop: Any
    xp: float
    fxp: float
    fshift: float


@dataclass(frozen=True)
class Steffensen:
    name: ClassVar[str] = "steffensen"
    bracketing: ClassVar[bool] = False
    can_diverge: ClassVar[bool] = True
    needs_residual: ClassVar[bool] = False
    first_index: ClassVar[int] = 1
    init_evals: ClassVar[int] = 1
    step_evals: ClassVar[int] = 2

    def columns(self, problem):
        return (Column("i", "index"), Column("{v}_i", "x"), Column("f({v}_i)", "f"),
                Column("f({v}_i + f)", "f"), Column("{v}_i+1", "x"), Column("error", "x"))

    def init(self, problem, x0):
        fx = problem.f(x0)
        nan = float("nan")
        return SteffensenState(x0, fx, float("inf"), start_stop(problem, x0, fx), x0, fx, nan)

    def step(self, problem, s):
        x, fx = s.x, s.fx
        fs = problem.f(x + fx)
        if fs == fx:
            why = f"f(x + f) = f at {problem.var} = {x!r}"
            return new_state(SteffensenState, (x, fx, float("nan"), (Status.ZERO_DERIVATIVE, why), x, fx, fs))
        x1 = x - fx * fx / (fs - fx)
        return new_state(SteffensenState, (x1, problem.f(x1), abs(x1 - x), None, x, fx, fs))

    def initial_row(self, problem, s):
        return None

    def row(self, problem, s, i):
        if s.stop is not None:
            return (i, s.xp, s.fxp, s.fshift, None, None)
        return (i, s.xp, s.fxp, s.fshift, s.x, s.err)
'''

REGISTER_AND_RUN = '''
import sys
sys.path.insert(0, {folder!r})
from linkage.methods import MethodEntry, register
register(MethodEntry("steffensen", "toy_steffensen", "Steffensen", "x0", 2.0, 2,
                     "x - f^2 / (f(x + f) - f)"))
from linkage.cli import run_cli
sys.exit(run_cli({args!r}))
'''


@pytest.fixture(scope="module")
def toy_folder(tmp_path_factory) -> str:
    folder = tmp_path_factory.mktemp("toy_method")
    (folder / "toy_steffensen.py").write_text(textwrap.dedent(TOY))
    return str(folder)


def run_with_toy(folder: str, *args: str):
    return run_process(code=REGISTER_AND_RUN.format(folder=folder, args=list(args)))


def test_a_method_registered_at_run_time_prints_its_table(toy_folder):
    run = run_with_toy(toy_folder, "solve", "--method", "steffensen", "--equation", "x**3 - 2*x - 5",
                       "--x0", "2", "--tol", "1e-13", "--format", "json")
    assert run.returncode == 0, run.stderr
    doc = json.loads(run.stdout)
    assert doc["method"] == "steffensen" and doc["status"] == "converged_step"
    with mpmath.workdps(40):
        root = mpmath.findroot(lambda x: x**3 - 2 * x - 5, mpmath.mpf(2))
        assert abs(mpmath.mpf(doc["solution"]["x"]) - root) <= 1e-14
    # its entry's theory, and the order the convergence analysis measures on its iterates
    assert doc["convergence"]["theory_order"] == 2.0
    assert doc["convergence"]["order"] == pytest.approx(2.0, abs=0.1)
    table = run_with_toy(toy_folder, "solve", "--method", "steffensen", "--equation", "x**3 - 2*x - 5",
                         "--x0", "2", "--tol", "1e-13", "--format", "plain")
    assert table.returncode == 0, table.stderr
    header = next(line for line in table.stdout.splitlines() if "f(x_i + f)" in line)
    assert header.split() == ["i", "x_i", "f(x_i)", "f(x_i", "+", "f)", "x_i+1", "error"]
    assert "method: steffensen" in table.stdout and "(theory 2)" in table.stdout


def test_a_method_registered_at_run_time_is_in_method_all(toy_folder):
    run = run_with_toy(toy_folder, "solve", "--method", "all", "--format", "json")
    assert run.returncode == 0, run.stderr
    from linkage.methods import SCALAR_METHODS

    runs = json.loads(run.stdout)["runs"]
    assert [d["method"] for d in runs] == [*SCALAR_METHODS, "steffensen"]
    assert runs[-1]["solution"]["phi"] == pytest.approx(runs[0]["solution"]["phi"], abs=1e-5)
    on_an_equation = run_with_toy(toy_folder, "solve", "--equation", "x**2 - 2", "--x0", "1",
                                  "--method", "all", "--format", "json")
    assert "steffensen" in [d["method"] for d in json.loads(on_an_equation.stdout)["runs"]]


def test_methods_named_with_commas_are_compared_in_one_summary(cli):
    run = cli("solve", "--method", "secant,newton", "--format", "json")
    assert run.code == 0, run.err
    runs = json.loads(run.out)["runs"]
    assert [d["method"] for d in runs] == ["secant", "newton"]
    assert all(d["seconds_per_solve"] > 0 for d in runs)


@pytest.mark.parametrize("named,why", [("newton,nope", "unknown method 'nope'"),
                                        ("newton,newton", "a method named twice")])
def test_a_named_set_with_an_unknown_or_repeated_method_is_refused_in_one_line(cli, named, why):
    run = cli("solve", "--method", named)
    assert run.code == 2 and run.out == ""
    assert len(run.err.strip().splitlines()) == 1 and why in run.err
