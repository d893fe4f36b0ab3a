"""Smale's alpha test: a certificate that Newton's method from a computed point converges
to a root, that two computed points are two roots, and that a root is real.

As alphaCertified does it (Hauenstein and Sottile, "Algorithm 921: alphaCertified:
certifying solutions to polynomial systems", ACM TOMS 38(4), 2012, sec. 1-2), for a square
system f and a point x where Df(x) is invertible:
- beta(f, x) = ||Df(x)^-1 f(x)||, the length of Newton's step;
- gamma(f, x) = sup_k>=2 ||Df(x)^-1 D^k f(x) / k!||^(1/(k-1)), bounded above (Shub and Smale;
  Blum, Cucker, Shub and Smale, *Complexity and Real Computation*, Springer 1998, ch. 8 and
  12) by mu(f, x) D^(3/2) / (2 ||(1, x)||), where D is the largest degree, mu(f, x) =
  max(1, ||f|| ||Df(x)^-1 Delta(x)||), Delta(x) = diag(sqrt(d_i) ||(1, x)||^(d_i - 1)), and
  ||f|| the Bombieri-Weyl norm: ||f_i||^2 = sum over terms |c_e|^2 e! (d_i - |e|)! / d_i!;
- alpha = beta gamma. If alpha < (13 - 3 sqrt 17) / 4 = 0.1577, Newton's iterates from x
  converge quadratically to a root xi with ||x - xi|| <= 2 beta (Smale's alpha theorem).
- Two certified points whose distance exceeds the sum of their radii (2 beta each, below)
  have distinct roots: each root lies in its own ball.
- If alpha(f, x) < 0.03 and ||x - y|| < 1 / (20 gamma(f, x)), then x and y are approximate
  solutions with one associated root (Hauenstein and Sottile, sec. 2.2). A real structure
  R (here R(x) = conj(x[conjugate]), :attr:`PolySystem.conjugate`) with f(R(x)) = A conj(f(x))
  for a constant invertible A maps Newton's iterates to Newton's iterates, so the root of
  R(x) is R(xi); with y = R(x) the root is its own image: real. A point that is its own
  image, x = R(x) exactly, needs only alpha < alpha_0: its iterates are their own images,
  and so is their limit. If instead
  ||x - R(x)|| > 4 beta, the root is not real (a real xi would be within 2 beta of both x
  and R(x)).

gamma is unchanged when the equations are multiplied by a constant invertible matrix, so
the bound may be taken for any such rescaling: each equation is scaled by a power of two
(exact) to a Bombieri-Weyl norm within a factor sqrt 2 of 1 first (the bound then hardly
depends on how the equations were written down).
The bound is not unchanged by a change of variables, and grows as ||(1, x)||^(D - 1) with
a large coordinate: the test is made on g(u) = f(T u), T diagonal with powers of two
(:func:`stretch`: each variable of size about 1), whose Newton iterates are T^-1 times
f's, exactly (u = T^-1 x is exact in binary). beta, gamma and alpha are g's at u; the root
lies within 2 beta of u in u's norm, so within :attr:`Certificate.radius` = 2 beta max T of
x, and R commutes with T when T is the same for a variable and its conjugate.

Precision, honestly: the point and the coefficients are double-precision numbers, taken
exactly; f, Df and the linear algebra are evaluated in mpmath at :data:`DIGITS` digits,
floating point (alphaCertified's rational mode is exact; this is not). The rounding at 50
digits perturbs alpha relatively by about cond(Df) 10^-50 (below 10^-30 at any condition
up to 10^20; Problem 3's worst root has 1.5e15), and each verdict keeps a relative
margin of :data:`SAFETY`, so rounding cannot change one. The operator norm in mu is
bounded by the Frobenius norm, and every bound used is an upper bound on the quantity the
theorems name (alpha, gamma) or the radius they give, so the verdicts stay valid.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import mpmath
import numpy as np

from ..records import frozen
from .polynomials import Polynomial, PolySystem

DIGITS = 50
"""mpmath's working precision for the certificate."""
ALPHA_0 = (13 - 3 * math.sqrt(17)) / 4
"""Smale's constant: alpha below it certifies an approximate solution (0.157671...)."""
ALPHA_SAME = 0.03
"""alpha below this lets a point within 1 / (20 gamma) share its root (the realness test)."""
SAFETY = 1e-6
"""Relative margin on every verdict, far above the 50-digit rounding (module docstring)."""


@frozen
class Certificate:
    """Smale's alpha test at one point (module docstring). ``certified``: Newton's method
    from the point converges quadratically to a root within ``radius``; ``real``: that root
    is real (only for a system with a real structure, :func:`has_real_structure`)."""

    alpha: float
    beta: float
    gamma: float  # the Shub-Smale bound on gamma, not gamma itself
    certified: bool
    real: bool
    not_real: bool = False  # the root is certified nonreal: ||u - R(u)|| > 4 beta
    radius: float = math.inf  # where certified, the root is within this of the point (2 beta max T)


def bombieri_weyl_squared(p: Polynomial, degree: int) -> mpmath.mpf:
    """||p||^2 = sum |c_e|^2 e! (d - |e|)! / d!, p homogenised to degree d."""
    total = mpmath.mpf(0)
    for e, c in p.items():
        weight = mpmath.mpf(math.prod(math.factorial(k) for k in e) * math.factorial(degree - sum(e)))
        total += abs(mpmath.mpc(complex(c))) ** 2 * weight / math.factorial(degree)
    return total


def _powers(x: Sequence[mpmath.mpc], top: int) -> list[list[mpmath.mpc]]:
    out = []
    for v in x:
        row = [mpmath.mpc(1)]
        for _ in range(top):
            row.append(row[-1] * v)
        out.append(row)
    return out


def value_and_jacobian(system: PolySystem, x: Sequence[mpmath.mpc]
                       ) -> tuple[list[mpmath.mpc], list[list[mpmath.mpc]]]:
    """f(x) and Df(x) (rows) at the working precision, term by term from the coefficients."""
    n = system.n
    pw = _powers(x, max(system.degrees))
    zero = mpmath.mpc(0)
    F = [zero] * len(system.polynomials)
    J = [[zero] * n for _ in system.polynomials]
    for i, p in enumerate(system.polynomials):
        row = J[i]
        for e, c in p.items():
            parts = [pw[v][k] for v, k in enumerate(e)]
            term = mpmath.mpc(complex(c))
            for part in parts:
                term = term * part
            F[i] += term
            for v, k in enumerate(e):
                if k:
                    t = mpmath.mpc(complex(c)) * k * pw[v][k - 1]
                    for u, part in enumerate(parts):
                        if u != v:
                            t = t * part
                    row[v] += t
    return F, J


def solve_many(J: list[list[mpmath.mpc]], rhs: list[list[mpmath.mpc]]) -> list[list[mpmath.mpc]] | None:
    """J^-1 [rhs] by Gaussian elimination with partial pivoting (rows of J; ``rhs`` rows of
    the right-hand sides, one column per system); None where J is singular."""
    n = len(J)
    A = [list(J[i]) + list(rhs[i]) for i in range(n)]
    width = len(A[0])
    for k in range(n):
        pivot = max(range(k, n), key=lambda r: abs(A[r][k]))
        if A[pivot][k] == 0:
            return None
        A[k], A[pivot] = A[pivot], A[k]
        inv = 1 / A[k][k]
        for r in range(k + 1, n):
            factor = A[r][k] * inv
            if factor:
                Ar, Ak = A[r], A[k]
                for c in range(k + 1, width):
                    Ar[c] -= factor * Ak[c]
    out = [[mpmath.mpc(0)] * (width - n) for _ in range(n)]
    for r in range(n - 1, -1, -1):
        for c in range(width - n):
            acc = A[r][n + c]
            for q in range(r + 1, n):
                acc -= A[r][q] * out[q][c]
            out[r][c] = acc / A[r][r]
    return out


def normalised(system: PolySystem) -> PolySystem:
    """Each equation divided by the power of two nearest its Bombieri-Weyl norm (a norm
    within a factor sqrt 2 of 1): exactly the same equations scaled, so the same roots and
    the same gamma (a division by the norm itself would round the coefficients, and the
    certificate would be of a system 1e-16 away)."""
    with mpmath.workdps(DIGITS):
        shifts = [round(float(mpmath.log(bombieri_weyl_squared(p, d), 2)) / 2)
                  for p, d in zip(system.polynomials, system.degrees)]
    return PolySystem(system.n, tuple({e: _shifted(complex(c), -k) for e, c in p.items()}
                                      for p, k in zip(system.polynomials, shifts)),
                      system.names, system.groups, system.conjugate)


def _shifted(c: complex, k: int) -> complex:
    """c times 2^k, exactly."""
    return complex(math.ldexp(c.real, k), math.ldexp(c.imag, k))


def constants(system: PolySystem, x: np.ndarray, digits: int = DIGITS
              ) -> tuple[mpmath.mpf, mpmath.mpf, mpmath.mpf] | None:
    """(alpha, beta, the bound on gamma) of ``system`` as given (no rescaling) at the point
    ``x``, at ``digits`` digits; None where Df(x) is singular."""
    with mpmath.workdps(digits):
        X = [mpmath.mpc(complex(v)) for v in x]
        F, J = value_and_jacobian(system, X)
        norms = [bombieri_weyl_squared(p, d) for p, d in zip(system.polynomials, system.degrees)]
        return constants_at(F, J, X, system.degrees, norms)


def constants_at(F: Sequence[mpmath.mpc], J: Sequence[Sequence[mpmath.mpc]], X: Sequence[mpmath.mpc],
                 degrees: Sequence[int], norms_squared: Sequence[mpmath.mpf]
                 ) -> tuple[mpmath.mpf, mpmath.mpf, mpmath.mpf] | None:
    """(alpha, beta, the bound on gamma) from f(x), Df(x) (rows), x, the degrees and the
    equations' squared Bombieri-Weyl norms, at the working precision (module docstring);
    None where Df(x) is singular."""
    one_x = mpmath.sqrt(1 + sum(abs(v) ** 2 for v in X))
    n = len(degrees)
    # right-hand sides: f(x), then the columns of Delta(x) = diag(sqrt(d_i) ||(1, x)||^(d_i - 1))
    rhs = [[F[i]] + [mpmath.sqrt(d) * one_x ** (d - 1) if j == i else mpmath.mpc(0) for j in range(n)]
           for i, d in enumerate(degrees)]
    solved = solve_many([list(row) for row in J], rhs)
    if solved is None:
        return None
    beta = mpmath.sqrt(sum(abs(row[0]) ** 2 for row in solved))
    frobenius = mpmath.sqrt(sum(abs(v) ** 2 for row in solved for v in row[1:]))
    mu = max(mpmath.mpf(1), mpmath.sqrt(mpmath.fsum(norms_squared)) * frobenius)
    gamma = mu * mpmath.mpf(max(degrees)) ** 1.5 / (2 * one_x)
    return beta * gamma, beta, gamma


def has_real_structure(system: PolySystem) -> bool:
    """Whether R(x) = conj(x[conjugate]) (an involution) maps Newton's iterates to Newton's
    iterates, so roots to roots: each polynomial's image under R (coefficients conjugated,
    exponents permuted) is a constant multiple of one of the polynomials, each used once
    (then f(R(x)) = A conj(f(x)) with A constant and invertible)."""
    mirror = system.mirror
    used: set[int] = set()
    for p in system.polynomials:
        image = {tuple(e[mirror[v]] for v in range(system.n)): complex(c).conjugate() for e, c in p.items()}
        match = next((j for j, q in enumerate(system.polynomials)
                      if j not in used and _proportional(image, q)), None)
        if match is None:
            return False
        used.add(match)
    return True


def _proportional(p: dict[tuple[int, ...], complex], q: Polynomial) -> bool:
    if p.keys() != q.keys():
        return False
    e0 = next(iter(p))
    ratio = complex(q[e0]) / p[e0]
    return all(abs(complex(q[e]) - ratio * c) <= 1e-15 * abs(complex(q[e])) for e, c in p.items())


def stretch(x: np.ndarray, mirror: np.ndarray) -> np.ndarray:
    """T: for each variable the largest power of two at most max(1, |x_v|, |x_conjugate(v)|)."""
    size = np.maximum(1.0, np.maximum(np.abs(x), np.abs(x[mirror])))
    return np.exp2(np.floor(np.log2(size)))


def stretched(system: PolySystem, T: np.ndarray) -> PolySystem:
    """g(u) = f(T u): each coefficient times prod T_v^e_v (exact for powers of two)."""
    k = np.log2(T).astype(int)
    return PolySystem(system.n, tuple({e: _shifted(complex(c), int(k @ np.array(e))) for e, c in p.items()}
                                      for p in system.polynomials),
                      system.names, system.groups, system.conjugate)


def certify(system: PolySystem, x: np.ndarray, real_structure: bool | None = None,
            scaled: PolySystem | None = None) -> Certificate:
    """Smale's alpha test at ``x`` (module docstring), on g(u) = f(T u) with each equation
    at Bombieri-Weyl norm 1 (``scaled``: the system so normalised, when the caller has it
    already; it is used where T = 1). ``real_structure``: :func:`has_real_structure` of the
    system, when known."""
    if real_structure is None:
        real_structure = has_real_structure(system)
    T = stretch(x, system.mirror)
    if np.all(T == 1.0):
        g = normalised(system) if scaled is None else scaled
    else:
        g = normalised(stretched(system, T))
    u = x / T
    return verdict(constants(g, u), u, system.mirror if real_structure else None, float(T.max()))


def verdict(found: tuple[mpmath.mpf, mpmath.mpf, mpmath.mpf] | None, u: np.ndarray,
            mirror: np.ndarray | None, largest: float = 1.0) -> Certificate:
    """The certificate from (alpha, beta, gamma bound) at u = T^-1 x (None: Df singular);
    ``mirror``: the real structure's permutation (None: none, no verdict on realness);
    ``largest``: max T (module docstring)."""
    if found is None:
        return Certificate(math.inf, math.inf, math.inf, False, False)
    alpha, beta, gamma = found
    certified = alpha * (1 + SAFETY) < ALPHA_0
    real = not_real = False
    if certified and mirror is not None:
        with mpmath.workdps(DIGITS):
            U = [mpmath.mpc(complex(v)) for v in u]
            gap = mpmath.sqrt(sum(abs(U[m] - mpmath.conj(U[v])) ** 2 for v, m in enumerate(mirror)))
            # a point its own image has Newton iterates their own images: its root is real
            real = gap == 0 or (alpha * (1 + SAFETY) < ALPHA_SAME and gap * (1 + SAFETY) * 20 * gamma < 1)
            not_real = gap > 4 * beta * (1 + SAFETY)
    radius = float(2 * beta * largest * (1 + SAFETY)) if certified else math.inf
    return Certificate(float(alpha), float(beta), float(gamma), bool(certified), bool(real), bool(not_real),
                       radius)


def distinct(x1: np.ndarray, c1: Certificate, x2: np.ndarray, c2: Certificate) -> bool:
    """Two certified points whose roots are certainly two: ||x1 - x2|| > radius1 + radius2
    (each root lies within its radius, 2 beta, of its point)."""
    if not (c1.certified and c2.certified):
        return False
    with mpmath.workdps(DIGITS):
        gap = mpmath.sqrt(sum(abs(mpmath.mpc(complex(a)) - mpmath.mpc(complex(b))) ** 2
                              for a, b in zip(x1, x2)))
        return bool(gap > (mpmath.mpf(c1.radius) + mpmath.mpf(c2.radius)) * (1 + SAFETY))


def undistinguished(points: Sequence[np.ndarray], certificates: Sequence[Certificate]
                    ) -> list[tuple[int, int]]:
    """Pairs of certified points that :func:`distinct` cannot tell apart (none, when every
    certified root is certainly a different root). Pairs whose distance in double precision
    is over twice the sum of their radii are apart beyond any rounding of that distance;
    only the others are judged at 50 digits (the pairs of 1,400 points in a second)."""
    idx = np.array([i for i, c in enumerate(certificates) if c.certified], dtype=np.intp)
    if len(idx) < 2:
        return []
    X = np.array([np.asarray(points[i], dtype=complex) for i in idx])
    r = np.array([certificates[i].radius for i in idx])
    out = []
    for a in range(len(idx) - 1):
        gap = np.linalg.norm(X[a + 1:] - X[a], axis=1)
        for b in a + 1 + np.flatnonzero(gap <= 2 * (r[a] + r[a + 1:])):
            i, j = int(idx[a]), int(idx[b])
            if not distinct(points[i], certificates[i], points[j], certificates[j]):
                out.append((i, j))
    return out
