"""The generated loops equal the reference loop bit for bit.

Every tight loop (Newton's, the secant's, fixed point's, bisection's, the systems'
Newton for n and for two unknowns) is generated from the one ordered stopping rule of
linkage.iterate around the method's step; the reference is the generic loop
(``iterate.run``) stepping the method's class on states. On 10,000 seeded random problems
(roots, no roots, poles, overflow, domain errors, tight and loose tolerances, short caps)
both give the same final iterate, residual, error, status, detail and iteration count.
"""

from __future__ import annotations

import math
import random
import struct
from collections import Counter
from typing import Any

from linkage.iterate import Criteria, Loop, loop_source, run, stopping_tests
from linkage.methods import method_class
from linkage.methods.newton_system import NewtonSystem, max_abs, newton_system_lean
from linkage.problems.scalar import ScalarProblem
from linkage.problems.system import generic_system
from linkage.result import Status
from linkage.solve import certify_root
from linkage.solve.scalar import newton_result

SCALAR_CASES = 8_000
SYSTEM_CASES = 2_000


def _bits(v: Any) -> Any:
    """A value compared bit for bit (NaN equal to itself, -0.0 unequal to 0.0)."""
    if isinstance(v, float):
        return struct.pack("<d", v)
    if isinstance(v, (list, tuple)):
        return tuple(_bits(c) for c in v)
    return v


def _random_problem(rng: random.Random) -> tuple[ScalarProblem, float, float, tuple[float, float]]:
    """f(x) = a (x - r)(x - s)(x - t) + b sin(k x) + c, or a variant that overflows, leaves
    its domain, has a pole or no root; with its exact f' and a g for fixed point."""
    a, b = rng.uniform(-3, 3), rng.choice([0.0, rng.uniform(-2, 2)])
    c, k = rng.uniform(-1, 1), rng.uniform(0.1, 4)
    r, s, t = (rng.uniform(-5, 5) for _ in range(3))
    kind = rng.choice(["poly", "poly", "poly", "exp", "sqrt", "pole", "flat"])
    if kind == "poly":
        def f(x: float) -> float:
            return a * (x - r) * (x - s) * (x - t) + b * math.sin(k * x) + c

        def fp(x: float) -> float:
            return a * ((x - s) * (x - t) + (x - r) * (x - t) + (x - r) * (x - s)) + b * k * math.cos(k * x)
    elif kind == "exp":
        def f(x: float) -> float:
            return math.exp(k * x) - 3.0 - a * a

        def fp(x: float) -> float:
            return k * math.exp(k * x)
    elif kind == "sqrt":
        def f(x: float) -> float:
            return math.sqrt(x - r) - abs(a)

        def fp(x: float) -> float:
            return 0.5 / math.sqrt(x - r)
    elif kind == "pole":
        def f(x: float) -> float:
            return 1.0 / (x - r) + c

        def fp(x: float) -> float:
            return -1.0 / (x - r) ** 2
    else:
        def f(x: float) -> float:
            return math.atan(k * (x - r)) + 0.1 * c

        def fp(x: float) -> float:
            return k / (1.0 + (k * (x - r)) ** 2)
    w = rng.uniform(0.05, 0.9)

    def g(x: float) -> float:  # a damped fixed-point form: x - w f(x)/f'(x0-ish scale)
        return x - w * f(x) / (1.0 + abs(a) + abs(b) * k)

    x0 = rng.uniform(-8, 8)
    x1 = x0 + rng.choice([1e-3, 0.5, 2.0, -1.0])
    lo, hi = sorted((rng.uniform(-8, 8), rng.uniform(-8, 8)))
    return ScalarProblem(f, fprime=fp, g=g), x0, x1, (lo, hi if hi > lo else lo + 1.0)


def _criteria(rng: random.Random) -> Criteria:
    tol = 10.0 ** rng.uniform(-16, -2)
    rtol = rng.choice([0.0, 0.0, 10.0 ** rng.uniform(-15, -6)])
    ftol = rng.choice([None, None, None, 10.0 ** rng.uniform(-15, -4)])
    return Criteria(tol, rtol, ftol, rng.choice([3, 8, 30, 100]))


def _certify(problem: ScalarProblem) -> Any:
    def certify(x: float, fx: Any, width: float) -> tuple[Status, str]:
        verdict, why, _ = certify_root(problem, x, fx if fx is not None else problem.f(x), width)
        return verdict, why
    return certify


def _compare(lean: tuple[Any, ...], generic: tuple[Any, ...], case: Any) -> None:
    (ls, lstatus, ldetail, lk), (gs, gstatus, gdetail, gk, _rows) = lean, generic
    assert (lstatus, ldetail, lk) == (gstatus, gdetail, gk), case
    assert _bits((ls.x, ls.fx, ls.err)) == _bits((gs.x, gs.fx, gs.err)), case


def test_generated_scalar_loops_equal_the_generic_loop_bit_for_bit():
    rng = random.Random(20261128)
    statuses: Counter[Status] = Counter()
    compared = 0
    for case in range(SCALAR_CASES):
        problem, x0, x1, bracket = _random_problem(rng)
        crit = _criteria(rng)
        name = ("newton", "secant", "fixed-point", "bisection")[case % 4]
        cls = method_class(name)
        m = cls(evaluate_f=crit.ftol is not None or rng.random() < 0.5) if name == "fixed-point" else cls()
        args = {"newton": (x0,), "secant": (x0, x1), "fixed-point": (x0,), "bisection": bracket}[name]
        try:
            state = m.init(problem, *args)
        except (ArithmeticError, ValueError):
            continue
        if state.stop is not None:
            continue
        certify = None if m.bracketing else _certify(problem)
        generic = run(m, problem, state, crit, record=False, certify=certify)
        if name == "newton":  # the generated Newton runs from x0 through its own front door
            r = newton_result(problem, x0, crit)
            assert (r.status, r.detail, r.iterations) == generic[1:4], (case, name)
            assert _bits((r.x, r.residual, r.error)) == _bits((generic[0].x, generic[0].fx, generic[0].err))
        else:
            _compare(m.run_lean(problem, state, crit, certify), generic, (case, name))
        statuses[generic[1]] += 1
        compared += 1
    assert compared > 0.8 * SCALAR_CASES
    # the battery reaches the stopping tests, not only the step test
    for status in (Status.CONVERGED_STEP, Status.CONVERGED_RESIDUAL, Status.MAX_ITER, Status.DIVERGED,
                   Status.DOMAIN_ERROR, Status.STALLED, Status.NON_FINITE):
        assert statuses[status] >= 5, statuses


def test_recorded_newton_has_the_generic_loops_outcome_and_rows_bit_for_bit():
    """Newton with history on (newton_lean) and off (newton_quiet, the quiet path) end
    where the generic loop does, and the recorded table is the generic loop's, row for row."""
    rng = random.Random(4242)
    m = method_class("newton")()
    for case in range(1_500):
        problem, x0, _, _ = _random_problem(rng)
        crit = _criteria(rng)
        try:
            state = m.init(problem, x0)
        except (ArithmeticError, ValueError):
            continue
        if state.stop is not None:
            continue
        _, status, detail, k, rows = run(m, problem, state, crit, record=True, certify=_certify(problem))
        on, off = newton_result(problem, x0, crit, record=True), newton_result(problem, x0, crit)
        for r in (on, off):
            assert (r.status, r.detail, r.iterations) == (status, detail, k), case
        assert _bits((on.x, on.residual, on.error)) == _bits((off.x, off.residual, off.error)), case
        assert _bits(on.history.rows) == _bits(tuple(rows.finish()[0])), case


def test_a_long_recorded_newton_keeps_the_generic_loops_head_and_tail():
    """Past the history's head (HISTORY_HEAD rows) the recorded loop hands rows to the
    ring: a cycling Newton (x^3 - 2x + 2 from 0) of 700 steps has the generic loop's table."""
    from linkage.iterate import HISTORY_HEAD

    problem = ScalarProblem(lambda x: x ** 3 - 2.0 * x + 2.0, fprime=lambda x: 3.0 * x * x - 2.0)
    m = method_class("newton")()
    crit = Criteria(1e-12, 0.0, None, 700)
    _, status, detail, k, rows = run(m, problem, m.init(problem, 0.0), crit, record=True,
                                     certify=_certify(problem))
    on = newton_result(problem, 0.0, crit, record=True)
    assert (on.status, on.detail, on.iterations) == (status, detail, k) == (Status.MAX_ITER, "", 700)
    assert on.history.elided > 0 and on.history.gap_at == HISTORY_HEAD
    assert _bits(on.history.rows) == _bits(tuple(rows.finish()[0]))


def _random_system(rng: random.Random, n: int) -> tuple[Any, Any, tuple[float, ...]]:
    """Phi_i(q) = sum_j A_ij q_j + c_i sin(q_i) + d_i q_i^3 - b_i, with its exact J."""
    A = [[rng.uniform(-2, 2) for _ in range(n)] for _ in range(n)]
    c = [rng.choice([0.0, rng.uniform(-3, 3)]) for _ in range(n)]
    d = [rng.choice([0.0, rng.uniform(-0.5, 0.5)]) for _ in range(n)]
    b = [rng.uniform(-4, 4) for _ in range(n)]

    def F(q: list[float]) -> list[float]:
        return [sum(A[i][j] * q[j] for j in range(n)) + c[i] * math.sin(q[i]) + d[i] * q[i] ** 3 - b[i]
                for i in range(n)]

    def J(q: list[float]) -> list[list[float]]:
        return [[A[i][j] + ((c[i] * math.cos(q[i]) + 3.0 * d[i] * q[i] ** 2) if i == j else 0.0)
                 for j in range(n)] for i in range(n)]
    return F, J, tuple(rng.uniform(-4, 4) for _ in range(n))


def test_generated_system_loops_equal_the_generic_loop_bit_for_bit():
    rng = random.Random(33)
    statuses: Counter[Status] = Counter()
    for case in range(SYSTEM_CASES):
        n = 2 if case % 3 else 3  # two unknowns: newton_2x2; three: the general loop
        F, J, q0 = _random_system(rng, n)
        damped = case % 2 == 0
        tol = 10.0 ** rng.uniform(-14, -4)
        max_iter = rng.choice([2, 10, 50])
        problem = generic_system(F, n, J)
        phi0 = F(list(q0))
        lean = newton_system_lean(problem, q0, phi0, tol, 0.0, tol, max_iter, damped)
        m = NewtonSystem("analytic", None, damped, diagnostics=False)
        crit = Criteria(tol, 0.0, tol, max_iter)
        final, status, detail, k, _ = run(m, problem, m.init(problem, q0, phi0), crit, record=False,
                                          magnitude=max_abs)
        assert (lean[3], lean[4], lean[5]) == (status, detail, k), case
        assert _bits((tuple(lean[0]), lean[2])) == _bits((tuple(final.x), final.err)), case
        assert _bits(tuple(lean[1])) == _bits(tuple(final.phi_x)), case
        assert (lean[6], lean[7]) == (final.nfev, final.njev), case
        statuses[status] += 1
    assert statuses[Status.CONVERGED_STEP] > 100 and statuses[Status.MAX_ITER] > 100, statuses
    assert len(statuses) >= 3, statuses


def test_every_generated_loop_carries_the_one_ordered_rule():
    """The stopping tests appear in each loop's source in the rule's order (non-finite,
    exact zero, step, divergence, rounding)."""
    from linkage.methods.bisection import BISECTION_LOOP
    from linkage.methods.fixed_point import FIXED_POINT_LOOP
    from linkage.methods.newton import NEWTON_LOOP
    from linkage.methods.newton_system import NEWTON_2X2_LOOP, NEWTON_SYSTEM_LOOP
    from linkage.methods.secant import SECANT_LOOP

    marks = ["_S.NON_FINITE", "_S.CONVERGED_EXACT", "if err <= limit:", "_S.PRECISION_LIMIT"]
    from linkage.solve.system import user_two_loop

    loops = (NEWTON_LOOP, SECANT_LOOP, FIXED_POINT_LOOP, BISECTION_LOOP, NEWTON_SYSTEM_LOOP, NEWTON_2X2_LOOP,
             user_two_loop(True), user_two_loop(False))
    for loop in loops:
        rule = "\n".join(stopping_tests(loop))
        assert rule in loop_source(loop)
        positions = [rule.index(mark) for mark in marks]
        assert positions == sorted(positions), loop.signature
    assert isinstance(NEWTON_LOOP, Loop)


def test_newtons_quiet_path_takes_any_real_number_type_as_the_generic_loop_does():
    """The quiet path of the generated Newton is comparisons only (no type test): f and f'
    returning numpy floats, ints, or a complex value part of the way end where the
    generic loop does, with its status, detail, iterate and count."""
    import numpy as np

    def numpy_f(x: float) -> Any:
        return np.float64(x) ** 3 - 2.0 * x - 5.0

    def complex_f(x: float) -> Any:  # real down to x = 1.5, then (x - 1.5) ** 0.5 is complex
        return (x - 1.5) ** 0.5 - 0.2 if x >= 1.5 else complex(0.0, 1.0)

    cases = [
        (ScalarProblem(numpy_f, fprime=lambda x: np.float64(3.0) * x * x - 2.0), 3.0),
        (ScalarProblem(lambda x: round(x) ** 2 - 4 if abs(x) < 1e6 else x * x - 4.0,
                       fprime=lambda x: 2.0 * x), 7.0),
        (ScalarProblem(complex_f, fprime=lambda x: 0.5 / (abs(x - 1.5) ** 0.5 + 1e-300)), 9.0),
        (ScalarProblem(lambda x: x * x - 2.0, fprime=lambda x: 2.0 * x), 1e150),
    ]
    m = method_class("newton")()
    for tol in (1e-12, 1e-6):
        for problem, x0 in cases:
            crit = Criteria(tol, 0.0, None, 60)
            state = m.init(problem, x0)
            final, status, detail, k, _ = run(m, problem, state, crit, record=False,
                                              certify=_certify(problem))
            r = newton_result(problem, x0, crit)
            assert (r.status, r.detail, r.iterations) == (status, detail, k), (x0, tol)
            assert _bits((r.x, r.residual, r.error)) == _bits((final.x, final.fx, final.err)), (x0, tol)


def test_newtons_quiet_path_bound_on_x_is_exact_about_rounding():
    """The quiet path reads test 7 (rounding) from |x| < tol / ROUNDING, exact only because
    ROUNDING is a power of two; roots on both sides of that bound (where the path compares
    as test 7 does instead) end where the generic loop does, bit for bit."""
    from linkage.iterate import ROUNDING

    assert math.frexp(ROUNDING)[0] == 0.5
    m = method_class("newton")()
    for tol in (1e-16, 1e-14, 1e-12):
        cap = tol / ROUNDING
        for scale in (0.25, 0.999, 1.0, 1.001, 4.0, -1.0, -4.0):
            root = scale * cap
            problem = ScalarProblem(lambda x, r=root: (x - r) * (x + 0.5 * r) + 1e-3 * math.sin(x),
                                    fprime=lambda x, r=root: 2.0 * x - 0.5 * r + 1e-3 * math.cos(x))
            x0 = root * 1.3 + 0.7
            crit = Criteria(tol, 0.0, None, 80)
            final, status, detail, k, _ = run(m, problem, m.init(problem, x0), crit, record=False,
                                              certify=_certify(problem))
            r = newton_result(problem, x0, crit)
            assert (r.status, r.detail, r.iterations) == (status, detail, k), (tol, scale)
            assert _bits((r.x, r.residual, r.error)) == _bits((final.x, final.fx, final.err)), (tol, scale)
