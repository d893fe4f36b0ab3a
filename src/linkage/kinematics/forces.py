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
from ..problems.loads import Loads, load_link
from .bodies import Frame, checked_loads, metre

EPS = sys.float_info.epsilon
FORCE_RTOL = 1e-6
"""Forces whose error bound (condition number x rounding, doubled) exceeds this relative to
their size are flagged ill_conditioned; a singular matrix (a toggle) leaves them undefined."""
TOGGLE_COND = 1e3
"""A force matrix this ill-conditioned is near a toggle: the forces are amplified so that a
0.1% change in the geometry can change them by 100%. Such forces are flagged near_toggle,
with the condition number."""


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
    """Output over input, where it is one number of one kind (:func:`mechanical_advantage`),
    else None."""
    applied: tuple[float, float, float] | None = None
    """The known loads' total (external, gravity and inertia): force x, y (N) and moment
    about the origin (N m). In equilibrium the ground carries exactly this."""

    @property
    def max_pin_force(self) -> float | None:
        if self.status == "undefined" or not self.pins:
            return None
        return max(p.magnitude for p in self.pins)


def _body_motion(frame: Frame, pos: Mapping[str, Any], vel: Mapping[str, Any], acc: Mapping[str, Any]
                 ) -> dict[str, tuple[Any, Any, Any]]:
    """Each body's (rotation since the drawing, omega, alpha), arrays over the positions:
    from two of its joints, a one-joint block from the body its line is on; the ground's
    all zero."""
    import numpy as np

    d = frame.drawing
    zero = np.zeros_like(next(iter(pos.values()))[0])
    out: dict[str, tuple[Any, Any, Any]] = {"ground": (zero, zero, zero)}
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
        out[body] = (np.arctan2(ry, rx) - drawn, (rx * dvy - ry * dvx) / r2, (rx * day - ry * dax) / r2)
    for body in pending:
        slide = d.sliders.get(body)
        out[body] = out.get(slide.on, out["ground"]) if slide is not None else out["ground"]
    return out


def cg_motion(d: Any, body: str, mass: Any, k: float, pos: Mapping[str, Any], vel: Mapping[str, Any],
              acc: Mapping[str, Any], motion: tuple[Any, Any, Any]) -> tuple[Any, Any, Any]:
    """The one rule for a link's centre of mass (``mass.cg``, drawn in the file's unit, ``k``
    m per unit): its position, velocity and acceleration, each (x, y) in SI, from the
    link's centre joint's (``pos``, ``vel``, ``acc``, m, m/s, m/s^2) and the link's
    (rotation since the drawing, omega, alpha) (:func:`_body_motion`): r_G = r_0 + R rel,
    v_G = v_0 + omega x rel, a_G = a_0 + alpha x rel - omega^2 rel. Floats or arrays."""
    import numpy as np

    j0 = d.center(body)
    rot, w, al = motion
    dx, dy = (mass.cg[0] - d.xy[j0][0]) * k, (mass.cg[1] - d.xy[j0][1]) * k
    c, s = np.cos(rot), np.sin(rot)
    rel = (c * dx - s * dy, s * dx + c * dy)
    cg = (pos[j0][0] + rel[0], pos[j0][1] + rel[1])
    vg = (vel[j0][0] - w * rel[1], vel[j0][1] + w * rel[0])
    ag = (acc[j0][0] - al * rel[1] - w * w * rel[0], acc[j0][1] + al * rel[0] - w * w * rel[1])
    return cg, vg, ag


def body_motion(frame: Frame, pos: Mapping[str, Any], vel: Mapping[str, Any], acc: Mapping[str, Any]
                ) -> dict[str, tuple[Any, Any, Any]]:
    """Each body's (rotation since the drawing, omega, alpha): :func:`_body_motion`, public
    for the dynamics (kinematics.dynamics)."""
    return _body_motion(frame, pos, vel, acc)


def _two_apart(d: Any, joints: Sequence[str]) -> tuple[str, str] | None:
    for i, a in enumerate(joints):
        for b in joints[i + 1:]:
            if d.xy[a] != d.xy[b]:
                return a, b
    return None


def _cross(r: tuple[Any, Any], f: tuple[Any, Any]) -> Any:
    return r[0] * f[1] - r[1] * f[0]


@dataclass(frozen=True)
class ForceArrays:
    """The matrix method over N positions at once (arrays of shape (N,), NaN where the
    force matrix is singular)."""

    input: Any
    input_unit: str
    pins: tuple[tuple[str, str, str, Any, Any], ...]
    """(joint, on, by, fx, fy) per pin force."""
    sliders: tuple[tuple[str, str, Any, Any], ...]
    ground: tuple[Any, Any, Any]
    virtual_power_input: Any
    condition: Any
    applied: tuple[Any, Any, Any]


def pin_pairs(d: Any) -> list[tuple[str, str, str]]:
    """The one rule for what a pin joins: (joint, owner, link) for each link on a joint that
    two or more bodies share, other than its owner (the ground where the pin is fixed,
    else the first body listing it); a pin shared by k bodies is k - 1 pairs."""
    out = []
    for j in d.xy:
        on = [b for b, js in d.bodies.items() if j in js]
        if len(on) < 2:
            continue
        first = "ground" if "ground" in on else on[0]
        out += [(j, first, b) for b in on if b != first]
    return out


def solve_loads(frame: Frame, pos: Mapping[str, tuple[Any, Any]], vel: Mapping[str, tuple[Any, Any]],
                acc: Mapping[str, tuple[Any, Any]], vstar: Mapping[str, tuple[Any, Any]], loads: Loads,
                source: str = "<mechanism>") -> ForceArrays:
    """The one definition of the matrix method: every position's system assembled and solved
    at once. ``pos``, ``vel``, ``acc``: each joint's (x, y) arrays in m, m/s, m/s^2;
    ``vstar`` its velocity at a unit driver speed (m/s per rad/s, or per unit/s), for the
    virtual-power answer."""
    import numpy as np

    d = frame.drawing
    k = metre(frame.length_unit)
    n_pos = len(next(iter(pos.values()))[0])
    motion = _body_motion(frame, pos, vel, acc)
    zeros = {j: (np.zeros(n_pos), np.zeros(n_pos)) for j in pos}
    star = _body_motion(frame, pos, vstar, zeros)
    moving = [b for b in d.bodies if b != "ground"]
    row = {b: 3 * i for i, b in enumerate(moving)}
    cols: list[tuple[str, Any]] = []  # what each unknown is
    entries: list[tuple[int, int, Any]] = []

    def add_force(body: str, at: tuple[Any, Any], cx: int, cy: int, sign: float = 1.0) -> None:
        if body == "ground":
            return
        r = row[body]
        entries.extend([(r, cx, sign), (r + 2, cx, -sign * at[1]),
                        (r + 1, cy, sign), (r + 2, cy, sign * at[0])])

    for j, first, b in pin_pairs(d):
        cx, cy = len(cols), len(cols) + 1
        cols += [("pin", (j, b, first)), ("pin_y", None)]
        add_force(b, pos[j], cx, cy)
        add_force(first, pos[j], cx, cy, sign=-1.0)
    line_dirs: dict[str, tuple[Any, Any]] = {}
    for s, slide in d.sliders.items():
        at = pos[d.bodies[s][0]]
        t = math.radians(slide.angle_deg) + motion[slide.on][0]
        u = (np.cos(t), np.sin(t))
        n = (-u[1], u[0])
        line_dirs[s] = u
        cn, cm = len(cols), len(cols) + 1
        cols += [("slider", (s, slide.on)), ("slider_m", None)]
        for body, sign in ((s, 1.0), (slide.on, -1.0)):
            if body != "ground":
                r = row[body]
                entries.extend([(r, cn, sign * n[0]), (r + 1, cn, sign * n[1]),
                                (r + 2, cn, sign * _cross(at, n)), (r + 2, cm, sign)])
    ci = len(cols)
    cols.append(("input", None))
    if frame.driver_slider is not None:
        s = frame.driver_slider
        at, u = pos[d.bodies[s][0]], line_dirs[s]
        for body, sign in ((s, 1.0), (d.sliders[s].on, -1.0)):
            if body != "ground":
                r = row[body]
                entries.extend([(r, ci, sign * u[0]), (r + 1, ci, sign * u[1]),
                                (r + 2, ci, sign * _cross(at, u))])
        input_unit = "N"
    else:
        entries.append((row[frame.driver_link] + 2, ci, 1.0))
        input_unit = "N m"
    n_eq, n_un = 3 * len(moving), len(cols)
    if n_eq != n_un:
        raise InputError(f"{source}: {n_eq} equilibrium equations but {n_un} unknown forces: the matrix "
                         "method needs a mobility-1 mechanism of pins and sliders")
    a = np.zeros((n_pos, n_eq, n_un))
    for r, c, v in entries:
        a[:, r, c] += v
    # the right-hand side: minus the known loads (external, gravity, inertia) on each body
    rhs = np.zeros((n_pos, n_eq))
    power = np.zeros(n_pos)  # the known loads' virtual power, for the independent answer
    applied = [np.zeros(n_pos), np.zeros(n_pos), np.zeros(n_pos)]

    def known(body: str, at: tuple[Any, Any], f: tuple[Any, Any], moment: Any, v_at: tuple[Any, Any]) -> None:
        nonlocal power
        power = power + f[0] * v_at[0] + f[1] * v_at[1] + moment * star[body][1]
        m_at = _cross(at, f) + moment
        applied[0] += f[0]
        applied[1] += f[1]
        applied[2] += m_at
        if body != "ground":
            r = row[body]
            rhs[:, r] -= f[0]
            rhs[:, r + 1] -= f[1]
            rhs[:, r + 2] -= m_at

    origin = (np.zeros(n_pos), np.zeros(n_pos))
    for j, f in loads.forces.items():
        known(load_link(d, j, loads.on.get(j)), pos[j], f, 0.0, vstar[j])
    for b, t in loads.torques.items():
        known(b, origin, (0.0, 0.0), t, origin)
    g = loads.gravity
    for b, mass in loads.masses.items():
        cg, _, ag = cg_motion(d, b, mass, k, pos, acc, acc, motion[b])
        _, vg, _ = cg_motion(d, b, mass, k, pos, vstar, vstar, star[b])
        al = motion[b][2]
        known(b, cg, (-mass.mass * ag[0], -mass.mass * ag[1]), -mass.inertia * al, vg)
        if g is not None:
            known(b, cg, (mass.mass * g[0], mass.mass * g[1]), 0.0, vg)
    # in the mechanism's own size: moments per metre of it, torques as forces at that arm, so
    # the condition number (the near-toggle test) is the same in mm, in m or in miles
    size = np.broadcast_to(np.asarray(frame.size, dtype=float), (n_pos,))[:, None]
    couples = [i for i, (kind, _) in enumerate(cols)
               if kind == "slider_m" or (kind == "input" and frame.driver_slider is None)]
    a[:, 2::3, :] /= size[:, :, None]
    rhs[:, 2::3] /= size
    a[:, :, couples] *= size[:, :, None]
    cond, inv = condition_np(a)
    good = np.isfinite(cond) & (cond * EPS < 0.5)
    x = np.full((n_pos, n_un), np.nan)
    if good.any():
        x[good] = np.einsum("pij,pj->pi", inv[good], rhs[good])
    x[:, couples] *= size
    # the unit driver speed's own size: rad/s, or the length unit per second in m/s
    vp = -power / (1.0 if frame.driver_slider is None else k)
    pins, sliders = [], []
    gx, gy, gm = np.zeros(n_pos), np.zeros(n_pos), np.zeros(n_pos)
    for i, (kind, what) in enumerate(cols):
        if kind == "pin":
            j, on, by = what
            fx, fy = x[:, i], x[:, i + 1]
            pins.append((j, on, by, fx, fy))
            if by == "ground":
                gx, gy, gm = gx - fx, gy - fy, gm - _cross(pos[j], (fx, fy))
        elif kind == "slider":
            s, on = what
            nn, mm = x[:, i], x[:, i + 1]
            sliders.append((s, on, nn, mm))
            if on == "ground":
                u = line_dirs[s]
                f = (-u[1] * nn, u[0] * nn)
                gx, gy, gm = gx - f[0], gy - f[1], gm - _cross(pos[d.bodies[s][0]], f) - mm
    inp = x[:, ci]
    if frame.driver_slider is None:
        gm = gm - inp
    elif d.sliders[frame.driver_slider].on == "ground":
        s = frame.driver_slider
        u = line_dirs[s]
        f = (u[0] * inp, u[1] * inp)
        gx, gy, gm = gx - f[0], gy - f[1], gm - _cross(pos[d.bodies[s][0]], f)
    return ForceArrays(inp, input_unit, tuple(pins), tuple(sliders), (gx, gy, gm), vp, cond,
                       (applied[0], applied[1], applied[2]))


def condition_np(a: Any) -> tuple[Any, Any]:
    """Each matrix's condition number in the 1-norm, ||A|| ||A^-1|| (inf where A is
    singular), and A^-1 (NaN there): an LU inverse costs a fraction of the SVD that the
    2-norm's needs, and bounds the same error (within a factor of the matrix's size)."""
    import numpy as np

    from .rate_bounds import inverse_np

    inv, usable = inverse_np(a)
    cond = np.full(a.shape[:-2], np.inf)
    with np.errstate(over="ignore", invalid="ignore"):
        cond[usable] = (np.abs(a[usable]).sum(axis=-2).max(axis=-1) *
                        np.abs(inv[usable]).sum(axis=-2).max(axis=-1))
    cond[~np.isfinite(cond)] = np.inf
    return cond, inv


def _arrays(points: Mapping[str, tuple[float, float]], k: float) -> dict[str, tuple[Any, Any]]:
    import numpy as np

    return {j: (np.array([p[0] * k]), np.array([p[1] * k])) for j, p in points.items()}


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
    per s and s^2 for a sliding driver): :func:`solve_loads` for one position, judged."""
    from ..arguments import check_number
    from .rates import rates_at

    if not hasattr(mechanism, "extra") or not hasattr(mechanism, "unknowns"):
        raise InputError("mechanism: give a Mechanism (linkage.load_mechanism), got "
                         f"{type(mechanism).__name__}")
    speed, accel = check_number("speed", speed), check_number("accel", accel)
    frame = Frame.of(mechanism)
    if loads is None:
        loads = mechanism.extra.get("loads") or Loads()
        frame.check_masses(loads)
    else:
        loads = checked_loads(loads, mechanism)
    actual = rates_at(mechanism, q, speed=speed, accel=accel, driver=driver)
    # the virtual velocities: a unit driver speed's
    unit = per_unit_speed(actual, speed) or rates_at(mechanism, q, speed=1.0, accel=0.0, driver=driver)
    return judged(frame, actual, unit, loads, mechanism.source)


def speed_usable(speed: float | None) -> bool:
    """Whether velocities at ``speed`` can be divided by it (:func:`per_unit_speed`)."""
    return speed is not None and 1e-100 < abs(speed) < 1e100


def scaled_to_unit_speed(actual: Any, speed: float) -> Any:
    """``actual`` (rates at ``speed``: one position's Rates or a block's RateBlock) with its
    joint velocities and their bounds divided by the speed: they are linear in it."""
    from dataclasses import replace

    k = 1.0 / speed
    velocities = {j: (v[0] * k, v[1] * k) for j, v in actual.joint_velocities.items()}
    bounds = {j: b * abs(k) for j, b in actual.joint_velocity_bounds.items()}
    return replace(actual, joint_velocities=velocities, joint_velocity_bounds=bounds)


def per_unit_speed(actual: Any, speed: float) -> Any:
    """The velocities of a unit driver speed from those at ``speed``
    (:func:`scaled_to_unit_speed`), or None where there is no speed to divide by (then they
    are computed)."""
    if not speed_usable(speed) or actual.status == "undefined" or not actual.joint_velocities:
        return None
    return scaled_to_unit_speed(actual, speed)


def judged(frame: Frame, actual: Any, unit: Any, loads: Loads, source: str) -> Forces:
    """One position's forces from its rates (kinematics.rates.Rates at the driver's motion and
    at a unit speed), flagged by their bounds."""
    if actual.status == "undefined" or unit.status == "undefined":
        return undefined_forces(frame, "the kinematics are undefined here (a toggle or dead centre)")
    k = metre(frame.length_unit)
    pos = _arrays(actual.joints, k)
    zero = {j: (0.0, 0.0) for j in actual.joints}
    vel = _arrays(actual.joint_velocities or zero, k)
    acc = _arrays(actual.joint_accelerations or zero, k)
    vstar = _arrays(unit.joint_velocities, k)
    fa = solve_loads(frame, pos, vel, acc, vstar, loads, source)
    return position_forces(fa, 0, unit, actual.status, loads)


FORCE_STATUSES = ("ok", "near_toggle", "ill_conditioned", "undefined")
"""A position's forces, by :func:`force_status` (codes: their index here)."""


def matrix_bound(cond: Any) -> Any:
    """The forces' error bound (relative to the largest) from solving the force matrix:
    condition number x rounding, with room for assembling the matrix, doubled."""
    return 2.0 * cond * EPS * 4.0


def kinematic_bound(unit: Any) -> float:
    """The error bound the kinematics carry into the forces (relative): the unit-speed
    rates' largest joint-velocity bound over the fastest joint's speed (near a toggle they
    carry into the forces as into the velocities they balance); 0 where there is none.
    A position's force bound is the larger of this and :func:`matrix_bound`."""
    vmax = max((math.hypot(*v) for v in unit.joint_velocities.values()), default=0.0)
    if vmax > 0.0 and unit.joint_velocity_bounds:
        return max(unit.joint_velocity_bounds.values()) / vmax
    return 0.0


def kinematic_bound_np(unit: Any) -> Any:
    """:func:`kinematic_bound` of each position of a block of unit-speed rates
    (kinematics.rate_blocks.RateBlock)."""
    import numpy as np

    n = len(unit.status)
    speeds = [np.hypot(x, y) for x, y in unit.joint_velocities.values()]
    vmax = np.maximum.reduce(speeds) if speeds else np.zeros(n)
    if not unit.joint_velocity_bounds:
        return np.zeros(n)
    top = np.maximum.reduce(list(unit.joint_velocity_bounds.values()))
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(vmax > 0.0, top / vmax, 0.0)


def force_status(cond: float, bound: float, kinematics_ok: bool) -> str:
    """The one rule judging a position's forces (``bound``: their error bound, relative):
    ill_conditioned where the bound exceeds FORCE_RTOL or the kinematics are flagged,
    near_toggle where the matrix's condition number reaches TOGGLE_COND, else ok. (No
    number at all is ``undefined``, decided before.) :func:`force_status_np` is its twin."""
    if not bound <= FORCE_RTOL or not kinematics_ok:
        return "ill_conditioned"
    if cond >= TOGGLE_COND:
        return "near_toggle"
    return "ok"


def force_status_np(inp: Any, cond: Any, bound: Any, kinematics_ok: Any) -> Any:
    """:func:`force_status` over arrays, as codes into FORCE_STATUSES; ``undefined`` where
    the input is not a number."""
    import numpy as np

    code = np.where(cond >= TOGGLE_COND, 1, 0)
    code = np.where(~(bound <= FORCE_RTOL) | ~kinematics_ok, 2, code)
    return np.where(np.isfinite(inp), code, 3).astype(np.int8)


def force_peaks(status: Any, *columns: Any) -> tuple[list[Any], Any]:
    """The one rule for peaks over positions (arrays of shape (rows, positions), status as
    FORCE_STATUSES codes): per row, for each column the index of its largest absolute
    value (the first, of values equal to rounding) among the positions whose forces are ok
    (-1 where none is), and how many
    positions' forces are flagged (near_toggle, ill_conditioned or undefined; a negative
    code, an unsolved position, is neither). Flagged forces are large or unknown: counted,
    never taken as a peak."""
    import numpy as np

    ok = status == 0
    any_ok = ok.any(axis=1)
    at = []
    for col in columns:
        size = _peak_sizes(ok, col)
        at.append(np.where(any_ok, np.argmax(_near_top(size), axis=1), -1))
    return at, _flagged(status).sum(axis=1)


def _peak_sizes(ok: Any, col: Any) -> Any:
    """What a peak is the largest of: |value| where the forces are ok and there is a
    number, -1 elsewhere (never a peak)."""
    import numpy as np

    with np.errstate(invalid="ignore"):
        return np.where(ok & np.isfinite(col), np.abs(col), -1.0)


def _near_top(size: Any) -> Any:
    """The sizes equal to the largest (along the last axis) within rounding: the peak is
    the first of them (a closed cycle's 0 and 360 deg differ by an ulp, and the peak is at 0)."""
    top = size.max(axis=-1, keepdims=True)
    return size >= top * (1.0 - 8.0 * EPS)


def _flagged(status: Any) -> Any:
    """Positions whose forces are flagged: near_toggle, ill_conditioned or undefined (a
    negative code, an unsolved position, is neither)."""
    return (status > 0) & (status < len(FORCE_STATUSES))


class PeakTracker:
    """:func:`force_peaks` of one sweep fed a chunk of positions at a time, in order: the
    same indices and count as the rule over the whole sweep at once, holding only the
    candidates (for each size within rounding of the largest so far, the first position
    with it: a handful, whatever the sweep's length). A later, larger size drops the
    candidates it leaves behind; one never among them cannot become the peak."""

    def __init__(self, columns: int) -> None:
        import numpy as np

        self.seen = 0
        self.flagged = 0
        self.sizes = [np.empty(0) for _ in range(columns)]
        self.where = [np.empty(0, dtype=np.int64) for _ in range(columns)]

    def add(self, status: Any, *columns: Any) -> None:
        """The next ``len(status)`` positions: their FORCE_STATUSES codes and columns."""
        import numpy as np

        status = np.asarray(status)
        ok = status == 0
        at = self.seen + np.arange(len(status))
        for k, col in enumerate(columns):
            size = _peak_sizes(ok, np.asarray(col, dtype=float))
            usable = size >= 0.0  # ok, with a number (the status rule gives every ok one)
            sizes = np.concatenate([self.sizes[k], size[usable]])
            where = np.concatenate([self.where[k], at[usable]])
            if len(sizes):
                near = _near_top(sizes)
                # the first position of each size (np.unique's first occurrence: in order)
                kept, first = np.unique(sizes[near], return_index=True)
                sizes, where = kept, where[near][first]
            self.sizes[k], self.where[k] = sizes, where
        self.seen += len(status)
        self.flagged += int(_flagged(status).sum())

    def peaks(self) -> tuple[list[int], int]:
        """Per column the index of its peak (-1 where no position is ok), and how many
        positions are flagged: :func:`force_peaks`' answer for the whole sweep."""
        at = []
        for sizes, where in zip(self.sizes, self.where):
            at.append(int(where[_near_top(sizes)].min()) if len(sizes) else -1)
        return at, self.flagged


def mechanical_advantage(loads: Loads, inp: float, input_unit: str) -> float | None:
    """The one rule: |output torque / input torque| for a turning driver with a single torque
    load, |output force| / |input force| for a sliding driver with a single force load (its
    force form); None with masses, with loads of both kinds or of the other kind (a ratio
    with a unit), or where the input is zero."""
    if loads.masses or not inp:
        return None
    if input_unit == "N m" and len(loads.torques) == 1 and not loads.forces:
        return abs(next(iter(loads.torques.values())) / inp)
    if input_unit == "N" and len(loads.forces) == 1 and not loads.torques:
        return math.hypot(*next(iter(loads.forces.values()))) / abs(inp)
    return None


def position_forces(fa: ForceArrays, i: int, unit: Any, kinematics_status: str, loads: Loads) -> Forces:
    """Position ``i`` of :func:`solve_loads`' answer as a :class:`Forces`, flagged: its error
    bound from the condition number and from the kinematics' own bounds (the unit-speed
    rates, relative to the fastest joint: near a toggle they carry into the forces as into
    the velocities they balance)."""
    cond = float(fa.condition[i])
    inp = float(fa.input[i])
    if not math.isfinite(inp):
        return Forces(None, fa.input_unit, (), (), None, None, None, cond, "undefined")
    bound = max(matrix_bound(cond), kinematic_bound(unit))
    status = force_status(cond, bound, kinematics_status == "ok" and unit.status == "ok")
    ma = mechanical_advantage(loads, inp, fa.input_unit)
    pins = tuple(PinForce(j, on, by, float(fx[i]), float(fy[i])) for j, on, by, fx, fy in fa.pins)
    sliders = tuple(SliderForce(s, on, float(nn[i]), float(mm[i])) for s, on, nn, mm in fa.sliders)
    gx, gy, gm = (float(v[i]) for v in fa.ground)
    return Forces(inp, fa.input_unit, pins, sliders, (gx, gy), gm, float(fa.virtual_power_input[i]), cond,
                  status, bound, ma, tuple(float(v[i]) for v in fa.applied))  # type: ignore[arg-type]


def undefined_forces(frame: Frame, why: str, cond: float = math.inf) -> Forces:
    return Forces(None, "N" if frame.driver_slider else "N m", (), (), None, None, None, cond, "undefined")
