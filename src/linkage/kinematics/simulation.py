"""A simulation in time (``linkage simulate``, docs/simulate.md) of the equation of motion
that :mod:`.dynamics` evaluates:

    I(theta) theta'' + (1/2) I'(theta) theta'^2 = Q(t, theta, theta'),

integrated by scipy's solve_ivp (DOP853); the work of the drive, of friction and of the
loads is integrated beside it, so kinetic + potential - work stays constant (the printed
energy balance). Each output time's pin forces come from the kinetostatic matrix method
(kinematics.forces) at the simulated speed and acceleration, and its input must equal the
simulated drive: the second printed check.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

from ..errors import InputError
from ..problems.loads import MAX_LOAD, Loads
from ..records import frozen
from ..units import radians
from .dynamics import DEAD_POINT_SENSITIVITY, MAX_WALK_STEPS, Drive, Dynamics, Friction

STEADY_RTOL = 0.01
"""The last turn is a steady-state cycle where the turn before's mean speed is within this
of its own."""

EVENTS = ("dead_point", "limit_of_assembly", "stopped", "integration_failed")
"""The named events that end a simulation short of its time span (exit 1): a dead point
(the mechanism still assembles beyond it), a limit of assembly (it does not), the driver
at rest under Coulomb friction (sticking is not modelled), the integrator's own failure."""


@frozen
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
    beyond_rates: int = 0
    """Output times whose forces are undefined (None) because the simulated speed or
    acceleration is beyond the kinetostatic solver's range (:func:`linkage.arguments.rate_in_range`:
    a drive with a pole, a drive of 1e300 N m)."""


@frozen
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


def _checked_time(time: Any, samples: int) -> tuple[float, float]:
    """(start, end) s, finite, end > start, and ``samples`` output times between them that
    double precision resolves (:func:`linkage.rules.grid_resolved`, the driver grids' rule:
    at t = 1e15 s times are 0.125 s apart, and a span of 0.1 s there has no time in it for
    the integrator to step to)."""
    from ..arguments import describe, finite_real
    from ..rules import grid_resolved

    if not isinstance(time, (tuple, list)) or len(time) != 2:
        raise InputError(f"time: give (start, end) in s, got {describe(time)}")
    a, b = (finite_real(v) for v in time)
    if a is None or b is None or not b > a:
        raise InputError(f"time: give finite (start, end) in s with end > start, got {describe(time)}")
    a, b = float(a), float(b)
    resolved, ulp = grid_resolved(a, b, (b - a) / (samples - 1))
    if not resolved:
        raise InputError(f"time: {a!r} to {b!r} s in {samples} output times is finer than double precision "
                         f"resolves there (times {ulp:.3g} s apart): start nearer 0 or span longer")
    return a, b


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
    from ..problems.loops import ANGLE_UNITS
    from .bodies import Frame, checked_loads
    from .loading import mechanism_of

    mechanism = mechanism_of("mechanism", mechanism)
    if mechanism.extra.get("drawing") is None:  # Frame.of's refusal speaks of loads, which need not be given
        raise InputError(f"{mechanism.source}: the dynamics need links as bodies with masses: give the "
                         "mechanism in the joints form (linkage convert --form joints FILE writes it) "
                         "with a [mass] table")
    frame = Frame.of(mechanism)
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
    start, end = _checked_time(time, samples)
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
    return [radians(p.solution[u.name]) if u.kind == "angle" else p.solution[u.name]
            for u in mechanism.unknowns]


class Equation:
    """The equation of motion as solve_ivp calls it (:meth:`rhs`: theta, omega and the three
    works' rates), with its evaluation budget: at most MAX_EVALUATIONS, and a span whose
    first PILOT_EVALUATIONS project more than that is refused (:class:`SpanTooLong`)."""

    def __init__(self, dyn: Dynamics, drive: Callable[[float, float, float], float], start: float,
                 end: float) -> None:
        self.dyn, self.drive, self.start, self.end = dyn, drive, start, end
        self.calls = 0
        self.last_t = start

    def rhs(self, t: float, y: Any) -> Any:
        import numpy as np

        self.calls += 1
        if self.calls > MAX_EVALUATIONS:
            raise _TooLong(f"more than {MAX_EVALUATIONS:,} evaluations of the equation of motion "
                           f"(at t = {t:.6g} s): shorten --time")
        if self.calls == PILOT_EVALUATIONS and t > self.start:
            projected = self.calls * (self.end - self.start) / (t - self.start)
            if projected > SPAN_FACTOR * MAX_EVALUATIONS:
                raise SpanTooLong(
                    f"time: {self.start:g} to {self.end:g} s needs about {projected:.2g} evaluations of the "
                    f"equation of motion at the rate of its first {t - self.start:.3g} s, more than "
                    f"{MAX_EVALUATIONS:,}: shorten --time, or lower what makes the motion that fast or "
                    "stiff (--omega0, the drive, friction, loads)")
        theta, omega = float(y[0]), float(y[1])
        dyn = self.dyn
        p = dyn.at(theta, MAX_WALK_STEPS)
        if p is None or not p.inertia > 0.0:
            return np.full(5, np.nan)  # not assembled (or out of a step's reach): refused and shortened
        try:
            tau = float(self.drive(t, theta, omega))
        except (ArithmeticError, ValueError) as exc:
            raise _TooLong(f"the drive cannot be evaluated at t = {t:.6g} s, theta = {theta:.6g} rad, "
                           f"omega = {omega:.6g} rad/s ({exc})") from None
        if not abs(tau) <= MAX_LOAD:  # a load's bound (problems.loads): beyond it the motion overflows
            raise _TooLong(f"the drive is {tau:g} at t = {t:.6g} s, theta = {theta:.6g} rad, omega = "
                           f"{omega:.6g} rad/s: beyond {MAX_LOAD:g} (N m or N), a load's bound")
        fr = dyn.friction_force(p, omega)
        q = tau + p.loads + p.weight + fr
        with np.errstate(all="ignore"):
            alpha = (q - p.half_slope * omega * omega) / p.inertia
        if not math.isfinite(alpha):  # a trial step beyond the doubles: refused and shortened
            return np.full(5, np.nan)
        self.last_t = t
        return np.array([omega, alpha, tau * omega, fr * omega, p.loads * omega])

    def events(self) -> list[Any]:
        """The terminal events: a dead point (the sensitivity reaching DEAD_POINT_SENSITIVITY),
        and with Coulomb friction the driver at rest."""
        dyn = self.dyn

        def dead(t: float, y: Any) -> float:
            p = dyn.at(y[0])
            if p is None:
                return -1.0
            return math.log(DEAD_POINT_SENSITIVITY) - math.log(max(p.sensitivity, 1e-300))

        dead.terminal = True  # type: ignore[attr-defined]
        out: list[Any] = [dead]
        if dyn.friction.any_coulomb:
            def stopped(t: float, y: Any) -> float:
                return float(y[1])

            stopped.terminal = True  # type: ignore[attr-defined]
            out.append(stopped)
        return out


def integrate(dyn: Dynamics, drive: Callable[[float, float, float], float], theta0: float, omega0: float,
              start: float, end: float, samples: int, rtol: float, atol: float) -> Simulation:
    """Integrate the equation of motion (DOP853) with its events, then every output time's
    energies, forces and checks."""
    import numpy as np
    from scipy.integrate import solve_ivp

    p0 = dyn.at(theta0)
    if p0 is None:
        raise InputError("theta0: the mechanism is not assembled there (or is at a limit of its assembly)")
    if not p0.sensitivity < DEAD_POINT_SENSITIVITY:
        raise InputError(f"theta0: at or next to a dead point or limit: an unknown moves "
                         f"{p0.sensitivity:.3g} times as fast as the driver there (a run starts below "
                         f"{DEAD_POINT_SENSITIVITY:g})")
    if not p0.inertia > 0.0:
        raise InputError("the mechanism has no inertia to move: give its links a mass or an inertia in "
                         "[mass], or a flywheel (--flywheel)")
    eq = Equation(dyn, drive, start, end)
    y0 = [theta0, omega0, 0.0, 0.0, 0.0]
    t_eval = np.linspace(start, end, samples)
    try:
        first = eq.rhs(start, np.array(y0))
    except _TooLong as exc:
        raise InputError(f"drive: {exc}") from None
    if not np.isfinite(first[1]):  # the start is assembled (p0): its theta'' overflowed
        tau = drive(start, theta0, omega0)
        raise InputError(f"the acceleration overflows at the start, t = {start:g} s (drive {tau:g}, speed "
                         f"{omega0:g}, inertia {p0.inertia:g}): no step can follow it")
    with np.errstate(all="ignore"):
        try:
            sol = solve_ivp(eq.rhs, (start, end), y0, method="DOP853", t_eval=t_eval, rtol=rtol,
                            atol=[atol] * 5, events=eq.events(), dense_output=True)
        except SpanTooLong as exc:
            raise InputError(str(exc)) from None
        except _TooLong as exc:
            # the rows up to the last time the equation could be evaluated, by integrating
            # again to it (with a budget of its own)
            stop = eq.last_t
            if not stop > start:
                raise InputError(f"drive: {exc}") from None
            eq.calls = -MAX_EVALUATIONS
            dyn.restart()  # followed from the start again, not from the last trial position
            sol = solve_ivp(eq.rhs, (start, stop), y0, method="DOP853",
                            t_eval=np.append(t_eval[t_eval < stop], stop), rtol=rtol, atol=[atol] * 5,
                            dense_output=True)
            return _outputs(dyn, drive, sol, sol.t, sol.y, "integration_failed", stop, str(exc))
    if sol.status == 1:
        return _outputs(dyn, drive, sol, *_at_event(dyn, eq, sol, rtol, atol))
    event, event_time, message = None, None, ""
    t_out, y_out = sol.t, sol.y
    if sol.status != 0 and not len(t_out):
        # no step from the start (a drive or a span too large for any step: the rows are
        # the start's alone, the run integration_failed there)
        return _outputs(dyn, drive, sol, np.array([start]), np.array(y0, dtype=float)[:, None],
                        "integration_failed", start, sol.message)
    if sol.status != 0:
        event, message = "integration_failed", sol.message
        ts = getattr(sol.sol, "ts", None) if sol.sol is not None else None
        event_time = float(ts[-1]) if ts is not None and len(ts) else eq.last_t
        if ts is not None and len(ts) and event_time > float(t_out[-1]):  # the row where it stopped
            t_out = np.append(t_out, event_time)
            y_out = np.column_stack([y_out, sol.sol(event_time)])
    return _outputs(dyn, drive, sol, t_out, y_out, event, event_time, message)


def _at_event(dyn: Dynamics, eq: Equation, sol: Any, rtol: float, atol: float
              ) -> tuple[Any, Any, str, float, str]:
    """(times, states, event, its time, message) of a run ended by a terminal event: the
    output rows, then the event's state integrated to it from its step's start (the dense
    output's interpolant is less accurate than a step, and the motion is fastest there)."""
    import numpy as np
    from scipy.integrate import solve_ivp

    which = 0 if len(sol.t_events[0]) else 1
    event_time = float(sol.t_events[which][0])
    ts = sol.sol.ts
    before = float(ts[-2]) if ts[-1] >= event_time else float(ts[-1])
    with np.errstate(all="ignore"):
        last = solve_ivp(eq.rhs, (before, event_time), sol.sol(before), method="DOP853", rtol=rtol,
                         atol=[atol] * 5)
    ye = last.y[:, -1] if last.status == 0 else sol.y_events[which][0]
    keep = sol.t < event_time  # an output time at the event itself is the event's row, once
    t_out = np.append(sol.t[keep], event_time)
    y_out = np.column_stack([sol.y[:, keep], ye])
    if which == 1:
        return t_out, y_out, "stopped", event_time, \
            "the driver came to rest under Coulomb friction (sticking is not modelled)"
    event = _dead_or_limit(dyn, float(ye[0]), float(ye[1]))
    message = ("the mechanism does not assemble beyond this driver value" if event == "limit_of_assembly"
               else "the driver can no longer drive the mechanism (J is singular here)")
    return t_out, y_out, event, event_time, message


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


PILOT_EVALUATIONS = 2_000
"""Evaluations after which a run projects its whole span's (at the rate so far)."""

SPAN_FACTOR = 4.0
"""A span projected to need more than this many times MAX_EVALUATIONS is refused there
(exit 2, one line), not integrated for minutes to fail at the budget: --time 0:1e6 from
10 rad/s needs some 1e10."""


class _TooLong(Exception):
    pass


class SpanTooLong(Exception):
    """The time span needs far more evaluations than a simulation may take (:class:`Equation`)."""


def _dead_or_limit(dyn: Dynamics, theta: float, omega: float) -> str:
    """A dead point where the loops close a little beyond (1e-3 of a radian, or of the
    mechanism's size, along the motion), else a limit of assembly."""
    step = 1e-3 * (dyn.size * dyn.k if dyn.sliding else 1.0)
    beyond = dyn.position(theta + math.copysign(step, omega if omega else 1.0))
    return "dead_point" if beyond is not None else "limit_of_assembly"


def _outputs(dyn: Dynamics, drive: Callable[[float, float, float], float], sol: Any, t: Any, y: Any,
             event: str | None, event_time: float | None, message: str) -> Simulation:
    import numpy as np

    from ..arguments import rate_in_range
    from ..problems.loads import Loads
    from .forces import forces_at

    names = [u.name for u in dyn.mechanism.unknowns]
    n = len(t)
    alpha, tau, kin, pot = (np.zeros(n) for _ in range(4))
    unknowns = {u: np.zeros(n) for u in names}
    forces = []
    worst = size = 0.0
    beyond = 0
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
        speed, accel = _at_rest(omega / c), _at_rest(alpha[i] / c)
        if not (rate_in_range(speed) and rate_in_range(accel)):
            beyond += 1  # the kinetostatic solver takes no such rate: no forces here
            forces.append(None)
            continue
        f = forces_at(dyn.mechanism, p.q, loads, speed=speed, accel=accel, driver=theta / c)
        forces.append(f)
        if f.input is not None:
            need = f.input + dyn.flywheel * alpha[i]
            worst = max(worst, abs(need - tau[i]))
    total = kin + pot - y[2] - y[3] - y[4]
    energy = max(float(np.nanmax(np.abs(np.concatenate([kin, pot - pot[0], y[2], y[3], y[4]])))), 1e-300)
    balance = float(np.nanmax(np.abs(total - total[0]))) / energy
    stepped = sol.sol is not None and len(sol.t) > 0  # (not where no step was taken)
    cycle = None if dyn.sliding or not stepped else _last_cycle(dyn, sol, float(t[-1]))
    unit = "N" if dyn.sliding else "N m"
    tt = np.linspace(float(t[0]), float(t[-1]), 2001)
    dense = sol.sol(tt) if stepped else np.repeat(np.asarray(y, dtype=float)[:, :1], len(tt), axis=1)
    return Simulation(t, y[0], y[1], alpha, tau, unknowns, kin, pot, y[2], y[3], y[4], balance,
                      tuple(forces), worst / max(size, 1e-300), event, event_time, message, int(sol.nfev),
                      cycle,
                      unit, dyn.sliding, dyn.flywheel, (tt, dense[0], dense[1]), beyond)


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
