"""Smale's alpha test (linkage.homotopy.alpha) against values computed by hand from the
definitions (Hauenstein and Sottile, "alphaCertified", ACM TOMS 38(4), 2012, sec. 1-2) in
40-digit mpmath, against Macaulay2's NumericalCertification example, and on the roots of
assemblies and Burmester problems."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

from linkage.homotopy import alpha
from linkage.homotopy.polynomials import PolySystem

SQRT2_SYSTEM = PolySystem(1, ({(2,): 1.0, (0,): -2.0},))  # x^2 - 2


def test_univariate_constants_equal_the_hand_computed_ones():
    # f = x^2 - 2: ||f||^2 = 1 + 4 (Bombieri-Weyl), D = 2, Delta = sqrt(2) ||(1, x)||,
    # mu = ||f|| sqrt(2) ||(1, x)|| / |f'(x)|, gamma bound = mu 2^(3/2) / (2 ||(1, x)||) =
    # 2 sqrt(5) / |f'(x)|: at x = 1.5, beta = 0.25 / 3 and gamma = 2 sqrt(5) / 3
    with mpmath.workdps(40):
        a, b, g = alpha.constants(SQRT2_SYSTEM, np.array([1.5 + 0j]), 40)
        assert abs(b - mpmath.mpf(1) / 12) < mpmath.mpf(10) ** -35
        assert abs(g - 2 * mpmath.sqrt(5) / 3) < mpmath.mpf(10) ** -35
        assert abs(a - mpmath.sqrt(5) / 18) < mpmath.mpf(10) ** -35
        # at x = 2: beta = 2 / 4, gamma = sqrt(5) / 2, alpha = sqrt(5) / 4
        a, b, g = alpha.constants(SQRT2_SYSTEM, np.array([2.0 + 0j]), 40)
        assert abs(a - mpmath.sqrt(5) / 4) < mpmath.mpf(10) ** -35
    # the bound is above the exact gamma, |f''(x) / (2 f'(x))| = 1 / 3 at 1.5
    assert g > 1 / 3


def test_a_point_near_a_root_is_certified_and_a_far_point_is_not():
    near = alpha.certify(SQRT2_SYSTEM, np.array([1.5 + 0j]))  # alpha = sqrt(5) / 18 = 0.124
    far = alpha.certify(SQRT2_SYSTEM, np.array([2.0 + 0j]))  # alpha = sqrt(5) / 4 = 0.559
    assert near.certified and not far.certified
    assert near.alpha == pytest.approx(5 ** 0.5 / 18, rel=1e-14)
    # the root is within 2 beta of a certified point
    assert abs(1.5 - 2 ** 0.5) <= near.radius


def test_bivariate_constants_equal_the_hand_computed_ones():
    # f = (x^2 + y^2 - 1, x - y) at (0.7, 0.7): f = (-0.02, 0), J = [[1.4, 1.4], [1, -1]],
    # J^-1 f = (-0.02 / 2.8) (1, 1); ||f||^2 = 3 + 2; ||(1, x)||^2 = 1.98;
    # J^-1 Delta = [[c, 0.5], [c, -0.5]], c = sqrt(2) sqrt(1.98) / 2.8 (Frobenius norm)
    f = PolySystem(2, ({(2, 0): 1.0, (0, 2): 1.0, (0, 0): -1.0}, {(1, 0): 1.0, (0, 1): -1.0}))
    with mpmath.workdps(40):
        a, b, g = alpha.constants(f, np.array([0.7, 0.7], dtype=complex), 40)
        x = mpmath.mpf(0.7)  # the double nearest 0.7, as the point is
        one = 1 + 2 * x * x
        f1 = 2 * x * x - 1
        beta = abs(f1) / (4 * x) * mpmath.sqrt(2)
        c2 = 2 * one / (4 * x) ** 2  # c^2, with 2.8 = 4x
        mu = mpmath.sqrt(5) * mpmath.sqrt(2 * c2 + mpmath.mpf(0.5))
        gamma = mu * mpmath.mpf(2) ** 1.5 / (2 * mpmath.sqrt(one))
        assert abs(b - beta) < mpmath.mpf(10) ** -35
        assert abs(g - gamma) < mpmath.mpf(10) ** -35
        assert abs(a - beta * gamma) < mpmath.mpf(10) ** -35


def test_beta_and_the_gamma_bound_agree_with_macaulay2_numerical_certification():
    """NumericalCertification's documented example (x1, x2, y1, y2 at .95, .32, -.30, .95):
    (alpha, beta, gamma) = (.0505356, .00526407, 9.60011). Its gamma takes the largest entry
    of J^-1 Delta where the bound needs an operator norm (Macaulay2's norm of a matrix); with
    that entry in place of the Frobenius norm, the bound's other factors give its figure."""
    f = PolySystem(4, ({(0, 0, 1, 0): 3, (0, 0, 0, 1): 2, (0, 0, 0, 0): -1},
                       {(1, 0, 0, 0): 3, (0, 1, 0, 0): 2, (0, 0, 0, 0): -3.5},
                       {(2, 0, 0, 0): 1, (0, 0, 2, 0): 1, (0, 0, 0, 0): -1},
                       {(0, 2, 0, 0): 1, (0, 0, 0, 2): 1, (0, 0, 0, 0): -1}))
    x = np.array([.95, .32, -.30, .95], dtype=complex)
    a, b, g = alpha.constants(f, x)
    assert float(b) == pytest.approx(.00526407, abs=5e-9)
    with mpmath.workdps(40):
        X = [mpmath.mpc(v) for v in x]
        _, J = alpha.value_and_jacobian(f, X)
        one = mpmath.sqrt(1 + sum(abs(v) ** 2 for v in X))
        rhs = [[mpmath.sqrt(d) * one ** (d - 1) if j == i else 0 for j in range(4)]
               for i, d in enumerate(f.degrees)]
        M = alpha.solve_many(J, rhs)
        norm = mpmath.sqrt(sum(alpha.bombieri_weyl_squared(p, d) for p, d in zip(f.polynomials, f.degrees)))
        m2_gamma = norm * max(abs(v) for row in M for v in row) * 2 ** 1.5 / (2 * one)
        frobenius = mpmath.sqrt(sum(abs(v) ** 2 for row in M for v in row))
    assert float(m2_gamma) == pytest.approx(9.60011, abs=5e-6)
    assert float(g) == pytest.approx(float(norm * frobenius * 2 ** 1.5 / (2 * one)), rel=1e-14)
    assert float(a) == pytest.approx(float(b * g), rel=1e-14)


def test_two_nearby_distinct_roots_are_certified_distinct():
    # (x - 1)(x - 1 - 1e-6): gamma is about 1 / 1e-6, the roots 1e-6 apart
    f = PolySystem(1, ({(2,): 1.0, (1,): -(2 + 1e-6), (0,): 1 + 1e-6},))
    x1, x2 = np.array([1.0 + 0j]), np.array([1 + 1e-6 + 0j])
    c1, c2 = alpha.certify(f, x1), alpha.certify(f, x2)
    assert c1.certified and c2.certified
    assert c1.gamma > 1e5
    assert alpha.distinct(x1, c1, x2, c2)
    assert alpha.undistinguished([x1, x2], [c1, c2]) == []
    # one root twice: not distinct
    assert alpha.undistinguished([x1, x1 + 1e-15], [c1, alpha.certify(f, x1 + 1e-15)]) == [(0, 1)]


def test_a_real_root_is_certified_real_and_a_complex_one_nonreal():
    x = np.array([2 ** 0.5 + 0j])
    c = alpha.certify(SQRT2_SYSTEM, x)
    assert c.certified and c.real and not c.not_real
    f = PolySystem(1, ({(2,): 1.0, (0,): 1.0},))  # x^2 + 1
    c = alpha.certify(f, np.array([1j]))
    assert c.certified and not c.real and c.not_real
    # a point near the real root but off the real line by more than 1 / (20 gamma): no
    # verdict on realness either way (within 4 beta of its mirror image)
    c = alpha.certify(SQRT2_SYSTEM, np.array([2 ** 0.5 + 0.2j]))
    assert not c.real


def test_a_system_with_complex_coefficients_has_no_real_structure():
    assert alpha.has_real_structure(SQRT2_SYSTEM)
    assert not alpha.has_real_structure(PolySystem(1, ({(2,): 1.0, (0,): 1j},)))
    # isotropic coordinates: (z, w) with w the conjugate of z, z w = 1 and z + w = 1
    iso = PolySystem(2, ({(1, 1): 1.0, (0, 0): -1.0}, {(1, 0): 1.0, (0, 1): 1.0, (0, 0): -1.0}),
                     conjugate=(1, 0))
    assert alpha.has_real_structure(iso)
    z = np.exp(1j * np.pi / 3)  # cos(theta) = 1/2
    c = alpha.certify(iso, np.array([z, np.conj(z)]))
    assert c.certified and c.real


def test_every_root_of_a_stephenson_sixbars_assemblies_is_certified_and_distinct():
    from linkage.kinematics.assemblies import every_assembly

    a = every_assembly("sample_inputs/stephenson_sixbar.toml")
    s = a.solutions
    finite = [e for e in s.endpoints if e.kind == "finite"]
    assert len(finite) >= 2 and len(s.certified) == len(finite)
    assert s.undistinguished == []
    real = [c for e, c in s.certified if e.real]
    assert len(real) == len(a.real) and all(c.real for c in real)
    assert all(c.not_real for e, c in s.certified if not e.real)


def test_every_root_of_a_five_pose_burmester_problem_is_certified_and_distinct():
    from linkage.synthesis.burmester import burmester_points

    b = burmester_points([(0, 0, 0), (1, 0.2, 10), (1.8, 0.7, 25), (2.2, 1.5, 45), (2.1, 2.4, 70)])
    s = b.solutions
    finite = [e for e in s.endpoints if e.kind == "finite"]
    assert len(s.certified) == len(finite) >= 2
    assert s.undistinguished == []
    assert sum(c.real for _, c in s.certified) == len(b.cranks)
    assert all(c.real == e.real and c.not_real != e.real for e, c in s.certified)


def test_the_nine_point_equations_multiplied_out_equal_the_factored_ones():
    from linkage.homotopy import ninepoint as npt
    from linkage.homotopy import ninepoint_alpha as na

    rng = np.random.default_rng(4)
    d, db = rng.normal(size=8) + 1j * rng.normal(size=8), rng.normal(size=8) + 1j * rng.normal(size=8)
    system = na.polynomial_system(d, db)
    assert system.degrees == (7,) * 8  # the terms of degree 8 cancel
    z = rng.normal(size=(5, 8)) + 1j * rng.normal(size=(5, 8))
    E, J, _, _ = npt.equations(z, d, db)
    assert np.allclose(system.evaluate(z), E, rtol=1e-12, atol=1e-12 * np.abs(E).max())
    assert np.allclose(system.jacobian(z), J, rtol=1e-12, atol=1e-12 * np.abs(J).max())
    # for real points the bars' swap with conjugation is a real structure
    assert alpha.has_real_structure(na.polynomial_system(d, np.conj(d)))


def test_a_real_four_bar_through_nine_of_its_coupler_points_is_certified_real():
    """A crank-rocker (ground 0 to 3, crank 1, coupler 3, rocker 2.5, coupler point at
    0.4 + 0.6i along the coupler) placed by plane geometry at nine crank angles: the
    four-bar (pivots relative to the first point) is a root of those points' equations."""
    import cmath
    import math

    from linkage.homotopy import ninepoint_alpha as na

    A, B, r1, L, r2, k = 0j, 3 + 0j, 1.0, 3.0, 2.5, 0.4 + 0.6j
    pts, first = [], None
    for phi in np.linspace(0.2, 5.8, 9):
        M = A + r1 * cmath.exp(1j * phi)
        d = abs(B - M)
        along = (L * L - r2 * r2 + d * d) / (2 * d)
        u = (B - M) / d
        N = M + along * u + math.sqrt(L * L - along * along) * u * 1j
        pts.append(M + (N - M) * k)
        first = first or (M, N)
    M, N = first
    z = np.array([A, M, B, N]) - pts[0]
    z = np.concatenate([z, np.conj(z)])
    c = na.certify_rows(z[None, :], pts)[0]
    assert c.certified and c.real and c.alpha < 1e-6
    # a point off by 1e-3: no longer within reach of the test's bound
    assert not na.certify_rows(z[None, :] + 1e-3, pts)[0].certified


def test_a_root_far_from_the_origin_is_tested_in_stretched_variables():
    """x^2 + y^2 = 1e4, x = y at (70.7, 70.7): T = 64 for both, u = x / 64 exactly, and the
    root is within 2 beta(u) 64 of x (the radius in x's own units)."""
    f = PolySystem(2, ({(2, 0): 1.0, (0, 2): 1.0, (0, 0): -1e4}, {(1, 0): 1.0, (0, 1): -1.0}))
    x = np.array([1e2 / 2 ** 0.5, 1e2 / 2 ** 0.5], dtype=complex)
    assert list(alpha.stretch(x, f.mirror)) == [64.0, 64.0]
    c = alpha.certify(f, x)
    assert c.certified and c.real
    assert c.radius == pytest.approx(2 * 64 * c.beta, rel=1e-5)
    root = 1e2 / mpmath.sqrt(2)
    assert float(mpmath.sqrt(2) * abs(mpmath.mpf(x[0].real) - root)) <= c.radius
    # unstretched, the bound grows with ||(1, x)||: the same point tests worse
    a, _, _ = alpha.constants(alpha.normalised(f), x)
    assert a > c.alpha


@pytest.mark.parametrize("scale", [1e-9, 1e6])
def test_the_nine_point_alpha_test_is_the_same_at_every_scale(scale):
    """The docs' nine points in nanometres found the same four-bars but certified none of them
    (the Bombieri-Weyl norms of the unscaled equations are posed for unit size); the test now
    runs at the points' unit size, as the tracking does, its radius scaled back."""
    from linkage.homotopy import ninepoint_track
    from linkage.homotopy.ninepoint_alpha import certify_rows

    pts = [0.25, 0.52 + 0.1j, 0.8 + 0.7j, 1.2 + 1j, 1.4 + 1.3j, 1.1 + 1.48j, 0.7 + 1.4j, 0.2 + 1j,
           0.02 + 0.4j]
    found = ninepoint_track.solve_points(pts, orbits=3)
    unit = certify_rows(found.solutions, found.points)
    scaled = certify_rows(found.solutions * scale, np.asarray(found.points) * scale)
    assert all(c.certified for c in unit)
    assert [c.certified for c in scaled] == [True] * len(unit)
    for a, b in zip(unit, scaled):  # the radius: the rounding of the scaled point's, in its units
        assert b.radius <= 1e-12 * scale and a.real == b.real and a.not_real == b.not_real
