"""Error bounds of one position's rates (:func:`rate_bounds`), and their numpy twins for a
block of positions (:func:`rate_bounds_np`, the same bounds position by position).

Each bound covers rounding in J and the right-hand side, the position's remaining error and
the inputs' representation, propagated through J^-1 without first-order estimates: the
changes of e^(i theta) by chords, products whole, the inverse by a Neumann series that must
contract (see :func:`rate_bounds`). Where it does not, J may be singular within its own
uncertainty and the rates are undefined. The twins run the same formulas (the shared ones
take ``xp``: :data:`~.vectors.SCALAR` or numpy) and differ only where control flow does:
the inverse and the series, per position by masks.
"""

from __future__ import annotations

import math
from operator import mul
from typing import Any

from ..linalg import SingularMatrix, back_substitute_np, lu, lu_np, lu_solve
from ..problems.loops import DRIVER, LoopModel
from ..records import NamedTuple
from .vectors import EPS, SCALAR, rate_of, value_of

SAFETY = 2.0
"""Every bound is the first-order analysis below, doubled."""


class Uncertainty(NamedTuple):
    """How far each input of the rate equations may be from its exact value: the
    unknowns' position, velocity and acceleration (``eq``, ``ev``, ``ea``, absolute) and
    the driver's value, speed and acceleration (``ed``, ``evd``, ``evdd``). Constants
    (lengths, angles, offsets) are taken within one rounding of their decimal values."""

    eq: Any
    ev: Any
    ea: Any
    ed: float
    evd: float
    evdd: float


Shape = tuple[float, float, float, float, float, float]
"""What :func:`parts_bounds` needs of z = c e^(i theta) that does not depend on the
inputs' uncertainties, computed once per vector and order (:func:`shape`)."""


def shape(re: Any, im: Any, rc: Any, co: Any, si: Any, xp: Any = SCALAR) -> Shape:
    """(rc, |c|, x, y, 3 eps x, 3 eps y) for c = re + i im, with |Re z| <= x, |Im z| <= y
    (see :func:`parts_bounds`)."""
    cr, ci = abs(re), abs(im)
    x = cr * co + ci * si
    y = cr * si + ci * co
    return rc, xp.hypot(re, im), x, y, 3.0 * EPS * x, 3.0 * EPS * y


def parts_bounds(sh: Shape, dc: float, dth: float) -> tuple[float, float]:
    """Bounds on the x and y error of z = c e^(i theta) computed in floating point: c within
    dc of exact (and rounded within rc), theta within dth; ``sh`` is :func:`shape` of c
    (|Re z| <= x, |Im z| <= y, and the rounding scales with them). The change of angle
    moves x by at most |Im z| dth + |z| dth^2 / 2 (and y by |Re z| dth + ...), a change of
    c by dc."""
    rc, big, x, y, x3, y3 = sh
    common = dc + rc + (big + dc) * dth * dth / 2.0
    return common + x3 + (y + dc) * dth, common + y3 + (x + dc) * dth


def static_values(t: Any, q: Any, d: Any, qd: Any, vd: Any, qdd: Any, vdd: Any,
                  xp: Any = SCALAR) -> tuple[Any, ...]:
    """One vector's values at a position, computed once for all its bounds: (length
    index and constant, angle index and constant, the offset's rounding, position,
    velocity, acceleration (as :func:`~.vectors.term`), |r|, |w|, |r'|, |w'|, and the
    :func:`shape` of its position, velocity and acceleration coefficients and of its
    Jacobian columns (angle, length; None where fixed))."""
    _sign, lc, li, ac, ai, off = t
    r, th = value_of(li, lc, q, d), value_of(ai, ac, q, d) + off
    r1, w = rate_of(li, qd, vd), rate_of(ai, qd, vd)
    r2, al = rate_of(li, qdd, vdd), rate_of(ai, qdd, vdd)
    pos, vel, acc = xp.term(t, q, d, qd, vd, qdd, vdd)  # the one definition of the three
    co, si = abs(xp.cos(th)), abs(xp.sin(th))
    ar, aw, ar1, aal = abs(r), abs(w), abs(r1), abs(al)
    # the coefficients' own rounding: each product and sum within an ulp
    rm = 2.0 * EPS * (abs(r2) + ar * w * w + ar * aal + 2.0 * ar1 * aw)
    return (li, lc, ai, ac,
            # with an offset, the offset's decimal value and the sum's rounding (half an ulp each)
            0.5 * EPS * (abs(off) + abs(th)) if off else 0.0,
            pos, vel, acc, ar, aw, ar1, aal,
            shape(r, 0.0, 0.0, co, si, xp),
            shape(r1, r * w, EPS * ar * aw, co, si, xp),
            shape(r2 - r * w * w, r * al + 2.0 * r1 * w, rm, co, si, xp),
            shape(0.0, r, EPS * ar, co, si, xp) if ai >= 0 else None,
            shape(1.0, 0.0, 0.0, co, si, xp) if li >= 0 else None)


def bounds_of(s: tuple[Any, ...], u: Uncertainty, order: int) -> tuple[float, float]:
    """Bounds on how far one vector's computed position, velocity or acceleration
    (``order`` 0, 1, 2; :func:`~.vectors.term`), as (x, y), may be from its exact value at the
    exact inputs, from its :func:`static_values` values: rounding in evaluating it, plus the
    inputs' uncertainties propagated exactly (the products by |x y - x' y'| <= |x| |dy| +
    |y| |dx| + |dx| |dy|, the angle by :func:`parts_bounds`)."""
    li, lc, ai, ac, offr = s[:5]
    eq = u.eq
    dr = eq[li] if li >= 0 else (u.ed if li == DRIVER else EPS * abs(lc))
    dth = (eq[ai] if ai >= 0 else (u.ed if ai == DRIVER else EPS * abs(ac))) + offr
    if order == 0:
        return parts_bounds(s[12], dr, dth)
    ar, aw, ar1, aal = s[8:12]
    ev = u.ev
    dr1 = ev[li] if li >= 0 else (u.evd if li == DRIVER else 0.0)
    dw = ev[ai] if ai >= 0 else (u.evd if ai == DRIVER else 0.0)
    if order == 1:
        return parts_bounds(s[13], dr1 + dr * aw + ar * dw + dr * dw, dth)
    ea = u.ea
    dr2 = ea[li] if li >= 0 else (u.evdd if li == DRIVER else 0.0)
    dal = ea[ai] if ai >= 0 else (u.evdd if ai == DRIVER else 0.0)
    dm = (dr2 + dr * aal + ar * dal + dr * dal + 2.0 * (ar1 * dw + aw * dr1 + dr1 * dw)
          + dr * (aw + dw) ** 2 + ar * (2.0 * aw * dw + dw * dw))
    return parts_bounds(s[14], dm, dth)


def loop_residuals(data: list[list[tuple[Any, ...]]], u: Uncertainty, order: int) -> list[float]:
    """Per equation row (x then y of each loop): a bound on the exact residual of the
    loop's position (``order`` 0), velocity (1) or acceleration (2) equation at the
    exact inputs, for the computed values: |computed residual| plus its bound. ``data``:
    each loop's vectors' :func:`static_values` values."""
    out: list[float] = []
    at = 5 + order
    for terms in data:
        total = 0j
        bx = by = 0.0
        sx = sy = 0.0
        for s in terms:
            z = s[at]
            ex, ey = bounds_of(s, u, order)
            total += z
            bx, by = bx + ex, by + ey
            sx, sy = sx + abs(z.real), sy + abs(z.imag)
        # the sum's own rounding: each addition within half an ulp of its partial sum
        k = 0.5 * (len(terms) - 1) * EPS
        out += [abs(total.real) + bx + k * sx, abs(total.imag) + by + k * sy]
    return out


def jacobian_spread(data: list[list[tuple[Any, ...]]], n: int, u: Uncertainty) -> list[list[float]]:
    """|J(exact) - J(computed)| entry by entry, from the position's uncertainty: column j
    of an angle is sum sign i r e^(i theta), of a length sum sign e^(i theta)."""
    rows: list[list[float]] = []
    eq, ed = u.eq, u.ed
    for terms in data:
        row_x, row_y = [0.0] * n, [0.0] * n
        for s in terms:
            li, lc, ai, ac, offr = s[:5]
            dth = (eq[ai] if ai >= 0 else (ed if ai == DRIVER else EPS * abs(ac))) + offr
            if ai >= 0:
                dr = eq[li] if li >= 0 else (ed if li == DRIVER else EPS * abs(lc))
                ex, ey = parts_bounds(s[15], dr, dth)
                row_x[ai] += ex
                row_y[ai] += ey
            if li >= 0:
                ex, ey = parts_bounds(s[16], 0.0, dth)
                row_x[li] += ex
                row_y[li] += ey
        rows += [row_x, row_y]
    return rows


def abs_inverse(jac: list[list[float]]) -> list[list[float]] | None:
    """|J^-1| entry by entry, enlarged by the inverse's own rounding; None where J is
    singular to working precision (the rounding would be of the order of J^-1 itself)."""
    n = len(jac)
    if n == 2:
        (a, b), (c, d) = jac
        det = a * d - b * c
        size = abs(a * d) + abs(b * c)
        if det == 0.0 or not math.isfinite(det) or EPS * size > 1e-3 * abs(det):
            return None
        grow = (1.0 + 4.0 * EPS * size / abs(det)) / abs(det)
        return [[abs(d) * grow, abs(b) * grow], [abs(c) * grow, abs(a) * grow]]
    try:
        f = lu(jac)
    except SingularMatrix:
        return None
    cols = [lu_solve(f, [1.0 if i == j else 0.0 for i in range(n)]) for j in range(n)]
    inv = [[abs(cols[j][i]) for j in range(n)] for i in range(n)]
    if not all(math.isfinite(v) for row in inv for v in row):
        return None
    # Skeel's condition number || |J^-1| |J| || (infinity norm) bounds the inverse's error
    jrow = [sum(abs(v) for v in row) for row in jac]
    kappa = max(sum(inv[i][k] * jrow[k] for k in range(n)) for i in range(n))
    if EPS * kappa * n > 1e-3:
        return None
    grow = 1.0 + 8.0 * n * EPS * kappa
    return [[v * grow for v in row] for row in inv]


def matvec(a: list[list[float]], x: list[float]) -> list[float]:
    return [sum(map(mul, row, x)) for row in a]


def through_inverse(inv: list[list[float]], spread: list[list[float]], g: list[float]) -> list[float] | None:
    """A bound on |x| where J(exact) x = y, |y| <= g, |J(exact) - J| <= spread: the
    Neumann series |J^-1| g + B |J^-1| g + ..., B = |J^-1| spread, summed until a term w
    has B w <= rho w with rho <= 1/2 (then the rest is at most rho / (1 - rho) w, as B is
    nonnegative). None when it does not contract: J may be singular within its spread."""
    w = matvec(inv, g)
    total = list(w)
    top = max(w, default=0.0)
    if top == 0.0:
        return total
    floor = 1e-30 * top
    for _ in range(60):
        bw = matvec(inv, matvec(spread, w))
        rho = max(b / max(x, floor) for b, x in zip(bw, w))
        if not math.isfinite(rho):
            return None
        if rho <= 0.5:
            return [t + x * rho / (1.0 - rho) for t, x in zip(total, w)]
        total = [t + b for t, b in zip(total, bw)]
        w = bw
    return None




def inverse_np(a: Any) -> tuple[Any, Any]:
    """The inverse of each matrix of a stack (NaN where it is singular or not finite) and
    where it exists: :func:`solve_np` with no right-hand side."""
    inv, _, usable = solve_np(a, None)
    return inv, usable


def solve_np(a: Any, b: Any) -> tuple[Any, Any, Any]:
    """Each matrix of a stack ``a`` (..., n, n): its inverse, its solution for the columns
    ``b`` (..., n, k) (None: none) and where they exist (NaN where the matrix is singular or
    not finite). One batched LU inverse, the solution through it (numpy's inverse and a
    product cost less CPU than its solve of [I | b]); the singular ones found only when
    there are some; no copies where every matrix is usable."""
    import numpy as np

    n = a.shape[-1]
    k = 0 if b is None else b.shape[-1]
    usable = np.isfinite(a).all(axis=(-2, -1)) if a.size else np.ones(a.shape[:-2], dtype=bool)
    if n == 0 or not usable.any():
        return np.full(a.shape, np.nan), np.full((*a.shape[:-1], k), np.nan), usable
    if n == 2:
        return solve_two_np(a, b, usable)

    def inverted(rows: Any) -> Any:
        with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
            if rows.all():
                return np.linalg.inv(a)
            inv = np.full(a.shape, np.nan)
            inv[rows] = np.linalg.inv(a[rows])
            return inv

    try:
        inv = inverted(usable)
    except np.linalg.LinAlgError:  # an exactly singular one: find them by their determinant
        with np.errstate(invalid="ignore", over="ignore"):
            usable &= np.linalg.det(np.where(usable[..., None, None], a, 0.0)) != 0.0
        inv = inverted(usable) if usable.any() else np.full(a.shape, np.nan)
    usable &= np.isfinite(inv).all(axis=(-2, -1))
    if not usable.all():
        inv = np.where(usable[..., None, None], inv, np.nan)
    with np.errstate(invalid="ignore", over="ignore"):
        x = np.zeros((*a.shape[:-1], 0)) if b is None else inv @ b
    return inv, x, usable


def solve_two_np(a: Any, b: Any, usable: Any) -> tuple[Any, Any, Any]:
    """:func:`solve_np` of a stack of 2 x 2 matrices, by cofactors: [[d, -b], [-c, a]] / det
    (numpy's batched LU spends most of a 2 x 2's time on its per-matrix set-up), usable
    where ``usable`` (the entries finite), det is not zero and the inverse is finite."""
    import numpy as np

    p, q, r, s = a[..., 0, 0], a[..., 0, 1], a[..., 1, 0], a[..., 1, 1]
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        det = p * s - q * r
        cof = np.stack([np.stack([s, -q], axis=-1), np.stack([-r, p], axis=-1)], axis=-2)
        inv = cof / det[..., None, None]
        x = np.zeros((*a.shape[:-1], 0)) if b is None else inv @ b
    usable = usable & (det != 0.0) & np.isfinite(inv).all(axis=(-2, -1))
    where = usable[..., None, None]
    return np.where(where, inv, np.nan), np.where(where, x, np.nan), usable


def abs_inverse_np(jac: list[list[Any]]) -> tuple[list[list[Any]], Any]:
    """:func:`abs_inverse` over a block (``jac`` rows of columns of arrays): (|J^-1| enlarged
    by its rounding, usable), the same tests position by position (an LU of each by numpy,
    :func:`~linkage.linalg.lu_np`, ``lu``'s twin, beyond two unknowns)."""
    import numpy as np

    n = len(jac)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        if n == 2:
            (a, b), (c, d) = jac
            det = a * d - b * c
            size = np.abs(a * d) + np.abs(b * c)
            ok = (det != 0.0) & np.isfinite(det) & ~(EPS * size > 1e-3 * np.abs(det))
            grow = (1.0 + 4.0 * EPS * size / np.abs(det)) / np.abs(det)
            return [[np.abs(d) * grow, np.abs(b) * grow], [np.abs(c) * grow, np.abs(a) * grow]], ok
        shape = np.broadcast_shapes(*(np.shape(v) for row in jac for v in row))
        t = np.stack([np.stack([np.broadcast_to(np.asarray(v, dtype=float), shape) for v in row])
                      for row in jac]).reshape(n, n, -1)
        unit = np.broadcast_to(np.eye(n)[:, :, None], t.shape).copy()  # column j: e_j
        ok = lu_np(t, unit)
        inv = np.abs(back_substitute_np(t, unit)).reshape(n, n, *shape)  # [i][j]: (J^-1)_ij
        ok = ok.reshape(shape) & np.isfinite(inv).all(axis=(0, 1))
        # Skeel's condition number, as abs_inverse bounds the inverse's error
        jrow = [sum(np.abs(v) for v in row) for row in jac]
        kappa = np.maximum.reduce([sum(inv[i][k] * jrow[k] for k in range(n)) for i in range(n)])
        ok &= ~(EPS * kappa * n > 1e-3)
        grow = 1.0 + 8.0 * n * EPS * kappa
        return [[v * grow for v in row] for row in inv], ok


def through_inverse_np(inv: list[list[Any]], spread: list[list[Any]], g: list[Any]
                       ) -> tuple[list[Any], Any]:
    """:func:`through_inverse` over a block: (the bound, usable), each position's series
    summed until its own term contracts (its own rho <= 1/2), as the scalar one is."""
    import numpy as np

    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        w = matvec(inv, g)
        total = list(w)
        top = np.maximum.reduce([np.asarray(x, dtype=float) for x in w]) if w else np.zeros(())
        out = [np.where(top == 0.0, t, np.nan) for t in total]
        done = top == 0.0
        failed = np.zeros(np.shape(top), dtype=bool)
        floor = 1e-30 * top
        for _ in range(60):
            if np.all(done | failed):
                break
            bw = matvec(inv, matvec(spread, w))
            rho = np.maximum.reduce([b / np.maximum(x, floor) for b, x in zip(bw, w)])
            active = ~(done | failed)
            failed |= active & ~np.isfinite(rho)
            now = active & np.isfinite(rho) & (rho <= 0.5)
            if now.any():
                out = [np.where(now, t + x * rho / (1.0 - rho), o) for t, x, o in zip(total, w, out)]
                done |= now
            total = [t + b for t, b in zip(total, bw)]
            w = bw
        return out, done & ~failed
class RateBounds(NamedTuple):
    """Absolute error bounds of one position's rates: per unknown (``velocity``,
    ``acceleration``, and ``position`` for the polished q) in internal units."""

    position: list[float]
    velocity: list[float]
    acceleration: list[float]
    uncertainty: Uncertainty


def rate_bounds(model: LoopModel, q: Any, d: float, speed: float, accel: float, qd: Any, qdd: Any,
                jac: list[list[float]], data: list[list[tuple[Any, ...]]] | None = None
                ) -> RateBounds | None:
    """Error bounds for (q, q', q'') at driver (d, speed, accel), or None where J is
    singular within its own uncertainty (the rates are then undefined).

    The exact position q* solves Phi*(q*) = 0 with the exact parameters; J(q*) (q - q*) =
    Phi*(q) to within the spread of J over the segment, so |q - q*| is bounded by
    |J^-1| (|Phi(q)| + rounding + the inputs' representation), amplified by the Neumann
    series of |J^-1| |dJ| (:func:`through_inverse`), with dJ the spread of J for that
    |q - q*| (checked self-consistent). The velocity equation J(q*) q'* = -V(q*) v' is
    linear: J(q*) (q' - q'*) is the velocity residual at (q*, q'), bounded by the
    computed residual at (q, q') plus its rounding plus its change from q to q*; the same
    for the acceleration, whose right-hand side holds the velocities, with their bound.
    No step is a first-order estimate: each change is bounded whole (chords of
    e^(i theta), products), and the rounding model allows an ulp or more per operation."""
    n = model.n
    inv = abs_inverse(jac)
    if inv is None:
        return None
    ed = 2.0 * EPS * abs(d)  # the driver: a decimal value, then degrees to radians
    zero = [0.0] * n
    u0 = Uncertainty(zero, zero, zero, ed, EPS * abs(speed), EPS * abs(accel))
    if data is None:
        data = [[static_values(t, q, d, qd, speed, qdd, accel) for t in terms] for terms in model.terms]
    g = loop_residuals(data, u0, 0)
    guess = through_inverse(inv, jacobian_spread(data, n, u0), g)
    if guess is None:
        return None
    eq: list[float] | None = None
    for _ in range(6):
        trial = [1.25 * x + EPS * abs(v) for x, v in zip(guess, q)]
        spread = jacobian_spread(data, n, Uncertainty(trial, zero, zero, ed, 0.0, 0.0))
        got = through_inverse(inv, spread, g)
        if got is None:
            return None
        if all(a <= b for a, b in zip(got, trial)):
            eq = trial  # the spread assumed holds for the bound it gives
            break
        guess = got
    if eq is None:
        return None
    uq = Uncertainty(eq, zero, zero, ed, u0.evd, u0.evdd)
    ev = through_inverse(inv, spread, loop_residuals(data, uq, 1))
    if ev is None:
        return None
    uv = Uncertainty(eq, ev, zero, ed, u0.evd, u0.evdd)
    ea = through_inverse(inv, spread, loop_residuals(data, uv, 2))
    if ea is None:
        return None
    return RateBounds(eq, ev, ea, Uncertainty(eq, ev, ea, ed, u0.evd, u0.evdd))




def rate_bounds_np(model: LoopModel, q: Any, d: Any, speed: float, accel: float, jac: list[list[Any]],
                   data: list[list[tuple[Any, ...]]]) -> tuple[RateBounds, Any]:
    """:func:`rate_bounds` over a block of positions (``q`` one array per unknown, ``jac``
    rows of columns of arrays, ``data`` the loops' :func:`static_values` with numpy): (the
    bounds as arrays, usable), each position through the same steps as the scalar one
    (the same six trials of the position's bound, accepted per position); unusable where
    the scalar one gives None."""
    import numpy as np

    n = model.n
    inv, ok = abs_inverse_np(jac)
    ed = 2.0 * EPS * np.abs(d)
    zero = [0.0] * n
    u0 = Uncertainty(zero, zero, zero, ed, EPS * abs(speed), EPS * abs(accel))
    g = loop_residuals(data, u0, 0)
    guess, usable = through_inverse_np(inv, jacobian_spread(data, n, u0), g)
    ok &= usable
    eq = [np.full(np.shape(d), np.nan) for _ in range(n)]
    found = np.zeros(np.shape(d), dtype=bool)
    with np.errstate(invalid="ignore", over="ignore"):
        for _ in range(6):
            trial = [1.25 * x + EPS * np.abs(v) for x, v in zip(guess, q)]
            spread = jacobian_spread(data, n, Uncertainty(trial, zero, zero, ed, 0.0, 0.0))
            got, usable = through_inverse_np(inv, spread, g)
            ok &= usable | found  # the scalar one gives up at the first unusable trial
            holds = ~found & np.logical_and.reduce([a <= b for a, b in zip(got, trial)])
            eq = [np.where(holds, t, e) for t, e in zip(trial, eq)]
            found |= holds
            guess = got
            if np.all(found | ~ok):
                break
        ok &= found
        eq = [np.where(ok, e, 0.0) for e in eq]
        spread = jacobian_spread(data, n, Uncertainty(eq, zero, zero, ed, 0.0, 0.0))
        uq = Uncertainty(eq, zero, zero, ed, u0.evd, u0.evdd)
        ev, usable = through_inverse_np(inv, spread, loop_residuals(data, uq, 1))
        ok &= usable
        uv = Uncertainty(eq, ev, zero, ed, u0.evd, u0.evdd)
        ea, usable = through_inverse_np(inv, spread, loop_residuals(data, uv, 2))
        ok &= usable
    return RateBounds(eq, ev, ea, Uncertainty(eq, ev, ea, ed, u0.evd, u0.evdd)), ok
