"""The bracketing methods at the ends of the double range: brackets as wide as the doubles
(a width, f(b) - f(a) and the interpolation's products beyond the largest double), on one
side only, and f values whose product f(a) f(b) overflows. Each root against the exact one
or 40-digit mpmath; "converged" only with the root within the tolerance, and no inf or NaN
in any row's point or width."""

from __future__ import annotations

import json
import math
import random
import sys

import mpmath as mp
import pytest

from linkage import Status, solve_scalar
from linkage.methods.bisection import halvings_needed
from linkage.methods.hybrid import scaled_interpolation
from linkage.methods.regula_falsi import secant_from_ratio
from linkage.methods.secant import chord_slope

mp.mp.dps = 40

BIG = sys.float_info.max
EPS = sys.float_info.epsilon
CONVERGED = (Status.CONVERGED_STEP, Status.CONVERGED_EXACT, Status.CONVERGED_RESIDUAL)
TOL, RTOL = 1e-6, 1e-12


def signed_sqrt(x: float) -> float:
    return math.copysign(math.sqrt(abs(x)), x)


WIDE = [
    # (name, f, bracket, the root: exact, or 40-digit mpmath)
    ("x - 1 on [-1e308, 1e308]", lambda x: x - 1.0, (-1e308, 1e308), mp.mpf(1)),
    ("x - 1 on the widest bracket", lambda x: x - 1.0, (-BIG, BIG), mp.mpf(1)),
    ("0.5 x - 3e307: f(b) - f(a) overflows", lambda x: 0.5 * x - 3e307, (-BIG, BIG), 2 * mp.mpf(3e307)),
    ("sqrt|x| - 3, signed", lambda x: signed_sqrt(x) - 3.0, (-1e308, 1e308), mp.mpf(9)),
    ("atan(x) - 1", lambda x: math.atan(x) - 1.0, (-1e308, 1e308), mp.tan(1)),
    ("x - 1 on [0, 1e308]", lambda x: x - 1.0, (0.0, 1e308), mp.mpf(1)),
    ("x - 1 on [-1e308, 5]", lambda x: x - 1.0, (-1e308, 5.0), mp.mpf(1)),
    ("x - 1.5e308 near the top", lambda x: x - 1.5e308, (-1e307, BIG), mp.mpf(1.5e308)),
    ("1e200 (x - 2): f(a) f(b) overflows", lambda x: 1e200 * (x - 2.0), (-1.0, 10.0), mp.mpf(2)),
]


def rows_finite(r) -> bool:
    return all(isinstance(v, str) or v is None or math.isfinite(v) for row in r.history.rows for v in row)


@pytest.mark.parametrize("method", ["regula-falsi", "hybrid"])
@pytest.mark.parametrize("name,f,bracket,root", WIDE, ids=[w[0] for w in WIDE])
def test_interpolating_bracket_methods_converge_on_brackets_at_the_ends_of_the_doubles(
        method, name, f, bracket, root):
    """The hybrid failed 'a value became infinite' on [-1e308, 1e308] (its width and
    f(b) - f(a) overflowed) and regula falsi bisected to its cap (its secant's product
    overflowed): both now converge to the root, with every row finite."""
    r = solve_scalar(f, method=method, bracket=bracket, tol=TOL, rtol=RTOL, max_iter=2000)
    assert r.status in CONVERGED, (name, r.status, r.message)
    assert abs(mp.mpf(r.root) - root) <= TOL + RTOL * abs(root), (name, r.root)
    assert rows_finite(r), name


@pytest.mark.parametrize("method", ["regula-falsi", "hybrid"])
def test_a_bracket_as_wide_as_the_doubles_needs_a_few_steps_not_a_thousand(method):
    """The brief's command: x - 1 on [-1e308, 1e308] within the default cap of 100 (regula
    falsi needed 1,026 halvings before; the hybrid failed at its first step)."""
    r = solve_scalar(lambda x: x - 1.0, method=method, bracket=(-1e308, 1e308))
    assert r.converged and abs(r.root - 1.0) <= 1e-6 and r.iterations <= 5, (r.status, r.iterations)


def test_hybrid_on_the_widest_bracket_bisects_first_then_interpolates():
    """The first step's bracket is wider than the largest double: it bisects (halving the
    bracket in halves), and interpolates once the width is finite."""
    r = solve_scalar(lambda x: x - 1.0, method="hybrid", bracket=(-BIG, BIG))
    kinds = [row[1] for row in r.history.rows]
    assert kinds[0] == "bisection" and "secant" in kinds[1:], kinds
    assert r.history.rows[0][6] == BIG  # the width after halving [-BIG, BIG] at 0


@pytest.mark.parametrize("method", ["regula-falsi", "hybrid"])
def test_cli_solves_x_minus_1_on_the_widest_brackets(cli, method):
    run = cli("solve", "-e", "x - 1", "--method", method, "--bracket", "-1e308", "1e308", "--format", "json")
    assert run.code == 0, run.out + run.err
    doc = json.loads(run.out)
    assert doc["converged"] is True and abs(doc["solution"]["x"] - 1.0) <= 1e-6


def ordinary_interpolation(xcur, fcur, xpre, fpre, xblk, fblk):
    """The hybrid's interpolation step as its loop computes it (hybrid.Hybrid.step)."""
    if xpre == xblk:
        return -fcur * (xcur - xpre) / (fcur - fpre)
    dpre = (fpre - fcur) / (xpre - xcur)
    dblk = (fblk - fcur) / (xblk - xcur)
    return -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))


def test_scaled_interpolation_is_the_ordinary_step_bit_for_bit_in_range():
    """Scaling by powers of two is exact, so where nothing over- or underflows the
    overflow-safe step is the ordinary one, bit for bit (2,000 random secant and
    inverse-quadratic steps at scales from 1e-40 to 1e40)."""
    rng = random.Random(7)
    for k in range(2000):
        sx, sf = 10.0 ** rng.uniform(-40, 40), 10.0 ** rng.uniform(-40, 40)
        xcur, xpre = rng.uniform(-1, 1) * sx, rng.uniform(-1, 1) * sx
        xblk = xpre if k % 2 else rng.uniform(-1, 1) * sx
        fcur, fpre, fblk = (rng.uniform(-1, 1) * sf for _ in range(3))
        if xcur in (xpre, xblk) or fblk == fpre:
            continue
        want = ordinary_interpolation(xcur, fcur, xpre, fpre, xblk, fblk)
        assert scaled_interpolation(xcur, fcur, xpre, fpre, xblk, fblk) == want, k


def test_scaled_interpolation_where_the_ordinary_overflows_is_the_exact_step():
    """Where the ordinary secant and inverse-quadratic steps are inf or NaN (f values near
    the largest double), the scaled step is the exact one (40-digit mpmath) to a few ulps."""
    cases = [(1.0, -1e308, 9e307, 1.5e308, 9e307, 1.5e308),     # secant: f(cur) - f(pre) overflows
             (0.0, -1e300, 2.0, 1e308, 5.0, 1.7e308)]          # inverse quadratic: f products overflow
    for xcur, fcur, xpre, fpre, xblk, fblk in cases:
        ordinary = ordinary_interpolation(xcur, fcur, xpre, fpre, xblk, fblk)
        assert not math.isfinite(ordinary)
        m = [mp.mpf(v) for v in (xcur, fcur, xpre, fpre, xblk, fblk)]
        xc, fc, xp, fp, xb, fb = m
        if xpre == xblk:
            exact = -fc * (xc - xp) / (fc - fp)
        else:  # the inverse quadratic through the three points, at f = 0, less xcur
            exact = (xc * fp * fb / ((fc - fp) * (fc - fb)) + xp * fc * fb / ((fp - fc) * (fp - fb))
                     + xb * fc * fp / ((fb - fc) * (fb - fp))) - xc
        got = scaled_interpolation(xcur, fcur, xpre, fpre, xblk, fblk)
        assert abs(mp.mpf(got) - exact) <= 8 * EPS * abs(exact), (got, exact)


def test_regula_falsi_point_where_the_secant_overflows_is_the_exact_one():
    """The overflow-safe secant point of regula falsi against 40-digit mpmath, on brackets
    where F(b) (b - a) or F(b) - F(a) overflow; the midpoint where the width itself does."""
    for a, fa, b, fb in [(0.0, -1.0, 1e308, 1e308), (-1e308, -1e308, 1e307, 1.5e308),
                         (1.0, -1e308, 2.0, 1e308), (0.0, -3.0, 1e300, 1.7e308)]:
        c = b - fb * (b - a) / (fb - fa)
        assert not a < c < b or not math.isfinite(fb - fa)  # the ordinary point overflowed
        got = secant_from_ratio(a, fa, b, fb)
        exact = mp.mpf(b) - mp.mpf(fb) * (mp.mpf(b) - mp.mpf(a)) / (mp.mpf(fb) - mp.mpf(fa))
        assert a < got < b and abs(mp.mpf(got) - exact) <= 4 * EPS * (b - a), (a, b, got, exact)
    r = solve_scalar(lambda x: x - 1.0, method="regula-falsi", bracket=(-BIG, BIG))
    assert r.history.rows[0][5] == 0.0  # the first point: the midpoint of the widest bracket


FAR_SECANT = [
    ("x - 1 from -1e308, 1e308", lambda x: x - 1.0, -1e308, 1e308, mp.mpf(1)),
    ("x - 1 from the largest doubles", lambda x: x - 1.0, BIG, -BIG, mp.mpf(1)),
    ("0.5 x - 3e307: a false zero slope", lambda x: 0.5 * x - 3e307, -BIG, BIG, 2 * mp.mpf(3e307)),
    ("sqrt|x| - 3, signed", lambda x: signed_sqrt(x) - 3.0, -1e308, 1e308, mp.mpf(9)),
]


@pytest.mark.parametrize("record", [True, False])
@pytest.mark.parametrize("name,f,x0,x1,root", FAR_SECANT, ids=[c[0] for c in FAR_SECANT])
def test_secant_from_two_far_points_follows_the_chord(record, name, f, x0, x1, root):
    """From points of opposite signs near the largest double, x - x_p overflowed: the
    slope was inf/inf = NaN ('a value became infinite') or a finite difference over inf =
    0 (a false 'the secant slope is zero'). The chord's slope is now computed on halves
    where the quotient is not finite or zero, in the generated loop as in the step."""
    r = solve_scalar(f, method="secant", x0=x0, x1=x1, tol=TOL, rtol=RTOL, max_iter=200, record=record)
    assert r.status in CONVERGED, (name, r.status, r.message)
    assert abs(mp.mpf(r.root) - root) <= TOL + RTOL * abs(root), (name, r.root)


def test_chord_slope_is_the_ordinary_quotient_bit_for_bit_in_range():
    """Halving is exact: where no difference overflows, the guarded slope is the ordinary
    quotient, bit for bit, including a flat chord's 0 and an underflowed quotient's 0."""
    rng = random.Random(11)
    for k in range(3000):
        x, xp = (rng.uniform(-1, 1) * 10.0 ** rng.uniform(-300, 300) for _ in range(2))
        fx, fxp = (rng.uniform(-1, 1) * 10.0 ** rng.uniform(-300, 300) for _ in range(2))
        if k % 5 == 0:
            fxp = fx
        if x == xp:
            continue
        want = (fx - fxp) / (x - xp)
        if (math.isfinite(want) and abs(want) >= 4 * sys.float_info.min) or want == 0.0:
            assert chord_slope(x, fx, xp, fxp) == want, (x, fx, xp, fxp)


def test_bisection_cap_message_says_how_many_halvings_the_bracket_needs(cli):
    """x - 1 on [-1e308, 1e308] needs ceil(log2(2e308 / 1e-6)) = 1,045 halvings (40-digit
    mpmath), beyond the default cap of 100: the cap's message said only '100 iterations,
    last error 1.58e+278'. It now names the count, and that cap is enough."""
    need = int(mp.ceil(mp.log(2 * mp.mpf(1e308) / mp.mpf(1e-6), 2)))
    run = cli("solve", "-e", "x - 1", "--method", "bisection", "--bracket", "-1e308", "1e308")
    assert run.code == 1 and f"this bracket needs {need:,} halvings to reach tol = 1e-06" in run.out
    r = solve_scalar(lambda x: x - 1.0, method="bisection", bracket=(-1e308, 1e308), max_iter=need)
    assert r.converged and abs(r.root - 1.0) <= 1e-6 and r.iterations == need
    short = solve_scalar(lambda x: x - 1.0, method="bisection", bracket=(-1e308, 1e308), max_iter=need - 1)
    assert short.status is Status.MAX_ITER


def test_halvings_needed_is_the_count_bisection_takes():
    """The a-priori count against runs to the tolerance: random brackets up to the widest,
    and dyadic ones whose error lands exactly on the tolerance."""
    rng = random.Random(5)
    for k in range(300):
        if k % 2:
            a, b = -(10.0 ** rng.uniform(-5, 308)), 10.0 ** rng.uniform(-5, 308)
            tol = 10.0 ** rng.uniform(-12, 3)
            root = 0.3 * min(b, 1.0)  # where the spacing of doubles is below every tol
        else:
            a, b, tol = 1.0, 1.0 + 2.0 ** -rng.randint(0, 30), 2.0 ** -rng.randint(1, 45)
            root = 1.0 + 2.0 ** -31 + 2.0 ** -50  # inside every bracket, never a midpoint
        r = solve_scalar(lambda x, root=root: x - root, method="bisection", bracket=(a, b), tol=tol,
                         record=False, max_iter=5000)
        assert r.status is Status.CONVERGED_STEP, (a, b, tol, r.status)
        assert r.iterations == halvings_needed(a, b, tol), (a, b, tol, r.iterations)


TINY = [
    # (name, f, bracket, tol, the exact root)
    ("x - 1e-300 on [0, 3e-300]", lambda x: x - 1e-300, (0.0, 3e-300), 1e-310, 1e-300),
    ("x - 1e-300 on [-1, 3e-300]", lambda x: x - 1e-300, (-1.0, 3e-300), 1e-310, 1e-300),
    ("(x - 1) 1e-300, products underflow", lambda x: (x - 1.0) * 1e-300, (0.0, 3.0), 1e-12, 1.0),
    ("(x^3 - 1) 1e-300", lambda x: (x**3 - 1.0) * 1e-300, (0.0, 3.0), 1e-12, 1.0),
]


@pytest.mark.parametrize("name,f,bracket,tol,root", TINY, ids=[c[0] for c in TINY])
def test_regula_falsi_on_tiny_brackets_and_values_does_not_underflow_into_bisection(
        name, f, bracket, tol, root):
    """Products of values near 1e-300 underflowed to 0: regula falsi's secant point fell on
    an end and it bisected (35 steps on [0, 3e-300] at tol 1e-310). It now takes the
    point from the ratio of the end values, and finds a linear f's root in a few steps."""
    r = solve_scalar(f, method="regula-falsi", bracket=bracket, tol=tol, max_iter=200)
    assert r.status in CONVERGED and abs(r.root - root) <= tol, (name, r.status, r.root)
    assert r.iterations <= (16 if "^3" in name else 3), (name, r.iterations)


@pytest.mark.parametrize("name,f,bracket,tol,root", TINY, ids=[c[0] for c in TINY])
def test_hybrid_on_tiny_brackets_and_values_converges_within_the_tolerance(name, f, bracket, tol, root):
    """The hybrid's interpolation underflows there too (a zero step, lengthened to its
    tolerance, or a zero denominator: it bisects); it converges, to the root."""
    r = solve_scalar(f, method="hybrid", bracket=bracket, tol=tol, max_iter=400)
    assert r.status in CONVERGED and abs(r.root - root) <= tol, (name, r.status, r.root)
