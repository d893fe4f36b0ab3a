"""Velocity and acceleration of every unknown, joint and named point, at one position.

Every vector of every loop is ``sign * r * e^(i theta)``. Differentiating the loops in
time (PROBLEMS.md P7), with ' for d/dt:

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
the first loop starts at the origin, with x along the 0-degree direction; a later loop
starts at its first joint if an earlier loop placed it (a six-bar's second loop at the
rocker pivot), else at the origin too. A named point (``[points.P]``) starts at a joint
and adds its own vectors. Their velocities and accelerations are the same sums,
differentiated.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass, field
from typing import Any

from ..methods.newton_system import newton_direction
from ..problems.loops import DRIVER, LoopModel

FIXED = -1

XY = tuple[float, float]


@dataclass(frozen=True)
class Rates:
    """One position's kinematics. ``velocities``/``accelerations``: unknown name -> rad/s
    and rad/s^2 (angles) or length unit/s and /s^2 (lengths); the joint and point maps:
    name -> (x, y) in the length unit (/s, /s^2). Empty rate maps when ``status`` is
    ``singular`` (J cannot be inverted there) or when no driver motion was given."""

    joints: dict[str, XY]
    velocities: dict[str, float] = field(default_factory=dict)
    accelerations: dict[str, float] = field(default_factory=dict)
    joint_velocities: dict[str, XY] = field(default_factory=dict)
    joint_accelerations: dict[str, XY] = field(default_factory=dict)
    status: str = "ok"


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


def solve_rates(model: LoopModel, q: Any, d: float, speed: float,
                accel: float) -> tuple[list[float], list[float]] | None:
    """(q', q'') at (q, d) for driver rate ``speed`` and ``accel`` (internal units), or
    None where J is singular."""
    _, J, V = model.factory(d)
    jac, dv = J(list(q)), V(list(q))
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
    if qdd is None:
        return None
    return qd, qdd


def place(model: LoopModel, q: Any, d: float, qd: Any = None, vd: float = 0.0, qdd: Any = None,
          vdd: float = 0.0) -> dict[str, tuple[complex, complex, complex]]:
    """Every named joint and point: name -> (position, velocity, acceleration), complex."""
    m = model.mechanism
    n = model.n
    qd = qd if qd is not None else [0.0] * n
    qdd = qdd if qdd is not None else [0.0] * n
    placed: dict[str, tuple[complex, complex, complex]] = {}
    for loop, terms in zip(m.loops, model.terms):
        names = loop.joints
        start = placed.get(names[0]) if names and names[0] else None
        origin = start if start is not None else (0j, 0j, 0j)
        parts = [_term(t, q, d, qd, vd, qdd, vdd) for t in terms]
        moving = [t[2] != FIXED or t[4] != FIXED for t in terms]
        for k in range(len(terms)):
            if not names or not names[k] or names[k] in placed:
                continue
            # reach joint k along the side of the loop with fewer moving vectors (a ground
            # pivot then has exactly zero velocity, and fewer terms round)
            forward = range(k)
            backward = range(k, len(terms))
            ahead = sum(moving[j] for j in forward) <= sum(moving[j] for j in backward)
            sign = 1.0 if ahead else -1.0
            p, v, a = origin
            for j in (forward if ahead else backward):
                p, v, a = p + sign * parts[j][0], v + sign * parts[j][1], a + sign * parts[j][2]
            placed[names[k]] = (p, v, a)
    for name, (origin, terms) in model.point_terms.items():
        p, v, a = placed.get(origin, (0j, 0j, 0j))
        for t in terms:
            dp, dv, da = _term(t, q, d, qd, vd, qdd, vdd)
            p, v, a = p + dp, v + dv, a + da
        placed[name] = (p, v, a)
    return placed


def _xy(c: complex) -> XY:
    return (c.real, c.imag)


def position_rates(model: LoopModel, q: Any, d: float, speed: float | None = None,
                   accel: float = 0.0) -> Rates:
    """The joints and points at (q, d) (internal units), and with a driver ``speed`` the
    rates of every unknown, joint and point (internal units: rad/s for angles)."""
    names = [u.name for u in model.mechanism.unknowns]
    if speed is None:
        return Rates({k: _xy(p) for k, (p, _, _) in place(model, q, d).items()})
    solved = solve_rates(model, q, d, speed, accel)
    if solved is None:
        return Rates({k: _xy(p) for k, (p, _, _) in place(model, q, d).items()}, status="singular")
    qd, qdd = solved
    pts = place(model, q, d, qd, speed, qdd, accel)
    return Rates(
        joints={k: _xy(p) for k, (p, _, _) in pts.items()},
        velocities=dict(zip(names, qd)),
        accelerations=dict(zip(names, qdd)),
        joint_velocities={k: _xy(v) for k, (_, v, _) in pts.items()},
        joint_accelerations={k: _xy(a) for k, (_, _, a) in pts.items()},
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
    from ..arguments import check_mechanism, check_number, check_rate, check_reals
    from ..errors import InputError

    mechanism = check_mechanism("mechanism", mechanism)
    names = [u.name for u in mechanism.unknowns]
    q = check_reals("q", q, len(names), names)
    per_s = "rad/s" if mechanism.driver.kind == "angle" else f"{mechanism.length_unit or 'length unit'}/s"
    if speed is not None:
        speed = check_rate("speed", speed, per_s)
    accel = check_rate("accel", accel, f"{per_s}^2")
    if speed is None and accel != 0.0:
        raise InputError("accel needs speed (the driver's velocity)")
    model = mechanism.model
    d = mechanism.driver.value if driver is None else check_number("driver", driver)
    return position_rates(model, q, d, speed, accel)
