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
from typing import Any

from ..errors import InputError
from ..problems.loads import Loads
from ..records import frozen
from .bodies import Frame, checked_loads, metre
from .load_matrix import ForceArrays, solve_loads

EPS = sys.float_info.epsilon
FORCE_RTOL = 1e-6
"""Forces whose error bound (condition number x rounding, doubled) exceeds this relative to
their size are flagged ill_conditioned; a singular matrix (a toggle) leaves them undefined."""
TOGGLE_COND = 1e3
"""A force matrix this ill-conditioned is near a toggle: the forces are amplified so that a
0.1% change in the geometry can change them by 100%. Such forces are flagged near_toggle,
with the condition number."""


@frozen
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


@frozen
class SliderForce:
    slider: str
    on: str
    """The body whose line it slides on."""
    normal: float
    """N, along the line's left normal, on the slider."""
    couple: float
    """N m, on the slider."""


@frozen
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
