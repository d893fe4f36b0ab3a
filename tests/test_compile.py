"""Compiled code equals its definitions: loop models (F, J, dPhi/dv) against the term
walk and finite differences, equations (f, f', f'') against mpmath on random expressions."""

from __future__ import annotations

import math
import random
from pathlib import Path
from typing import Any

import mpmath as mp
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from linkage import load_mechanism
from linkage.problems.expression import Expression
from linkage.problems.loops import LoopModel

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"


def _random_state(m, rng: random.Random) -> tuple[float, list[float]]:
    scale = m.length_scale
    d = rng.uniform(-7, 7) if m.driver.kind == "angle" else rng.uniform(-2, 2) * scale
    q = [rng.uniform(-7, 7) if u.kind == "angle" else rng.uniform(-2, 2) * scale for u in m.unknowns]
    return d, q


@pytest.mark.parametrize("path", sorted(SAMPLES.glob("*.toml")), ids=lambda p: p.name)
def test_compiled_model_equals_the_term_walk(path):
    m = load_mechanism(path)
    model = LoopModel.compile(m)
    rng = random.Random(path.name)
    tol = 1e-12 * m.length_scale * len(m.loops[0].vectors)
    for _ in range(300):
        d, q = _random_state(m, rng)
        F, J = model.functions(d)
        Fi, Ji = model.interpreted_functions(d)
        assert max(abs(a - b) for a, b in zip(F(q), Fi(q))) <= tol
        assert max(abs(a - b) for ra, rb in zip(J(q), Ji(q)) for a, b in zip(ra, rb)) <= tol


@pytest.mark.parametrize("path", sorted(SAMPLES.glob("*.toml")), ids=lambda p: p.name)
def test_compiled_jacobian_and_driver_derivative_match_finite_differences(path):
    m = load_mechanism(path)
    model = LoopModel.compile(m)
    rng = random.Random(path.name + "fd")
    for _ in range(50):
        d, q = _random_state(m, rng)
        F, J = model.functions(d)
        V = model.driver_derivative(d)
        jac, v = J(q), V(q)
        for c in range(len(q)):
            h = 1e-6 * max(1.0, abs(q[c]))
            qp, qm = list(q), list(q)
            qp[c] += h
            qm[c] -= h
            for r, (a, b) in enumerate(zip(F(qp), F(qm))):
                assert (a - b) / (2 * h) == pytest.approx(jac[r][c], rel=1e-6, abs=1e-6 * m.length_scale)
        h = 1e-6 * max(1.0, abs(d))
        Fp, _ = model.functions(d + h)
        Fm, _ = model.functions(d - h)
        for r, (a, b) in enumerate(zip(Fp(q), Fm(q))):
            assert (a - b) / (2 * h) == pytest.approx(v[r], rel=1e-6, abs=1e-6 * m.length_scale)


# --- equations ------------------------------------------------------------------------------

LEAVES = ["x", "2", "0.5", "pi", "3.25"]
UNARY = ["sin", "cos", "exp", "atan", "sqrt", "log", "tanh", "cosd", "sind"]


def expressions(depth: int) -> st.SearchStrategy[str]:
    leaf = st.sampled_from(LEAVES)
    if depth == 0:
        return leaf
    sub = expressions(depth - 1)
    return st.one_of(
        leaf,
        st.builds(lambda a, op, b: f"({a} {op} {b})", sub, st.sampled_from(["+", "-", "*", "/"]), sub),
        st.builds(lambda f, a: f"{f}({a})", st.sampled_from(UNARY), sub),
        st.builds(lambda a, k: f"({a})**{k}", sub, st.sampled_from(["2", "3", "0.5", "x"])),
        st.builds(lambda a: f"-({a})", sub),
    )


MP = {"sin": mp.sin, "cos": mp.cos, "exp": mp.exp, "atan": mp.atan, "sqrt": mp.sqrt, "log": mp.log,
      "tanh": mp.tanh, "pi": mp.pi, "cosd": lambda v: mp.cos(v * mp.pi / 180),
      "sind": lambda v: mp.sin(v * mp.pi / 180)}


def _moderate(e: Expression, x: float) -> bool:
    """Whether f and its intermediate values stay moderate in double precision at x: an
    expression such as exp(exp(exp(exp(3.25)))) overflows there, and 40-digit mpmath
    would spend minutes and gigabytes on it."""
    try:
        values = [e.function()(x), e.rounding_bound()(x)]
    except (ArithmeticError, ValueError):
        return False
    return all(isinstance(v, float) and math.isfinite(v) and abs(v) < 1e100 for v in values)


def _mp(text: str):
    code = compile(text.replace("^", "**"), "<test>", "eval")  # the test's own grammar, not user text
    return lambda x: eval(code, {"__builtins__": {}}, {**MP, "x": x})


@settings(max_examples=300, deadline=None, derandomize=True)
@given(expressions(4), st.floats(0.2, 2.5))
def test_compiled_equation_and_derivatives_match_mpmath(text, x):
    e = Expression.parse(text)
    if not _moderate(e, x):
        return
    g = _mp(text)
    mp.mp.dps = 40
    try:
        exact = [g(mp.mpf(x)), mp.diff(g, mp.mpf(x)), mp.diff(g, mp.mpf(x), 2)]
    except (ZeroDivisionError, ValueError, OverflowError):
        return
    if any(not isinstance(v, mp.mpf) or not mp.isfinite(v) or abs(v) > 1e12 for v in exact):
        return
    try:
        bound = e.rounding_bound()(x)
    except (ArithmeticError, ValueError):
        return
    if not bound <= 1e-9 * (1.0 + abs(float(exact[0]))):
        return  # ill-conditioned in double precision (sin of 5e23): no digits to compare
    for fn, want in zip((e.function(), e.derivative(), e.second_derivative()), exact):
        try:
            got = fn(x)
        except (ArithmeticError, ValueError):
            return  # double precision may fail where 40 digits do not (a near-zero sqrt argument)
        if not isinstance(got, float) or not math.isfinite(got):
            return
        scale = 1.0 + abs(float(want))
        assert abs(got - float(want)) <= 1e-6 * scale, (text, x, got, float(want))


@settings(max_examples=200, deadline=None, derandomize=True)
@given(expressions(4), st.floats(0.2, 2.5))
def test_rounding_bound_covers_the_actual_rounding_error(text, x):
    """The compiled bound on |computed f - exact f| holds (with a small factor, since it is
    a first-order bound)."""
    e = Expression.parse(text)
    if not _moderate(e, x):
        return
    mp.mp.dps = 40
    try:
        exact = _mp(text)(mp.mpf(x))
        got, bound = e.function()(x), e.rounding_bound()(x)
    except (ArithmeticError, ValueError):
        return
    if not (isinstance(exact, mp.mpf) and mp.isfinite(exact) and math.isfinite(got) and math.isfinite(bound)):
        return
    assert abs(got - float(exact)) <= 4 * bound + 1e-300, (text, x, got, float(exact), bound)


# --- lean loops against the generic loop -----------------------------------------------------

def _same(a, b, label):
    assert a.status is b.status, (label, a.status, b.status, a.detail, b.detail)
    assert a.iterations == b.iterations, (label, a.iterations, b.iterations)
    xa, xb = (a.x, b.x) if isinstance(a.x, tuple) else ((a.x,), (b.x,))
    assert all(u == v or (u != u and v != v) for u, v in zip(xa, xb)), (label, a.x, b.x)


def _generic_newton(f, fprime, x0, tol, rtol, max_iter):
    """Newton through the generic loop (`run`), bypassing the lean one."""
    from linkage.methods import Newton
    from linkage.solve import check_criteria
    from linkage.solve.scalar import finish, problem_of

    problem = problem_of(f, fprime, None)
    m = Newton()
    try:
        state = m.init(problem, x0)
    except (ArithmeticError, ValueError, TypeError):
        return None
    return finish(m, problem, state, check_criteria(tol, rtol, None, max_iter), True, {"x0": x0})


@pytest.mark.parametrize("method", ["newton", "secant", "bisection", "fixed-point"])
def test_lean_scalar_loops_equal_the_generic_loop_on_the_stress_battery(method):
    """With history off each of these methods runs its own tight loop; with history on,
    the generic loop. Status, root and iteration count must agree on every case."""
    from linkage import solve_scalar
    from linkage.measure.stress import start_arguments
    from linkage.measure.stress_cases import (
        bad_start_cases,
        fourbar_equation_cases,
        non_finite_cases,
        tiny_tol_cases,
    )
    from linkage.problems.catalog import classic_cases

    cases = [*classic_cases(), *fourbar_equation_cases(random.Random(0), 600), *bad_start_cases(),
             *tiny_tol_cases(), *non_finite_cases()]
    compared = 0
    for case in cases:
        start = start_arguments(case, method)
        if start is None:
            continue
        kw = dict(method=method, fprime=case.fprime, g=case.g, tol=case.tol, rtol=case.rtol,
                  max_iter=2000 if method == "bisection" else 500, **start)
        try:
            lean = solve_scalar(case.f, record=False, **kw)
        except Exception as exc:  # the generic path must raise the same
            with pytest.raises(type(exc)):
                solve_scalar(case.f, record=True, **kw)
            continue
        full = solve_scalar(case.f, record=True, **kw)
        if method == "newton":  # Newton records in its lean loop too: compare with the generic one
            generic = _generic_newton(case.f, case.fprime, start["x0"], case.tol, case.rtol, 500)
            if generic is not None:
                _same(full, generic, case.name)
                assert repr(full.history.rows) == repr(generic.history.rows), case.name
                full = generic
        _same(lean, full, case.name)
        assert lean.nfev == full.nfev, (case.name, lean.nfev, full.nfev)
        compared += 1
    if method == "fixed-point":  # the battery has no x = g(x) forms: the catalogue's and the four-bar's
        from linkage import fourbar_equation
        from linkage.problems.catalog import CATALOG

        rng = random.Random(3)
        problems = [(e.name, e.problem(), e.x0) for e in CATALOG if e.g is not None or e.equation is None]
        problems += [(f"four-bar alpha {a}", fourbar_equation(float(a)), rng.uniform(0.0, 180.0))
                     for a in range(0, 360, 7)]
        for name, p, x0 in problems:
            for tol in (1e-3, 1e-8, 1e-13, 1e-300):
                kw = dict(method="fixed-point", x0=x0, tol=tol, max_iter=300)
                lean, full = solve_scalar(p, record=False, **kw), solve_scalar(p, record=True, **kw)
                _same(lean, full, name)
                assert lean.nfev == full.nfev
                compared += 1
    assert compared > 200


def test_lean_system_newton_equals_the_generic_loop_on_the_stress_battery():
    from linkage import solve_system
    from linkage.measure.stress_cases import fourbar_cases, fourbar_mechanism
    from linkage.problems.catalog import mgh_cases

    for it in fourbar_cases(random.Random(0), 400):
        p = fourbar_mechanism(it).problem()
        for damped in (True, False):
            kw = dict(tol=1e-10, max_iter=100, damped=damped)
            _same(solve_system(p, record=False, **kw), solve_system(p, record=True, **kw), it["links"])
    for label, s, factor in mgh_cases():
        for damped in (True, False):
            kw = dict(jac=s.J, tol=1e-10, ftol=1e-10, max_iter=200, damped=damped)
            _same(solve_system(s.F, s.start(factor), record=False, **kw),
                  solve_system(s.F, s.start(factor), record=True, **kw), label)


def test_the_user_two_unknown_entries_equal_the_generic_loop_from_anywhere():
    """The entries for user callables of two unknowns, one compiled for each truth of
    damped (solve.system.user_two_loop), against the generic loop (recording on, one
    NewtonSystem.step a step): the same status, iterations, x, error, residual and counts
    on four-bars from random starts (singular and refused steps included), and with damped
    given as 1 and 0."""
    from collections import Counter

    from linkage import solve_system
    from linkage.measure.stress_cases import fourbar_cases, fourbar_mechanism

    rng = random.Random(12)
    statuses: Counter = Counter()
    for it in fourbar_cases(random.Random(13), 60):
        p = fourbar_mechanism(it).problem()
        for damped in (True, False, 1, 0):
            x0 = (rng.uniform(-3.2, 3.2), rng.uniform(-3.2, 3.2))
            kw = dict(jac=p.J, tol=1e-11, max_iter=40, damped=damped)
            fast = solve_system(p.F, x0, record=False, **kw)
            generic = solve_system(p.F, x0, record=True, **kw)
            _same(fast, generic, (it["links"], x0, damped))
            assert repr((fast.error, fast.residual, fast.nfev, fast.njev, fast.detail)) == \
                repr((generic.error, generic.residual, generic.nfev, generic.njev, generic.detail)), x0
            statuses[fast.status] += 1
    assert len(statuses) >= 5, statuses  # converged, local minima, precision limits, the cap


def seen(result: Any) -> dict[str, Any]:
    """A Result's fields as a reader sees them (a fast solve keeps some raw until read)."""
    return {name: getattr(result, name) for name in result.__dataclass_fields__}


def general_path(F: Any, x0: Any, **options: Any) -> Any:
    """solve_system by its general path (every argument checked, the lean loop or the
    generic run), whatever short front door would apply."""
    from linkage.solve.system import solve_general

    chosen = dict(jac=None, method="newton", tol=1e-6, rtol=0.0, ftol=None, max_iter=50, record=True,
                  fd_step=None, damped=True, show_jacobian=False)
    chosen.update(options)
    return solve_general(F, x0, **chosen)


def test_the_two_unknown_front_door_equals_the_general_path():
    """solve_system on user callables of two unknowns with a start of two floats, a tuple
    or a list, takes a short front door. Everything in the Result agrees with the general
    path's."""
    from linkage import solve_system
    from linkage.measure.stress_cases import fourbar_cases, fourbar_mechanism
    from linkage.problems.catalog import mgh_cases

    pairs = []
    for it in fourbar_cases(random.Random(1), 200):
        p = fourbar_mechanism(it).problem()
        pairs.append((it["links"], p.F, p.J, tuple(float(v) for v in p.x0)))
    for label, s, factor in mgh_cases():
        start = s.start(factor)
        if len(start) == 2:
            pairs.append((label, s.F, s.J, tuple(float(v) for v in start)))
    assert len(pairs) > 200
    for label, F, J, x0 in pairs:
        for damped in (True, False):
            for kw in (dict(tol=1e-10), dict(tol=1e-12, ftol=1e-9, max_iter=7), dict(tol=1e-8, rtol=1e-6)):
                full = general_path(F, list(x0), jac=J, record=False, damped=damped, **kw)
                for start in (x0, list(x0)):
                    fast = solve_system(F, start, jac=J, record=False, damped=damped, **kw)
                    assert seen(fast) == seen(full) or repr(seen(fast)) == repr(seen(full)), (label, kw)



def test_a_remembered_two_unknown_solve_equals_the_general_path():
    """The same user callables at the same criteria objects solved again go from
    solve_system straight to the loop (solve.system._ready); each Result equals the general
    path's, from every start, damped or not, after other functions and other criteria
    were solved in between; criteria of a mutable or non-float type and a non-bool damped
    are not remembered; a function that later returns the wrong kind of value is named as
    the general path names it."""
    import numpy as np

    from linkage import solve_system
    from linkage.errors import InputError
    from linkage.measure.stress_cases import fourbar_cases, fourbar_mechanism
    from linkage.solve import system

    problems = [fourbar_mechanism(it).problem() for it in fourbar_cases(random.Random(3), 40)]
    rng = random.Random(4)
    tol, ftol, rtol = 1e-11, 1e-9, 0.0
    remembered = 0
    for p in problems:
        for damped in (True, False):
            for _ in range(3):
                x0 = (rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0))
                for start in (x0, list(x0)):
                    fast = solve_system(p.F, start, jac=p.J, tol=tol, ftol=ftol, rtol=rtol, max_iter=30,
                                        record=False, damped=damped)
                    remembered += system._ready[0] is p.F and system._ready[6] is damped
                    full = general_path(p.F, list(x0), jac=p.J, tol=tol, ftol=ftol, rtol=rtol, max_iter=30,
                                        record=False, damped=damped)
                    assert repr(seen(fast)) == repr(seen(full)), (x0, damped)
    assert remembered == len(problems) * 2 * 3 * 2
    p = problems[0]
    for options in (dict(tol=np.float64(1e-10)), dict(tol=1e-10, damped=1)):
        fast = solve_system(p.F, (0.5, 1.0), jac=p.J, record=False, **options)
        assert system._ready[0] is not p.F, options
        full = general_path(p.F, [0.5, 1.0], jac=p.J, record=False, **options)
        assert repr(seen(fast)) == repr(seen(full)), options

    broken: list[str] = []

    def F(q: Any) -> Any:
        return None if "F" in broken else p.F(q)

    def J(q: Any) -> Any:
        return None if "J" in broken else p.J(q)

    for name, named in (("F", "F must return"), ("J", "jac must return")):
        broken.clear()
        solve_system(F, (0.5, 1.0), jac=J, tol=tol, record=False)
        assert system._ready[0] is F
        broken.append(name)
        messages = []
        for solve in (lambda: solve_system(F, (0.5, 1.0), jac=J, tol=tol, record=False),
                      lambda: general_path(F, [0.5, 1.0], jac=J, tol=tol, record=False)):
            with pytest.raises(InputError) as caught:
                solve()
            messages.append(str(caught.value))
        assert messages[0] == messages[1] and messages[0].startswith(named), messages


def test_the_two_unknown_mechanism_front_door_equals_the_general_path():
    """A compiled problem of two angles with a tuple start (its own x0 included) takes a
    short front door when Newton converges; a list start takes the general path."""
    from linkage import solve_system
    from linkage.measure.stress_cases import fourbar_cases, fourbar_mechanism

    problems = [fourbar_mechanism(it).problem() for it in fourbar_cases(random.Random(2), 200)]
    assert len(problems) == 200
    converged = 0
    for p in problems:
        x0 = tuple(float(v) for v in p.x0)
        for damped in (True, False):
            for kw in (dict(tol=1e-10), dict(tol=1e-12, ftol=1e-9, max_iter=7), dict(tol=1e-8, rtol=1e-6)):
                fast = solve_system(p, x0, record=False, damped=damped, **kw)
                full = solve_system(p, list(x0), record=False, damped=damped, **kw)
                assert repr(seen(fast)) == repr(seen(full)), kw
                fast = solve_system(p, record=False, damped=damped, **kw)  # its own x0
                assert repr(seen(fast)) == repr(seen(full)), kw
                converged += fast.converged
    assert converged > 300


def _two_unknown_mechanisms():
    from linkage.measure.stress_cases import fourbar_cases, fourbar_mechanism

    sample = [load_mechanism(p) for p in sorted(SAMPLES.glob("*.toml"))]
    return [m for m in sample if len(m.unknowns) == 2] + \
        [fourbar_mechanism(it) for it in fourbar_cases(random.Random(5), 60)]


def test_compiled_newton_two_equals_the_lean_loop():
    """The model's generated Newton (one function, Phi and J written in) gives the same
    iterations and root, bit for bit, as newton_2x2 with the verdict, wherever it returns
    a result; it hands back (None) only runs that did not converge by whole steps."""
    from linkage.methods.newton_system import max_abs, newton_2x2
    from linkage.methods.newton_two import newton_two_of
    from linkage.problems.system import LeanProblem
    from linkage.solve import system_verdict

    agreed = handed_back = 0
    rng = random.Random(7)
    for m in _two_unknown_mechanisms():
        model = m.model
        size = m.length_scale
        for _ in range(60):
            d, q = _random_state(m, rng)
            if rng.random() < 0.5:  # near the file's own assembly as well as anywhere
                d = m.driver.value + rng.uniform(-0.3, 0.3)
                q = [u.value + rng.uniform(-0.2, 0.2) for u in m.unknowns]
            tol, gate = 1e-12, 1e-12 * size
            F, J = model.functions(d)
            try:
                phi0 = F(list(q))
            except (ArithmeticError, ValueError):
                continue
            light = LeanProblem(F, J, None, lambda m=m, d=d: m.model.problem_at(d))
            x, phi, _e, status, detail, k, _nf, _nj = newton_2x2(light, tuple(q), phi0, tol, 0.0, gate,
                                                                  50, False)
            status, _ = system_verdict(status, detail, max_abs(phi), gate)
            got = newton_two_of(model)(d, q[0], q[1], tol, gate, 50)
            if got is None:
                handed_back += status.converged
                continue
            assert status.converged, (m.name, d, q)
            assert (got[0], got[1], got[2]) == (k, x[0], x[1])
            (a, b), (c, e) = J([got[1], got[2]])
            assert got[3:7] == (a, b, c, e)
            assert list(got[7:]) == model.driver_derivative(d)([got[1], got[2]])
            agreed += 1
    assert agreed > 2000
    assert handed_back <= 0.01 * agreed  # singular or refused steps only


def _sweep_both_ways(m, values, **kw):
    from linkage.kinematics import continuation as C
    from linkage.kinematics import stepwise as S

    init = C.Solver.__init__

    def general(self, *a, **k):
        init(self, *a, **k)
        self.two = False

    out = [S.sweep(m, values, **kw)]
    C.Solver.__init__ = general
    try:
        out.append(S.sweep(m, values, **kw))
    finally:
        C.Solver.__init__ = init
    return out


def test_the_two_unknown_sweep_step_equals_the_general_step():
    """A continuation step on two unknowns runs on scalars with the generated Newton;
    every position of every sweep equals the general step's, bit for bit (gaps, re-entry,
    halved steps and both branches included)."""
    from linkage.kinematics.continuation import Solver

    checked = fast = 0
    for m in _two_unknown_mechanisms()[:40]:
        values = ([float(v) for v in range(0, 361, 3)] if m.driver.kind == "angle"
                  else [m.driver.value * (0.5 + k / 100) for k in range(100)])
        assert Solver(m, "newton", 1e-12, 50).two == (m.length_scale == 1.0 or
                                                       all(u.kind == "angle" for u in m.unknowns))
        for branch in (None, "crossed"):
            a, b = _sweep_both_ways(m, values, branch=branch)
            assert repr(a) == repr(b), (m.name, branch)
            checked += 1
            fast += Solver(m, "newton", 1e-12, 50).two
    assert checked >= 80 and fast >= 70


def test_a_converged_position_built_fast_equals_the_constructor():
    from dataclasses import fields

    from linkage.kinematics.positions import Position, converged_position

    assert [f.name for f in fields(Position)] == ["input", "status", "solution", "branch", "iterations",
                                                 "det", "transmission", "substeps", "note", "rates"]
    sol = {"theta3": 12.5, "theta4": 80.0}
    fast = converged_position(3.0, sol, "open", 3, -1.5, 67.5)
    slow = Position(3.0, "converged", sol, "open", 3, -1.5, 67.5)
    assert fast == slow and repr(fast) == repr(slow)


def test_a_mechanism_with_its_compiled_model_still_pickles():
    """Scans send mechanisms to worker processes; the compiled model (generated
    functions) stays behind and the worker compiles its own."""
    import pickle

    import linkage

    m = load_mechanism(SAMPLES / "crank_rocker.toml")
    before = linkage.sweep(m, [0.0, 10.0, 20.0])
    assert "model" in vars(m)
    copy = pickle.loads(pickle.dumps(m))
    assert "model" not in vars(copy) and copy == m
    assert repr(linkage.sweep(copy, [0.0, 10.0, 20.0])) == repr(before)


def test_lu_of_two_by_two_on_scalars_equals_lu():
    from linkage.linalg import SingularMatrix, det_from_lu, lu, lu_two

    rng = random.Random(9)
    cases = [(1.0, 2.0, 1.0, 3.0), (-2.0, 1.0, 2.0, 5.0), (0.0, 1.0, 0.0, 2.0), (1.0, 2.0, 2.0, 4.0),
             (0.0, 0.0, 3.0, 1.0)]
    cases += [tuple(rng.choice([0.0, rng.uniform(-5, 5)]) for _ in range(4)) for _ in range(2000)]
    for a, b, c, d in cases:
        got = lu_two(a, b, c, d)
        try:
            m, perm, sign = lu([[a, b], [c, d]])
        except SingularMatrix:
            assert got is None
            continue
        assert got == (m[0][0], m[0][1], m[1][0], m[1][1], perm == [1, 0])
        assert (-1.0 if got[4] else 1.0) * got[0] * got[3] == det_from_lu((m, perm, sign))
