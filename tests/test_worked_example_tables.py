"""The Freudenstein four-bar tables and the course notes' quadratic tables (docs/worked_examples.md P1,
P2), row by row.

Every value must round to the digits the seed printed. Run through the API and
through the CLI (JSON and CSV), so both paths are held to the same reference.
"""

from __future__ import annotations

import csv
import io
import itertools
import json

import pytest

from conftest import assert_rows, matches
from linkage import fourbar_equation, solve_scalar
from linkage.problems.expression import equation_problem
from worked_example_tables import (
    BISECTION,
    FIXED_POINT,
    NEWTON,
    QUADRATIC_NEWTON,
    QUADRATIC_ROOTS,
    SECANT,
)


def slope_slack(rows: list[tuple]) -> dict[int, list[float]]:
    """Secant slopes are (f_i - f_i-1)/(x_i - x_i-1) with f near 1e-6 at the end: each f
    carries about 4 eps of absolute rounding (terms of size ~1 cancel), so the slope is
    determined only to 8 eps / |x_i - x_i-1|. Row 5's printed last digit lies below that
    (40-digit value 0.0311429171714769; the seed printed 0.03114291718)."""
    eps = 2.220446049250313e-16
    out = [0.0]
    for prev, row in itertools.pairwise(rows):
        out.append(8 * eps / abs(row[1] - prev[1]))
    return {3: out}

SEED_RUNS = {
    # method: (expected table, API keyword arguments, CLI arguments)
    "bisection": (BISECTION, {"bracket": (50, 60)}, ["--bracket", "50", "60"]),
    "newton": (NEWTON, {"x0": 50}, ["--x0", "50"]),
    "secant": (SECANT, {"x0": 50, "x1": 60}, ["--x0", "50", "--x1", "60"]),
    "fixed-point": (FIXED_POINT, {"x0": 50}, ["--x0", "50"]),
}


@pytest.mark.parametrize("method", list(SEED_RUNS))
def test_seed_002_tables_from_the_api(method):
    expected, kwargs, _ = SEED_RUNS[method]
    result = solve_scalar(fourbar_equation(70.0), method=method, tol=1e-6, **kwargs)
    assert result.converged
    rows = list(result.history.rows)
    slack = slope_slack(rows) if method == "secant" else None
    assert_rows(rows, expected, label=method, slack=slack)


def test_secant_slopes_match_40_digit_arithmetic():
    mp = pytest.importorskip("mpmath")
    mp.mp.dps = 40

    def f(x):
        d = mp.pi / 180
        return (mp.mpf(5) / 3 * mp.cos(70 * d) - mp.mpf(5) / 2 * mp.cos(mp.mpf(x) * d)
                + mp.mpf(11) / 6 - mp.cos((70 - mp.mpf(x)) * d))

    rows = solve_scalar(fourbar_equation(70.0), method="secant", x0=50, x1=60).history.rows
    for prev, row in itertools.pairwise(rows):
        exact = (f(row[1]) - f(prev[1])) / (mp.mpf(row[1]) - mp.mpf(prev[1]))
        assert abs(row[3] - float(exact)) <= 8 * 2.2e-16 / abs(row[1] - prev[1]) + 1e-15


@pytest.mark.parametrize("method", list(SEED_RUNS))
def test_seed_002_tables_from_the_cli_json(cli, method):
    expected, _, args = SEED_RUNS[method]
    run = cli("solve", "--method", method, "--alpha", "70", *args, "--format", "json")
    assert run.code == 0, run.err
    doc = json.loads(run.out)
    rows = [tuple(row.values()) for row in doc["iterations"]]
    slack = slope_slack(rows) if method == "secant" else None
    assert_rows(rows, expected, label=f"cli json {method}", slack=slack)
    assert doc["converged"] is True
    assert matches(doc["solution"]["phi"], "54.887763")


@pytest.mark.parametrize("method", list(SEED_RUNS))
def test_seed_002_tables_from_the_cli_csv(cli, method):
    expected, _, args = SEED_RUNS[method]
    run = cli("solve", "--method", method, *args, "--format", "csv")
    assert run.code == 0, run.err
    reader = csv.reader(io.StringIO(run.out))
    header = next(reader)
    assert header[0] == "i" and any("(deg)" in h for h in header)
    rows = [tuple(float(c) if c else None for c in r) for r in reader]
    slack = slope_slack(rows) if method == "secant" else None
    assert_rows(rows, expected, label=f"cli csv {method}", slack=slack)


def test_default_solve_is_the_seed_newton_table(cli):
    run = cli("solve")
    assert run.code == 0, run.err
    lines = run.out.splitlines()
    # the four rows of P2's Newton table, as printed (12 significant digits)
    for i, phi_next in ((1, "55.2191411577"), (2, "54.889040279"), (3, "54.8877632079"),
                        (4, "54.8877631888")):
        row = next(line for line in lines if line.split()[:1] == [str(i)])
        assert phi_next in row, row
    assert "converged" in run.out
    assert "estimated order 2.0" in run.out


@pytest.mark.parametrize("x0", list(QUADRATIC_NEWTON))
def test_seed_000_quadratic_newton_tables(x0):
    problem = equation_problem("x**2 - 4*x + 1")
    result = solve_scalar(problem, method="newton", x0=float(x0), tol=1e-4)
    # the course notes columns: k, x, f, f', f/f' (= x_k - x_k+1)
    ours = [(i, x, f, d, x - x_next) for i, x, f, d, x_next, _ in result.history.rows]
    expected = QUADRATIC_NEWTON[x0]
    assert_rows(ours[: len(expected)], expected, label=f"x0={x0}")
    # the notes' fifth line is x_5; ours is the same iterate
    x5 = result.history.rows[3][4]
    assert matches(x5, QUADRATIC_ROOTS[x0])


@pytest.mark.parametrize("x0", list(QUADRATIC_NEWTON))
def test_seed_000_quadratic_from_the_cli(cli, x0):
    run = cli("solve", "--equation", "x^2 - 4*x + 1", "--x0", x0, "--tol", "1e-4", "--format", "json")
    assert run.code == 0, run.err
    doc = json.loads(run.out)
    rows = [(r["i"], r["x_i"], r["f(x_i)"], r["f'(x_i)"], r["x_i"] - r["x_i+1"])
            for r in doc["iterations"]]
    expected = QUADRATIC_NEWTON[x0]
    assert_rows(rows[: len(expected)], expected, label=f"cli x0={x0}")


def test_quadratic_root_depends_on_the_start():
    """P1: x0 = 5 and 2.5 find 2 + sqrt 3, x0 = 1 finds 2 - sqrt 3."""
    problem = equation_problem("x**2 - 4*x + 1")
    roots = {x0: solve_scalar(problem, method="newton", x0=x0, tol=1e-12).root for x0 in (5, 2.5, 1)}
    assert roots[5] == pytest.approx(2 + 3 ** 0.5, abs=1e-12)
    assert roots[2.5] == pytest.approx(2 + 3 ** 0.5, abs=1e-12)
    assert roots[1] == pytest.approx(2 - 3 ** 0.5, abs=1e-12)


@pytest.mark.parametrize("alpha,phi", [
    (10, "8.06934531362"), (40, "32.01518035933"), (70, "54.88776318878"),
    (100, "75.27087338607"), (130, "90.12408036526"), (160, "92.73496285135"),
])
def test_seed_002_solution_table_for_every_alpha(alpha, phi):
    """The seed's table of roots, reached from the default start at each alpha."""
    result = solve_scalar(fourbar_equation(alpha), method="newton", tol=1e-12)
    assert result.converged
    assert matches(result.root, phi)


@pytest.mark.parametrize("method,order,rate", [
    ("newton", 2.0, None), ("secant", 1.6, None), ("bisection", 1.0, 0.5), ("fixed-point", 1.0, 0.1275),
])
def test_estimated_orders_printed_for_the_seed_runs(cli, method, order, rate):
    """Newton about 2, secant about 1.6, bisection and fixed-point linear at rates about
    0.5 and 0.1275 (the student report's convergence analyses)."""
    doc = json.loads(cli("solve", "--method", method, "--format", "json").out)
    conv = doc["convergence"]
    assert conv["order"] == pytest.approx(order, abs=0.06)
    if rate is not None:
        assert conv["rate"] == pytest.approx(rate, abs=0.002)
    from linkage.render.report import fmt

    table = cli("solve", "--method", method).out
    assert f"estimated order {fmt(conv['order'], 4)} (theory" in table
