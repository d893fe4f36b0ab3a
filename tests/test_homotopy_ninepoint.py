"""The nine-point path synthesis family (linkage.homotopy.ninepoint), against a four-bar
whose coupler points are computed here by the closed form (two circles' intersection),
its own expansion, and finite differences; and monodromy on it, each root certified."""

from __future__ import annotations

import cmath
import math

import numpy as np

from linkage.homotopy.ninepoint import CONJUGATE, DEGREE, K, N, NinePointFamily, parameters, seed_instance
from linkage.homotopy.parameter import monodromy
from linkage.homotopy.solve import condition, relative_residual

FAMILY = NinePointFamily()


def _circles(c1: complex, r1: float, c2: complex, r2: float, near: complex) -> complex:
    """The intersection of two circles nearer ``near``."""
    d = abs(c2 - c1)
    along = (r1 ** 2 - r2 ** 2 + d ** 2) / (2 * d)
    half = math.sqrt(r1 ** 2 - along ** 2)
    base, across = c1 + along * (c2 - c1) / d, 1j * (c2 - c1) / d
    return min((base + half * across, base - half * across), key=lambda z: abs(z - near))


def _four_bar_points() -> tuple[np.ndarray, list[tuple[float, float]]]:
    """A real four-bar (pivots a, b; moving pivots at x, y from the coupler point, which is
    at the origin at the first point) and nine points of its coupler curve: with the coupler
    turned by psi, the coupler point is where the circles about a - e^(i psi) x and b -
    e^(i psi) y, of the links' lengths, meet."""
    a, b, x, y = complex(0.1, -0.5), complex(1.2, -0.4), complex(-0.3, -0.2), complex(0.5, -0.6)
    points, last = [0j], 0j
    for j in range(1, 9):
        turn = cmath.exp(0.03j * j)
        last = _circles(a - turn * x, abs(x - a), b - turn * y, abs(y - b), last)
        points.append(last)
    v = np.array([x, a, y, b, x.conjugate(), a.conjugate(), y.conjugate(), b.conjugate()])
    return v, [(z.real, z.imag) for z in points]


def test_a_four_bar_solves_the_equations_of_nine_points_on_its_coupler_curve():
    v, points = _four_bar_points()
    p = parameters(points)
    system = FAMILY.at(p)
    assert relative_residual(system, v) <= 1e-14
    assert system.realness(v) == 0.0 and CONJUGATE == system.conjugate
    F, _, _ = FAMILY.form.jet(np.concatenate([[1.0], v])[None], p[None], np.zeros((1, K)))
    assert np.abs(F).max() <= 1e-14
    moved = v.copy()
    moved[0] += 1e-3  # the moving pivot moved: the links no longer keep their lengths
    assert relative_residual(FAMILY.at(p), moved) > 1e-6
    # relabelling x <-> y is the same four-bar
    swapped = v[[2, 3, 0, 1, 6, 7, 4, 5]]
    assert relative_residual(system, swapped) <= 1e-14


def test_the_forward_derivatives_are_the_expanded_polynomials_and_finite_differences():
    rng = np.random.default_rng(2)
    p = rng.normal(size=K) + 1j * rng.normal(size=K)
    X = (rng.normal(size=N + 1) + 1j * rng.normal(size=N + 1))[None]
    dp = (rng.normal(size=K) + 1j * rng.normal(size=K))[None]
    F, JX, Fp = FAMILY.form.jet(X, p[None], dp)
    H = FAMILY.homogeneous_at(p)
    assert H.exponents.sum(axis=1).max() == DEGREE
    assert np.allclose(F, H.evaluate(X), rtol=1e-12, atol=1e-12 * np.abs(F).max())
    assert np.allclose(JX, H.jacobian(X), rtol=1e-12, atol=1e-12 * np.abs(JX).max())
    h = 1e-5
    up, _, _ = FAMILY.form.jet(X, p[None] + h * dp, dp)
    down, _, _ = FAMILY.form.jet(X, p[None] - h * dp, dp)
    assert np.abs((up - down) / (2 * h) - Fp).max() <= 1e-7 * np.abs(Fp).max()


def test_monodromy_on_a_generic_instance_finds_new_roots_each_certified():
    """One loop from one seed root: the count grows, and every root is finite, nonsingular
    (condition below 1e6), solves its system to rounding and is distinct from the others."""
    p, v = seed_instance(np.random.default_rng(0))
    system = FAMILY.at(p)
    assert relative_residual(system, v) <= 1e-13
    found = monodromy(FAMILY, p, v[None], max_loops=1, seed=1)
    assert found.counts[-1] == len(found.roots) > 1 and found.counts == tuple(sorted(found.counts))
    for i, x in enumerate(found.roots):
        assert relative_residual(system, x) <= 1e-13
        assert condition(system, x) < 1e6
        others = np.delete(found.roots, i, axis=0)
        assert np.linalg.norm(others - x, axis=1).min() > 1e-6 * max(1.0, np.linalg.norm(x))
