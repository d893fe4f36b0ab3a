"""Start systems whose roots are known: total degree, and linear products matched to a
multihomogeneous grouping of the variables.

A total-degree start (x_i^d_i = 1) has one root per product of the degrees, and every path
beyond the system's own root count goes to infinity, where its endgame is most of the
work. A linear-product start G_i = prod_k (a_ik . x + b_ik), each factor a random linear form
on a set of variables, has the multihomogeneous Bezout number of roots: with the variables
grouped (say every z = e^(i theta) in one group, every w = e^(-i theta) in another), F_i of
degree d_ij in group j gets d_ij factors on group j's variables, and F_i lies in the span
of such products, so the homotopy (1 - t) gamma G + t F stays in one family whose generic
member has exactly G's number of roots (Morgan and Sommese, "A homotopy for solving general
polynomial systems that respects m-homogeneous structures", Appl. Math. Comput. 24, 1987;
Verschelde and Cools, "Symbolic homotopy construction", AAECC 4, 1993; Sommese and Wampler
2005, sec. 8.4). A linear F_i keeps one factor on every variable it has. A choice of one
factor per equation is a linear system; for random coefficients it has one root exactly
when its supports admit a perfect matching of equations to variables, and the roots of G
are the roots of those systems.
"""

from __future__ import annotations

import numpy as np

from ..records import frozen
from .polynomials import PolySystem, total_degree_start, total_degree_start_points

TOTAL_DEGREE = "total degree"
LINEAR_PRODUCT = "linear product"


@frozen
class LinearProduct:
    """G_i(X) = prod_k A[i, k] . X over each equation's factors (a factor past its
    equation's count is 1), homogeneous in X = (X0, x): evaluated like a HomogeneousForm."""

    factors: np.ndarray  # (m, K, n + 1): each factor's coefficients on (X0, x)
    counts: np.ndarray  # (m,): factors of each equation

    def both(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """G (P, m) and dG/dX (P, m, n + 1)."""
        K = self.factors.shape[1]
        L = np.einsum("mkv,pv->pmk", self.factors, X)
        L = np.where(np.arange(K)[None, None, :] < self.counts[None, :, None], L, 1.0)
        # the product of every factor but the k-th, by prefix and suffix products (no division
        # by a factor that vanishes at a root)
        before = np.ones_like(L)
        after = np.ones_like(L)
        for k in range(1, K):
            before[:, :, k] = before[:, :, k - 1] * L[:, :, k - 1]
            after[:, :, K - 1 - k] = after[:, :, K - k] * L[:, :, K - k]
        others = np.where(np.arange(K)[None, None, :] < self.counts[None, :, None], before * after, 0.0)
        return before[:, :, -1] * L[:, :, -1], np.einsum("pmk,mkv->pmv", others, self.factors)

    def evaluate(self, X: np.ndarray) -> np.ndarray:
        return self.both(X)[0]

    def jacobian(self, X: np.ndarray) -> np.ndarray:
        return self.both(X)[1]


@frozen
class Start:
    """A start system, its roots (affine), each equation's degree in the homotopy (the
    target is homogenised to it) and the bound its root count is."""

    form: object  # a HomogeneousForm or a LinearProduct: has both(X)
    points: np.ndarray  # (paths, n)
    degrees: tuple[int, ...]
    kind: str


def total_degree(system: PolySystem) -> Start:
    start = total_degree_start(system.degrees)
    return Start(start.homogeneous, total_degree_start_points(system.degrees), system.degrees, TOTAL_DEGREE)


def factor_supports(system: PolySystem) -> list[list[tuple[int, ...]]]:
    """Each equation's linear factors, as the variables each is a form in: d_ij factors on
    the variables of group j that F_i has, d_ij its degree in group j; one factor on every
    variable of a linear F_i."""
    out = []
    for p, d in zip(system.polynomials, system.degrees):
        used = [v for v in range(system.n) if any(e[v] for e in p)]
        if d <= 1:
            out.append([tuple(used)])
            continue
        factors: list[tuple[int, ...]] = []
        for group in system.groups:
            degree = max(sum(e[v] for v in group) for e in p)
            factors += [tuple(v for v in group if v in used)] * degree
        out.append(factors)
    return out


def _augment(row: int, supports: list[tuple[int, ...]], owner: dict[int, int], seen: set[int]) -> bool:
    """Kuhn's augmenting path: give ``row`` a variable, moving other rows along if needed."""
    for v in supports[row]:
        if v in seen:
            continue
        seen.add(v)
        if v not in owner or _augment(owner[v], supports, owner, seen):
            owner[v] = row
            return True
    return False


def choices(supports: list[list[tuple[int, ...]]], n: int) -> list[tuple[int, ...]]:
    """Every choice of one factor per equation whose supports admit a perfect matching of
    equations to variables (a depth-first search, cut where the rows so far have none)."""
    out: list[tuple[int, ...]] = []
    rows: list[tuple[int, ...]] = []

    def visit(i: int, owner: dict[int, int], picked: tuple[int, ...]) -> None:
        if i == len(supports):
            if len(owner) == n:
                out.append(picked)
            return
        for k, s in enumerate(supports[i]):
            rows.append(s)
            trial = dict(owner)
            if _augment(i, rows, trial, set()):
                visit(i + 1, trial, (*picked, k))
            rows.pop()

    visit(0, {}, ())
    return out


def linear_product_bound(system: PolySystem) -> int:
    """The number of roots of the linear-product start (:func:`factor_supports`): the
    multihomogeneous Bezout number of the grouping, or fewer where an equation lacks some of
    a group's variables (two loops that share no angle count as two four-bars, 2 x 2)."""
    return len(choices(factor_supports(system), system.n))


def linear_product(system: PolySystem, rng: np.random.Generator) -> Start:
    """The linear-product start for the system's groups, with random complex coefficients."""
    supports = factor_supports(system)
    m, n = len(supports), system.n
    K = max(len(f) for f in supports)
    A = np.zeros((m, K, n + 1), dtype=complex)
    for i, factors in enumerate(supports):
        for k, s in enumerate(factors):
            cols = [0, *(v + 1 for v in s)]
            A[i, k, cols] = rng.normal(size=len(cols)) + 1j * rng.normal(size=len(cols))
    picks = np.array(choices(supports, n), dtype=np.intp).reshape(-1, m)
    rows = A[np.arange(m)[None, :], picks]  # (roots, m, n + 1)
    points = np.linalg.solve(rows[:, :, 1:], -rows[:, :, 0:1])[:, :, 0] if len(picks) else np.zeros((0, n))
    counts = np.array([len(f) for f in supports])
    return Start(LinearProduct(A, counts), points, tuple(int(c) for c in counts), LINEAR_PRODUCT)


def start_for(system: PolySystem, rng: np.random.Generator) -> Start:
    """The linear-product start where the system has groups and it needs fewer paths than the
    total degree; the total-degree start otherwise."""
    if system.groups and linear_product_bound(system) < system.bezout:
        return linear_product(system, rng)
    return total_degree(system)
