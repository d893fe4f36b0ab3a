"""Velocity and acceleration of every unknown, joint and named point, at one position.

Every vector of every loop is ``sign * r * e^(i theta)``. Differentiating the loops in
time (worked example P7, docs/worked_examples.md), with ' for d/dt:

    velocity:      sum sign (r' + i r theta') e^(i theta) = 0
                   -> J q' = -(dPhi/dv) v'
    acceleration:  sum sign (r'' + i r theta'' + 2 i r' theta' - r theta'^2) e^(i theta) = 0
                   -> J q'' = -(dPhi/dv) v'' - b,
                      b = sum sign (2 i r' theta' - r theta'^2) e^(i theta)

with J and dPhi/dv the compiled Jacobian and driver derivative of the position problem
(the same J: a velocity or acceleration is one more linear solve), ``- r theta'^2`` the
centripetal term of every moving vector and ``2 i r' theta'`` the Coriolis term of a
vector whose length and angle both move (a slider on a rotating link). Where J is
singular (a toggle or dead centre) the rates are undefined and the status says so.

Joints are the start points of the loops' vectors that the file names (``joints``):
the first loop starts at the file's ``origin`` ((0, 0) unless it says; a drawing's is
where its first ground joint is drawn), with x along the 0-degree direction; a later loop
starts at its first joint if an earlier loop placed it (a six-bar's second loop at the
rocker pivot), else at the origin too. A named point (``[points.P]``) starts at a joint
and adds its own vectors. Their velocities and accelerations are the same sums,
differentiated.
"""

from __future__ import annotations

import cmath
import math
import sys
from dataclasses import dataclass, field
from operator import mul
from typing import TYPE_CHECKING, Any, NamedTuple

from ..linalg import SingularMatrix, lu, lu_solve
from ..methods.newton_system import max_abs, newton_direction
from ..problems.loops import ANGLE_UNITS, DRIVER, LoopModel
from .labels import rate_label

if TYPE_CHECKING:  # a solve's rates do not load the sweep's types
    from .positions import SweepResult

FIXED = -1

XY = tuple[float, float]

EPS = sys.float_info.epsilon

RATE_RTOL = 1e-6
"""A rate whose error bound exceeds this, relative to the rate (or to the driver's own
speed or acceleration where the rate is smaller), is ``ill_conditioned``."""

POLISH_STEPS = 60
"""Most Newton steps taken to polish a position before its rates (each must shrink)."""

SAFETY = 2.0
"""Every bound is the first-order analysis below, doubled."""


@dataclass(frozen=True)
class Rates:
    """One position's kinematics. ``velocities``/``accelerations``: unknown name -> rad/s
    and rad/s^2 (angles) or length unit/s and /s^2 (lengths); the joint and point maps:
    name -> (x, y) in the length unit (/s, /s^2). Empty rate maps when ``status`` is
    ``undefined`` (J is singular there, within its own uncertainty) or when no driver
    motion was given.

    Each rate carries an error bound (``*_bounds``: absolute, in the rate's unit; for a
    joint or point, on each of its x and y): the rates are computed at the position
    polished to full precision, and the bound covers rounding in J and the right-hand
    side, the position's remaining error and the inputs' representation, propagated
    through J^-1 (see :func:`rate_bounds`). A rate whose bound exceeds ``RATE_RTOL`` of
    itself (or of the driver's motion, where the rate is smaller) is listed by label in
    ``ill_conditioned`` (``dtheta3/dt``, ``d2theta3/dt2``, ``B.v``, ``B.a``), and the
    status is then ``ill_conditioned``."""

    joints: dict[str, XY]
    velocities: dict[str, float] = field(default_factory=dict)
    accelerations: dict[str, float] = field(default_factory=dict)
    joint_velocities: dict[str, XY] = field(default_factory=dict)
    joint_accelerations: dict[str, XY] = field(default_factory=dict)
    status: str = "ok"
    velocity_bounds: dict[str, float] = field(default_factory=dict)
    acceleration_bounds: dict[str, float] = field(default_factory=dict)
    joint_velocity_bounds: dict[str, float] = field(default_factory=dict)
    joint_acceleration_bounds: dict[str, float] = field(default_factory=dict)
    ill_conditioned: tuple[str, ...] = ()

    def flagged(self, label: str) -> bool:
        """Whether the rate labelled ``label`` (see :func:`rate_label`) is ill-conditioned."""
        return label in self.ill_conditioned


def _value(idx: int, const: float, q: Any, d: float) -> float:
    return q[idx] if idx >= 0 else (d if idx == DRIVER else const)


def _rate(idx: int, qdot: Any, ddot: float) -> float:
    return qdot[idx] if idx >= 0 else (ddot if idx == DRIVER else 0.0)


def _term(t: Any, q: Any, d: float, qd: Any, vd: float, qdd: Any,
          vdd: float) -> tuple[complex, complex, complex]:
    """One vector's position, velocity and acceleration (complex)."""
    sign, lc, li, ac, ai, off = t
    r, th = _value(li, lc, q, d), _value(ai, ac, q, d) + off
    r1, w = _rate(li, qd, vd), _rate(ai, qd, vd)
    r2, al = _rate(li, qdd, vdd), _rate(ai, qdd, vdd)
    e = cmath.exp(1j * th)
    pos = sign * r * e
    vel = sign * (r1 + 1j * r * w) * e
    acc = sign * (r2 + 1j * r * al + 2j * r1 * w - r * w * w) * e
    return pos, vel, acc


class _Uncertainty(NamedTuple):
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
"""What :func:`_parts_bounds` needs of z = c e^(i theta) that does not depend on the
inputs' uncertainties, computed once per vector and order (:func:`_shape`)."""


def _shape(c: complex, rc: float, co: float, si: float) -> Shape:
    """(rc, |c|, x, y, 3 eps x, 3 eps y) with |Re z| <= x, |Im z| <= y (see
    :func:`_parts_bounds`)."""
    cr, ci = abs(c.real), abs(c.imag)
    x = cr * co + ci * si
    y = cr * si + ci * co
    return rc, abs(c), x, y, 3.0 * EPS * x, 3.0 * EPS * y


def _parts_bounds(sh: Shape, dc: float, dth: float) -> tuple[float, float]:
    """Bounds on the x and y error of z = c e^(i theta) computed in floating point: c within
    dc of exact (and rounded within rc), theta within dth; ``sh`` is :func:`_shape` of c
    (|Re z| <= x, |Im z| <= y, and the rounding scales with them). The change of angle
    moves x by at most |Im z| dth + |z| dth^2 / 2 (and y by |Re z| dth + ...), a change of
    c by dc."""
    rc, big, x, y, x3, y3 = sh
    common = dc + rc + (big + dc) * dth * dth / 2.0
    return common + x3 + (y + dc) * dth, common + y3 + (x + dc) * dth


def _static(t: Any, q: Any, d: float, qd: Any, vd: float, qdd: Any, vdd: float) -> tuple[Any, ...]:
    """One vector's values at a position, computed once for all its bounds: (length
    index and constant, angle index and constant, the offset's rounding, position,
    velocity, acceleration (as :func:`_term`), |r|, |w|, |r'|, |w'|, and the
    :func:`_shape` of its position, velocity and acceleration coefficients and of its
    Jacobian columns (angle, length; None where fixed))."""
    _sign, lc, li, ac, ai, off = t
    r, th = _value(li, lc, q, d), _value(ai, ac, q, d) + off
    r1, w = _rate(li, qd, vd), _rate(ai, qd, vd)
    r2, al = _rate(li, qdd, vdd), _rate(ai, qdd, vdd)
    pos, vel, acc = _term(t, q, d, qd, vd, qdd, vdd)  # the one definition of the three
    co, si = abs(math.cos(th)), abs(math.sin(th))
    ar, aw, ar1, aal = abs(r), abs(w), abs(r1), abs(al)
    # the coefficients' own rounding: each product and sum within an ulp
    rm = 2.0 * EPS * (abs(r2) + ar * w * w + ar * aal + 2.0 * ar1 * aw)
    return (li, lc, ai, ac,
            # with an offset, the offset's decimal value and the sum's rounding (half an ulp each)
            0.5 * EPS * (abs(off) + abs(th)) if off else 0.0,
            pos, vel, acc, ar, aw, ar1, aal,
            _shape(complex(r), 0.0, co, si),
            _shape(complex(r1, r * w), EPS * ar * aw, co, si),
            _shape(complex(r2 - r * w * w, r * al + 2.0 * r1 * w), rm, co, si),
            _shape(complex(0.0, r), EPS * ar, co, si) if ai >= 0 else None,
            _shape(complex(1.0), 0.0, co, si) if li >= 0 else None)


def _bounds_of(s: tuple[Any, ...], u: _Uncertainty, order: int) -> tuple[float, float]:
    """Bounds on how far one vector's computed position, velocity or acceleration
    (``order`` 0, 1, 2; :func:`_term`), as (x, y), may be from its exact value at the
    exact inputs, from its :func:`_static` values: rounding in evaluating it, plus the
    inputs' uncertainties propagated exactly (the products by |x y - x' y'| <= |x| |dy| +
    |y| |dx| + |dx| |dy|, the angle by :func:`_parts_bounds`)."""
    li, lc, ai, ac, offr = s[:5]
    eq = u.eq
    dr = eq[li] if li >= 0 else (u.ed if li == DRIVER else EPS * abs(lc))
    dth = (eq[ai] if ai >= 0 else (u.ed if ai == DRIVER else EPS * abs(ac))) + offr
    if order == 0:
        return _parts_bounds(s[12], dr, dth)
    ar, aw, ar1, aal = s[8:12]
    ev = u.ev
    dr1 = ev[li] if li >= 0 else (u.evd if li == DRIVER else 0.0)
    dw = ev[ai] if ai >= 0 else (u.evd if ai == DRIVER else 0.0)
    if order == 1:
        return _parts_bounds(s[13], dr1 + dr * aw + ar * dw + dr * dw, dth)
    ea = u.ea
    dr2 = ea[li] if li >= 0 else (u.evdd if li == DRIVER else 0.0)
    dal = ea[ai] if ai >= 0 else (u.evdd if ai == DRIVER else 0.0)
    dm = (dr2 + dr * aal + ar * dal + dr * dal + 2.0 * (ar1 * dw + aw * dr1 + dr1 * dw)
          + dr * (aw + dw) ** 2 + ar * (2.0 * aw * dw + dw * dw))
    return _parts_bounds(s[14], dm, dth)


def _loop_residuals(data: list[list[tuple[Any, ...]]], u: _Uncertainty, order: int) -> list[float]:
    """Per equation row (x then y of each loop): a bound on the exact residual of the
    loop's position (``order`` 0), velocity (1) or acceleration (2) equation at the
    exact inputs, for the computed values: |computed residual| plus its bound. ``data``:
    each loop's vectors' :func:`_static` values."""
    out: list[float] = []
    at = 5 + order
    for terms in data:
        total = 0j
        bx = by = 0.0
        sx = sy = 0.0
        for s in terms:
            z = s[at]
            ex, ey = _bounds_of(s, u, order)
            total += z
            bx, by = bx + ex, by + ey
            sx, sy = sx + abs(z.real), sy + abs(z.imag)
        # the sum's own rounding: each addition within half an ulp of its partial sum
        k = 0.5 * (len(terms) - 1) * EPS
        out += [abs(total.real) + bx + k * sx, abs(total.imag) + by + k * sy]
    return out


def _jacobian_spread(data: list[list[tuple[Any, ...]]], n: int, u: _Uncertainty) -> list[list[float]]:
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
                ex, ey = _parts_bounds(s[15], dr, dth)
                row_x[ai] += ex
                row_y[ai] += ey
            if li >= 0:
                ex, ey = _parts_bounds(s[16], 0.0, dth)
                row_x[li] += ex
                row_y[li] += ey
        rows += [row_x, row_y]
    return rows


def _abs_inverse(jac: list[list[float]]) -> list[list[float]] | None:
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


def _matvec(a: list[list[float]], x: list[float]) -> list[float]:
    return [sum(map(mul, row, x)) for row in a]


def _through_inverse(inv: list[list[float]], spread: list[list[float]], g: list[float]) -> list[float] | None:
    """A bound on |x| where J(exact) x = y, |y| <= g, |J(exact) - J| <= spread: the
    Neumann series |J^-1| g + B |J^-1| g + ..., B = |J^-1| spread, summed until a term w
    has B w <= rho w with rho <= 1/2 (then the rest is at most rho / (1 - rho) w, as B is
    nonnegative). None when it does not contract: J may be singular within its spread."""
    w = _matvec(inv, g)
    total = list(w)
    top = max(w, default=0.0)
    if top == 0.0:
        return total
    floor = 1e-30 * top
    for _ in range(60):
        bw = _matvec(inv, _matvec(spread, w))
        rho = max(b / max(x, floor) for b, x in zip(bw, w))
        if not math.isfinite(rho):
            return None
        if rho <= 0.5:
            return [t + x * rho / (1.0 - rho) for t, x in zip(total, w)]
        total = [t + b for t, b in zip(total, bw)]
        w = bw
    return None


def polish(model: LoopModel, q: Any, d: float, funcs: Any = None) -> list[float]:
    """The position q made as exact as double precision allows: Newton steps (quadratic
    there, so usually one or two) while each step is smaller than the last and max|Phi|
    does not grow; q as given if the first step is refused. A solve stopped at its
    tolerance can be 1e-7 rad from the root near a limit, where the rates' sensitivity
    turns that into percent. ``funcs``: ``model.factory(d)`` if already built."""
    F, J, _ = funcs if funcs is not None else model.factory(d)
    q = [float(x) for x in q]
    phi = F(q)
    res = max_abs(phi)
    last = math.inf
    for _ in range(POLISH_STEPS):
        if not res > 0.0:
            break
        dq = newton_direction(J(q), phi)[0]
        if dq is None or not all(map(math.isfinite, dq)):
            break
        size = max_abs(dq)
        if not size < last:
            break
        trial = [a + b for a, b in zip(q, dq)]
        phi_t = F(trial)
        res_t = max_abs(phi_t)
        if not res_t <= res:
            break
        q, phi, res, last = trial, phi_t, res_t, size
        if all(abs(s) <= 4.0 * EPS * abs(x) for s, x in zip(dq, q)):
            break  # a step at rounding level: nothing more to gain
    return q


def rates_from_jacobian(jac: list[list[float]], dv: list[float], model: LoopModel, q: Any, d: float,
                        speed: float, accel: float) -> tuple[list[float], list[float]] | None:
    # newton_direction solves J x = -rhs with the engine's equilibrated singularity test
    qd = newton_direction(jac, [speed * c for c in dv])[0]
    if qd is None or not all(map(math.isfinite, qd)):
        return None
    bias: list[float] = []
    for loop in model.terms:
        total = 0j
        for t in loop:
            sign, lc, li, ac, ai, off = t
            r, th = _value(li, lc, q, d), _value(ai, ac, q, d) + off
            r1, w = _rate(li, qd, speed), _rate(ai, qd, speed)
            # only the parts not multiplied by a second derivative
            total += sign * (2j * r1 * w - r * w * w) * cmath.exp(1j * th)
        bias += [total.real, total.imag]
    qdd = newton_direction(jac, [accel * c + b for c, b in zip(dv, bias)])[0]
    if qdd is None or not all(map(math.isfinite, qdd)):
        return None
    return qd, qdd


def solve_rates(model: LoopModel, q: Any, d: float, speed: float,
                accel: float) -> tuple[list[float], list[float]] | None:
    """(q', q'') at (q, d) for driver rate ``speed`` and ``accel`` (internal units), or
    None where J is singular. No polishing and no bound: see :func:`position_rates`."""
    _, J, V = model.factory(d)
    q = list(q)
    return rates_from_jacobian(J(q), V(q), model, q, d, speed, accel)


class RateBounds(NamedTuple):
    """Absolute error bounds of one position's rates: per unknown (``velocity``,
    ``acceleration``, and ``position`` for the polished q) in internal units."""

    position: list[float]
    velocity: list[float]
    acceleration: list[float]
    uncertainty: _Uncertainty


def rate_bounds(model: LoopModel, q: Any, d: float, speed: float, accel: float, qd: Any, qdd: Any,
                jac: list[list[float]], data: list[list[tuple[Any, ...]]] | None = None
                ) -> RateBounds | None:
    """Error bounds for (q, q', q'') at driver (d, speed, accel), or None where J is
    singular within its own uncertainty (the rates are then undefined).

    The exact position q* solves Phi*(q*) = 0 with the exact parameters; J(q*) (q - q*) =
    Phi*(q) to within the spread of J over the segment, so |q - q*| is bounded by
    |J^-1| (|Phi(q)| + rounding + the inputs' representation), amplified by the Neumann
    series of |J^-1| |dJ| (:func:`_through_inverse`), with dJ the spread of J for that
    |q - q*| (checked self-consistent). The velocity equation J(q*) q'* = -V(q*) v' is
    linear: J(q*) (q' - q'*) is the velocity residual at (q*, q'), bounded by the
    computed residual at (q, q') plus its rounding plus its change from q to q*; the same
    for the acceleration, whose right-hand side holds the velocities, with their bound.
    No step is a first-order estimate: each change is bounded whole (chords of
    e^(i theta), products), and the rounding model allows an ulp or more per operation."""
    n = model.n
    inv = _abs_inverse(jac)
    if inv is None:
        return None
    ed = 2.0 * EPS * abs(d)  # the driver: a decimal value, then degrees to radians
    zero = [0.0] * n
    u0 = _Uncertainty(zero, zero, zero, ed, EPS * abs(speed), EPS * abs(accel))
    if data is None:
        data = [[_static(t, q, d, qd, speed, qdd, accel) for t in terms] for terms in model.terms]
    g = _loop_residuals(data, u0, 0)
    guess = _through_inverse(inv, _jacobian_spread(data, n, u0), g)
    if guess is None:
        return None
    eq: list[float] | None = None
    for _ in range(6):
        trial = [1.25 * x + EPS * abs(v) for x, v in zip(guess, q)]
        spread = _jacobian_spread(data, n, _Uncertainty(trial, zero, zero, ed, 0.0, 0.0))
        got = _through_inverse(inv, spread, g)
        if got is None:
            return None
        if all(a <= b for a, b in zip(got, trial)):
            eq = trial  # the spread assumed holds for the bound it gives
            break
        guess = got
    if eq is None:
        return None
    uq = _Uncertainty(eq, zero, zero, ed, u0.evd, u0.evdd)
    ev = _through_inverse(inv, spread, _loop_residuals(data, uq, 1))
    if ev is None:
        return None
    uv = _Uncertainty(eq, ev, zero, ed, u0.evd, u0.evdd)
    ea = _through_inverse(inv, spread, _loop_residuals(data, uv, 2))
    if ea is None:
        return None
    return RateBounds(eq, ev, ea, _Uncertainty(eq, ev, ea, ed, u0.evd, u0.evdd))


def place(model: LoopModel, q: Any, d: float, qd: Any = None, vd: float = 0.0, qdd: Any = None,
          vdd: float = 0.0) -> dict[str, tuple[complex, complex, complex]]:
    """Every named joint and point: name -> (position, velocity, acceleration), complex."""
    return {k: v[:3] for k, v in _place(model, q, d, qd, vd, qdd, vdd, None).items()}


def _place(model: LoopModel, q: Any, d: float, qd: Any, vd: float, qdd: Any, vdd: float,
           unc: _Uncertainty | None, data: list[list[tuple[Any, ...]]] | None = None
           ) -> dict[str, tuple[complex, complex, complex, float, float]]:
    """:func:`place`, each joint and point with bounds on its velocity and acceleration
    (each of x and y) when ``unc`` gives the inputs' uncertainties (else 0). ``data``: the
    loops' :func:`_static` values at these arguments, if already computed."""
    m = model.mechanism
    n = model.n
    qd = qd if qd is not None else [0.0] * n
    qdd = qdd if qdd is not None else [0.0] * n

    def part(t: Any, at: tuple[int, int] | None
             ) -> tuple[tuple[complex, complex, complex], tuple[float, float]]:
        if unc is None:
            return _term(t, q, d, qd, vd, qdd, vdd), (0.0, 0.0)
        st = data[at[0]][at[1]] if data is not None and at is not None else _static(t, q, d, qd, vd, qdd, vdd)
        return st[5:8], (max(_bounds_of(st, unc, 1)), max(_bounds_of(st, unc, 2)))

    def add(start: tuple[complex, complex, complex, float, float], parts: Any, sign: float
            ) -> tuple[complex, complex, complex, float, float]:
        p, v, a, bv, ba = start
        for (dp, dv, da), (cv, ca) in parts:
            p, v, a = p + sign * dp, v + sign * dv, a + sign * da
            # each addition rounds by at most an ulp of the running sum
            bv += cv + EPS * abs(v) if unc is not None else 0.0
            ba += ca + EPS * abs(a) if unc is not None else 0.0
        return p, v, a, bv, ba

    return _walk(model, part, add, (complex(*m.origin), 0j, 0j, 0.0, 0.0),
                 lambda xy: (complex(*xy), 0j, 0j, 0.0, 0.0))


def place_np(model: LoopModel, q: Any, d: Any) -> dict[str, tuple[Any, Any]]:
    """:func:`place`'s positions over arrays: every named joint and point, name -> (x, y)
    arrays, for ``q`` (one array per unknown, internal units) and driver values ``d``.
    The same sums in the same order as :func:`_place` (each vector ``sign r e^(i theta)``,
    the joints by the one placing rule, :func:`_walk`), so it agrees
    with the scalar definition to the last bits of numpy's cos and sin (tests check it)."""
    import numpy as np

    d = np.asarray(d, dtype=float)
    zero = np.zeros(d.shape)

    def part(t: Any, _at: Any) -> tuple[Any, Any]:
        sign, lc, li, ac, ai, off = t
        r = q[li] if li >= 0 else (d if li == DRIVER else lc)
        th = (q[ai] if ai >= 0 else (d if ai == DRIVER else ac)) + off
        sr = sign * r  # as _term: (sign r) e^(i theta), e^(i theta) = cos + i sin
        return sr * np.cos(th), sr * np.sin(th)

    def add(start: tuple[Any, Any], parts: Any, sign: float) -> tuple[Any, Any]:
        x, y = start
        for dx, dy in parts:
            x, y = x + sign * dx, y + sign * dy
        return x, y

    origin0 = (zero + model.mechanism.origin[0], zero + model.mechanism.origin[1])
    placed = _walk(model, part, add, origin0, lambda xy: (zero + xy[0], zero + xy[1]))
    # a constant joint (a ground pivot) as a full column, as every position has it
    return {k: (x + zero, y + zero) for k, (x, y) in placed.items()}


def _walk(model: LoopModel, part: Any, add: Any, origin0: Any, at_rest: Any) -> dict[str, Any]:
    """The placing rule, over any values: each loop from its first joint if an earlier loop
    placed it (else the origin), a joint reached along the side of its loop with fewer
    moving vectors (a ground pivot then has exactly zero velocity, and fewer terms round),
    a point from its joint; a joint of ``model.drawn`` (a fixed joint of a drawing) where it
    was drawn, exactly. ``part(term, (loop, index))`` is a vector's value (``None`` for a
    point's), ``add(start, parts, sign)`` their sum, ``at_rest((x, y))`` a joint standing
    still there."""
    placed: dict[str, Any] = {}
    for i, (loop, terms) in enumerate(zip(model.mechanism.loops, model.terms)):
        names = loop.joints
        if names and names[0] in model.drawn and names[0] not in placed:
            placed[names[0]] = at_rest(model.drawn[names[0]])
        start = placed.get(names[0]) if names and names[0] else None
        origin = start if start is not None else origin0
        parts = [part(t, (i, j)) for j, t in enumerate(terms)]
        moving = [t[2] != FIXED or t[4] != FIXED for t in terms]
        for k in range(len(terms)):
            if not names or not names[k] or names[k] in placed:
                continue
            if names[k] in model.drawn:
                placed[names[k]] = at_rest(model.drawn[names[k]])
                continue
            forward, backward = range(k), range(k, len(terms))
            ahead = sum(moving[j] for j in forward) <= sum(moving[j] for j in backward)
            placed[names[k]] = add(origin, [parts[j] for j in (forward if ahead else backward)],
                                   1.0 if ahead else -1.0)
    for name, (origin_name, terms) in model.point_terms.items():
        placed[name] = add(placed.get(origin_name, origin0), [part(t, None) for t in terms], 1.0)
    return placed


def inverse_np(a: Any) -> tuple[Any, Any]:
    """The inverse of each matrix of a stack (NaN where it is singular or not finite) and
    where it exists: one batched LU, the singular ones found only when there are some."""
    import numpy as np

    inv = np.full(a.shape, np.nan)
    usable = np.isfinite(a).all(axis=(-2, -1)) if a.size else np.ones(a.shape[:-2], dtype=bool)
    if a.shape[-1] == 0 or not usable.any():
        return inv, usable
    try:
        inv[usable] = np.linalg.inv(a[usable])
    except np.linalg.LinAlgError:  # an exactly singular one: find them by their determinant
        with np.errstate(invalid="ignore", over="ignore"):
            usable &= np.linalg.det(a) != 0.0
        if usable.any():
            inv[usable] = np.linalg.inv(a[usable])
    usable &= np.isfinite(inv).all(axis=(-2, -1))
    return inv, usable


def solve_rates_np(model: LoopModel, q: Any, d: Any, speed: float, accel: float
                   ) -> tuple[list[Any], list[Any], Any]:
    """:func:`rates_from_jacobian`'s twin over arrays of positions (``model`` may carry arrays of
    parameters, :meth:`LoopModel.compile`'s ``values``): (q', q'', solved), the same two
    linear solves, J q' = -(dPhi/dv) v' and J q'' = -(dPhi/dv) v'' - b, with J and
    dPhi/dv from each vector's derivatives and b its centripetal and Coriolis parts. NaN
    (and solved False) where J is singular. No polishing and no bound: a batch's positions
    are judged by the loads' condition number (kinematics.forces)."""
    import numpy as np

    d = np.asarray(d, dtype=float)
    n, rows = model.n, 2 * len(model.terms)
    jac = np.zeros((*d.shape, rows, n))
    dv = np.zeros((*d.shape, rows))
    for k, loop in enumerate(model.terms):
        for sign, lc, li, ac, ai, off in loop:
            r = _value(li, lc, q, d)
            th = _value(ai, ac, q, d) + off
            c, s = sign * np.cos(th), sign * np.sin(th)
            for idx, (ex, ey) in ((li, (c, s)), (ai, (-r * s, r * c))):
                if idx >= 0:
                    jac[..., 2 * k, idx] += ex
                    jac[..., 2 * k + 1, idx] += ey
                elif idx == DRIVER:
                    dv[..., 2 * k] += ex
                    dv[..., 2 * k + 1] += ey
    inv, solved = inverse_np(jac)

    def solve(rhs: Any) -> Any:
        return -np.einsum("...ij,...j->...i", inv, rhs)

    qd = solve(speed * dv)
    qd_list = [qd[..., i] for i in range(n)]
    bias = np.zeros((*d.shape, rows))
    for k, loop in enumerate(model.terms):
        for sign, lc, li, ac, ai, off in loop:
            r = _value(li, lc, q, d)
            th = _value(ai, ac, q, d) + off
            r1, w = _rate(li, qd_list, speed), _rate(ai, qd_list, speed)
            # sign (2 i r' w - r w^2) e^(i theta), only the parts without a second derivative
            cen, cor = -r * w * w, 2.0 * r1 * w
            c, s = np.cos(th), np.sin(th)
            bias[..., 2 * k] += sign * (cen * c - cor * s)
            bias[..., 2 * k + 1] += sign * (cen * s + cor * c)
    qdd = solve(accel * dv + bias)
    return qd_list, [qdd[..., i] for i in range(n)], solved


def place_motion_np(model: LoopModel, q: Any, d: Any, qd: Any, vd: float, qdd: Any, vdd: float
                    ) -> dict[str, tuple[Any, Any, Any]]:
    """:func:`place`'s twin over arrays: every named joint and point, name -> (position,
    velocity, acceleration) as complex arrays, each vector by :func:`_term`'s formulas and
    the joints by the one placing rule (:func:`_walk`)."""
    import numpy as np

    d = np.asarray(d, dtype=float)
    zero = np.zeros(d.shape, dtype=complex)

    def part(t: Any, _at: Any) -> tuple[Any, Any, Any]:
        sign, lc, li, ac, ai, off = t
        r, th = _value(li, lc, q, d), _value(ai, ac, q, d) + off
        r1, w = _rate(li, qd, vd), _rate(ai, qd, vd)
        r2, al = _rate(li, qdd, vdd), _rate(ai, qdd, vdd)
        e = np.exp(1j * th)
        return (sign * r * e, sign * (r1 + 1j * r * w) * e,
                sign * (r2 + 1j * r * al + 2j * r1 * w - r * w * w) * e)

    def add(start: Any, parts: Any, sign: float) -> tuple[Any, Any, Any]:
        p, v, a = start
        for dp, dv, da in parts:
            p, v, a = p + sign * dp, v + sign * dv, a + sign * da
        return p, v, a

    origin0 = (zero + complex(*model.mechanism.origin), zero, zero)
    placed = _walk(model, part, add, origin0, lambda xy: (zero + complex(*xy), zero, zero))
    return {k: (p + zero, v + zero, a + zero) for k, (p, v, a) in placed.items()}


def _xy(c: complex) -> XY:
    return (c.real, c.imag)


def position_rates(model: LoopModel, q: Any, d: float, speed: float | None = None,
                   accel: float = 0.0) -> Rates:
    """The joints and points at (q, d) (internal units), and with a driver ``speed`` the
    rates of every unknown, joint and point (internal units: rad/s for angles), each with
    its error bound: computed at q polished to full precision (:func:`polish`), bounded by
    :func:`rate_bounds`, flagged ``ill_conditioned`` beyond ``RATE_RTOL``, and absent
    (status ``undefined``) where J is singular within its own uncertainty."""
    names = [u.name for u in model.mechanism.unknowns]
    if speed is None:
        return Rates({k: _xy(p) for k, (p, _, _) in place(model, q, d).items()})
    funcs = model.factory(d)
    q = polish(model, q, d, funcs)
    _, J, V = funcs
    jac = J(q)
    solved = rates_from_jacobian(jac, V(q), model, q, d, speed, accel)
    if solved is None:
        return Rates({k: _xy(p) for k, (p, _, _) in place(model, q, d).items()}, status="undefined")
    qd, qdd = solved
    # each vector's values, once for its bounds and for the joints
    data = [[_static(t, q, d, qd, speed, qdd, accel) for t in terms] for terms in model.terms]
    bounds = rate_bounds(model, q, d, speed, accel, qd, qdd, jac, data)
    if bounds is None:
        return Rates({k: _xy(p) for k, (p, _, _) in place(model, q, d).items()}, status="undefined")
    pts = _place(model, q, d, qd, speed, qdd, accel, bounds.uncertainty, data)
    # the scale below which a rate is judged against the driver's own motion instead
    size = model.mechanism.length_scale
    omega = abs(speed) / (1.0 if model.mechanism.driver.kind == "angle" else size)
    alpha = abs(accel) / (1.0 if model.mechanism.driver.kind == "angle" else size) + omega * omega
    kinds = [u.kind for u in model.mechanism.unknowns]
    flags: list[str] = []

    def judge(label: str, value: float, bound: float, floor: float) -> None:
        if not bound <= RATE_RTOL * max(abs(value), floor):
            flags.append(label)

    vb = [SAFETY * b for b in bounds.velocity]
    ab = [SAFETY * b for b in bounds.acceleration]
    for name, kind, v, a, bv, ba in zip(names, kinds, qd, qdd, vb, ab):
        unit = 1.0 if kind == "angle" else size
        judge(rate_label(name, 1), v, bv, omega * unit)
        judge(rate_label(name, 2), a, ba, alpha * unit)
    jvb = {k: SAFETY * bv for k, (_, _, _, bv, _) in pts.items()}
    jab = {k: SAFETY * ba for k, (_, _, _, _, ba) in pts.items()}
    for k, (_, v, a, _, _) in pts.items():
        judge(rate_label(k, 1, joint=True), abs(v), jvb[k], omega * size)
        judge(rate_label(k, 2, joint=True), abs(a), jab[k], alpha * size)
    return Rates(
        joints={k: _xy(p[0]) for k, p in pts.items()},
        velocities=dict(zip(names, qd)),
        accelerations=dict(zip(names, qdd)),
        joint_velocities={k: _xy(p[1]) for k, p in pts.items()},
        joint_accelerations={k: _xy(p[2]) for k, p in pts.items()},
        status="ill_conditioned" if flags else "ok",
        velocity_bounds=dict(zip(names, vb)),
        acceleration_bounds=dict(zip(names, ab)),
        joint_velocity_bounds=jvb,
        joint_acceleration_bounds=jab,
        ill_conditioned=tuple(flags),
    )


def rates_at(mechanism: Any, q: Any, *, speed: float | None = None, accel: float = 0.0,
             driver: float | None = None) -> Rates:
    """The public ``linkage.position_rates``: joints and points of ``mechanism`` at the
    solution ``q`` (radians and length units, as ``solve_system`` returns it), at its
    driver value (or ``driver``, internal units), with the rates of everything when a
    driver ``speed`` (rad/s or length/s) and ``accel`` are given. ``mechanism`` may be a
    path to a file. Numbers only, in those internal units (a unit string such as "10rpm"
    is the command line's); every argument is checked first, and a misuse raises
    :class:`~linkage.errors.InputError` naming it."""
    from ..arguments import check_motion, check_number, check_reals
    from .loading import mechanism_of

    mechanism = mechanism_of("mechanism", mechanism)
    names = [u.name for u in mechanism.unknowns]
    q = check_reals("q", q, len(names), names)
    speed, accel = check_motion(speed, accel, mechanism.driver.kind, mechanism.length_unit)
    model = mechanism.model
    d = mechanism.driver.value if driver is None else check_number("driver", driver)
    # the rates are those of the solution through q (polished to full precision): a q that
    # closes no loop would silently get another position's rates, or be called singular
    from ..errors import InputError
    from ..solve import MAX_RELATIVE_TOL

    gap = max(map(abs, model.functions(d)[0](list(q))), default=0.0)
    allowed = MAX_RELATIVE_TOL * mechanism.length_scale
    if not gap <= allowed:
        unit = f" {mechanism.length_unit}" if mechanism.length_unit else ""
        raise InputError(f"q is not a solution at this driver value: it leaves the loops open by "
                         f"{gap:.3g}{unit}, more than the {allowed:.3g}{unit} (1% of the mechanism's "
                         "size) any solve's tolerance allows; solve first (solve_system)")
    return position_rates(model, q, d, speed, accel)


def with_rates(m: Any, result: SweepResult, speed: float | None, accel: float) -> SweepResult:
    """Joints, and with a driver speed velocities and accelerations, at every solved position."""
    from dataclasses import replace

    from .positions import with_position_rates

    model = m.model
    scale = ANGLE_UNITS[m.driver.unit] if m.driver.kind == "angle" else 1.0
    kinds = [u.kind for u in m.unknowns]
    positions = []
    for p in result.positions:
        if p.solution is None:
            positions.append(p)
            continue
        q = [math.radians(p.solution[u.name]) if k == "angle" else p.solution[u.name]
             for u, k in zip(m.unknowns, kinds)]
        positions.append(with_position_rates(p, position_rates(model, q, p.input * scale, speed, accel)))
    motion = (speed, accel) if speed is not None else None
    return replace(result, positions=tuple(positions), motion=motion)
