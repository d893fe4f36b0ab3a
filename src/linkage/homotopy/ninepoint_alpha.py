"""The nine-point equations as polynomials, and alpha certificates of their solutions.

:func:`.ninepoint.equations` evaluates E_j = N1 N2 - D^2 in the factored form of Wampler,
Morgan and Sommese (1992). Smale's alpha test (:mod:`.alpha`) needs each E_j's
coefficients for its Bombieri-Weyl norm, and a residual measured against a polynomial's
terms needs them too: :func:`polynomial_system` multiplies the factors out (N1 N2 and D^2
are of degree 8, but their terms of degree 8, which do not involve the points, cancel:
E_j has degree 7). The test itself evaluates E and its Jacobian in the factored form at 50
digits (the same values, far fewer operations than 260 terms and their derivatives).

The real structure: for real points (deltabar_j = conj(delta_j)), R(z) = conj of z with
each unknown swapped for its bar maps P to conj(Pb), Pb to conj(P), R to conj(R), so N1 to
-conj(N2), N2 to -conj(N1), D to -conj(D), and E_j(R(z)) = conj(E_j(z)): a real structure
with A = I (:mod:`.alpha`, module docstring).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import mpmath
import numpy as np

from . import ninepoint as npt
from .alpha import DIGITS, Certificate, bombieri_weyl_squared, constants_at, stretch, verdict
from .polynomials import PolySystem
from .solve import equation_sizes

Poly = dict[tuple[int, ...], Any]
MIRROR = np.array([npt.AB, npt.XB, npt.BB, npt.YB, npt.A, npt.X, npt.B, npt.Y])
"""Each unknown's bar: a real four-bar has z[MIRROR] = conj(z)."""


def _var(k: int) -> Poly:
    e = [0] * 8
    e[k] = 1
    return {tuple(e): 1}


def _sum(*ps: Poly) -> Poly:
    out: Poly = {}
    for p in ps:
        for e, c in p.items():
            out[e] = out.get(e, 0) + c
    return out


def _times(p: Poly, q: Poly, sign: int = 1) -> Poly:
    out: Poly = {}
    for e1, c1 in p.items():
        for e2, c2 in q.items():
            e = tuple(a + b for a, b in zip(e1, e2))
            out[e] = out.get(e, 0) + sign * c1 * c2
    return out


def _dyad(g: int, m: int, gb: int, mb: int, d: Any, db: Any) -> tuple[Poly, Poly, Poly]:
    """P, Pb, R of :func:`.ninepoint.equations` (module docstring there) as polynomials."""
    P = _sum({e: c * db for e, c in _var(m).items()}, _times(_var(m), _var(gb), -1))
    Pb = _sum({e: c * d for e, c in _var(mb).items()}, _times(_var(mb), _var(g), -1))
    R = _sum({(0,) * 8: d * db}, {e: -d * c for e, c in _var(gb).items()},
             {e: -db * c for e, c in _var(g).items()}, _times(_var(m), _var(gb)), _times(_var(mb), _var(g)))
    return P, Pb, R


def expanded(d: Any, db: Any) -> Poly:
    """E = N1 N2 - D^2 for one point (delta, deltabar), multiplied out; the coefficients
    are of the type of ``d`` (complex, or mpmath's mpc for exact norms)."""
    P, Pb, R = _dyad(npt.A, npt.X, npt.AB, npt.XB, d, db)
    Q, Qb, S = _dyad(npt.B, npt.Y, npt.BB, npt.YB, d, db)
    N1 = _sum(_times(Pb, S), _times(R, Qb, -1))
    N2 = _sum(_times(Q, R), _times(P, S, -1))
    D = _sum(_times(P, Qb), _times(Pb, Q, -1))
    return {e: c for e, c in _sum(_times(N1, N2), _times(D, D, -1)).items() if c != 0}


def polynomial_system(d: np.ndarray, db: np.ndarray) -> PolySystem:
    """The eight equations E_j (j = 1..8) as a :class:`PolySystem` in a, x, b, y and bars."""
    return PolySystem(8, tuple(expanded(complex(a), complex(b)) for a, b in zip(d, db)),
                      conjugate=tuple(int(k) for k in MIRROR))


Terms = list[tuple[list[mpmath.mpf], np.ndarray, int]]


def norm_terms(d: np.ndarray, db: np.ndarray) -> Terms:
    """For each E_j, multiplied out with coefficients at 50 digits: its terms' contributions
    to the squared Bombieri-Weyl norm, |c_e|^2 e! (deg - |e|)! / deg!, their exponents (so
    that the norm of E_j(T u), T powers of two, is a sum of exact binary shifts of them),
    and its degree."""
    out = []
    with mpmath.workdps(DIGITS):
        for a, b in zip(d, db):
            p = expanded(mpmath.mpc(complex(a)), mpmath.mpc(complex(b)))
            degree = max(sum(e) for e in p)
            weights = [bombieri_weyl_squared({e: c}, degree) for e, c in p.items()]
            out.append((weights, np.array(list(p)), degree))
    return out


def _exact(values: np.ndarray) -> np.ndarray:
    flat = [mpmath.mpc(complex(v)) for v in np.ravel(values)]
    return np.array(flat, dtype=object).reshape(np.shape(values))


def certify(z: np.ndarray, d: np.ndarray, db: np.ndarray, terms: Terms, real_points: bool = True
            ) -> Certificate:
    """Smale's alpha test at the solution ``z`` of the points (d, db) (``terms``:
    :func:`norm_terms`), on g(u) = E(T u) with T = :func:`.alpha.stretch` (z) and each
    equation scaled to Bombieri-Weyl norm 1; realness judged when the points are real
    (deltabar = conj(delta))."""
    T = stretch(z, MIRROR)
    u = z / T
    with mpmath.workdps(DIGITS):
        E, J, _, _ = npt.equations(_exact(z)[None, :], _exact(d), _exact(db))
        Tm = [mpmath.mpf(float(t)) for t in T]
        shifts = [2 * (e @ np.log2(T).astype(int)) for _, e, _ in terms]
        norms = [mpmath.fsum(mpmath.ldexp(w, int(k)) for w, k in zip(ws, sh))
                 for (ws, _, _), sh in zip(terms, shifts)]
        scale = [1 / mpmath.sqrt(n) for n in norms]
        F = [E[0, j] * scale[j] for j in range(8)]
        rows = [[J[0, j, k] * Tm[k] * scale[j] for k in range(8)] for j in range(8)]
        found = constants_at(F, rows, list(_exact(u)), [deg for _, _, deg in terms], [mpmath.mpf(1)] * 8)
    return verdict(found, u, MIRROR if real_points else None, float(T.max()))


def residuals(system: PolySystem, Z: np.ndarray, d: np.ndarray, db: np.ndarray) -> np.ndarray:
    """max_j |E_j(z)| / (E_j's terms' sizes at z, :func:`.solve.equation_sizes`), E evaluated
    at 50 digits (so the figure is the point's own, not the rounding of its evaluation): the
    residual as every other polynomial system's is measured (:func:`.solve.relative_residual`).
    The factored form's |N1 N2| + |D|^2 (:func:`.ninepoint.relative_residual`) understates
    the terms' size where N1, N2 or D is itself a near cancellation (pivots far from the
    points), and overstates the residual there."""
    out = np.empty(len(Z))
    with mpmath.workdps(DIGITS):
        E = npt.equations(_exact(Z), _exact(d), _exact(db))[0]
    for i, z in enumerate(Z):
        size = equation_sizes(system, z)
        out[i] = max(float(abs(E[i, j])) / size[j] for j in range(8))
    return out


def certify_rows(Z: np.ndarray, points: tuple[complex, ...] | np.ndarray,
                 progress: Callable[[int], None] | None = None) -> tuple[Certificate, ...]:
    """The certificate of each row of ``Z`` (solutions of the nine ``points``, P_0 at the
    origin, as :class:`.ninepoint_track.NinePointSolutions` has them)."""
    from dataclasses import replace

    p = np.asarray(points, dtype=complex)
    d = p[1:] - p[0]
    # the problem is the same at every scale (the pivots scale with the points, as
    # ninepoint_track.solve_points solves it): certified at the points' unit size, where the
    # Bombieri-Weyl norms are what the test is posed for, its distances scaled back
    size = float(np.max(np.abs(d))) or 1.0
    d = d / size
    db = np.conj(d)
    terms = norm_terms(d, db)
    out = []
    for k, z in enumerate(Z):
        c = certify(np.asarray(z) / size, d, db, terms)
        out.append(replace(c, beta=c.beta * size, gamma=c.gamma / size, radius=c.radius * size))
        if progress is not None:
            progress(k + 1)
    return tuple(out)
