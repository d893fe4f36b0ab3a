"""The counts of F and J evaluations where a step raises (iterate.counts_made, the one rule:
an evaluation counts once it has returned, in a step that then raises too): the generic
loop (recording on) reports the evaluations it made, counted independently here as they
return, and the generated loops (recording off: newton_2x2 for two unknowns,
newton_system_lean for more) report the generic loop's numbers, with an F that raises
after J (in the loop's own step or in NewtonSystem.step's line search) and with a J that
raises."""

from __future__ import annotations

import math

import pytest

from linkage import solve_system
from linkage.iterate import Criteria, run
from linkage.methods.least_squares import LevenbergMarquardt
from linkage.problems.system import generic_system
from linkage.result import Status

HOLES = {
    "full step": ((-3.6, -3.4), None),  # Newton's whole first step from 2 lands at -3.53
    "half step": ((-1.0, -0.5), None),  # damped: that step is refused, its half lands at -0.77
    "J": (None, 3.0),  # J raises beyond |x| = 3: undamped, at the second iterate
}


def counted_system(n: int, hole: tuple[float, float] | None, j_limit: float | None):
    """Phi = (atan(x), y - 1, z + 2)[:n] from (2, 1, -2) (Newton's first step overshoots to
    -3.53), F raising ValueError for x inside ``hole`` and J for |x| beyond ``j_limit``;
    with the evaluations of each that returned."""
    made = {"F": 0, "J": 0}

    def F(q):  # type: ignore[no-untyped-def]
        if hole is not None and hole[0] < q[0] < hole[1]:
            raise ValueError("F is undefined here")
        made["F"] += 1
        return [math.atan(q[0]), q[1] - 1.0, *([q[2] + 2.0] if n == 3 else [])]

    def J(q):  # type: ignore[no-untyped-def]
        if j_limit is not None and abs(q[0]) > j_limit:
            raise ValueError("J is undefined here")
        made["J"] += 1
        rows = [[1.0 / (1.0 + q[0] * q[0]), 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
        return [row[:n] for row in rows[:n]]

    return F, J, made


@pytest.mark.parametrize("n", [2, 3])
@pytest.mark.parametrize("damped", [True, False])
@pytest.mark.parametrize("where", sorted(HOLES))
def test_a_step_that_raises_counts_its_evaluations_alike_on_the_generated_and_generic_paths(
        n: int, damped: bool, where: str) -> None:
    hole, j_limit = HOLES[where]
    F, J, made = counted_system(n, hole, j_limit)
    x0 = (2.0, 1.0, -2.0)[:n]
    generic = solve_system(F, x0, jac=J, damped=damped, record=True, max_iter=30)
    # the generic loop's counts are its evaluations, counted apart as they returned
    assert (generic.nfev, generic.njev) == (made["F"], made["J"]), (generic.status, made)
    fast = solve_system(F, x0, jac=J, damped=damped, record=False, max_iter=30)
    assert (fast.status, fast.iterations, fast.nfev, fast.njev) == \
        (generic.status, generic.iterations, generic.nfev, generic.njev)
    assert fast.x == generic.x


def test_the_cases_raise_where_they_say() -> None:
    """The cases above end in a domain error where they mean to: a J made and then an F
    that raises, on the full step and (damped) on the line search's half step, and a J
    that raises (undamped)."""
    for where, damped in (("full step", True), ("full step", False), ("half step", True), ("J", False)):
        hole, j_limit = HOLES[where]
        F, J, _ = counted_system(3, hole, j_limit)
        r = solve_system(F, (2.0, 1.0, -2.0), jac=J, damped=damped, record=True, max_iter=30)
        assert r.status is Status.DOMAIN_ERROR and "undefined" in r.detail, (where, damped)
        assert r.njev >= 1, (where, damped)


def test_levenberg_marquardt_counts_a_jacobian_made_before_a_raising_f() -> None:
    """The generic loop stepping LevenbergMarquardt: the J of the step whose trial F raises
    is in njev (the step's counts reach the loop on the exception)."""
    F, J, made = counted_system(3, (-3.6, 1.9), None)  # every trial below x = 1.9 raises
    m = LevenbergMarquardt()
    problem = generic_system(F, 3, J)
    crit = Criteria(1e-10, 0.0, 1e-10, 30)
    final, status, _, k, _ = run(m, problem, m.init(problem, (2.0, 1.0, -2.0)), crit, record=False,
                                 magnitude=lambda q: max(map(abs, q)))
    assert status is Status.DOMAIN_ERROR and k == 0
    assert (final.nfev, final.njev) == (made["F"], made["J"]) == (1, 1)
