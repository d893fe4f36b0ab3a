"""The nine-point path synthesis problem for four-bars as a parameter family (Wampler,
Morgan and Sommese, "Complete solution of the nine-point path synthesis problem for
four-bar linkages", J. Mech. Des. 114, 1992; Sommese and Wampler 2005, sec. 9.6).

Isotropic coordinates, relative to the first precision point P0: a and b are the fixed
pivots, x and y the vectors from the coupler point to the moving pivots at the first
position, and each has its conjugate as an independent unknown (x~ is conj(x) for a real
four-bar): v = (x, a, y, b, x~, a~, y~, b~). At point j = 1..8 the coupler point is at P0 +
d_j and the coupler has turned by Theta_j = 1 + Q_j. The links keep their lengths:

    |d_j + Theta_j x - a|^2 = |x - a|^2,  the same for y and b,

which read A Q + B Q~ = C and D Q + E Q~ = F with

    A = x (d~ - a~),  B = x~ (d - a),  C = -(d~ (x - a) + d (x~ - a~) + d d~),

D, E, F the same in y and b. Cramer's rule gives Q and Q~, and Theta Theta~ = 1, that is Q +
Q~ + Q Q~ = 0, becomes one equation of degree 7 per point:

    (CE - BF)(AE - BD) + (AF - CD)(AE - BD) + (CE - BF)(AF - CD) = 0.

The parameters are p = (d_1..d_8, d~_1..d~_8); for real points d~_j = conj(d_j). A generic
member has 8652 nonsingular roots (1442 four-bars up to Roberts' cognates, times 3, times
the relabelling x <-> y); Problem 3's nine points have 64 real four-bars up to those six
(WMS 1992, table 3). The total degree is 7^8 = 5,764,801 and the two-homogeneous Bezout
number of {x, a, y, b}, {x~, a~, y~, b~} is 4,587,520, so its roots are reached by a
parameter homotopy from a generic instance, whose roots monodromy finds (:mod:`.parameter`).

:class:`NinePointForm` evaluates the family and every derivative (in X and in p) as numpy
blocks by forward differentiation of that chain of products: the expanded polynomials have
thousands of terms each. :meth:`NinePointFamily.at` expands one member (for Newton
refinement and the condition number of an endpoint).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .polynomials import HomogeneousForm, PolySystem

N = 8
"""Unknowns: x, a, y, b, then their conjugates."""
K = 16
"""Parameters: d_1..d_8, then d~_1..d~_8."""
DEGREE = 7
GROUPS = ((0, 1, 2, 3), (4, 5, 6, 7))
CONJUGATE = (4, 5, 6, 7, 0, 1, 2, 3)
GENERIC_ROOTS = 8652
"""A generic member's nonsingular roots (WMS 1992)."""


@dataclass(frozen=True)
class _Dual:
    """A value over paths and points (P, 8) with its derivatives (P, 8, 1 + N + 1): in X0,
    each unknown, and along the parameters' direction."""

    val: np.ndarray
    grad: np.ndarray

    def __add__(self, o: _Dual) -> _Dual:
        return _Dual(self.val + o.val, self.grad + o.grad)

    def __sub__(self, o: _Dual) -> _Dual:
        return _Dual(self.val - o.val, self.grad - o.grad)

    def __neg__(self) -> _Dual:
        return _Dual(-self.val, -self.grad)

    def __mul__(self, o: _Dual) -> _Dual:
        return _Dual(self.val * o.val, self.val[..., None] * o.grad + o.val[..., None] * self.grad)


def _equations(h: _Dual, x: _Dual, a: _Dual, y: _Dual, b: _Dual, xc: _Dual, ac: _Dual, yc: _Dual, bc: _Dual,
               d: _Dual, dc: _Dual) -> _Dual:
    """The eight equations, homogenised by h (each term of degree 7 in (h, v))."""
    A, B = x * (dc * h - ac), xc * (d * h - a)
    C = -(dc * (x - a) + d * (xc - ac) + d * dc * h)
    D, E = y * (dc * h - bc), yc * (d * h - b)
    F = -(dc * (y - b) + d * (yc - bc) + d * dc * h)
    q, qc, det = C * E - B * F, A * F - C * D, A * E - B * D
    return q * det + qc * det + q * qc * h


@dataclass(frozen=True)
class NinePointForm:
    """The family, homogeneous of degree 7 in (X0, v), with its derivatives by forward
    differentiation: a :class:`.parameter.ParameterForm`."""

    def jet(self, X: np.ndarray, p: np.ndarray, dp: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """F (P, 8), dF/dX (P, 8, 9) and dF/dp . dp (P, 8) at (X, p), one row a path."""
        P, width = X.shape[0], N + 2
        eye = np.eye(width, dtype=complex)

        def column(c: int) -> _Dual:
            return _Dual(np.broadcast_to(X[:, c:c + 1], (P, N)), np.broadcast_to(eye[c], (P, N, width)))

        def parameter(first: int) -> _Dual:
            grad = np.zeros((P, N, width), dtype=complex)
            grad[:, :, -1] = dp[:, first:first + N]
            return _Dual(p[:, first:first + N], grad)

        out = _equations(column(0), *[column(1 + i) for i in range(N)], parameter(0), parameter(N))
        return out.val, out.grad[:, :, :-1], out.grad[:, :, -1]


# --- members expanded, for refinement and conditions --------------------------------------

Poly = dict[tuple[int, ...], complex]


def _mul(p: Poly, q: Poly) -> Poly:
    out: Poly = {}
    for e, c in p.items():
        for f, k in q.items():
            g = tuple(i + j for i, j in zip(e, f))
            out[g] = out.get(g, 0j) + c * k
    return out


def _add(p: Poly, q: Poly, sign: float = 1.0) -> Poly:
    out = dict(p)
    for e, c in q.items():
        out[e] = out.get(e, 0j) + sign * c
    return out


def _var(i: int) -> Poly:
    return {tuple(int(k == i) for k in range(N)): 1 + 0j}


def _const(c: complex) -> Poly:
    return {(0,) * N: complex(c)}


def member(d: complex, dc: complex) -> Poly:
    """One point's equation with numbers for d and d~, expanded in v."""
    x, a, y, b, xc, ac, yc, bc = (_var(i) for i in range(N))
    A, B = _mul(x, _add(_const(dc), ac, -1)), _mul(xc, _add(_const(d), a, -1))
    C = _add(_add(_mul(_const(-dc), _add(x, a, -1)), _mul(_const(-d), _add(xc, ac, -1))), _const(-d * dc))
    D, E = _mul(y, _add(_const(dc), bc, -1)), _mul(yc, _add(_const(d), b, -1))
    F = _add(_add(_mul(_const(-dc), _add(y, b, -1)), _mul(_const(-d), _add(yc, bc, -1))), _const(-d * dc))
    q = _add(_mul(C, E), _mul(B, F), -1)
    qc = _add(_mul(A, F), _mul(C, D), -1)
    det = _add(_mul(A, E), _mul(B, D), -1)
    out = _add(_add(_mul(q, det), _mul(qc, det)), _mul(q, qc))
    return {e: c for e, c in out.items() if c != 0}


@dataclass(frozen=True)
class NinePointFamily:
    """The family as :func:`.parameter.track_parameters` and :func:`.parameter.monodromy`
    take it (n, k, degrees, form, at)."""

    n: int = N
    k: int = K

    @property
    def degrees(self) -> tuple[int, ...]:
        return (DEGREE,) * N

    @cached_property
    def form(self) -> NinePointForm:
        return NinePointForm()

    def at(self, p: np.ndarray) -> PolySystem:
        p = np.asarray(p, dtype=complex)
        polys = tuple(member(p[j], p[N + j]) for j in range(N))
        return PolySystem(N, polys, groups=GROUPS, conjugate=CONJUGATE)

    def homogeneous_at(self, p: np.ndarray) -> HomogeneousForm:
        return HomogeneousForm.of(self.at(p), self.degrees)


def parameters(points: list[tuple[float, float]] | np.ndarray) -> np.ndarray:
    """p for nine points in the plane: d_j = P_j - P_0 as complex numbers and their
    conjugates."""
    z = np.array([complex(px, py) for px, py in points])
    if len(z) != 9:
        raise ValueError(f"nine points are needed, got {len(z)}")
    d = z[1:] - z[0]
    return np.concatenate([d, d.conjugate()])


def seed_instance(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """A generic complex member with one root known: v random, each d_j random and d~_j a
    root of point j's equation, a cubic in d~_j once v and d_j are numbers. (p, v)."""
    v = rng.normal(size=N) + 1j * rng.normal(size=N)
    p = np.zeros(K, dtype=complex)
    form = NinePointForm()
    samples = np.array([-1.0, -0.5, 0.0, 0.5, 1.0, 1.5]) * (1 + 0.3j)
    for j in range(N):
        d = complex(rng.normal(), rng.normal())
        values = []
        for s in samples:
            trial = p.copy()
            trial[j], trial[N + j] = d, s
            F, _, _ = form.jet(np.concatenate([[1.0 + 0j], v])[None], trial[None], np.zeros((1, K)))
            values.append(F[0, j])
        roots = np.roots(np.polyfit(samples, np.array(values), 3))
        p[j], p[N + j] = d, roots[np.argmin(np.abs(roots))]
    return p, v
