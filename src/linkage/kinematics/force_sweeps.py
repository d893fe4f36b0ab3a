"""Loads over many positions: a sweep's (each position's rates with their bounds, then the
one matrix method for all of them) and a scan's (the numpy twins of the rates, then the
same matrix method), judged by the one status rule (kinematics.forces)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from ..problems.loads import Loads
from .bodies import Frame, force_size, metre
from .forces import (
    ForceArrays,
    Forces,
    force_status_np,
    matrix_bound,
    per_unit_speed,
    position_forces,
    solve_loads,
    undefined_forces,
)


@dataclass(frozen=True)
class BatchForces:
    """:func:`batch_forces`' answer: the matrix method's arrays (NaN where unsolved or
    undefined), each position's status (FORCE_STATUSES codes), its largest pin force and
    the size of the ground's force (the shaking force), N."""

    arrays: ForceArrays | None
    status: Any
    input: Any
    pin_max: Any
    shaking: Any
    virtual_power: Any
    """The independent answer for ``input`` at every position."""


def batch_forces(mechanism: Any, q: Sequence[Any], d: Any, loads: Loads, *, speed: float = 0.0,
                 accel: float = 0.0, values: Mapping[str, Any] | None = None) -> BatchForces:
    """The forces at many positions at once (a scan's designs x positions, flat): ``q`` one
    array per unknown and ``d`` the driver (internal units, NaN where unsolved),
    ``values`` parameters replaced by arrays (internal units, one per position). The
    kinematics by the numpy twins (kinematics.rates.solve_rates_np, place_motion_np), the
    forces by the one matrix method (:func:`solve_loads`), judged by
    :func:`force_status_np` with the matrix's bound (no kinematic bounds here: where J is
    singular the forces are undefined)."""
    import numpy as np

    from ..problems.loops import LoopModel
    from .rates import place_motion_np, solve_rates_np

    frame = Frame.of(mechanism)
    d = np.asarray(d, dtype=float)
    n = d.shape[0]
    rows = np.isfinite(d)
    for c in q:
        rows &= np.isfinite(c)
    status = np.full(n, 3, dtype=np.int8)
    inp, pin_max, shaking, vp = (np.full(n, np.nan) for _ in range(4))
    if not rows.any():
        return BatchForces(None, status, inp, pin_max, shaking, vp)
    sub = {k: (v[rows] if isinstance(v, np.ndarray) and v.shape == (n,) else v)
           for k, v in (values or {}).items()}
    model = LoopModel.compile(mechanism, sub)
    qs, ds = [c[rows] for c in q], d[rows]
    qd1, _, ok = solve_rates_np(model, qs, ds, 1.0, 0.0)
    unit = place_motion_np(model, qs, ds, qd1, 1.0, [np.zeros_like(ds)] * model.n, 0.0)
    if speed or accel:
        qd, qdd, ok2 = solve_rates_np(model, qs, ds, speed, accel)
        ok &= ok2
        moving = place_motion_np(model, qs, ds, qd, speed, qdd, accel)
    else:
        moving = unit
    k = metre(frame.length_unit)

    def xy(which: Mapping[str, Any], part: int, scale: float) -> dict[str, tuple[Any, Any]]:
        return {j: (v[part].real * scale, v[part].imag * scale) for j, v in which.items()}

    zero = np.zeros(len(ds))
    pos = xy(unit, 0, k)
    vel = xy(moving, 1, k) if (speed or accel) else {j: (zero, zero) for j in pos}
    acc = xy(moving, 2, k) if (speed or accel) else {j: (zero, zero) for j in pos}
    vstar = xy(unit, 1, k)
    if sub:  # each design at its own size, as it is judged on its own
        from dataclasses import replace

        frame = replace(frame, size=np.broadcast_to(force_size(mechanism, sub), ds.shape))
    fa = solve_loads(frame, pos, vel, acc, vstar, loads, mechanism.source)
    got = np.where(ok, fa.input, np.nan)
    status[rows] = force_status_np(got, fa.condition, matrix_bound(fa.condition), ok)
    inp[rows] = got
    vp[rows] = np.where(ok, fa.virtual_power_input, np.nan)
    mags = [np.hypot(fx, fy) for _, _, _, fx, fy in fa.pins]
    if mags:
        pin_max[rows] = np.where(ok, np.max(mags, axis=0), np.nan)
    shaking[rows] = np.where(ok, np.hypot(fa.ground[0], fa.ground[1]), np.nan)
    return BatchForces(fa, status, inp, pin_max, shaking, vp)


def sweep_forces(mechanism: Any, result: Any, loads: Loads, speed: float, accel: float
                 ) -> list[Forces | None]:
    """Every position of a sweep's forces (None where unsolved): each position's rates as the
    sweep's own (kinematics.rates), the matrix method for all of them in one
    :func:`solve_loads`."""
    import numpy as np

    from .rates import rates_at

    frame = Frame.of(mechanism)
    frame.check_masses(loads)
    angle = mechanism.driver.kind == "angle"
    k = metre(frame.length_unit)
    kept: list[tuple[int, Any, Any]] = []
    out: list[Forces | None] = [None] * len(result.positions)
    for i, pos in enumerate(result.positions):
        if pos.status != "converged" or pos.solution is None:
            continue
        q = [math.radians(pos.solution[u.name]) if u.kind == "angle" else pos.solution[u.name]
             for u in mechanism.unknowns]
        drv = math.radians(pos.input) if angle else pos.input
        # the sweep's own rates where it computed them at this motion (--speed), else here
        given = pos.rates if speed and pos.rates is not None and pos.rates.joint_velocities else None
        actual = given or rates_at(mechanism, q, speed=speed, accel=accel, driver=drv)
        unit = per_unit_speed(actual, speed) or rates_at(mechanism, q, speed=1.0, accel=0.0, driver=drv)
        if actual.status == "undefined" or unit.status == "undefined":
            out[i] = undefined_forces(frame, "the kinematics are undefined here")
            continue
        kept.append((i, actual, unit))
    if not kept:
        return out
    names = list(kept[0][1].joints)

    def stack(get: Any) -> dict[str, tuple[Any, Any]]:
        return {j: (np.array([get(r)[j][0] * k for r in rows]),
                    np.array([get(r)[j][1] * k for r in rows])) for j in names}

    rows = [a for _, a, _ in kept]
    zero = {j: (0.0, 0.0) for j in names}
    pos_a = stack(lambda r: r.joints)
    vel_a = stack(lambda r: r.joint_velocities or zero)
    acc_a = stack(lambda r: r.joint_accelerations or zero)
    rows = [u for _, _, u in kept]
    vstar = stack(lambda r: r.joint_velocities)
    fa = solve_loads(frame, pos_a, vel_a, acc_a, vstar, loads, mechanism.source)
    for n, (i, actual, unit) in enumerate(kept):
        out[i] = position_forces(fa, n, unit, actual.status, loads)
    return out


def with_forces(mechanism: Any, result: Any, loads: Loads, speed: float | None, accel: float) -> Any:
    """The sweep ``result`` carrying every position's forces (``result.forces``)."""
    from dataclasses import replace

    return replace(result, forces=tuple(sweep_forces(mechanism, result, loads, speed or 0.0, accel)))
