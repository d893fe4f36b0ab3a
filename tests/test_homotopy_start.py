"""Start systems of linkage.homotopy (linkage.homotopy.start): the linear-product start
finds the same roots as the total-degree start, with fewer paths, on random systems whose
structure is that of a mechanism's loops in isotropic coordinates; its path count is the
multihomogeneous Bezout number counted by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest

from linkage.homotopy import PolySystem, solve
from linkage.homotopy.start import (
    LINEAR_PRODUCT,
    TOTAL_DEGREE,
    choices,
    factor_supports,
    linear_product_bound,
)


def _loops(supports: list[list[int]], rng: np.random.Generator, n_angles: int) -> PolySystem:
    """Random loops in isotropic coordinates: for each loop, sum_k a_k z_k + b = 0 and its
    conjugate sum_k conj(a_k) w_k + conj(b) = 0; z_k w_k = 1 per angle. Variables z_k at 2k,
    w_k at 2k + 1."""
    n = 2 * n_angles

    def mono(*idx: int) -> tuple[int, ...]:
        e = [0] * n
        for i in idx:
            e[i] += 1
        return tuple(e)

    polys = []
    for loop in supports:
        a = rng.normal(size=len(loop)) + 1j * rng.normal(size=len(loop))
        b = complex(rng.normal(), rng.normal())
        polys.append({**{mono(2 * k): c for k, c in zip(loop, a)}, mono(): b})
        polys.append({**{mono(2 * k + 1): c.conjugate() for k, c in zip(loop, a)}, mono(): b.conjugate()})
    polys += [{mono(2 * k, 2 * k + 1): 1 + 0j, mono(): -1 + 0j} for k in range(n_angles)]
    groups = (tuple(range(0, n, 2)), tuple(range(1, n, 2)))
    conjugate = tuple(k ^ 1 for k in range(n))
    return PolySystem(n, tuple(polys), groups=groups, conjugate=conjugate)


def _finite(sols) -> list[np.ndarray]:
    return [e.x for e in sols.endpoints if e.kind == "finite"]


def _same_roots(a: list[np.ndarray], b: list[np.ndarray], tol: float = 1e-9) -> bool:
    left = list(b)
    for x in a:
        size = max(1.0, float(np.linalg.norm(x)))
        k = next((i for i, y in enumerate(left) if np.linalg.norm(x - y) <= tol * size), None)
        if k is None:
            return False
        left.pop(k)
    return not left


@pytest.mark.parametrize("loops,n_angles,bound", [
    ([[0, 1]], 2, 2),  # a four-bar: two unknown angles in one loop
    ([[0, 1, 2, 3], [0, 1, 2, 3]], 4, 6),  # two loops on every angle: C(4, 2)
    ([[0, 1], [2, 3]], 4, 4),  # two four-bars that share no angle (a Watt six-bar): 2 x 2
])
def test_the_linear_product_start_finds_the_total_degrees_roots_with_fewer_paths(loops, n_angles, bound):
    """On random complex instances the total-degree homotopy's finite roots (its other paths
    go to infinity) are the linear-product homotopy's, which tracks the bound's number of
    paths and loses none to infinity."""
    rng = np.random.default_rng(7)
    for _ in range(3):
        system = _loops(loops, rng, n_angles)
        assert linear_product_bound(system) == bound
        full = solve(PolySystem(system.n, system.polynomials))  # no groups: total degree
        product = solve(system)
        assert full.start == TOTAL_DEGREE and full.bound == 2 ** n_angles
        assert product.start == LINEAR_PRODUCT and product.bound == bound
        assert full.count("failed") == product.count("failed") == 0
        assert len(_finite(product)) == bound == len(_finite(full))
        assert _same_roots(_finite(product), _finite(full))
        assert all(e.residual <= 1e-13 and e.condition < 1e6 for e in product.finite)


def test_the_six_bars_bound_counted_by_hand():
    """Circles z_k w_k = 1 each give a z- or a w-factor; two loops on all four angles (one
    equation in the z's, one in the w's) leave two z's and two w's to pick: C(4, 2) = 6
    choices, each a perfect matching; four-bar loops on disjoint angles allow 2 x 2."""
    rng = np.random.default_rng(1)
    system = _loops([[0, 1, 2, 3], [0, 1, 2, 3]], rng, 4)
    supports = factor_supports(system)
    assert [len(f) for f in supports] == [1, 1, 1, 1, 2, 2, 2, 2]
    picked = choices(supports, system.n)
    assert len(picked) == math.comb(4, 2)
    assert all(sorted(p[4:]).count(0) == 2 for p in picked)  # two circles give z-factors


def test_a_real_point_in_isotropic_coordinates_is_one_whose_w_is_conj_z():
    """z = e^(i theta), w = conj(z) is real for the system's real structure, though z has an
    imaginary part; the endpoint of a mechanism-like system is classified by it."""
    system = _loops([[0, 1]], np.random.default_rng(3), 2)
    z = complex(math.cos(0.3), math.sin(0.3))
    assert system.realness(np.array([z, z.conjugate(), 1j, -1j])) == 0.0
    assert system.realness(np.array([z, z, 1j, -1j])) > 0.1
    x = system.nearest_real(np.array([z, z.conjugate() + 1e-3, 1j, -1j]))
    assert system.realness(x) == 0.0
