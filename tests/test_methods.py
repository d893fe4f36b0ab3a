"""Every method against 40-digit mpmath roots, and hypothesis properties of the engine."""

from __future__ import annotations

import math

import mpmath as mp
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from linkage import Status, fourbar_equation, solve_scalar
from linkage.methods import METHODS, SCALAR_METHODS
from linkage.problems.catalog import CATALOG
from linkage.problems.expression import Expression

mp.mp.dps = 40

MP_FUNCS = {name: getattr(mp, name) for name in
            ("sin", "cos", "tan", "asin", "acos", "atan", "exp", "log", "sqrt")}


def mp_function(entry):
    if entry.equation is None:  # the Freudenstein four-bar, phi in degrees
        d = mp.pi / 180
        return lambda x: (mp.mpf(5) / 3 * mp.cos(70 * d) - mp.mpf(5) / 2 * mp.cos(x * d)
                          + mp.mpf(11) / 6 - mp.cos((70 - x) * d))
    text = entry.equation.replace("^", "**")
    return lambda x: eval(text, {"__builtins__": {}}, {**MP_FUNCS, "x": x, "pi": mp.pi})


def reference_root(entry):
    a, b = entry.bracket
    return mp.findroot(mp_function(entry), (mp.mpf(a), mp.mpf(b)), solver="anderson")


def start(entry, method):
    if method in ("bisection", "regula-falsi", "hybrid"):
        return {"bracket": entry.bracket}
    if method == "secant":
        return {"x0": entry.x0, "x1": entry.x1}
    return {"x0": entry.x0}


CUBIC_METHODS = [m for m in SCALAR_METHODS if {a for a, _ in METHODS[m].needs} <= {"fprime"}]
"""The methods a plain f with its f' can run (every one but those needing g or more)."""

CASES = [(e, m) for e in CATALOG for m in SCALAR_METHODS
         if m != "fixed-point" or e.g is not None or e.equation is None]


@pytest.mark.parametrize("entry,method", CASES, ids=[f"{e.name}-{m}" for e, m in CASES])
def test_methods_reach_the_40_digit_root(entry, method):
    root = reference_root(entry)
    r = float(root)
    tol = 1e-12 * max(1.0, abs(r))
    result = solve_scalar(entry.problem(), method=method, tol=tol, max_iter=500, **start(entry, method))
    assert result.converged, result.message
    err = abs(result.root - root)
    if method in ("bisection", "regula-falsi", "hybrid"):
        # a bracket's bound is a guarantee, not an estimate
        assert err <= tol + 4 * math.ulp(r), (err, tol)
    else:
        assert err <= 1e3 * tol, (err, tol)


def test_fixed_point_rate_matches_g_prime_at_the_40_digit_root():
    """Worked example P2: |g'(r)| is about 0.1275; the observed ratio of successive errors too."""
    p = fourbar_equation(70.0)
    entry = next(e for e in CATALOG if e.equation is None)
    r = reference_root(entry)
    assert p.gprime(float(r)) == pytest.approx(0.1274827, abs=1e-6)
    rows = solve_scalar(p, method="fixed-point", x0=50).history.rows
    errors = [abs(row[-1]) for row in rows]
    assert errors[-1] / errors[-2] == pytest.approx(p.gprime(float(r)), rel=1e-3)


def test_newton_constant_sign_and_size_against_mpmath():
    """f''(r)/(2 f'(r)) for the student report is +0.0117539 per degree (docs/worked_examples.md prints it
    negative; both derivatives are positive at the root, and the iterates approach from
    above with e4/e3^2 > 0)."""
    entry = next(e for e in CATALOG if e.equation is None)
    f = mp_function(entry)
    r = reference_root(entry)
    c = mp.diff(f, r, 2) / (2 * mp.diff(f, r, 1))
    assert float(c) == pytest.approx(0.0117539, abs=5e-7)
    p = fourbar_equation(70.0)
    assert p.fsecond(float(r)) / (2 * p.fprime(float(r))) == pytest.approx(float(c), rel=1e-9)
    rows = solve_scalar(p, method="newton", x0=50).history.rows
    signed = [row[1] - float(r) for row in rows]  # x_k - r, k = 1..4
    assert signed[3] / signed[2] ** 2 == pytest.approx(float(c), rel=1e-3)


@pytest.mark.parametrize("text", ["x**2 - 4*x + 1", "sin(x)*exp(-x)", "x**x", "atan(3*x)/x",
                                  "sqrt(1 + x**2)", "log10(x) * tan(x)", "acos(x/3)", "cosd(x) + sind(2*x)",
                                  "2**-x + abs(x - 5)", "(x - 1)**5"])
def test_symbolic_derivatives_match_mpmath(text):
    e = Expression.parse(text)
    f, d1, d2 = e.function(), e.derivative(), e.second_derivative()
    ns = {**MP_FUNCS, "pi": mp.pi, "log10": lambda v: mp.log(v, 10), "abs": abs,
          "cosd": lambda v: mp.cos(v * mp.pi / 180), "sind": lambda v: mp.sin(v * mp.pi / 180)}
    g = lambda x: eval(text, {"__builtins__": {}}, {**ns, "x": x})  # noqa: E731
    for x in (0.3, 0.7, 1.3, 2.2):
        assert f(x) == pytest.approx(float(g(mp.mpf(x))), rel=1e-13, abs=1e-15)
        assert d1(x) == pytest.approx(float(mp.diff(g, mp.mpf(x))), rel=1e-12, abs=1e-14)
        assert d2(x) == pytest.approx(float(mp.diff(g, mp.mpf(x), 2)), rel=1e-10, abs=1e-12)


# --- properties ------------------------------------------------------------------------

cubic = st.tuples(*(st.floats(-5, 5, allow_nan=False, allow_infinity=False) for _ in range(3)))


def bracketed_cubic(c, lo, width):
    a0, a1, a2 = c

    def f(x):
        return ((x + a2) * x + a1) * x + a0

    return f, lo, lo + width


@settings(max_examples=150, deadline=None)
@given(cubic, st.floats(-10, 10), st.floats(1e-3, 20))
def test_bisection_brackets_hold_a_sign_change_and_halve(c, lo, width):
    f, a, b = bracketed_cubic(c, lo, width)
    fa, fb = f(a), f(b)
    if fa * fb >= 0:
        return
    result = solve_scalar(f, method="bisection", bracket=(a, b), tol=1e-9, max_iter=200)
    assert result.status in (Status.CONVERGED_STEP, Status.CONVERGED_EXACT, Status.PRECISION_LIMIT)
    prev = None
    for _, ra, rfa, rb, rfb, rc, re in result.history.rows:
        assert (rfa < 0) != (rfb < 0), "the bracket lost its sign change"
        assert ra < rc < rb and re == (rb - ra) / 2
        if prev is not None:
            # halved, up to the rounding of the midpoint c = (a + b)/2
            assert abs(re - prev[6] / 2) <= math.ulp(max(abs(ra), abs(rb)))
            assert prev[1] <= ra and rb <= prev[3]
        prev = (None, ra, rfa, rb, rfb, rc, re)


@settings(max_examples=150, deadline=None)
@given(cubic, st.floats(-10, 10), st.floats(1e-3, 20), st.sampled_from(CUBIC_METHODS),
       st.floats(1e-14, 1e-2), st.one_of(st.none(), st.floats(1e-14, 1e-3)))
def test_a_converged_result_satisfies_its_stopping_test(c, lo, width, method, tol, ftol):
    f, a, b = bracketed_cubic(c, lo, width)
    if f(a) * f(b) >= 0:
        return
    d = lambda x: (3 * x + 2 * c[2]) * x + c[1]  # noqa: E731
    kwargs = {"bracket": (a, b)} if method in ("bisection", "regula-falsi", "hybrid") else {"x0": a, "x1": b}
    result = solve_scalar(f, fprime=d, method=method, tol=tol, ftol=ftol, max_iter=300, **kwargs)
    if result.status is Status.CONVERGED_STEP:
        assert result.error <= tol
    elif result.status is Status.CONVERGED_RESIDUAL:
        assert abs(result.residual) <= ftol
    elif result.status is Status.CONVERGED_EXACT:
        assert result.residual == 0.0
    if method in ("bisection", "regula-falsi", "hybrid"):
        assert min(a, b) <= result.root <= max(a, b)  # a bracketing method never leaves
        assert result.converged or result.status is Status.PRECISION_LIMIT


@settings(max_examples=100, deadline=None)
@given(st.floats(1, 179), st.floats(0.2, 5), st.floats(0.2, 5), st.floats(-3, 3))
@example(63.0, 1.0, 1.0, 1.0)  # regression: the table's f(x) once stopped fixed-point on an exact zero
@example(1.0, 1.0, 1.0, 1.0)   # regression: g'(x) at u = 1 (display only) once crashed the solve
def test_recording_does_not_change_the_answer(alpha, r1, r2, r3):
    p = fourbar_equation(alpha, r1, r2, r3)
    if p.guess is None:
        return
    for method in SCALAR_METHODS:
        on = solve_scalar(p, method=method, record=True)
        off = solve_scalar(p, method=method, record=False)
        assert (on.root == off.root) or (math.isnan(on.root) and math.isnan(off.root))
        assert on.status is off.status and on.iterations == off.iterations
        assert off.history is None
