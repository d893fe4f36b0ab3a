"""Which branch linkage synthesize follows (least squares, limits, change points, the
search's twin of each rule): each test failed before its fix.

The reference here is the linkage's own geometry at 40 digits (mpmath): R from the
precision points, the links from R, the output where the coupler's circle about A meets
the output's circle about O4 on the side of the line O4 -> A the first precision point
is on (that side changes only at a limit position)."""

from __future__ import annotations

import json

import mpmath as mp
import numpy as np
import pytest

from linkage.cli import run_cli
from linkage.synthesis import search, synthesize_function

FUNCTIONS = {"log10(x)": mp.log10, "x**2": lambda x: x * x, "sin(x)": mp.sin, "exp(x)": mp.exp}


def _reference(fs, xr, ar, pr, xs, ground=1.0, n=2000):
    """(max |structural error| deg, x of it, gaps, side changes of the precision points'
    nearer roots): least squares by 40-digit normal equations for more than 3 points."""
    mp.mp.dps = 40
    f = FUNCTIONS[fs]
    (lo, hi), (a0, a1), (p0, p1) = ([mp.mpf(v) for v in r] for r in (xr, ar, pr))
    y0, y1 = f(lo), f(hi)

    def alpha(x):
        return a0 + (x - lo) / (hi - lo) * (a1 - a0)

    def phi(x):
        return p0 + (f(x) - y0) / (y1 - y0) * (p1 - p0)

    xs = [mp.mpf(x) for x in xs]
    mat = mp.matrix([[mp.cos(mp.radians(alpha(x))), -mp.cos(mp.radians(phi(x))), 1] for x in xs])
    rhs = mp.matrix([mp.cos(mp.radians(alpha(x) - phi(x))) for x in xs])
    r = mp.lu_solve(mat.T * mat, mat.T * rhs)
    d = mp.mpf(ground)
    a, c = d / r[1], d / r[0]  # signed: negative is a link drawn the other way
    b = mp.sqrt(a * a + c * c + d * d - 2 * a * c * r[2])

    def pin(x):
        t = mp.radians(alpha(x))
        return d + a * mp.cos(t), a * mp.sin(t)

    def side(x, ph):
        ax, ay = pin(x)
        return mp.sign(ax * c * mp.sin(mp.radians(ph)) - ay * c * mp.cos(mp.radians(ph)))

    s1 = side(xs[0], phi(xs[0]))
    worst, at, gaps = mp.mpf(0), None, 0
    for i in range(n + 1):
        x = lo + (hi - lo) * i / n
        ax, ay = pin(x)
        dist = mp.sqrt(ax * ax + ay * ay)
        along = (c * c - b * b + dist * dist) / (2 * dist)
        if c * c < along * along:
            gaps += 1
            continue
        h = mp.sqrt(c * c - along * along) * s1
        bx, by = (along * ax - h * ay) / dist, (along * ay + h * ax) / dist  # |B| = |c|
        ph = mp.degrees(mp.atan2(by / c, bx / c))  # B = c e^(i phi), c signed
        e = abs(mp.fmod(ph - phi(x) + 540, 360) - 180)
        if e > worst:
            worst, at = e, x
    changes = sum(side(x, phi(x)) != s1 for x in xs)
    return float(worst), at, gaps, changes


# --- least squares (--points > 3) is not a "branch" defect --------------------------------------


@pytest.mark.parametrize("points, spacing", [(4, "chebyshev"), (5, "chebyshev"), (10, "uniform")])
def test_least_squares_points_are_not_a_false_branch_defect(points, spacing) -> None:
    s = synthesize_function("log10(x)", (1, 2), (90, 150), (0, 90), points=points, spacing=spacing)
    worst, _, gaps, changes = _reference(
        "log10(x)", (1, 2), (90, 150), (0, 90), [p.x for p in s.precision_points]
    )
    assert gaps == 0 and changes == 0  # one assembly passes (nearest to) every point
    assert s.defect_names == []
    assert s.max_error_deg == pytest.approx(worst, rel=1e-6)


def test_search_with_more_points_keeps_what_synthesize_keeps() -> None:
    r = search("log10(x)", (1, 2), None, None,
               ["alpha0=0:300:6", "alpha_span=60:90:2", "phi0=0:300:6", "phi_span=60:90:2"],
               points=4, top=100000, workers=1)
    kept = {int(d) for d in r.rows["design"]}
    design, single = 0, set()
    for a0 in np.linspace(0, 300, 6):
        for da in (60.0, 90.0):
            for p0 in np.linspace(0, 300, 6):
                for dp in (60.0, 90.0):
                    s = synthesize_function("log10(x)", (1, 2), (a0, a0 + da), (p0, p0 + dp), points=4)
                    if not s.defects:
                        single.add(design)
                    design += 1
    assert single and kept == single


def test_least_squares_cli_exit_0(capsys) -> None:
    code = run_cli(["synthesize", "--function", "log10(x)", "--x", "1:2", "--alpha", "90:150",
                    "--phi", "0:90", "--points", "5", "-f", "json"])
    doc = json.loads(capsys.readouterr().out)
    assert code == 0 and doc["defects"] == []


# --- a gap in assembly narrower than the grid's step -------------------------------------------

# The linkage a, b, c, d = 1, 3 + 1e-8, 2, 2 (seed convention, R1, R2, R3 below) is a hair
# past a change point: it cannot be assembled for alpha in about 179.9943..180.0057 deg,
# narrower than the 2001-point grid's step of 0.03 deg over 150.015..210.015, which puts grid
# points at 179.985 and 180.015, both outside it. f is that linkage's own output (acos
# reflected past -1 so f is finite everywhere), so the design is that linkage.
_U = "((1.0*cosd(x)+-1.4999999908837935e-08)/sqrt((2.0+cosd(x))**2+sind(x)**2))"
GAP_F = f"atand(sind(x)/(2.0+cosd(x))) + acosd(-1 + abs(1 + {_U}))"
GAP_X = (150.015, 210.015)


def _gap_phi() -> tuple[float, float]:
    from linkage.synthesis.request import make_request

    return make_request(GAP_F, GAP_X, (0, 1), (0, 1)).y_ends


def test_a_gap_between_grid_points_is_a_grashof_defect_in_search_too() -> None:
    from linkage.problems.freudenstein import equation_roots

    r1, r2, r3 = 1.0, 2.0, -1.4999999908837935e-08
    assert not equation_roots(180.0, r1, r2, r3)  # the gap is real
    assert equation_roots(179.985, r1, r2, r3) and equation_roots(180.015, r1, r2, r3)
    p = _gap_phi()
    s = synthesize_function(GAP_F, GAP_X, GAP_X, p, min_transmission=0)
    assert "grashof" in s.defect_names
    r = search(GAP_F, GAP_X, GAP_X, p, ["alpha0=150.015:150.015:1"], min_transmission=0, workers=1)
    assert r.scanned == 1 and r.without_defects == 0


def test_assembly_gap_against_dense_sampling() -> None:
    import random

    from linkage.problems.freudenstein import equation_roots
    from linkage.synthesis.solve import assembly_gap, assembly_gap_np

    rng = random.Random(7)
    seen = set()
    for _ in range(400):
        r = [rng.uniform(-3, 3) for _ in range(3)]
        a0 = rng.uniform(-400, 400)
        a1 = a0 + rng.uniform(-350, 350)
        dense = any(not equation_roots(a0 + (a1 - a0) * i / 2000, *r) for i in range(2001))
        got = assembly_gap(r, a0, a1)
        if dense:
            assert got
        seen.add((dense, got))
        assert bool(assembly_gap_np(*(np.array([v]) for v in (*r, a0, a1)))[0]) == got
    assert (True, True) in seen and (False, False) in seen


# --- refusals name the option given ------------------------------------------------------------


@pytest.mark.parametrize("rows", ["1", "-1", "1000000000"])
def test_bad_rows_names_rows(rows, capsys) -> None:
    code = run_cli(["synthesize", "--function", "log10(x)", "--x", "1:2", "--alpha", "90:150",
                    "--phi", "0:90", "--rows", rows])
    err = capsys.readouterr().err.strip()
    assert code == 2 and err.startswith("error: --rows") and "\n" not in err


# --- the continuation must not jump to the other branch near a limit ----------------------------

NEAR_LIMIT = ("exp(x)", (0, 1), (-95.42062855059999, 93.55703245593415),
              (40.77987358806064, -46.77855364187823))
"""Uniform spacing, ground 37.5: the branch through point 1 passes within 0.5 deg of a
toggle (transmission) near x = 0.5 without a gap, and point 3 lies on the other branch."""


def test_the_followed_branch_does_not_jump_near_a_limit() -> None:
    fs, xr, ar, pr = NEAR_LIMIT
    s = synthesize_function(fs, xr, ar, pr, spacing="uniform", ground=37.5)
    worst, at, gaps, changes = _reference(fs, xr, ar, pr, [p.x for p in s.precision_points], 37.5, n=4000)
    assert gaps == 0 and changes == 1  # no gap, but point 3 is on the other side
    assert "branch" in s.defect_names and "grashof" not in s.defect_names
    assert s.max_error_deg == pytest.approx(worst, rel=1e-5)
    assert s.at_x == pytest.approx(float(at), abs=1e-3)
    last = s.curve[-1]
    assert last.x == 1.0 and abs(last.error_deg) > 10.0  # not point 3's zero on the other branch


# --- the branch sign's twin at a limit position --------------------------------------------------


def test_branch_sign_twin_agrees_at_a_limit_position() -> None:
    from linkage.problems.freudenstein import branch_sign, branch_sign_np

    # phi - atan2(...) = +-180 exactly: the two roots meet (acos at pi); and random points
    cases = [(0.0, 180.0, 1.0, 2.0, 0.5), (0.0, -180.0, 1.0, 2.0, 0.5), (0.0, 0.0, 1.0, -2.0, 0.5),
             (360.0, 540.0, 0.3, 1.5, -1.0)]
    rng = np.random.default_rng(3)
    cases += [tuple(v) for v in rng.uniform(-400, 400, (200, 5))]
    for c in cases:
        assert branch_sign(*c) == branch_sign_np(*(np.array([v]) for v in c))[0], c
    assert branch_sign(0.0, 180.0, 1.0, 2.0, 0.5) == branch_sign(0.0, -180.0, 1.0, 2.0, 0.5) == 1.0


def test_search_keeps_what_synthesize_keeps_through_a_change_point() -> None:
    # ground 37.5, uniform: point 1 (alpha 0, phi 180) is the change point's collinear pose
    args = ("exp(x)", (0, 1), (0, 60), (180, 120))
    s = synthesize_function(*args, spacing="uniform", ground=37.5, min_transmission=0)
    assert s.grashof == "change point"
    r = search(*args, ["alpha0=0:0:1"], spacing="uniform", ground=37.5, min_transmission=0, workers=1)
    assert r.without_defects == (0 if s.defects else 1)
