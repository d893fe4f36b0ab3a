"""Loads: the input torque (or force) and every joint's force, by the matrix method, at one
position; the input checked by virtual power.

Each moving link of a joints-form mechanism is a rigid body with three equilibrium
equations (forces in x and y, the moment about the origin), d'Alembert's inertia force
-m a_G at its centre of mass and couple -I alpha included where masses are given. The
unknowns are the pins' reactions (a pin shared by k bodies carries k - 1 forces, each on
one body from the pin's owner: the ground where the pin is fixed, else the first link
listed), each slider's normal force and couple, and the driver's torque (or force along
its line, for a sliding driver). Mobility 1 makes the system square: 3 equations per link,
2 unknowns per lower pair and the driver's one.

Units inside are SI (m, N, kg, s): lengths from the file's unit, velocities and
accelerations from the kinematics (kinematics.rates) in that unit, converted.

The independent check: the input found must equal the virtual-power answer,
(sum over links of m a_G . v_G + I alpha omega - sum of the loads' F . v + M omega) /
(driver speed), with the velocities of a unit driver speed (kinematics.rates, a separate
computation: no force enters it).
"""

from __future__ import annotations

import math
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from ..errors import InputError
from ..problems.loads import Loads, parse_loads

EPS = sys.float_info.epsilon
FORCE_RTOL = 1e-6
"""Forces whose error bound (condition number x rounding, doubled) exceeds this relative to
their size are flagged ill_conditioned; a singular matrix (a toggle) leaves them undefined."""
TOGGLE_COND = 1e3
"""A force matrix this ill-conditioned is near a toggle: the forces are amplified so that a
0.1% change in the geometry can change them by 100% (every sample, away from its limits,
stays below 500). Such forces are flagged near_toggle, with the condition number."""


@dataclass(frozen=True)
class PinForce:
    joint: str
    on: str
    """The link the force acts on."""
    by: str
    """The body exerting it (the pin's owner: the ground or a link)."""
    fx: float
    fy: float

    @property
    def magnitude(self) -> float:
        return math.hypot(self.fx, self.fy)


@dataclass(frozen=True)
class SliderForce:
    slider: str
    on: str
    """The body whose line it slides on."""
    normal: float
    """N, along the line's left normal, on the slider."""
    couple: float
    """N m, on the slider."""


@dataclass(frozen=True)
class Forces:
    """One position's loads answer (SI units)."""

    input: float | None
    """The driver's torque (N m) or force (N) that holds the motion; None where undefined."""
    input_unit: str
    pins: tuple[PinForce, ...]
    sliders: tuple[SliderForce, ...]
    ground_force: tuple[float, float] | None
    """The force the mechanism puts on the ground (the shaking force), N."""
    ground_moment: float | None
    """Its moment about the origin, N m."""
    virtual_power_input: float | None
    """The independent answer for ``input``."""
    condition: float
    status: str
    """ok; near_toggle (the condition number at least TOGGLE_COND: the forces are large and
    as sensitive to the geometry); ill_conditioned (their error bound beyond FORCE_RTOL: the
    digits printed are the bound's); or undefined (at a toggle: no number)."""
    bound: float | None = None
    """An error bound on every force (relative to the largest), where defined."""
    mechanical_advantage: float | None = None
    """|output load torque / input torque| for a single torque load, else None."""
    applied: tuple[float, float, float] | None = None
    """The known loads' total (external, gravity and inertia): force x, y (N) and moment
    about the origin (N m). In equilibrium the ground carries exactly this."""

    @property
    def max_pin_force(self) -> float | None:
        if self.status == "undefined" or not self.pins:
            return None
        return max(p.magnitude for p in self.pins)


def metre(length_unit: str) -> float:
    """Metres per unit of ``length_unit``."""
    from ..problems.loops import LENGTH_UNITS

    return LENGTH_UNITS[length_unit] / 10_000


def command_loads(mechanism: Any, load: Sequence[str], torque: Sequence[str], gravity: str | None) -> Loads:
    """The file's loads with the command line's added or overriding: ``--load P=FX,FY``
    (N), ``--torque LINK=T`` (N m), ``--gravity G`` (m/s^2 in -y) or ``GX,GY``."""
    from ..numbers import parse_number

    base: Loads = mechanism.extra.get("loads") or Loads()
    spec: dict[str, Any] = {}
    for option, items in (("--load", load), ("--torque", torque)):
        for item in items:
            name, eq, value = item.partition("=")
            name = name.strip()
            if not eq or not name:
                raise InputError(f"{option} {item!r}: write NAME=" + ("FX,FY" if option == "--load" else "T"))
            if option == "--load":
                parts = value.split(",")
                if len(parts) != 2:
                    raise InputError(f"{option} {item!r}: the force is FX,FY in N")
                spec[name] = {"force": [parse_number(f"{option} {name}", v) for v in parts]}
            else:
                spec[name] = {"torque": parse_number(f"{option} {name}", value)}
    g: tuple[float, float] | None = None
    if gravity is not None:
        parts = gravity.split(",")
        if len(parts) == 1:
            g = (0.0, -abs(parse_number("--gravity", parts[0])))
        elif len(parts) == 2:
            g = (parse_number("--gravity", parts[0]), parse_number("--gravity", parts[1]))
        else:
            raise InputError(f"--gravity {gravity!r}: give G (m/s^2, in -y) or GX,GY")
        if not all(math.isfinite(v) and abs(v) <= 1e6 for v in g):
            raise InputError(f"--gravity {gravity!r}: must be finite, within 1e6 m/s^2")
    drawing = mechanism.extra.get("drawing")
    if (spec or g is not None) and drawing is None:
        Frame.of(mechanism)  # says why: loads need the joints form
    extra = parse_loads({"loads": spec}, drawing, "the command line") if spec else Loads()
    return base.merged(Loads(extra.forces, extra.torques, {}, g))


# --- one position ------------------------------------------------------------------------------


@dataclass(frozen=True)
class Frame:
    """The drawing's bodies as the matrix method needs them."""

    drawing: Any
    driver_link: str | None
    driver_slider: str | None
    length_unit: str

    @classmethod
    def of(cls, mechanism: Any) -> Frame:
        drawing = mechanism.extra.get("drawing")
        if drawing is None:
            raise InputError(
                f"{mechanism.source}: loads need links as bodies: give the mechanism in the "
                "joints form (linkage convert --form joints FILE writes it)"
            )
        doc = mechanism.extra.get("drawing_driver", {})
        return cls(drawing, doc.get("link"), doc.get("slider"), mechanism.length_unit)


def _body_motion(
    frame: Frame,
    pos: Mapping[str, tuple[float, float]],
    vel: Mapping[str, tuple[float, float]],
    acc: Mapping[str, tuple[float, float]],
) -> dict[str, tuple[float, float, float]]:
    """Each body's (rotation since the drawing, omega, alpha): from two of its joints, a
    one-joint block from the body its line is on; the ground's all zero."""
    d = frame.drawing
    out: dict[str, tuple[float, float, float]] = {"ground": (0.0, 0.0, 0.0)}
    pending = []
    for body, joints in d.bodies.items():
        if body == "ground":
            continue
        pair = _two_apart(d, joints)
        if pair is None:
            pending.append(body)
            continue
        j0, j1 = pair
        rx, ry = pos[j1][0] - pos[j0][0], pos[j1][1] - pos[j0][1]
        r2 = rx * rx + ry * ry
        dvx, dvy = vel[j1][0] - vel[j0][0], vel[j1][1] - vel[j0][1]
        dax, day = acc[j1][0] - acc[j0][0], acc[j1][1] - acc[j0][1]
        drawn = math.atan2(d.xy[j1][1] - d.xy[j0][1], d.xy[j1][0] - d.xy[j0][0])
        out[body] = (math.atan2(ry, rx) - drawn, (rx * dvy - ry * dvx) / r2, (rx * day - ry * dax) / r2)
    for body in pending:
        slide = d.sliders.get(body)
        out[body] = out.get(slide.on, (0.0, 0.0, 0.0)) if slide is not None else (0.0, 0.0, 0.0)
    return out


def _two_apart(d: Any, joints: Sequence[str]) -> tuple[str, str] | None:
    for i, a in enumerate(joints):
        for b in joints[i + 1 :]:
            if d.xy[a] != d.xy[b]:
                return a, b
    return None


def _rotate(v: tuple[float, float], t: float) -> tuple[float, float]:
    c, s = math.cos(t), math.sin(t)
    return c * v[0] - s * v[1], s * v[0] + c * v[1]


def _cross(r: tuple[float, float], f: tuple[float, float]) -> float:
    return r[0] * f[1] - r[1] * f[0]


def forces_at(
    mechanism: Any,
    q: Sequence[float],
    loads: Loads | None = None,
    *,
    speed: float = 0.0,
    accel: float = 0.0,
    driver: float | None = None,
) -> Forces:
    """The loads answer at one position ``q`` (internal units, as a sweep's solution) with
    the driver moving at ``speed`` and ``accel`` (rad/s and rad/s^2, or the length unit
    per s and s^2 for a sliding driver)."""
    import numpy as np

    from .rates import rates_at

    frame = Frame.of(mechanism)
    if loads is None:
        loads = mechanism.extra.get("loads") or Loads()
    d = frame.drawing
    k = metre(frame.length_unit)
    actual = rates_at(mechanism, q, speed=speed, accel=accel, driver=driver)
    unit = rates_at(mechanism, q, speed=1.0, accel=0.0, driver=driver)  # virtual velocities
    if actual.status == "undefined" or unit.status == "undefined":
        return _undefined(frame, "the kinematics are undefined here (a toggle or dead centre)")
    pos = {j: (p[0] * k, p[1] * k) for j, p in actual.joints.items()}
    vel = {j: (v[0] * k, v[1] * k) for j, v in actual.joint_velocities.items()}
    acc = {j: (a[0] * k, a[1] * k) for j, a in actual.joint_accelerations.items()}
    vstar = {j: (v[0] * k, v[1] * k) for j, v in unit.joint_velocities.items()}
    zero = {j: (0.0, 0.0) for j in pos}
    motion = _body_motion(frame, pos, vel or zero, acc or zero)
    star = _body_motion(frame, pos, vstar, zero)
    moving = [b for b in d.bodies if b != "ground"]
    row = {b: 3 * i for i, b in enumerate(moving)}
    cols: list[tuple[str, Any]] = []  # what each unknown is
    entries: list[tuple[int, int, float]] = []

    def add_force(
        body: str,
        at: tuple[float, float],
        col_x: int | None,
        col_y: int | None,
        fx: float = 1.0,
        fy: float = 1.0,
        sign: float = 1.0,
    ) -> None:
        if body == "ground":
            return
        r = row[body]
        if col_x is not None:
            entries.extend([(r, col_x, sign * fx), (r + 2, col_x, sign * -at[1] * fx)])
        if col_y is not None:
            entries.extend([(r + 1, col_y, sign * fy), (r + 2, col_y, sign * at[0] * fy)])

    owner: dict[str, str] = {}
    for j in d.xy:
        on = [b for b, js in d.bodies.items() if j in js]
        if len(on) < 2:
            continue
        first = "ground" if "ground" in on else on[0]
        owner[j] = first
        for b in on:
            if b == first:
                continue
            cx, cy = len(cols), len(cols) + 1
            cols += [("pin", (j, b, first)), ("pin_y", None)]
            add_force(b, pos[j], cx, cy)
            add_force(first, pos[j], cx, cy, sign=-1.0)
    line_dirs: dict[str, tuple[float, float]] = {}
    for s, slide in d.sliders.items():
        at = pos[d.bodies[s][0]]
        t = math.radians(slide.angle_deg) + motion[slide.on][0]
        u = (math.cos(t), math.sin(t))
        n = (-u[1], u[0])
        line_dirs[s] = u
        cn, cm = len(cols), len(cols) + 1
        cols += [("slider", (s, slide.on)), ("slider_m", None)]
        for body, sign in ((s, 1.0), (slide.on, -1.0)):
            if body == "ground":
                continue
            r = row[body]
            entries.extend(
                [
                    (r, cn, sign * n[0]),
                    (r + 1, cn, sign * n[1]),
                    (r + 2, cn, sign * _cross(at, n)),
                    (r + 2, cm, sign),
                ]
            )
    ci = len(cols)
    cols.append(("input", None))
    if frame.driver_slider is not None:
        s = frame.driver_slider
        at, u = pos[d.bodies[s][0]], line_dirs[s]
        on = d.sliders[s].on
        for body, sign in ((s, 1.0), (on, -1.0)):
            if body != "ground":
                r = row[body]
                entries.extend(
                    [(r, ci, sign * u[0]), (r + 1, ci, sign * u[1]), (r + 2, ci, sign * _cross(at, u))]
                )
        input_unit = "N"
    else:
        entries.append((row[frame.driver_link] + 2, ci, 1.0))
        input_unit = "N m"
    n_eq, n_un = 3 * len(moving), len(cols)
    if n_eq != n_un:
        raise InputError(
            f"{mechanism.source}: {n_eq} equilibrium equations but {n_un} unknown forces: "
            "the matrix method needs a mobility-1 mechanism of pins and sliders"
        )
    a = np.zeros((n_eq, n_un))
    for r, c, v in entries:
        a[r, c] += v
    # the right-hand side: minus the known loads (external and inertia) on each body
    rhs = np.zeros(n_eq)
    loads_power = 0.0  # their virtual power, for the check
    external = (0.0, 0.0, 0.0)  # the known loads' total force and moment, for global equilibrium

    def known(
        body: str,
        at: tuple[float, float],
        f: tuple[float, float],
        moment: float,
        vstar_at: tuple[float, float],
    ) -> None:
        nonlocal loads_power, external
        loads_power += f[0] * vstar_at[0] + f[1] * vstar_at[1] + moment * star[body][1]
        external = (external[0] + f[0], external[1] + f[1], external[2] + _cross(at, f) + moment)
        if body == "ground":
            return
        r = row[body]
        rhs[r] -= f[0]
        rhs[r + 1] -= f[1]
        rhs[r + 2] -= _cross(at, f) + moment

    for j, f in loads.forces.items():
        body = next((b for b in moving if j in d.bodies[b]), "ground")
        known(body, pos[j], f, 0.0, vstar[j])
    for b, t in loads.torques.items():
        known(b, (0.0, 0.0), (0.0, 0.0), t, (0.0, 0.0))
    g = loads.gravity
    for b, mass in loads.masses.items():
        j0 = d.center(b) if b in d.bodies else d.bodies[b][0]
        rot, w, al = motion[b]
        rel = _rotate(((mass.cg[0] - d.xy[j0][0]) * k, (mass.cg[1] - d.xy[j0][1]) * k), rot)
        cg = (pos[j0][0] + rel[0], pos[j0][1] + rel[1])
        a0 = acc.get(j0, (0.0, 0.0)) if acc else (0.0, 0.0)
        ag = (a0[0] - al * rel[1] - w * w * rel[0], a0[1] + al * rel[0] - w * w * rel[1])
        ws = star[b][1]
        v0 = vstar[j0]
        vg = (v0[0] - ws * rel[1], v0[1] + ws * rel[0])
        f_in = (-mass.mass * ag[0], -mass.mass * ag[1])
        known(b, cg, f_in, -mass.inertia * al, vg)
        if g is not None:
            known(b, cg, (mass.mass * g[0], mass.mass * g[1]), 0.0, vg)
    cond = float(np.linalg.cond(a))
    if not math.isfinite(cond) or cond * EPS >= 0.5:
        return _undefined(frame, "the force matrix is singular here (a toggle)", cond)
    x = np.linalg.solve(a, rhs)
    bound = 2.0 * cond * EPS * 4.0
    # the unit driver speed's own size: rad/s, or the length unit per second in m/s
    unit_speed = 1.0 if frame.driver_slider is None else k
    vp = -loads_power / unit_speed
    pins, sliders = [], []
    gx = gy = gm = 0.0
    for i, (kind, what) in enumerate(cols):
        if kind == "pin":
            j, on, by = what
            fx, fy = float(x[i]), float(x[i + 1])
            pins.append(PinForce(j, on, by, fx, fy))
            if by == "ground":
                gx, gy, gm = gx - fx, gy - fy, gm - _cross(pos[j], (fx, fy))
        elif kind == "slider":
            s, on = what
            nn, mm = float(x[i]), float(x[i + 1])
            sliders.append(SliderForce(s, on, nn, mm))
            if on == "ground":
                u = line_dirs[s]
                f = (-u[1] * nn, u[0] * nn)
                at = pos[d.bodies[s][0]]
                gx, gy, gm = gx - f[0], gy - f[1], gm - _cross(at, f) - mm
    inp = float(x[ci])
    if frame.driver_slider is None:
        gm -= inp
    else:
        s = frame.driver_slider
        if d.sliders[s].on == "ground":
            u = line_dirs[s]
            at = pos[d.bodies[s][0]]
            gx, gy, gm = gx - u[0] * inp, gy - u[1] * inp, gm - _cross(at, (u[0] * inp, u[1] * inp))
    # the kinematics' own uncertainty near a toggle (the rates' bounds, relative to the
    # fastest joint) carries into the forces as into the velocities they balance
    vmax = max((math.hypot(*v) for v in unit.joint_velocities.values()), default=0.0)
    if vmax > 0.0 and unit.joint_velocity_bounds:
        bound = max(bound, max(unit.joint_velocity_bounds.values()) / vmax)
    if bound > FORCE_RTOL or actual.status != "ok" or unit.status != "ok":
        status = "ill_conditioned"
    elif cond >= TOGGLE_COND:
        status = "near_toggle"
    else:
        status = "ok"
    ma = None
    if len(loads.torques) == 1 and not loads.forces and not loads.masses and inp != 0.0:
        ma = abs(next(iter(loads.torques.values())) / inp)
    return Forces(inp, input_unit, tuple(pins), tuple(sliders), (gx, gy), gm, vp, cond, status, bound, ma,
                  external)


def _undefined(frame: Frame, why: str, cond: float = math.inf) -> Forces:
    return Forces(None, "N" if frame.driver_slider else "N m", (), (), None, None, None, cond, "undefined")
