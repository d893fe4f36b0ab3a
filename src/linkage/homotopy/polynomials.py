"""Polynomial systems as data, evaluated with their Jacobians for many points at once.

A system is a list of polynomials in n variables, each a mapping from an exponent tuple to
a complex coefficient. Homotopy continuation tracks paths in projective space (so a path
that goes to infinity stays bounded): each polynomial is homogenised to its total degree
with an extra variable X0, and a point is X = (X0, X1, ..., Xn), the affine point being
X[1:] / X0. Every evaluation takes an array of points, one per row, so that all paths of a
homotopy are one numpy block (Sommese and Wampler, *The Numerical Solution of Systems of
Polynomials Arising in Engineering and Science*, World Scientific 2005, ch. 3).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from functools import cached_property

import numpy as np

from ..records import frozen

Polynomial = Mapping[tuple[int, ...], complex]
"""Exponents -> coefficient; an exponent tuple has one entry per (affine) variable."""


@frozen
class PolySystem:
    """A square or overdetermined polynomial system in ``n`` affine variables."""

    n: int
    polynomials: tuple[Polynomial, ...]
    names: tuple[str, ...] = ()
    groups: tuple[tuple[int, ...], ...] = ()
    """A partition of the variables for a multihomogeneous start system (:mod:`.start`);
    empty: the total-degree start."""
    conjugate: tuple[int, ...] = ()
    """The real structure: a point x is real when x[conjugate] = conj(x). Isotropic
    coordinates (z = e^(i theta), w = e^(-i theta)) pair z with w; empty: every variable is
    its own conjugate (the usual real points)."""

    def __post_init__(self) -> None:
        for p in self.polynomials:
            for e in p:
                if len(e) != self.n or any(k < 0 for k in e):
                    raise ValueError(f"exponent {e} does not fit {self.n} variables")
            if not p:
                raise ValueError("a polynomial with no terms")
        if self.groups and sorted(v for g in self.groups for v in g) != list(range(self.n)):
            raise ValueError(f"groups {self.groups} are not a partition of the {self.n} variables")
        if self.conjugate and sorted(self.conjugate) != list(range(self.n)):
            raise ValueError(f"conjugate {self.conjugate} is not a permutation of the {self.n} variables")

    @property
    def mirror(self) -> np.ndarray:
        """The conjugate's index array (the identity without one)."""
        return np.array(self.conjugate or range(self.n), dtype=np.intp)

    def realness(self, x: np.ndarray) -> float:
        """How far x is from real, against max(1, |x|): max |x[conjugate] - conj(x)| / 2."""
        gap = float(np.abs(x[self.mirror] - np.conj(x)).max(initial=0.0)) / 2
        return gap / max(1.0, float(np.linalg.norm(x)))

    def nearest_real(self, x: np.ndarray) -> np.ndarray:
        """The real point nearest x: (x + conj(x[conjugate])) / 2."""
        return (x + np.conj(x[self.mirror])) / 2

    @cached_property
    def degrees(self) -> tuple[int, ...]:
        return tuple(max(sum(e) for e in p) for p in self.polynomials)

    @cached_property
    def bezout(self) -> int:
        """The total-degree (Bezout) bound on isolated solutions of a square system."""
        out = 1
        for d in self.degrees:
            out *= d
        return out

    @cached_property
    def homogeneous(self) -> HomogeneousForm:
        return HomogeneousForm.of(self)

    def homogenised(self, degrees: Sequence[int]) -> HomogeneousForm:
        """Each polynomial homogenised to the given degree (at least its own): a start system
        whose equation i has more factors than F_i's degree needs F_i at that degree."""
        return HomogeneousForm.of(self, degrees)

    def evaluate(self, x: np.ndarray) -> np.ndarray:
        """F at affine points ``x`` (P, n): (P, m)."""
        X = np.concatenate([np.ones((x.shape[0], 1), dtype=complex), x], axis=1)
        return self.homogeneous.evaluate(X)

    def jacobian(self, x: np.ndarray) -> np.ndarray:
        """dF/dx at affine points (P, n): (P, m, n)."""
        X = np.concatenate([np.ones((x.shape[0], 1), dtype=complex), x], axis=1)
        return self.homogeneous.jacobian(X)[:, :, 1:]


@frozen
class HomogeneousForm:
    """Each polynomial homogenised to its degree, as matrices over one list of monomials:
    F(X) = C M(X) and dF/dX_v = D_v M(X), M(X) the monomials' values."""

    exponents: np.ndarray  # (monomials, n + 1)
    coefficients: np.ndarray  # (m, monomials)
    derivatives: np.ndarray  # (m, n + 1, monomials)
    max_power: int

    @classmethod
    def of(cls, system: PolySystem, degrees: Sequence[int] | None = None,
           counted: int | None = None) -> HomogeneousForm:
        """``counted``: only the first so many variables count toward a term's degree (the
        unknowns of a family whose last variables are its parameters, :mod:`.parameter`)."""
        counted = system.n if counted is None else counted
        own = tuple(max(sum(e[:counted]) for e in p) for p in system.polynomials)
        degrees = own if degrees is None else tuple(degrees)
        if any(d < o for d, o in zip(degrees, own)) or len(degrees) != len(own):
            raise ValueError(f"degrees {degrees} below the polynomials' own {own}")
        index: dict[tuple[int, ...], int] = {}

        def slot(e: tuple[int, ...]) -> int:
            if e not in index:
                index[e] = len(index)
            return index[e]

        terms = []
        for d, p in zip(degrees, system.polynomials):
            for e, c in p.items():
                terms.append((d, (d - sum(e[:counted]), *e), complex(c)))
        # every monomial and every first derivative's monomial, in one list
        for _, e, _ in terms:
            slot(e)
            for v, k in enumerate(e):
                if k:
                    slot((*e[:v], k - 1, *e[v + 1:]))
        m, nv = len(system.polynomials), system.n + 1
        C = np.zeros((m, len(index)), dtype=complex)
        D = np.zeros((m, nv, len(index)), dtype=complex)
        for i, (d, p) in enumerate(zip(degrees, system.polynomials)):
            for e, c in p.items():
                h = (d - sum(e[:counted]), *e)
                C[i, index[h]] += c
                for v, k in enumerate(h):
                    if k:
                        D[i, v, index[(*h[:v], k - 1, *h[v + 1:])]] += k * c
        E = np.array(list(index), dtype=np.intp).reshape(len(index), nv)
        return cls(E, C, D, int(E.max(initial=0)))

    def monomials(self, X: np.ndarray) -> np.ndarray:
        """M(X): (monomials, P)."""
        powers = np.ones((X.shape[1], self.max_power + 1, X.shape[0]), dtype=complex)
        for k in range(1, self.max_power + 1):
            powers[:, k, :] = powers[:, k - 1, :] * X.T
        v = np.arange(X.shape[1])
        return powers[v[None, :], self.exponents, :].prod(axis=1)

    def evaluate(self, X: np.ndarray) -> np.ndarray:
        return (self.coefficients @ self.monomials(X)).T

    def _jacobian(self, M: np.ndarray) -> np.ndarray:
        m, nv, k = self.derivatives.shape
        # one matrix product (einsum took three times as long on these small blocks)
        return (self.derivatives.reshape(m * nv, k) @ M).T.reshape(M.shape[1], m, nv)

    def jacobian(self, X: np.ndarray) -> np.ndarray:
        return self._jacobian(self.monomials(X))

    def both(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        M = self.monomials(X)
        return (self.coefficients @ M).T, self._jacobian(M)


def total_degree_start(degrees: Sequence[int]) -> PolySystem:
    """G_i = x_i^d_i - 1: its solutions are every combination of d_i-th roots of unity."""
    n = len(degrees)
    polys = []
    for i, d in enumerate(degrees):
        e = [0] * n
        e[i] = d
        polys.append({tuple(e): 1.0 + 0j, (0,) * n: -1.0 + 0j})
    return PolySystem(n, tuple(polys))


def total_degree_start_points(degrees: Sequence[int]) -> np.ndarray:
    """Every solution of :func:`total_degree_start` (prod d_i rows, affine)."""
    grids = np.meshgrid(*[np.exp(2j * np.pi * np.arange(d) / d) for d in degrees], indexing="ij")
    return np.stack([g.reshape(-1) for g in grids], axis=1)
