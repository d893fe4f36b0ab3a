"""Parameter homotopy and monodromy (linkage.homotopy.parameter), against roots known
otherwise: closed forms (square and cube roots), the total-degree homotopy's count on a
generic six-bar-like family (C(4, 2) = 6), and a real Stephenson six-bar's assemblies from
its closed form, every root refined at 50 digits by mpmath."""

from __future__ import annotations

import cmath
import math
from pathlib import Path

import mpmath
import numpy as np
import pytest

from linkage.homotopy import PolySystem, solve
from linkage.homotopy.parameter import Family, monodromy, track_parameters
from linkage.kinematics.assemblies import assembly_system, encode
from linkage.kinematics.loading import load

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"


def _matched(ours, theirs, tol: float = 1e-9) -> bool:
    left = [np.asarray(y) for y in theirs]
    for x in ours:
        size = max(1.0, float(np.linalg.norm(x)))
        k = next((i for i, y in enumerate(left) if np.linalg.norm(np.asarray(x) - y) <= tol * size), None)
        if k is None:
            return False
        left.pop(k)
    return not left


@pytest.mark.parametrize("d", [2, 3, 5])
def test_roots_of_a_number_by_parameter_homotopy_and_monodromy(d):
    """x^d - p: from the d-th roots of a complex p0 to those of p1 = 4 (closed form), and
    monodromy from one root of p0 finds all d (the loops wind about p = 0)."""
    family = Family(1, 1, ({(d, 0): 1 + 0j, (0, 1): -1 + 0j},))
    p0 = 0.3 + 1.1j
    start = np.array([[cmath.exp((cmath.log(p0) + 2j * math.pi * k) / d)] for k in range(d)])
    ends = track_parameters(family, [p0], [4.0], start)
    want = [[4 ** (1 / d) * cmath.exp(2j * math.pi * k / d)] for k in range(d)]
    assert [e.kind for e in ends.endpoints] == ["finite"] * d
    assert _matched([e.x for e in ends.endpoints], want, 1e-13)
    assert sum(e.real for e in ends.endpoints) == (2 if d % 2 == 0 else 1)
    found = monodromy(family, [p0], start[:1], seed=1)
    assert len(found.roots) == d and found.stable == 5 and found.dropped == 0
    assert _matched(found.roots, start, 1e-12)


def test_each_monodromy_loop_is_reported_as_it_ends():
    """on_loop sees each loop's record as it ends: the count after it, what it added and
    dropped; the records add up to the result's counts, roots and dropped paths."""
    family = Family(1, 1, ({(4, 0): 1 + 0j, (0, 1): -1 + 0j},))
    seen = []
    found = monodromy(family, [2.0 + 1.0j], [[complex(2.0 + 1.0j) ** 0.25]], seed=5, on_loop=seen.append)
    assert tuple(seen) == found.loops and [r.count for r in seen] == list(found.counts)
    assert sum(r.new for r in seen) == len(found.roots) - 1 == 3
    assert sum(r.dropped for r in seen) == found.dropped


def _six_bar_family(seed: int) -> Family:
    """Two loops on four angles in isotropic coordinates, sum_k a_jk z_k + p_j = 0 and its
    conjugate-structured twin sum_k conj(a_jk) w_k + q_j = 0, z_k w_k = 1: the loops'
    constant terms are the parameters (four, complex)."""
    rng = np.random.default_rng(seed)
    n, k = 8, 4

    def mono(*idx: int) -> tuple[int, ...]:
        e = [0] * (n + k)
        for i in idx:
            e[i] += 1
        return tuple(e)

    polys = []
    for j in range(2):
        a = rng.normal(size=4) + 1j * rng.normal(size=4)
        polys.append({**{mono(2 * q): c for q, c in enumerate(a)}, mono(n + 2 * j): 1 + 0j})
        twin = {mono(2 * q + 1): c.conjugate() for q, c in enumerate(a)}
        polys.append({**twin, mono(n + 2 * j + 1): 1 + 0j})
    polys += [{mono(2 * q, 2 * q + 1): 1 + 0j, mono(): -1 + 0j} for q in range(4)]
    return Family(n, k, tuple(polys), groups=((0, 2, 4, 6), (1, 3, 5, 7)), conjugate=(1, 0, 3, 2, 5, 4, 7, 6))


def test_monodromy_from_one_seed_finds_the_six_roots_the_total_degree_finds():
    """A seed made by choosing x first (p = -the loops' other terms at x): monodromy finds
    6 roots, stable for 5 loops, and they are the total-degree homotopy's finite roots (its
    other 10 paths go to infinity)."""
    family = _six_bar_family(3)
    rng = np.random.default_rng(4)
    z = np.exp(1j * rng.normal(size=4) + 0.3 * rng.normal(size=4))
    x = np.empty(8, complex)
    x[0::2], x[1::2] = z, 1 / z
    p = -family.at(np.zeros(4)).evaluate(x[None])[0][:4]
    found = monodromy(family, p, x[None], seed=2)
    system = family.at(p)
    full = solve(PolySystem(8, system.polynomials))
    finite = [e.x for e in full.endpoints if e.kind == "finite"]
    assert len(finite) == 6 == len(found.roots) and full.count("infinite") == 10
    assert found.stable == 5 and found.counts[-1] == 6
    assert _matched(found.roots, finite)


def _refined_50_digits(system: PolySystem, x: np.ndarray) -> list[mpmath.mpc]:
    """Newton's method at 50 digits from x, with the exact Jacobian of the polynomials."""
    mpmath.mp.dps = 50

    def f(*v):
        return [sum(mpmath.mpc(c) * mpmath.fprod(v[i] ** k for i, k in enumerate(e)) for e, c in p.items())
                for p in system.polynomials]

    def jac(*v):
        rows = []
        for p in system.polynomials:
            row = []
            for j in range(system.n):
                row.append(sum(mpmath.mpc(c) * e[j] * mpmath.fprod(
                    v[i] ** (k - (i == j)) for i, k in enumerate(e)) for e, c in p.items() if e[j]))
            rows.append(row)
        return mpmath.matrix(rows)

    root = mpmath.findroot(f, [mpmath.mpc(complex(v)) for v in x], J=jac, tol=mpmath.mpf(10) ** -45)
    return [root[i] for i in range(system.n)]


def test_a_stephenson_six_bars_assemblies_by_parameter_homotopy_from_a_generic_instance():
    """The sample's loops with their constant terms (the ground link and the crank) as
    parameters: monodromy fills a generic complex instance from one seed, and tracking those
    roots to the sample's own constants gives its assemblies: the closed form's real ones,
    and every root (real or complex) within 1e-12 of its 50-digit refinement."""
    m = load(SAMPLES / "stephenson_sixbar.toml")
    system = assembly_system(m, m.driver.value)
    n, loops = system.n, 4
    zero = (0,) * n
    polys = []
    for j, p in enumerate(system.polynomials):
        e = {(*key, *([0] * loops)): c for key, c in p.items() if key != zero or j >= loops}
        if j < loops:
            e[(*zero, *[int(i == j) for i in range(loops)])] = 1 + 0j
        polys.append(e)
    family = Family(n, loops, tuple(polys), system.groups, system.conjugate)
    target = [complex(system.polynomials[j].get(zero, 0j)) for j in range(loops)]
    rng = np.random.default_rng(8)
    z = np.exp(1j * rng.normal(size=4) + 0.3 * rng.normal(size=4))
    x = np.empty(n, complex)
    x[0::2], x[1::2] = z, 1 / z
    p0 = -family.at(np.zeros(loops)).evaluate(x[None])[0][:loops]
    found = monodromy(family, p0, x[None], seed=3)
    assert len(found.roots) == 4 and found.stable == 5  # the driver is in a four-bar loop: 2 x 2
    ends = track_parameters(family, p0, target, found.roots)
    assert [e.kind for e in ends.endpoints] == ["finite"] * 4
    real = [e.x for e in ends.endpoints if e.real]
    want = [np.array(encode(m, q)) for _, q in m.derivation.solutions(m.driver.value)]
    assert len(real) == len(want) == 2 and _matched(real, want)
    for e in ends.endpoints:
        exact = _refined_50_digits(system, e.x)
        assert max(abs(complex(a) - b) for a, b in zip(exact, e.x)) <= 1e-12
        assert e.residual <= 1e-13 and e.condition < 1e4
