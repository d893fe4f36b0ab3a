"""Nine-point path synthesis of four-bars as a polynomial system, and its symmetries.

A four-bar's coupler point P passes through nine given points P_0..P_8. Following Wampler,
Morgan and Sommese ("Complete solution of the nine-point path synthesis problem for
four-bar linkages", J. Mech. Des. 114(1):153-159, 1992), put P_0 at the origin, write
delta_j = P_j - P_0 and work in isotropic coordinates: each planar vector v is the pair
(v, vbar), v = v_x + i v_y and vbar = v_x - i v_y, which are conjugates for a real linkage
and independent complex unknowns for the algebra.

The unknowns, with the coupler point at the origin in the first position:
    a, b   the ground pivots;  x, y  the moving pivots;  and their bars.
In position j the coupler has turned by Theta_j (Theta_j Thetabar_j = 1), the moving pivot
is at delta_j + Theta_j x, and its distance to a is unchanged:
    (delta_j + Theta_j x - a)(deltabar_j + Thetabar_j xbar - abar) = (x - a)(xbar - abar),
that is (with Theta Thetabar = 1)  Theta_j P_j + Thetabar_j Pb_j + R_j = 0, where
    P_j = x (deltabar_j - abar),  Pb_j = xbar (delta_j - a),
    R_j = delta_j deltabar_j - delta_j abar - deltabar_j a + x abar + xbar a,
and Theta_j Q_j + Thetabar_j Qb_j + S_j = 0 likewise for (b, y). Cramer's rule gives
Theta_j = N1/D and Thetabar_j = N2/D with N1 = Pb S - R Qb, N2 = Q R - P S, D = P Qb - Pb Q,
and Theta_j Thetabar_j = 1 becomes one equation per position,
    E_j = N1 N2 - D^2 = 0,   j = 1..8:
eight equations in the eight unknowns. The published count: 8,652 nondegenerate solutions
for generic points, 1,442 four-bars up to the symmetries below (WMS 1992).

Two symmetries map solutions to solutions for any points, so one solution in each orbit
of six is enough to track (:func:`orbit`):
- exchanging the two dyads, (a, x) <-> (b, y);
- Roberts' cognates: three four-bars trace one coupler curve. Writing the coupler point as
  delta_j = c + psi_j u - phi_j v, where phi_j, psi_j are the cranks' rotations and
      c = (x b - y a)/(x - y),  u = x (y - b)/(x - y),  v = y (x - a)/(x - y),
  the four-bar with ground pivots a and c, moving pivots a - x and v, traces the same
  points (its coupler turns with the first crank; derivation in :func:`cognate`).
"""

from __future__ import annotations

import numpy as np

from ..records import frozen

A, X, B, Y, AB, XB, BB, YB = range(8)
"""Columns of an unknown vector: a, x, b, y, abar, xbar, bbar, ybar."""


def _dyad(g: np.ndarray, m: np.ndarray, gb: np.ndarray, mb: np.ndarray, d: np.ndarray,
          db: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, ...]:
    """The dyad's coefficients P, Pb, R, homogenised with w (w = 1: the affine ones), and
    their derivatives: with respect to its ground pivot g, moving pivot m, their bars
    (order g, m, gb, mb) and w; and with respect to delta and deltabar."""
    P = m * (db * w - gb)
    Pb = mb * (d * w - g)
    R = d * db * w * w - (d * gb + db * g) * w + m * gb + mb * g
    zero = np.zeros_like(P)
    dP = (zero, db * w - gb, -m, zero, m * db)
    dPb = (-mb, zero, zero, d * w - g, mb * d)
    dR = (-db * w + mb, gb, -d * w + m, g, 2.0 * d * db * w - d * gb - db * g)
    pP = (zero, m * w)
    pPb = (mb * w, zero)
    pR = (db * w * w - gb * w, d * w * w - g * w)
    return P, Pb, R, dP, dPb, dR, pP, pPb, pR


def equations(z: np.ndarray, d: np.ndarray, db: np.ndarray, w: np.ndarray | None = None
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """E (paths, 8), its Jacobian in the unknowns (paths, 8, 8; with ``w``, the
    homogenising coordinate, a ninth column for it), and its derivatives in delta_j and
    deltabar_j (paths, 8) each (E_j depends on delta_j and deltabar_j only). ``z`` is
    (paths, 8); ``d``, ``db`` are (paths, 8) or (8,); ``w`` (paths,) or None for 1."""
    d = np.broadcast_to(d, (z.shape[0], 8))
    db = np.broadcast_to(db, (z.shape[0], 8))
    wcol = np.ones((z.shape[0], 1), dtype=z.dtype) if w is None else np.asarray(w)[:, None]
    col = [z[:, k:k + 1] for k in range(8)]
    P, Pb, R, dP, dPb, dR, pP, pPb, pR = _dyad(col[A], col[X], col[AB], col[XB], d, db, wcol)
    Q, Qb, S, dQ, dQb, dS, pQ, pQb, pS = _dyad(col[B], col[Y], col[BB], col[YB], d, db, wcol)
    N1 = Pb * S - R * Qb
    N2 = Q * R - P * S
    D = P * Qb - Pb * Q
    E = N1 * N2 - D * D

    def chain(dp, dpb, dr, dq, dqb, ds):
        dn1 = dpb * S + Pb * ds - dr * Qb - R * dqb
        dn2 = dq * R + Q * dr - dp * S - P * ds
        dd = dp * Qb + P * dqb - dpb * Q - Pb * dq
        return dn1 * N2 + N1 * dn2 - 2.0 * D * dd

    zero = np.zeros_like(E)
    J = np.empty((z.shape[0], 8, 8 if w is None else 9), dtype=z.dtype)
    # the first dyad's unknowns (a, x, abar, xbar), then the second's
    for k, col_index in enumerate((A, X, AB, XB)):
        J[:, :, col_index] = chain(dP[k], dPb[k], dR[k], zero, zero, zero)
    for k, col_index in enumerate((B, Y, BB, YB)):
        J[:, :, col_index] = chain(zero, zero, zero, dQ[k], dQb[k], dS[k])
    if w is not None:
        J[:, :, 8] = chain(dP[4], dPb[4], dR[4], dQ[4], dQb[4], dS[4])
    Ed = chain(pP[0], pPb[0], pR[0], pQ[0], pQb[0], pS[0])
    Edb = chain(pP[1], pPb[1], pR[1], pQ[1], pQb[1], pS[1])
    return E, J, Ed, Edb


def rotations(z: np.ndarray, d: np.ndarray, db: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Theta_j and Thetabar_j (paths, 8): the coupler's rotation in each position."""
    d = np.broadcast_to(d, (z.shape[0], 8))
    db = np.broadcast_to(db, (z.shape[0], 8))
    col = [z[:, k:k + 1] for k in range(8)]
    one = np.ones_like(col[A])
    P, Pb, R = _dyad(col[A], col[X], col[AB], col[XB], d, db, one)[:3]
    Q, Qb, S = _dyad(col[B], col[Y], col[BB], col[YB], d, db, one)[:3]
    D = P * Qb - Pb * Q
    return (Pb * S - R * Qb) / D, (Q * R - P * S) / D


def swap(z: np.ndarray) -> np.ndarray:
    """The same four-bar with its dyads named the other way round."""
    return z[..., [B, Y, A, X, BB, YB, AB, XB]]


def cognate(z: np.ndarray) -> np.ndarray:
    """A Roberts cognate: ground pivots a and c, moving pivots a - x and v (module
    docstring). From the crank relations delta + Theta x - a = phi (x - a) and
    delta + Theta y - b = psi (y - b), eliminating Theta gives delta = c + psi u - phi v; the
    point a - Theta x = delta + phi (a - x) is at a fixed distance |x| from a, and
    delta + phi v = c + psi u at a fixed distance |u| from c, both rigid with a body that
    turns by phi."""
    a, x, b, y = (z[..., k] for k in (A, X, B, Y))
    ab, xb, bb, yb = (z[..., k] for k in (AB, XB, BB, YB))
    c = (x * b - y * a) / (x - y)
    v = y * (x - a) / (x - y)
    cb = (xb * bb - yb * ab) / (xb - yb)
    vb = yb * (xb - ab) / (xb - yb)
    return np.stack([a, a - x, c, v, ab, ab - xb, cb, vb], axis=-1)


def orbit(z: np.ndarray) -> np.ndarray:
    """The six solutions a solution stands for: its three cognates, each with its dyads
    either way round. ``z`` (8,) -> (6, 8)."""
    first = z[None, :]
    second = cognate(first)
    third = cognate(swap(first))
    three = np.concatenate([first, second, third])
    return np.concatenate([three, swap(three)])


def seed_instance(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A random complex instance with one solution known: random unknowns z and random
    delta_j, then each deltabar_j a root of E_j (a cubic in deltabar_j, fitted exactly
    from four values). Returns (z, delta, deltabar)."""
    z = rng.normal(size=8) + 1j * rng.normal(size=8)
    d = rng.normal(size=8) + 1j * rng.normal(size=8)
    db = np.empty(8, dtype=complex)
    probe = np.array([-1.0, 0.0, 1.0, 2.0]) + 0.5j
    for j in range(8):
        values = []
        for p in probe:
            dd, ddb = d.copy(), np.zeros(8, dtype=complex)
            ddb[j] = p
            values.append(equations(z[None, :], dd, ddb)[0][0, j])
        coeffs = np.polyfit(probe, np.array(values), 3)
        roots = np.roots(coeffs)
        db[j] = roots[np.argmax(np.abs(roots.imag))]  # any root; the least real is generic
    # polish deltabar so that z solves the instance to rounding
    for _ in range(3):
        E, _J, _Ed, Edb = equations(z[None, :], d, db)
        db = db - E[0] / Edb[0]
    return z, d, db


SAME = 1e-8
"""Two solutions closer than this (relative to their size) are one."""


KEY = np.array([0.3141592653589793 + 0.2718281828459045j, -0.5772156649015329 + 0.1618033988749895j,
                0.6931471805599453 - 0.4142135623730950j, 0.2236067977499790 + 0.7320508075688772j,
                -0.1234567890123456 + 0.9876543210987654j, 0.4472135954999579 - 0.3010299956639812j,
                0.8660254037844386 + 0.1111111111111111j, -0.7071067811865476 - 0.5j])
"""A fixed generic direction: a solution's key is the real part of its projection on it."""


def canonical(Z: np.ndarray) -> np.ndarray:
    """Each row replaced by the member of its orbit with the smallest key, so that two
    solutions of one orbit have one canonical form (rows that are not finite stay)."""
    out = Z.copy()
    for i, z in enumerate(Z):
        if not np.all(np.isfinite(z)):
            continue
        with np.errstate(all="ignore"):
            members = orbit(z)
        members = members[np.all(np.isfinite(members), axis=1)]
        if len(members):
            out[i] = members[np.argmin((members @ KEY).real)]
    return out


def distinct(Z: np.ndarray) -> np.ndarray:
    """Indices of the rows of ``Z`` that no earlier row equals (to SAME, relative): of
    rows that are one solution, the first (:func:`owners`)."""
    return np.flatnonzero(owners(Z) == np.arange(len(Z)))


def owners(Z: np.ndarray) -> np.ndarray:
    """For each row of ``Z``, the first row of the solution it is (to SAME, relative): itself
    when no earlier row equals it. Rows are sorted by key, and only rows whose keys are
    within reach are compared (|key difference| <= |difference| |KEY|); a row equal to an
    earlier one takes that one's owner, so rows that are one solution share one owner."""
    keys = (Z @ KEY).real
    order = np.argsort(keys, kind="stable")
    scale = np.maximum(1.0, np.linalg.norm(Z, axis=1))
    reach = SAME * scale * float(np.linalg.norm(KEY)) * 1.01
    equal = np.arange(len(Z))
    for pos, i in enumerate(order):
        for direction in (-1, 1):
            q = pos + direction
            while 0 <= q < len(order) and abs(keys[order[q]] - keys[i]) <= reach[i]:
                j = order[q]
                if j < i and np.linalg.norm(Z[i] - Z[j]) <= SAME * scale[i]:
                    equal[i] = j
                    break
                q += direction
            if equal[i] != i:
                break
    owner = equal.copy()
    for i in range(len(Z)):  # an earlier row's owner is settled before a later row's
        owner[i] = owner[equal[i]]
    return owner


@frozen
class Instance:
    """Points (delta, deltabar: P_j - P_0 in isotropic coordinates, j = 1..8) and the
    solutions known for them, one per orbit of six (:func:`orbit`)."""

    delta: np.ndarray
    deltabar: np.ndarray
    solutions: np.ndarray  # (orbits, 8)


def random_points(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    return (rng.normal(size=8) + 1j * rng.normal(size=8), rng.normal(size=8) + 1j * rng.normal(size=8))


START = "data/nine_point_start.npz"
"""A generic complex instance with one solution of each of its 1,442 orbits, made by
:func:`.parameter.monodromy` with :class:`.ninepoint_track.NinePointLoops` from one seed
(benchmarks/nine_point_start.py remakes it)."""
POLISH_STEPS = 8
REFINED = 1e-10
"""An endpoint is a solution when Newton's steps at the target fall below this, relative."""
REAL = 1e-8
"""A solution is real when each bar is the conjugate of its unbarred twin to this, relative."""


def load_start() -> Instance:
    from importlib.resources import files

    with files("linkage.homotopy").joinpath(START).open("rb") as fh:
        data = np.load(fh)
        return Instance(data["d"], data["db"], data["z"])


def polish(Z: np.ndarray, d: np.ndarray, db: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Newton's method at the target: (Z, last relative step, condition of J)."""
    last = np.full(len(Z), np.inf)
    for _ in range(POLISH_STEPS):
        E, J, _, _ = equations(Z, d, db)
        good = np.isfinite(J).all(axis=(1, 2)) & np.all(np.isfinite(E), axis=1)  # 0 rows: no reshape
        step = np.full(Z.shape, np.nan + 0j)
        if good.any():
            from .tracker import solve_batched

            step[good] = solve_batched(J[good], E[good])
        Z = np.where(np.isfinite(step), Z - step, Z)
        last = np.linalg.norm(step, axis=1) / np.maximum(1.0, np.linalg.norm(Z, axis=1))
    _, J, _, _ = equations(Z, d, db)
    cond = np.full(len(Z), np.inf)
    fin = np.isfinite(J).all(axis=(1, 2))
    if fin.any():
        cond[fin] = np.linalg.cond(J[fin])
    return Z, np.where(np.isfinite(last), last, np.inf), cond


PRECISE_DIGITS = 60
PRECISE_STEPS = 40


def polish_precisely(z: np.ndarray, d: np.ndarray, db: np.ndarray) -> np.ndarray | None:
    """Newton's method at PRECISE_DIGITS digits (mpmath) from an endpoint that would not
    settle in double precision (a solution whose condition is near 1/eps: its digits are
    lost in double arithmetic, not in the method). The solution rounded to double, or None
    when the steps do not fall below 1e-40 of its size or the Jacobian is singular there."""
    import mpmath

    with mpmath.workdps(PRECISE_DIGITS):
        Z = np.array([[mpmath.mpc(complex(v)) for v in z]], dtype=object)
        dd = np.array([mpmath.mpc(complex(v)) for v in d], dtype=object)
        ddb = np.array([mpmath.mpc(complex(v)) for v in db], dtype=object)
        for _ in range(PRECISE_STEPS):
            E, J, _, _ = equations(Z, dd, ddb)
            try:
                step = mpmath.lu_solve(mpmath.matrix(J[0].tolist()), mpmath.matrix(E[0].tolist()))
            except ZeroDivisionError:
                return None
            Z = Z - np.array([[step[k] for k in range(8)]], dtype=object)
            size = max(mpmath.mpf(1), max(abs(v) for v in Z[0]))
            if max(abs(step[k]) for k in range(8)) <= mpmath.mpf(10) ** -40 * size:
                return np.array([complex(v) for v in Z[0]])
    return None


def relative_residual(Z: np.ndarray, d: np.ndarray, db: np.ndarray) -> np.ndarray:
    """max over the equations of |E_j| / (|N1 N2| + |D|^2) (paths,): cheap, and what decides
    which endpoints are polished at PRECISE_DIGITS. Where N1, N2 or D is itself a near
    cancellation (pivots far from the points) this understates the size of E_j's terms and
    overstates the residual; :func:`.ninepoint_alpha.residuals` measures against the terms
    multiplied out. Works on object arrays of mpmath numbers too."""
    col = [Z[:, k:k + 1] for k in range(8)]
    dd = np.broadcast_to(d, (Z.shape[0], 8))
    ddb = np.broadcast_to(db, (Z.shape[0], 8))
    one = np.ones_like(col[A])
    P, Pb, R = _dyad(col[A], col[X], col[AB], col[XB], dd, ddb, one)[:3]
    Q, Qb, S = _dyad(col[B], col[Y], col[BB], col[YB], dd, ddb, one)[:3]
    N1 = Pb * S - R * Qb
    N2 = Q * R - P * S
    D = P * Qb - Pb * Q
    return np.array([max(float(abs(e) / (abs(a) + abs(b))) for e, a, b in zip(*row)) for row in
                     zip(N1 * N2 - D * D, N1 * N2, D * D)])


RESIDUAL = 1e-12
"""A found solution whose residual (:func:`relative_residual`, in double arithmetic) is
above this, or that is real, is polished at PRECISE_DIGITS and rounded: a root of
condition near 1/eps settles in double arithmetic only to about cond eps."""


def is_real(Z: np.ndarray) -> np.ndarray:
    scale = np.maximum(1.0, np.max(np.abs(Z), axis=1))
    return np.max(np.abs(Z[:, 4:] - np.conj(Z[:, :4])), axis=1) <= REAL * scale


SINGULAR = 1e12
"""An endpoint whose Jacobian's condition exceeds this is not counted as a solution."""
