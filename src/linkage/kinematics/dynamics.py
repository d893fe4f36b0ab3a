"""Forward dynamics of a one-degree-of-freedom mechanism with masses (``linkage simulate``,
docs/simulate.md): the driver's motion under a driving torque (or force), the file's
loads, gravity and pin friction, integrated in time.

The equation of motion is Lagrange's for one generalized coordinate theta (the driver's
angle in rad, or its slide in m), built from the rates engine (kinematics.rates) at a
unit driver speed, where no force enters:

    I(theta) = sum over links of m |v_G*|^2 + I_G omega*^2           (+ a flywheel's I_f)

with v_G* and omega* each link's centre-of-mass velocity and angular velocity per unit
driver speed. Since v_G = v_G* theta', the velocity-product acceleration (the rates at
unit speed and zero driver acceleration) is a_G0 = dv_G*/dtheta, and alpha0 =
domega*/dtheta, so

    (1/2) dI/dtheta = sum m v_G* . a_G0 + I_G omega* alpha0

exactly (no finite difference). Kinetic energy T = I theta'^2 / 2, and d/dt of it equals
the power of the generalized force Q (virtual power: each load's F . v* + M omega*, the
weights' m g . v_G*, the friction torques' and the drive's), which gives

    I(theta) theta'' + (1/2) I'(theta) theta'^2 = Q(t, theta, theta').

This module evaluates the equation's terms at a driver value (:class:`Dynamics`); its
integration in time, the events that end it and the checks are :mod:`.simulation`'s.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import field
from typing import Any

from ..problems.loads import Loads
from ..records import frozen

DEAD_POINT_SENSITIVITY = 300.0
"""A position is a dead point (the driver no longer drives the mechanism) where some
unknown moves this many times faster than the driver (angles in rad per rad of a turning
driver; lengths per the mechanism's size): a limit of assembly or a toggle is a
singular J, where that ratio s grows without bound (as 1/sqrt of the distance to a
limit). I(theta) holds s^2, and the motion near a limit is the integrator's hardest: at
s = 1e4 the energy balance at the event was 4e-7 on random four-bars, at 1e3 4e-8, at 300
within 1e-8 (tests/test_simulate.py, 50 random four-bars, rtol 1e-10)."""

FOLLOW_STEP = 0.2
"""The largest step Newton takes from a known position: the driver and the fastest unknown
each move at most this (rad; lengths as this fraction of the mechanism's size); farther,
the position is reached in such steps, each predicted along the last one's rates."""

MAX_WALK_STEPS = 4096
"""The most FOLLOW_STEPs the equation of motion walks to a trial position (about 130 turns
of a crank): a farther one is not reached (None), so the integrator refuses and shortens
its step; no step that long could meet its tolerance. Without it a runaway motion's trial
step, 1e40 rad on, was walked without end (a hang, not a failure)."""

ASSEMBLY_RTOL = 1e-9
"""A position closes its loops to this, relative to the mechanism's size, or it is not
assembled there."""

@frozen
class Friction:
    """Pin friction: each pin joins its owner (the ground where it is fixed, else the first
    link listing it) to each other link on it, and each such pair's relative rotation
    omega_rel is resisted by a torque -c omega_rel (``viscous``, N m s/rad) and
    -M sign(omega_rel) (``coulomb``, N m: a constant friction torque, zero at rest).
    ``default_*`` applies to every pin not named in the maps."""

    default_viscous: float = 0.0
    default_coulomb: float = 0.0
    viscous: Mapping[str, float] = field(default_factory=dict)
    coulomb: Mapping[str, float] = field(default_factory=dict)

    def at(self, pin: str) -> tuple[float, float]:
        return self.viscous.get(pin, self.default_viscous), self.coulomb.get(pin, self.default_coulomb)

    @property
    def any_coulomb(self) -> bool:
        return self.default_coulomb > 0.0 or any(v > 0.0 for v in self.coulomb.values())


@frozen
class Drive:
    """The driving torque (N m) or force (N) as a function of t (s), theta (rad or m) and
    omega (rad/s or m/s): ``text`` through the equations' safe parser
    (problems.expression.function_of), with named ``constants``."""

    text: str
    constants: Mapping[str, float] = field(default_factory=dict)

    def function(self) -> Callable[[float, float, float], float]:
        from ..problems.expression import function_of

        return function_of(self.text, ("t", "theta", "omega"), self.constants, what="drive")


@frozen
class Point:
    """The mechanism at one driver value, per unit driver speed (SI)."""

    q: list[float]
    """The unknowns, internal units."""
    qd: list[float]
    """Their rates per unit internal driver speed."""
    inertia: float
    """I(theta): kg m^2 (or kg, a sliding driver)."""
    half_slope: float
    """(1/2) dI/dtheta."""
    loads: float
    """The loads' generalized force (N m or N): their virtual power per unit speed."""
    weight: float
    """The weights' generalized force."""
    potential: float
    """The weights' potential energy, J."""
    pairs: tuple[tuple[str, str, str, float], ...]
    """(pin, owner, link, relative omega per unit speed) of every pin pair."""
    sensitivity: float
    """The largest unknown's rate per driver rate (see DEAD_POINT_SENSITIVITY)."""


class Dynamics:
    """A mechanism's equation of motion, evaluated at driver values (positions followed by
    Newton from the last one, predicted along its rates)."""

    def __init__(self, mechanism: Any, loads: Loads, friction: Friction, flywheel: float = 0.0) -> None:
        from .bodies import Frame, metre
        from .load_matrix import pin_pairs

        self.mechanism = mechanism
        self.model = mechanism.model
        self.frame = Frame.of(mechanism)
        self.loads = loads
        self.friction = friction
        self.flywheel = flywheel
        self.k = metre(mechanism.length_unit)
        self.sliding = mechanism.driver.kind != "angle"
        self.c = self.k if self.sliding else 1.0  # SI per internal unit of the driver
        self.size = mechanism.length_scale
        self.follow_step = FOLLOW_STEP * (self.size * self.k if self.sliding else 1.0)
        self.kinds = [u.kind for u in mechanism.unknowns]
        self.pin_pairs = tuple(pin_pairs(self.frame.drawing))
        self._last: tuple[float, list[float], list[float]] = (
            mechanism.driver.value * self.c, [u.value for u in mechanism.unknowns], [0.0] * self.model.n)
        self.initial = self._last
        self._memo: tuple[float, Point] | None = None

    def start(self, theta: float, q: Sequence[float]) -> None:
        """Follow the assembly through ``q`` at ``theta`` (SI), from here on."""
        self._last = self.initial = (theta, list(q), [0.0] * self.model.n)
        self._memo = None

    def restart(self) -> None:
        """Follow the assembly from the start again (the output times, after the integration)."""
        self._last = self.initial
        self._memo = None

    def sensitivity(self, qd: Sequence[float]) -> float:
        """The fastest unknown's rate per driver rate, from ``qd`` per internal driver unit:
        angles in rad, lengths in the mechanism's size, a sliding driver's too."""
        fastest = max((abs(v) if k == "angle" else abs(v) / self.size for v, k in zip(qd, self.kinds)),
                      default=0.0)
        return fastest * (self.size if self.sliding else 1.0)

    def position(self, theta: float, walk_limit: int | None = None) -> list[float] | None:
        """The unknowns at driver ``theta`` (SI) on the followed assembly, or None where the
        loops do not close there, or (with ``walk_limit``) where reaching it takes more than
        that many FOLLOW_STEPs."""
        if not math.isfinite(theta):
            return None
        start = self._last
        # a long way from the last position: walk there in steps, so Newton cannot jump to
        # another assembly (each step moves the fastest unknown at most FOLLOW_STEP); where
        # Newton does not close the loops, again in steps half as long, down to 1/64
        moved = abs(theta - start[0]) / self.follow_step  # the driver's move, in FOLLOW_STEPs
        reach = moved * max(self.sensitivity(start[2]), 1.0)
        limit = math.inf if walk_limit is None else walk_limit
        if not reach <= limit:
            return None
        steps = max(1, math.ceil(reach))
        for _ in range(7):
            if steps > limit:
                return None
            q = self._walk(start, theta, steps)
            if q is not None:
                return q
            steps *= 2
        return None

    def _walk(self, start: tuple[float, list[float], list[float]], theta: float, steps: int
              ) -> list[float] | None:
        from .rates import polish, solve_rates

        t0, q0, qd0 = start
        q = q0
        for i in range(1, steps + 1):
            at = start[0] + (theta - start[0]) * i / steps
            dd = (at - t0) / self.c
            guess = [a + b * dd for a, b in zip(q0, qd0)]
            d = at / self.c
            funcs = self.model.factory(d)
            q = polish(self.model, guess, d, funcs)
            gap = max(map(abs, funcs[0](q)), default=0.0)
            if not gap <= ASSEMBLY_RTOL * self.size:
                return None
            if i < steps:
                rates = solve_rates(self.model, q, d, 1.0, 0.0)
                if rates is None:
                    return None
                t0, q0, qd0 = at, q, rates[0]
        return q

    def at(self, theta: float, walk_limit: int | None = None) -> Point | None:
        """The equation's terms at driver ``theta`` (SI), or None where the mechanism is
        not assembled or its rates are undefined (J singular), or beyond ``walk_limit``
        (:meth:`position`)."""
        from .load_matrix import body_motion, cg_motion
        from .rates import place, rates_from_jacobian

        if self._memo is not None and self._memo[0] == theta:  # the event's call after the step's
            return self._memo[1]
        q = self.position(theta, walk_limit)
        if q is None:
            return None
        d = theta / self.c
        _, J, V = self.model.factory(d)
        solved = rates_from_jacobian(J(q), V(q), self.model, q, d, 1.0, 0.0)
        if solved is None:
            return None
        qd, qdd = solved
        self._last = (theta, q, qd)
        k, c = self.k, self.c
        placed = place(self.model, q, d, qd, 1.0, qdd, 0.0)
        pos = {j: (p.real * k, p.imag * k) for j, (p, _, _) in placed.items()}
        vel = {j: (v.real * k / c, v.imag * k / c) for j, (_, v, _) in placed.items()}
        acc = {j: (a.real * k / (c * c), a.imag * k / (c * c)) for j, (_, _, a) in placed.items()}
        motion = body_motion(self.frame, pos, vel, acc)
        inertia, half, weight, potential = self.flywheel, 0.0, 0.0, 0.0
        g = self.loads.gravity
        d_ = self.frame.drawing
        for b, m in self.loads.masses.items():
            cg, vg, ag = cg_motion(d_, b, m, k, pos, vel, acc, motion[b])
            w, al = float(motion[b][1]), float(motion[b][2])
            inertia += m.mass * (vg[0] ** 2 + vg[1] ** 2) + m.inertia * w * w
            half += m.mass * (vg[0] * ag[0] + vg[1] * ag[1]) + m.inertia * w * al
            if g is not None:
                weight += m.mass * (g[0] * vg[0] + g[1] * vg[1])
                potential -= m.mass * (g[0] * cg[0] + g[1] * cg[1])
        loads = sum(f[0] * vel[j][0] + f[1] * vel[j][1] for j, f in self.loads.forces.items())
        loads += sum(t * float(motion[b][1]) for b, t in self.loads.torques.items())
        pairs = tuple((j, a, b, float(motion[b][1] - motion[a][1])) for j, a, b in self.pin_pairs)
        sens = self.sensitivity(qd)
        point = Point(q, qd, float(inertia), float(half), float(loads), float(weight), float(potential),
                      pairs, sens)
        self._memo = (theta, point)
        return point

    def friction_force(self, p: Point, omega: float) -> float:
        """The friction torques' generalized force at driver speed ``omega``: minus the sum
        over pin pairs of c w*^2 omega + M |w*| sign(omega), w* the pair's relative rate
        per unit driver speed."""
        total = 0.0
        sign = (omega > 0.0) - (omega < 0.0)
        for j, _, _, w in p.pairs:
            cv, cc = self.friction.at(j)
            total -= cv * w * w * omega + cc * abs(w) * sign
        return total

    def friction_torques(self, p: Point, omega: float) -> dict[str, float]:
        """The same friction as torques on the links (N m; a pair's on the link, its
        reaction on the owner), for the kinetostatic check: their virtual power is
        :meth:`friction_force` times omega."""
        out: dict[str, float] = {}
        for j, a, b, w in p.pairs:
            cv, cc = self.friction.at(j)
            rel = w * omega
            t = -(cv * rel + cc * ((rel > 0.0) - (rel < 0.0)))
            for body, sign in ((b, 1.0), (a, -1.0)):
                if body != "ground":
                    out[body] = out.get(body, 0.0) + sign * t
        return out
