"""Scalar Newton's short front door (solve/scalar.py, ``solve_scalar``'s first branch) and
the loops' iteration range (iterate.py, ``STEPS``): the front door calls the quiet loop
itself, so a function that fails there must get the Result :func:`newton_result` gives (the
definition it stands in for), and a loop at the default cap must take every step."""

from __future__ import annotations

import math

import numpy as np
import pytest

from linkage import ScalarProblem, solve_scalar
from linkage.iterate import STEPS, Criteria
from linkage.result import Status
from linkage.solve.criteria import check_criteria
from linkage.solve.scalar import newton_result


def _fields(r: object) -> tuple[str, ...]:
    names = ("method", "x", "status", "iterations", "nfev", "error", "residual", "detail", "history",
             "njev", "meta")
    return tuple(repr(getattr(r, name)) for name in names)  # repr: nan equals nan, -0.0 is not 0.0


def _log_at_start(x: float) -> float:
    return math.log(x)  # ValueError at a negative start


def _inverse_at_start(x: float) -> float:
    return 1.0 / x  # ZeroDivisionError at 0


def _complex_root(x: float) -> float:
    return (x - 5.0) ** 0.5 - 1.0  # complex left of 5: the step's comparison raises TypeError


def _to_infinity(x: float) -> float:
    return math.exp(x) - 1e300  # a step to infinity: the loop names it (NON_FINITE)


FAILING = [
    ("ValueError at the start", ScalarProblem(_log_at_start, fprime=lambda x: 1.0 / x), -1.0),
    ("ZeroDivisionError at the start", ScalarProblem(_inverse_at_start, fprime=lambda x: -1.0 / x**2), 0.0),
    ("a complex f", ScalarProblem(_complex_root, fprime=lambda x: 1.0), 1.0),
    ("a derivative that returns None", ScalarProblem(lambda x: x * x - 2.0, fprime=lambda x: None), 1.0),
    ("a derivative that raises TypeError", ScalarProblem(lambda x: x * x - 2.0, fprime=lambda x: "2x"), 1.0),
    ("an infinite step", ScalarProblem(_to_infinity, fprime=lambda x: 1e-300), 0.0),
]


@pytest.mark.parametrize(("case", "problem", "x0"), FAILING, ids=[c[0] for c in FAILING])
def test_the_short_front_door_answers_a_failing_function_as_newton_result_does(case, problem, x0):
    crit = check_criteria(1e-12, 0.0, None, 100)
    for _ in range(2):  # the criteria checked, then remembered
        fast = solve_scalar(problem, method="newton", x0=x0, tol=1e-12, record=False)
        assert _fields(fast) == _fields(newton_result(problem, x0, crit, False)), case
        assert not fast.converged


def test_the_short_front_door_answers_a_good_function_as_newton_result_does():
    # the loop gets the criteria's values as a plain tuple, remembered or not (a numpy tolerance)
    problem = ScalarProblem(lambda x: x * x - 2.0, fprime=lambda x: 2.0 * x)
    cases = ((1e-12, None, 100), (1e-9, 1e-3, 7), (1e-15, None, 3), (np.float64(1e-10), None, 9))
    for tol, ftol, max_iter in cases:
        crit = check_criteria(tol, 0.0, ftol, max_iter)
        for _ in range(2):
            fast = solve_scalar(problem, method="newton", x0=1.0, tol=tol, ftol=ftol, max_iter=max_iter,
                                record=False)
            assert _fields(fast) == _fields(newton_result(problem, 1.0, crit, False))
            assert fast.meta["tol"] == tol and fast.meta["ftol"] == ftol


def _cycle(x: float) -> float:
    return x**3 - 2.0 * x + 2.0  # Newton from 0 cycles 0, 1, 0, ... (methods/newton.py)


@pytest.mark.parametrize("max_iter", [1, 99, 100, 101, 250])
def test_a_loop_at_the_default_cap_takes_every_step(max_iter):
    assert STEPS == range(1, Criteria().max_iter + 1)
    for record in (False, True):
        newton = solve_scalar(_cycle, method="newton", x0=0.0, fprime=lambda x: 3.0 * x * x - 2.0,
                              max_iter=max_iter, record=record)
        fixed = solve_scalar(_cycle, method="fixed-point", x0=1.0, g=lambda x: -x, max_iter=max_iter,
                             record=record)
        for r in (newton, fixed):
            assert (r.status, r.iterations) == (Status.MAX_ITER, max_iter)



def _refuses_far(x: float) -> float:
    if x > 50.0:
        raise ValueError(f"no model beyond 50, got {x!r}")
    return x * x - 4.0


def _slope_refuses_far(x: float) -> float:
    if x > 5.0:
        raise ValueError(f"no slope beyond 5, got {x!r}")
    return 2.0 * x


def test_a_function_that_raises_mid_loop_leaves_the_last_point_as_the_recording_loop_does():
    # the quiet loop writes f's value over fx; the recording loop keeps it apart (fx1)
    cases = [(ScalarProblem(_refuses_far, fprime=lambda x: 2.0 * x), x0) for x0 in (0.01, 3.0)]
    cases.append((ScalarProblem(lambda x: x * x - 4.0, fprime=_slope_refuses_far), 0.3))
    for problem, x0 in cases:
        quiet = solve_scalar(problem, method="newton", x0=x0, tol=1e-12, record=False)
        recorded = solve_scalar(problem, method="newton", x0=x0, tol=1e-12, record=True)
        assert _fields(quiet)[:8] == _fields(recorded)[:8]
    at_start = solve_scalar(cases[0][0], method="newton", x0=0.01, record=False)
    assert (at_start.status, at_start.x, at_start.residual) == (Status.DOMAIN_ERROR, 0.01, 0.01 * 0.01 - 4.0)
    x1 = 0.3 - (0.3 * 0.3 - 4.0) / 0.6  # the slope refused at the first step's end, x1 > 5
    after_one = solve_scalar(cases[2][0], method="newton", x0=0.3, record=False)
    assert (after_one.status, after_one.iterations, after_one.x, after_one.residual) == (
        Status.DOMAIN_ERROR, 1, x1, x1 * x1 - 4.0)
