"""Halley's method, added as one registry entry, one module and this test: its table
from the CLI, and its order 3 against theory on a 40-digit reference."""

from __future__ import annotations

import math

import mpmath
import pytest

from linkage import equation_problem, solve_scalar
from linkage.analysis.convergence import analyze
from linkage.errors import InputError
from linkage.problems.scalar import ScalarProblem
from linkage.result import Status

EQUATIONS = [("x**3 - 2*x - 5", 4.0), ("cos(x) - x", 3.0), ("exp(x) - 10*x", 5.0), ("x**2 - 2", 20.0)]


def _root(text: str, x0: float) -> mpmath.mpf:
    """The root a 40-digit Newton converges to from the Halley solve's answer."""
    f = {"x**3 - 2*x - 5": lambda x: x**3 - 2 * x - 5, "cos(x) - x": lambda x: mpmath.cos(x) - x,
         "exp(x) - 10*x": lambda x: mpmath.exp(x) - 10 * x, "x**2 - 2": lambda x: x**2 - 2}[text]
    with mpmath.workdps(40):
        return mpmath.findroot(f, mpmath.mpf(x0))


@pytest.mark.parametrize("text,x0", EQUATIONS)
def test_halley_converges_with_order_3_against_a_40_digit_root(text, x0):
    p = equation_problem(text)
    r = solve_scalar(p, method="halley", x0=x0, tol=1e-15, max_iter=50)
    assert r.converged, r.message
    root = _root(text, r.x)
    with mpmath.workdps(40):
        assert abs(mpmath.mpf(r.x) - root) <= 4 * math.ulp(float(root)) + 1e-300
        # the true errors of the iterates x_i (column 1), measured against the 40-digit root
        errors = [float(abs(mpmath.mpf(x) - root)) for x in [row[1] for row in r.history.rows] + [r.x]]
    # above rounding level: q = log(e_k+1 / e_k) / log(e_k / e_k-1) on the last three
    usable = [e for e in errors if e > 1e-12 * max(1.0, abs(float(root)))]
    assert len(usable) >= 3, errors
    a, b, c = usable[-3:]
    assert math.log(c / b) / math.log(b / a) == pytest.approx(3.0, abs=0.35), (text, errors)
    conv = analyze(r, p)
    assert conv.theory_order == 3.0
    # Newton from the same start, for contrast: its local order is 2, not 3
    newton = solve_scalar(p, method="newton", x0=x0, tol=1e-15, max_iter=50)
    assert r.iterations <= newton.iterations


def test_halley_table_from_the_cli(cli):
    run = cli("solve", "--method", "halley", "--equation", "x**3 - 2*x - 5", "--x0", "4", "--tol", "1e-14",
              "--format", "plain")
    assert run.code == 0, run.err
    header = next(line for line in run.out.splitlines() if "f''(x_i)" in line)
    assert header.split() == ["i", "x_i", "f(x_i)", "f'(x_i)", "f''(x_i)", "x_i+1", "error"]
    assert "method: halley" in run.out and "(theory 3)" in run.out
    assert "x = 2.09455148154233" in run.out


def test_halley_records_nothing_that_changes_the_answer():
    p = equation_problem("x**3 - 2*x - 5")
    on = solve_scalar(p, method="halley", x0=4.0, tol=1e-12)
    off = solve_scalar(p, method="halley", x0=4.0, tol=1e-12, record=False)
    assert (on.x, on.status, on.iterations, on.nfev) == (off.x, off.status, off.iterations, off.nfev)
    assert on.nfev == 1 + 3 * on.iterations


def test_halley_without_a_second_derivative_is_refused_by_name():
    with pytest.raises(InputError, match="halley needs the second derivative fsecond"):
        solve_scalar(ScalarProblem(lambda x: x * x - 2, fprime=lambda x: 2 * x), method="halley", x0=1.0)


def test_halley_stops_by_name_where_its_denominator_vanishes():
    # f = x + 1 with f' = 1 and (as given) f'' = 2: at x = 0, 2 f'^2 - f f'' = 2 - 2 = 0 exactly
    p = ScalarProblem(lambda x: x + 1.0, fprime=lambda x: 1.0, fsecond=lambda x: 2.0)
    r = solve_scalar(p, method="halley", x0=0.0)
    assert r.status is Status.ZERO_DERIVATIVE and "2 f'^2 - f f'' = 0" in r.detail
