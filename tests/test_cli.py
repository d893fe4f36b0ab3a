"""The command line: exit codes, one-line errors, formats, help."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import pytest

from conftest import run_process

BAD_INPUT = {
    "unknown method": (["--method", "golden"], "unknown method 'golden'"),
    "tolerance zero": (["--tol", "0"], "tol must be > 0"),
    "tolerance negative": (["--tol", "-1e-6"], "tol must be > 0"),
    "tolerance nan": (["--tol", "nan"], "tol must be finite"),
    "tolerance inf": (["--tol", "inf"], "tol must be finite"),
    "tolerance not a number": (["--tol", "abc"], "--tol"),
    "max-iter zero": (["--max-iter", "0"], "max_iter must be an integer >= 1"),
    "bracket without sign change": (["--method", "bisection", "--bracket", "60", "70"],
                                    "f(60) = 0.168559, f(70) = 0.548317"),
    "equal secant points": (["--method", "secant", "--x0", "50", "--x1", "50"],
                            "two different starting points"),
    "nan start": (["--x0", "nan"], "x0 must be finite"),
    "inf start": (["--x0", "inf"], "x0 must be finite"),
    "nan alpha": (["--alpha", "nan"], "alpha must be finite"),
    "nan bracket": (["--method", "bisection", "--bracket", "nan", "60"], "bracket start must be finite"),
    "equation does not parse": (["--equation", "x**", "--x0", "1"], "could not parse the equation"),
    "unknown name": (["--equation", "y + 1", "--x0", "1"], "unknown name 'y'"),
    "unsafe call": (["--equation", "__import__('os').system('true')", "--x0", "1"], "unknown function"),
    "attribute access": (["--equation", "x.real", "--x0", "1"], "is not allowed"),
    "unknown format": (["--format", "xml"], "unknown format 'xml'"),
    "bad fraction": (["--r1", "5/0"], "R1 must be a finite number"),
    "negative link": (["--links", "2", "4", "3", "-5"], "link length d must be a finite number > 0"),
    "newton without start on an equation": (["--equation", "x - 1"], "needs a starting point"),
    "bisection without bracket on an equation": (["--equation", "x - 1", "--method", "bisection"],
                                                 "needs a bracket"),
    "fixed-point without g": (["--equation", "x - 1", "--method", "fixed-point", "--x0", "1"],
                              "fixed-point needs the iteration function"),
    "four-bar options with an equation": (["--equation", "x", "--alpha", "3", "--x0", "1"],
                                          "cannot be combined with --equation"),
    "unknown option": (["--bogus"], "--bogus"),
    "missing option value": (["--bracket", "1"], "--bracket"),
}


@pytest.mark.parametrize("case", list(BAD_INPUT))
def test_bad_input_is_one_line_and_exit_2(cli, case):
    args, expected = BAD_INPUT[case]
    run = cli("solve", *args)
    assert run.code == 2, (run.code, run.out, run.err)
    lines = run.err.strip().splitlines()
    assert len(lines) == 1, run.err
    assert lines[0].startswith("error: ")
    assert expected in lines[0]
    assert "Traceback" not in run.err + run.out


def test_missing_output_directory_is_bad_input(cli, tmp_path):
    run = cli("solve", "--output", str(tmp_path / "no" / "such" / "dir.csv"))
    assert run.code == 2 and "cannot write" in run.err


def test_diverging_newton_exits_1_and_shows_its_rows(cli):
    run = cli("solve", "--equation", "atan(x)", "--x0", "1.5", "--format", "json")
    assert run.code == 1
    doc = json.loads(run.out)
    assert doc["status"] == "diverged" and doc["converged"] is False
    assert len(doc["iterations"]) >= 5
    xs = [abs(r["x_i+1"]) for r in doc["iterations"]]
    assert xs == sorted(xs)  # each iterate further out than the last


def test_zero_derivative_is_named_and_exits_1(cli):
    run = cli("solve", "--equation", "x**2 + 1", "--x0", "0")
    assert run.code == 1
    assert "stalled: the derivative (or slope) is zero" in run.out


def test_domain_error_at_the_start_exits_1_without_traceback(cli):
    run = cli("solve", "--equation", "sqrt(x)", "--x0", "-1")
    assert run.code == 1
    assert "outside its domain" in run.out
    assert "Traceback" not in run.err


def test_max_iter_stop_shows_rows_and_exits_1(cli):
    run = cli("solve", "--method", "bisection", "--max-iter", "5", "--format", "json")
    assert run.code == 1
    doc = json.loads(run.out)
    assert doc["status"] == "max_iter" and len(doc["iterations"]) == 5


def test_json_contract_and_round_trip_with_csv(cli):
    j = cli("solve", "--method", "secant", "--format", "json")
    c = cli("solve", "--method", "secant", "--format", "csv")
    assert j.code == c.code == 0
    doc = json.loads(j.out)
    for key in ("method", "status", "converged", "solution", "iterations", "convergence", "nfev"):
        assert key in doc
    assert doc["method"] == "secant" and doc["status"].startswith("converged")
    assert set(doc["solution"]) == {"phi"} and doc["units"] == {"phi": "deg"}
    assert doc["convergence"]["order"] == pytest.approx(1.65, abs=0.1)
    rows = list(csv.reader(io.StringIO(c.out)))
    header, body = rows[0], rows[1:]
    assert header == list(doc["iterations"][0].keys())
    assert all("(deg)" in h or h in ("i", "f(phi_i)") or "1/deg" in h for h in header)
    assert len(body) == len(doc["iterations"])
    for line, obj in zip(body, doc["iterations"]):
        for cell, (key, value) in zip(line, obj.items()):
            if value is None:
                assert cell == ""
            else:  # CSV keeps full precision: the exact same double comes back
                assert float(cell) == value, key


def test_method_all_lists_every_method(cli):
    run = cli("solve", "--method", "all", "--format", "json")
    assert run.code == 0
    docs = json.loads(run.out)["runs"]  # one document (an object), its runs under "runs"
    from linkage.methods import SCALAR_METHODS  # the registry, in the order tables list it

    assert [d["method"] for d in docs] == list(SCALAR_METHODS)
    assert SCALAR_METHODS[:5] == ("bisection", "regula-falsi", "hybrid", "secant", "newton")
    for d in docs:
        assert d["solution"]["phi"] == pytest.approx(54.887763188779143, abs=1e-6)
        assert d["seconds_per_solve"] > 0
    table = cli("solve", "--method", "all")
    assert "time per solve (us)" in table.out and "fixed-point" in table.out


def test_method_all_on_an_equation_runs_only_what_applies(cli):
    run = cli("solve", "--equation", "x**2 - 2", "--x0", "1", "--method", "all", "--format", "json")
    # from --x0 alone: every registered method that starts from x0 and needs only what an
    # equation has (its exact derivatives; no g without --g), in the registry's order
    from linkage import equation_problem
    from linkage.methods import METHODS

    problem = equation_problem("x**2 - 2")
    expected = [name for name, e in METHODS.items()
                if e.starts == "x0" and all(getattr(problem, attr) is not None for attr, _ in e.needs)]
    assert "newton" in expected and "fixed-point" not in expected and "secant" not in expected
    assert [d["method"] for d in json.loads(run.out)["runs"]] == expected


@pytest.mark.parametrize("fmt", ["table", "plain", "github", "grid", "latex"])
def test_human_formats_render_the_same_numbers(cli, fmt):
    run = cli("solve", "--format", fmt)
    assert run.code == 0
    assert "55.2191411577" in run.out and "54.8877631888" in run.out


def test_output_file_follows_the_suffix(cli, tmp_path):
    target = tmp_path / "run.json"
    run = cli("solve", "--output", str(target))
    assert run.code == 0 and run.out == ""
    assert json.loads(target.read_text())["solution"]["phi"] == pytest.approx(54.8877631888, abs=1e-9)


def test_links_give_the_seed_coefficients(cli):
    a = cli("solve", "--links", "2", "4", "3", "5", "--format", "json")
    b = cli("solve", "--format", "json")
    assert json.loads(a.out)["solution"] == json.loads(b.out)["solution"]


def all_commands() -> list[list[str]]:
    from linkage.cli import app

    return [[]] + [[c.name or c.callback.__name__] for c in app.registered_commands]


@pytest.mark.parametrize("command", all_commands(), ids=lambda c: " ".join(c) or "linkage")
def test_every_command_has_help_with_an_example(cli, command):
    run = cli(*command, "--help")
    assert run.code == 0
    assert "Example" in run.out and "linkage " in run.out
    assert len(all_commands()) >= 4  # solve, sweep, draw, and the top level


def test_help_lists_all_methods(cli):
    out = cli("solve", "--help").out
    for name in ("bisection", "regula-falsi", "hybrid", "secant", "newton", "fixed-point"):
        assert name in out


def test_entry_point_in_a_subprocess_prints_no_traceback():
    proc = run_process("solve", "--tol", "-1")
    assert proc.returncode == 2
    assert proc.stderr.strip() == "error: tol must be > 0, got -1.0"


def test_a_scalar_solve_does_not_import_numpy():
    code = (
        "import sys, runpy\n"
        "sys.argv = ['linkage', 'solve', '--method', 'all']\n"
        "try:\n"
        "    runpy.run_module('linkage', run_name='__main__')\n"
        "except SystemExit as e:\n"
        "    assert e.code == 0, e.code\n"
        "heavy = [m for m in ('numpy', 'scipy', 'matplotlib') if m in sys.modules]\n"
        "print('HEAVY', heavy)\n"
    )
    proc = run_process(code=code)
    assert proc.returncode == 0, proc.stderr
    assert "HEAVY []" in proc.stdout


def test_plain_tables_are_tabulates_simple_format_without_tabulate():
    """The plain renderer draws tabulate's ``simple`` format itself (tabulate costs ~20 ms
    of a piped command's start); random tables must come out identical."""
    import random

    from tabulate import tabulate

    from linkage.render.report import simple_table

    rng = random.Random(7)
    cells = ["—", "converged", "", "no_solution", "-0.5", "1e+300"]
    for _ in range(500):
        nc, nr = rng.randint(1, 7), rng.randint(0, 9)
        headers = ["h" * rng.randint(0, 14) for _ in range(nc)]
        rows = [[f"{rng.uniform(-1e5, 1e5):.{rng.randint(1, 12)}g}" if rng.random() < 0.7
                 else rng.choice(cells) for _ in range(nc)] for _ in range(nr)]
        want = tabulate(rows, headers=headers, tablefmt="simple", disable_numparse=True, stralign="right")
        assert simple_table(headers, rows) == want


def _simple_table_cell_by_cell(headers, rows):
    """simple_table as it was written before its lines went through one format: each cell
    right-aligned by str.rjust, a row's cells only (a short row's line ends early)."""
    widths = [len(h) + 2 for h in headers]
    for r in rows:
        for j, c in enumerate(r):
            widths[j] = max(widths[j], len(c))
    lines = ["  ".join(h.rjust(w) for h, w in zip(headers, widths)), "  ".join("-" * w for w in widths)]
    lines += ["  ".join(c.rjust(w) for c, w in zip(r, widths)) for r in rows]
    return "\n".join(line.rstrip() for line in lines)


def test_simple_table_is_its_cell_by_cell_layout_short_rows_included():
    """The one-format lines equal the cell-by-cell ones on random tables whose rows may
    be short (tabulate, above, pads them; this layout does not), with blanks, wide
    characters and braces in cells."""
    import random

    from linkage.render.report import simple_table

    rng = random.Random(11)
    cells = ["—", "converged", "", " ", "{}", "{0}", "-0.5", "1e+300", "open (mirror)"]
    for _ in range(500):
        nc, nr = rng.randint(1, 7), rng.randint(0, 9)
        headers = ["h" * rng.randint(0, 14) for _ in range(nc)]
        rows = [tuple(f"{rng.uniform(-1e5, 1e5):.{rng.randint(1, 12)}g}" if rng.random() < 0.6
                      else rng.choice(cells) for _ in range(rng.randint(0, nc) if rng.random() < 0.3 else nc))
                for _ in range(nr)]
        assert simple_table(headers, rows) == _simple_table_cell_by_cell(headers, rows)


def test_a_piped_solve_does_not_import_tabulate():
    from conftest import run_process

    p = run_process(code="import sys; from linkage.cli import run_cli; run_cli(['solve']); "
                         "print('tabulate' in sys.modules, file=sys.stderr)")
    assert p.stderr.strip().endswith("False")


@pytest.mark.parametrize("args", [
    ("solve", "--equation", "x**2 + 1", "--x0", "1"),
    # a mechanism that assembles, stopped by the cap (at theta2 = 150 it cannot be assembled:
    # refused as bad input, tests/test_unassemblable_refusals.py)
    ("solve", str(Path(__file__).resolve().parents[1] / "sample_inputs" / "fourbar_me581.toml"),
     "--max-iter", "2"),
])
def test_a_failed_run_has_no_solution_only_a_last_iterate(cli, args):
    run = cli(*args, "--format", "json")
    doc = json.loads(run.out)
    assert run.code == 1 and doc["converged"] is False
    assert doc["solution"] is None and doc["last_iterate"]
    text = cli(*args, "--format", "plain").out
    assert "last iterate" in text


def test_method_all_leaves_the_root_blank_for_a_failed_method(cli):
    doc = cli("solve", "--method", "all", "--equation", "x**2 - 2", "--x0", "1", "--x1", "2",
              "--bracket", "3", "4", "--format", "csv")
    rows = [r.split(",") for r in doc.out.splitlines()[1:]]
    for r in rows:
        if r[1] in ("converged_step", "converged_exact", "converged_residual"):
            assert r[4]
        else:
            assert r[4] == "", r


def test_a_run_builds_only_the_command_it_names(cli):
    """typer builds a parser for every registered command before it dispatches; a run
    that names a command gets an app with only that one. Its help and errors read as
    before, and anything that is not a command name gets the whole app."""
    from linkage.cli import _app_for, app

    assert [c.callback.__name__ for c in _app_for(["sweep", "x.toml"]).registered_commands] == ["sweep"]
    for args in ([], ["--help"], ["--version"], ["sovle"]):
        assert _app_for(args) is app
    assert cli("sweep", "--help").out.count("Usage: linkage sweep") == 1
    bad = cli("sovle")
    assert bad.code == 2 and "No such command 'sovle'" in bad.err and "solve" in bad.err
    top = cli("--help").out
    assert all(name in top for name in ("solve", "sweep", "scan", "draw", "samples", "stress", "bench"))


def test_plain_numbers_parse_as_fractions_do():
    """parse_number reads plain decimals with float() (fractions costs a cold start ~2 ms):
    the same double as Fraction, and the same refusals."""
    import random
    from fractions import Fraction

    from linkage.errors import InputError
    from linkage.numbers import parse_number

    rng = random.Random(3)
    for _ in range(5000):
        text = f"{rng.choice(['', '-', '+'])}{rng.randrange(10 ** rng.randrange(1, 20))}." \
               f"{rng.randrange(10 ** rng.randrange(1, 20))}e{rng.randrange(-320, 280)}"
        assert parse_number("x", text) == float(Fraction(text)), text
    assert parse_number("x", " 2.5 ") == 2.5 and parse_number("x", "5/3") == float(Fraction(5, 3))
    for text in ("1e400", "-1e999", "nan", "inf", "-inf", "1e", ".", "", "1 5", "+-1", "0x10", "1/0"):
        with pytest.raises(InputError):
            parse_number("x", text)


def test_a_solve_that_exits_1_to_a_table_file_says_why_on_stderr(cli, tmp_path):
    """A table file (csv) holds the iterations but not the verdict: a run that ends exit 1
    says its status and reason on stderr, one note per method that did not converge (the
    reason was nowhere but in -f json or the display)."""
    out = tmp_path / "s.csv"
    run = cli("solve", "-e", "x**2+1", "--x0", "1", "-o", str(out))
    assert run.code == 1 and out.exists()
    assert "note: newton: zero_derivative: stalled: the derivative (or slope) is zero" in run.err
    assert cli("solve", "-e", "x**2+1", "--x0", "1", "-o", str(tmp_path / "s.json")).err.count("note:") == 0
