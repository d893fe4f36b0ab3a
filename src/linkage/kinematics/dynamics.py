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

It is integrated by scipy's solve_ivp (DOP853); the work of the drive, of friction and
of the loads is integrated beside it, so kinetic + potential - work stays constant (the
printed energy balance). Each output time's pin forces come from the kinetostatic
matrix method (kinematics.forces) at the simulated speed and acceleration, and its
input must equal the simulated drive: the second printed check.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from ..errors import InputError
from ..problems.loads import Loads

DEAD_POINT_SENSITIVITY = 300.0
"""A position is a dead point (the driver no longer drives the mechanism) where some
unknown moves this many times faster than the driver (angles in rad per rad of a turning
driver; lengths per the mechanism's size): a limit of assembly or a toggle is a
singular J, where that ratio s grows without bound (as 1/sqrt of the distance to a
limit). I(theta) holds s^2, and the motion near a limit is the integrator's hardest: at
s = 1e4 the energy balance at the event was 4e-7 on random four-bars, at 1e3 4e-8, at 300
within 1e-8 (tests/test_simulate.py, 50 random four-bars, rtol 1e-10)."""

STEADY_RTOL = 0.01
"""The last turn is a steady-state cycle where the turn before's mean speed is within this
of its own."""

FOLLOW_STEP = 0.2
"""The largest step Newton takes from a known position: the driver and the fastest unknown
each move at most this (rad; lengths as this fraction of the mechanism's size); farther,
the position is reached in such steps, each predicted along the last one's rates."""

ASSEMBLY_RTOL = 1e-9
"""A position closes its loops to this, relative to the mechanism's size, or it is not
assembled there."""

EVENTS = ("dead_point", "limit_of_assembly", "stopped", "integration_failed")
"""The named events that end a simulation short of its time span (exit 1): a dead point
(the mechanism still assembles beyond it), a limit of assembly (it does not), the driver
at rest under Coulomb friction (sticking is not modelled), the integrator's own failure."""


@dataclass(frozen=True)
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


@dataclass(frozen=True)
class Drive:
    """The driving torque (N m) or force (N) as a function of t (s), theta (rad or m) and
    omega (rad/s or m/s): ``text`` through the equations' safe parser
    (problems.expression.function_of), with named ``constants``."""

    text: str
    constants: Mapping[str, float] = field(default_factory=dict)

    def function(self) -> Callable[[float, float, float], float]:
        from ..problems.expression import function_of

        return function_of(self.text, ("t", "theta", "omega"), self.constants, what="drive")


@dataclass(frozen=True)
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

    def position(self, theta: float) -> list[float] | None:
        """The unknowns at driver ``theta`` (SI) on the followed assembly, or None where the
        loops do not close there."""
        if not math.isfinite(theta):
            return None
        start = self._last
        # a long way from the last position: walk there in steps, so Newton cannot jump to
        # another assembly (each step moves the fastest unknown at most FOLLOW_STEP); where
        # Newton does not close the loops, again in steps half as long, down to 1/64
        moved = abs(theta - start[0]) / self.follow_step  # the driver's move, in FOLLOW_STEPs
        steps = max(1, math.ceil(moved * max(self.sensitivity(start[2]), 1.0)))
        for _ in range(7):
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

    def at(self, theta: float) -> Point | None:
        """The equation's terms at driver ``theta`` (SI), or None where the mechanism is
        not assembled or its rates are undefined (J singular)."""
        from .load_matrix import body_motion, cg_motion
        from .rates import place, rates_from_jacobian

        if self._memo is not None and self._memo[0] == theta:  # the event's call after the step's
            return self._memo[1]
        q = self.position(theta)
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


@dataclass(frozen=True)
class Simulation:
    """``linkage.simulate``'s answer (SI; theta in rad or m). Arrays over the output times."""

    t: Any
    theta: Any
    omega: Any
    alpha: Any
    drive: Any
    """The driving torque (N m) or force (N) at each time."""
    unknowns: dict[str, Any]
    """Each unknown's value at each time (internal units: rad, the file's length unit)."""
    kinetic: Any
    potential: Any
    work_drive: Any
    work_friction: Any
    work_loads: Any
    balance: float
    """max |(T + V - W) - (T + V - W)(0)| over the run, relative to the largest energy term."""
    forces: tuple[Any, ...]
    """kinematics.forces.Forces at each time (the kinetostatic matrix method at the
    simulated speed and acceleration, the friction torques among the loads)."""
    drive_check: float
    """max |kinetostatic input - simulated drive| (the flywheel's I_f alpha added to the
    kinetostatic input) relative to the equation's terms: the largest sum of the sizes of
    the drive, I alpha, I'/2 omega^2 and the loads', weights' and friction's torques."""
    event: str | None
    """None when the whole span was simulated, else one of EVENTS."""
    event_time: float | None
    message: str
    nfev: int
    cycle: Cycle | None
    input_unit: str
    sliding: bool
    flywheel: float = 0.0
    """kg m^2, on the driver."""
    trace: tuple[Any, Any, Any] = ((), (), ())
    """(t, theta, omega) at 2001 times from the integrator's dense output, for pictures."""


@dataclass(frozen=True)
class Cycle:
    """The last full driver turn's speed fluctuation (flywheel sizing)."""

    start: float
    end: float
    omega_max: float
    omega_min: float
    omega_mean: float
    """2 pi / the cycle's period."""
    energy_swing: float
    """The kinetic energy's max - min over the cycle, J."""
    inertia_mean: float
    steady: bool = False
    """Whether the turn before had the same mean speed (within STEADY_RTOL): a steady-state
    cycle, the one a flywheel is sized for."""

    @property
    def cs(self) -> float:
        """The coefficient of speed fluctuation (omega_max - omega_min) / omega_mean."""
        return (self.omega_max - self.omega_min) / self.omega_mean

    def flywheel_for(self, cs: float) -> float:
        """The flywheel inertia that would bring this cycle's fluctuation to ``cs`` by the
        classical estimate I_f = dE / (cs omega_mean^2) - the mechanism's mean inertia
        (its energy swing held; Shigley, Theory of Machines and Mechanisms, flywheels)."""
        return max(self.energy_swing / (cs * self.omega_mean ** 2) - self.inertia_mean, 0.0)


def _checked_time(time: Any) -> tuple[float, float]:
    from ..arguments import describe, finite_real

    if not isinstance(time, (tuple, list)) or len(time) != 2:
        raise InputError(f"time: give (start, end) in s, got {describe(time)}")
    a, b = (finite_real(v) for v in time)
    if a is None or b is None or not b > a:
        raise InputError(f"time: give finite (start, end) in s with end > start, got {describe(time)}")
    return float(a), float(b)


def _checked_friction(friction: Any, drawing: Any, what: str) -> tuple[float, dict[str, float]]:
    """A friction argument: a number for every pin, or a map pin -> number (the key "*":
    every pin not named); each >= 0. Returns (every pin's, the named pins')."""
    from ..arguments import describe, finite_real

    def one(v: Any, where: str) -> float:
        x = finite_real(v)
        if x is None or x < 0:
            raise InputError(f"{where}: give a finite number >= 0, got {describe(v)}")
        return float(x)

    if isinstance(friction, Mapping):
        from .load_matrix import pin_pairs

        pins = {j for j, _, _ in pin_pairs(drawing)}
        every, out = 0.0, {}
        for j, v in friction.items():
            if j == "*":
                every = one(v, f"{what}['*']")
                continue
            if j not in pins:
                raise InputError(f"{what}: {j!r} is not a pin (a joint two bodies share): "
                                 f"{', '.join(sorted(pins))}")
            out[j] = one(v, f"{what}[{j!r}]")
        return every, out
    return one(friction, what), {}


def simulate(
    mechanism: Any,
    drive: Any,
    time: Any,
    *,
    constants: Mapping[str, float] | None = None,
    theta0: float | None = None,
    omega0: float = 0.0,
    loads: Loads | None = None,
    friction_viscous: Any = 0.0,
    friction_coulomb: Any = 0.0,
    flywheel: float = 0.0,
    samples: int = 201,
    rtol: float = 1e-10,
    atol: float = 1e-12,
) -> Simulation:
    """Forward dynamics of ``mechanism`` (a joints-form Mechanism, or a path, with masses)
    under ``drive`` (a text in t, theta, omega: torque in N m, or force in N for a sliding
    driver; or a number) over ``time`` = (start, end) s, from ``theta0`` (the driver's
    value in the file's unit, deg or length; default the file's) at ``omega0`` (rad/s or
    length unit/s). ``loads``: the file's by default (with gravity, ``Loads.gravity``);
    ``friction_*``: N m s/rad and N m, a number for every pin or a dict pin -> number
    (``"*"``: every other pin);
    ``flywheel``: kg m^2 on a turning driver. ``samples`` output times. Every argument is
    checked first; a misuse raises InputError naming it."""
    from ..arguments import check_number, describe, finite_real
    from ..problems.loops import ANGLE_UNITS, mechanism_of
    from .bodies import Frame, checked_loads

    mechanism = mechanism_of("mechanism", mechanism)
    frame = Frame.of(mechanism)
    start, end = _checked_time(time)
    if isinstance(drive, str):
        consts = {}
        for kname, v in (constants or {}).items():
            x = finite_real(v)
            if not isinstance(kname, str) or not kname.isidentifier() or x is None:
                raise InputError(f"constants: give name -> finite number, got {kname!r}: {describe(v)}")
            consts[kname] = float(x)
        try:
            fn = Drive(drive, consts).function()
        except InputError as exc:
            raise InputError(f"drive: {exc}") from None
    else:
        x = finite_real(drive)
        if x is None:
            raise InputError("drive: give a text in t, theta, omega or a finite number, got "
                             f"{describe(drive)}")
        value = float(x)

        def fn(t: float, theta: float, omega: float) -> float:
            return value
    if loads is None:
        loads = mechanism.extra.get("loads") or Loads()
        frame.check_masses(loads)
    else:
        loads = checked_loads(loads, mechanism)
    if not loads.masses:
        raise InputError(f"{mechanism.source}: the dynamics need masses: add [mass] LINK = {{ mass = KG, "
                         "cg = [x, y], inertia = KG_M2 } to the file")
    fv_default, fv = _checked_friction(friction_viscous, frame.drawing, "friction_viscous")
    fc_default, fc = _checked_friction(friction_coulomb, frame.drawing, "friction_coulomb")
    flywheel = check_number("flywheel", flywheel)
    if not flywheel >= 0.0:
        raise InputError(f"flywheel: give an inertia >= 0 in kg m^2, got {flywheel!r}")
    if flywheel and mechanism.driver.kind != "angle":
        raise InputError("flywheel: a flywheel turns with a turning driver; this driver slides")
    omega0 = check_number("omega0", omega0)
    if not isinstance(samples, int) or isinstance(samples, bool) or not 2 <= samples <= 100_000:
        raise InputError("samples: give a whole number of output times from 2 to 100000, got "
                         f"{describe(samples)}")
    for name, tol in (("rtol", rtol), ("atol", atol)):
        if not 1e-14 <= check_number(name, tol) <= 1e-2:
            raise InputError(f"{name}: give a tolerance from 1e-14 to 1e-2, got {tol!r}")
    dyn = Dynamics(mechanism, loads, Friction(fv_default, fc_default, fv, fc), flywheel)
    scale = ANGLE_UNITS[mechanism.driver.unit] if mechanism.driver.kind == "angle" else 1.0
    if theta0 is not None:
        q0 = _assembled_at(mechanism, check_number("theta0", theta0) * scale)
    else:
        q0 = [u.value for u in mechanism.unknowns]
        theta0 = mechanism.driver.value / scale
    th0 = float(theta0) * scale * dyn.c
    w0 = omega0 * (dyn.k if dyn.sliding else 1.0)
    dyn.start(th0, q0)
    return integrate(dyn, fn, th0, w0, start, end, samples, rtol, atol)


def _assembled_at(mechanism: Any, d: float) -> list[float]:
    """The unknowns at driver value ``d`` (internal) on the file's assembly."""
    from .sweep import sweep_mechanism

    unit = mechanism.driver.unit
    from ..problems.loops import ANGLE_UNITS

    shown = d / ANGLE_UNITS[unit] if mechanism.driver.kind == "angle" else d
    r = sweep_mechanism(mechanism, [shown])
    p = r.positions[0]
    if p.solution is None or p.status != "converged":
        raise InputError(f"theta0: {shown:.10g} {unit}: the mechanism does not assemble there")
    return [math.radians(p.solution[u.name]) if u.kind == "angle" else p.solution[u.name]
            for u in mechanism.unknowns]


def integrate(dyn: Dynamics, drive: Callable[[float, float, float], float], theta0: float, omega0: float,
              start: float, end: float, samples: int, rtol: float, atol: float) -> Simulation:
    """Integrate the equation of motion (DOP853) with its events, then every output time's
    energies, forces and checks."""
    import numpy as np
    from scipy.integrate import solve_ivp

    p0 = dyn.at(theta0)
    if p0 is None or not p0.sensitivity < DEAD_POINT_SENSITIVITY:
        raise InputError("theta0: the mechanism is at a dead point or not assembled there")
    if not p0.inertia > 0.0:
        raise InputError("the mechanism has no inertia to move: give its links a mass or an inertia in "
                         "[mass], or a flywheel (--flywheel)")

    calls = [0]
    last_t = [start]

    def rhs(t: float, y: Any) -> Any:
        calls[0] += 1
        if calls[0] > MAX_EVALUATIONS:
            raise _TooLong(f"more than {MAX_EVALUATIONS:,} evaluations of the equation of motion "
                           f"(at t = {t:.6g} s): shorten --time")
        theta, omega = float(y[0]), float(y[1])
        p = dyn.at(theta)
        if p is None or not p.inertia > 0.0:
            return np.full(5, np.nan)  # not assembled: the step is refused and shortened
        try:
            tau = float(drive(t, theta, omega))
        except (ArithmeticError, ValueError) as exc:
            raise _TooLong(f"the drive cannot be evaluated at t = {t:.6g} s, theta = {theta:.6g} rad, "
                           f"omega = {omega:.6g} rad/s ({exc})") from None
        last_t[0] = t
        fr = dyn.friction_force(p, omega)
        q = tau + p.loads + p.weight + fr
        return np.array([omega, (q - p.half_slope * omega * omega) / p.inertia,
                         tau * omega, fr * omega, p.loads * omega])

    def dead(t: float, y: Any) -> float:
        p = dyn.at(y[0])
        if p is None:
            return -1.0
        return math.log(DEAD_POINT_SENSITIVITY) - math.log(max(p.sensitivity, 1e-300))

    dead.terminal = True  # type: ignore[attr-defined]
    events = [dead]
    if dyn.friction.any_coulomb:
        def stopped(t: float, y: Any) -> float:
            return float(y[1])

        stopped.terminal = True  # type: ignore[attr-defined]
        events.append(stopped)
    t_eval = np.linspace(start, end, samples)
    try:
        rhs(start, np.array([theta0, omega0, 0.0, 0.0, 0.0]))
    except _TooLong as exc:
        raise InputError(f"drive: {exc}") from None
    with np.errstate(all="ignore"):
        try:
            sol = solve_ivp(rhs, (start, end), [theta0, omega0, 0.0, 0.0, 0.0], method="DOP853",
                            t_eval=t_eval, rtol=rtol, atol=[atol, atol, atol, atol, atol],
                            events=events, dense_output=True)
        except _TooLong as exc:
            # the rows up to the last time the equation could be evaluated, by integrating
            # again to it (with a budget of its own)
            stop = last_t[0]
            if not stop > start:
                raise InputError(f"drive: {exc}") from None
            calls[0] = -MAX_EVALUATIONS
            sol = solve_ivp(rhs, (start, stop), [theta0, omega0, 0.0, 0.0, 0.0], method="DOP853",
                            t_eval=np.append(t_eval[t_eval < stop], stop), rtol=rtol, atol=[atol] * 5,
                            dense_output=True)
            return _outputs(dyn, drive, sol, sol.t, sol.y, "integration_failed", stop, str(exc))
    event, event_time, message = None, None, ""
    t_out, y_out = sol.t, sol.y
    if sol.status == 1:
        which = 0 if len(sol.t_events[0]) else 1
        event_time = float(sol.t_events[which][0])
        # the event's state integrated to it from its step's start (the dense output's
        # interpolant is less accurate than a step, and the motion is fastest there)
        ts = sol.sol.ts
        before = float(ts[-2]) if ts[-1] >= event_time else float(ts[-1])
        with np.errstate(all="ignore"):
            last = solve_ivp(rhs, (before, event_time), sol.sol(before), method="DOP853", rtol=rtol,
                             atol=[atol] * 5)
        ye = last.y[:, -1] if last.status == 0 else sol.y_events[which][0]
        t_out = np.append(t_out, event_time)
        y_out = np.column_stack([y_out, ye])
        if which == 1:
            event = "stopped"
            message = "the driver came to rest under Coulomb friction (sticking is not modelled)"
        else:
            event = _dead_or_limit(dyn, float(ye[0]), float(ye[1]))
            message = ("the mechanism does not assemble beyond this driver value"
                       if event == "limit_of_assembly"
                       else "the driver can no longer drive the mechanism (J is singular here)")
    elif sol.status != 0:
        event, message = "integration_failed", sol.message
        ts = getattr(sol.sol, "ts", None) if sol.sol is not None else None
        event_time = float(ts[-1]) if ts is not None and len(ts) else last_t[0]
        if ts is not None and len(ts) and event_time > float(t_out[-1]):  # the row where it stopped
            t_out = np.append(t_out, event_time)
            y_out = np.column_stack([y_out, sol.sol(event_time)])
    return _outputs(dyn, drive, sol, t_out, y_out, event, event_time, message)


def _at_rest(rate: float) -> float:
    """A simulated rate as the kinetostatic solver takes it: below arguments.MIN_RATE (a
    driver stopped by friction, or reversing at an output time) it is rest, 0; the solver
    refuses such a size as input from a person, where it would be a typo."""
    from ..arguments import MIN_RATE

    return 0.0 if abs(rate) < MIN_RATE else rate


MAX_EVALUATIONS = 200_000
"""Evaluations of the equation of motion one simulation may take (about 30 s here; a 2-s
run of the crank-rocker from rest takes 19,454): a run whose steps collapse ends as a named
event, not after hours."""


class _TooLong(Exception):
    pass


def _dead_or_limit(dyn: Dynamics, theta: float, omega: float) -> str:
    """A dead point where the loops close a little beyond (1e-3 of a radian, or of the
    mechanism's size, along the motion), else a limit of assembly."""
    step = 1e-3 * (dyn.size * dyn.k if dyn.sliding else 1.0)
    beyond = dyn.position(theta + math.copysign(step, omega if omega else 1.0))
    return "dead_point" if beyond is not None else "limit_of_assembly"


def _outputs(dyn: Dynamics, drive: Callable[[float, float, float], float], sol: Any, t: Any, y: Any,
             event: str | None, event_time: float | None, message: str) -> Simulation:
    import numpy as np

    from ..problems.loads import Loads
    from .forces import forces_at

    names = [u.name for u in dyn.mechanism.unknowns]
    n = len(t)
    alpha, tau, kin, pot = (np.zeros(n) for _ in range(4))
    unknowns = {u: np.zeros(n) for u in names}
    forces = []
    worst = size = 0.0
    base = dyn.loads
    dyn.restart()
    for i in range(n):
        theta, omega = float(y[0, i]), float(y[1, i])
        p = dyn.at(theta)
        if p is None:
            alpha[i] = tau[i] = kin[i] = pot[i] = math.nan
            forces.append(None)
            continue
        tau[i] = drive(float(t[i]), theta, omega)
        fr = dyn.friction_force(p, omega)
        alpha[i] = (tau[i] + p.loads + p.weight + fr - p.half_slope * omega * omega) / p.inertia
        # the size of the equation's terms, the drive check's scale (the drive may be zero)
        size = max(size, abs(tau[i]) + abs(p.inertia * alpha[i]) + abs(p.half_slope * omega * omega)
                   + abs(p.loads) + abs(p.weight) + abs(fr))
        kin[i] = 0.5 * p.inertia * omega * omega
        pot[i] = p.potential
        for u, v in zip(names, p.q):
            unknowns[u][i] = v
        torques = dict(base.torques)
        for b, tq in dyn.friction_torques(p, omega).items():
            torques[b] = torques.get(b, 0.0) + tq
        loads = Loads(base.forces, torques, base.masses, base.gravity, base.on)
        c = dyn.c
        f = forces_at(dyn.mechanism, p.q, loads, speed=_at_rest(omega / c), accel=_at_rest(alpha[i] / c),
                      driver=theta / c)
        forces.append(f)
        if f.input is not None:
            need = f.input + dyn.flywheel * alpha[i]
            worst = max(worst, abs(need - tau[i]))
    total = kin + pot - y[2] - y[3] - y[4]
    energy = max(float(np.nanmax(np.abs(np.concatenate([kin, pot - pot[0], y[2], y[3], y[4]])))), 1e-300)
    balance = float(np.nanmax(np.abs(total - total[0]))) / energy
    cycle = None if dyn.sliding else _last_cycle(dyn, sol, float(t[-1]))
    unit = "N" if dyn.sliding else "N m"
    tt = np.linspace(float(t[0]), float(t[-1]), 2001)
    dense = sol.sol(tt)
    return Simulation(t, y[0], y[1], alpha, tau, unknowns, kin, pot, y[2], y[3], y[4], balance,
                      tuple(forces), worst / max(size, 1e-300), event, event_time, message, int(sol.nfev),
                      cycle,
                      unit, dyn.sliding, dyn.flywheel, (tt, dense[0], dense[1]))


def _last_cycle(dyn: Dynamics, sol: Any, t_end: float) -> Cycle | None:
    """The last full turn of the driver before ``t_end`` (from the dense output), or None
    where it has not turned a full turn or has reversed within it; steady where the turn
    before it had the same mean speed within STEADY_RTOL."""
    import numpy as np
    from scipy.optimize import brentq

    ts = np.linspace(sol.t[0], t_end, 8001)
    th = sol.sol(ts)[0]
    th_end = float(th[-1])
    turn = math.copysign(2.0 * math.pi, th_end - th[0])

    def crossing(target: float) -> float | None:
        cross = np.nonzero(np.sign(th[:-1] - target) != np.sign(th[1:] - target))[0]
        if not len(cross):
            return None
        i = int(cross[-1])
        return float(brentq(lambda s: float(sol.sol(s)[0]) - target, ts[i], ts[i + 1], xtol=1e-14))

    if not abs(th_end - th[0]) >= 2.0 * math.pi:
        return None
    t0 = crossing(th_end - turn)
    if t0 is None:
        return None
    w = sol.sol(np.linspace(t0, t_end, 2001))[1]
    if not (np.all(w > 0) or np.all(w < 0)):
        return None
    # the kinetic energy at 401 of those times, followed back from the last output time
    # (where the positions are)
    y = sol.sol(np.linspace(t0, t_end, 401))
    inertia = np.array([dyn.at(float(v)).inertia for v in y[0][::-1]])[::-1]  # type: ignore[union-attr]
    ke = 0.5 * inertia * y[1] * y[1]
    mean = 2.0 * math.pi / (t_end - t0)
    before = crossing(th_end - 2.0 * turn) if abs(th_end - th[0]) >= 4.0 * math.pi else None
    steady = bool(before is not None and abs(2.0 * math.pi / (t0 - before) - mean) <= STEADY_RTOL * mean)
    return Cycle(float(t0), t_end, float(np.max(np.abs(w))), float(np.min(np.abs(w))), mean,
                 float(ke.max() - ke.min()), float(inertia.mean()), steady)
