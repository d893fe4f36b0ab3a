"""Velocities, accelerations and joint coordinates: JSON fields, CSV columns, tables."""

from __future__ import annotations

import math
from typing import Any

from ..kinematics.labels import rate_label
from .report import Block, denoise, table


def rate_units(kind: str, length_unit: str) -> tuple[str, str]:
    """(velocity unit, acceleration unit) of an unknown of this kind."""
    base = "rad" if kind == "angle" else length_unit
    return f"{base}/s", f"{base}/s^2"


def uncertain(value: float, bound: float, with_bound: bool = True) -> str:
    """An ill-conditioned rate as text: the digits its bound leaves, then the bound (unless
    a column beside it shows the bound)."""
    if not (math.isfinite(value) and math.isfinite(bound)) or bound <= 0.0:
        digits = 6
    else:
        digits = 1 if bound >= abs(value) else min(6, max(1, math.floor(math.log10(abs(value) / bound)) + 1))
    return f"{value:.{digits}g} ±{bound:.2g}" if with_bound else f"{value:.{digits}g}"


def rate_units_dict(names: Any, kinds: Any, length_unit: str, driver_kind: str) -> dict[str, Any]:
    """The JSON's ``rate_units``: the unit of the driver's speed and acceleration and of
    every rate field (``units`` gives the positions' display units, deg for an angle,
    while its rates are in rad/s and rad/s^2)."""
    speed, accel = rate_units(driver_kind, length_unit)
    return {"speed": speed, "accel": accel,
            "velocities": {n: rate_units(k, length_unit)[0] for n, k in zip(names, kinds)},
            "accelerations": {n: rate_units(k, length_unit)[1] for n, k in zip(names, kinds)},
            "joint_velocities": f"{length_unit}/s", "joint_accelerations": f"{length_unit}/s^2"}


def rates_dict(rates: Any) -> dict[str, Any]:
    """The JSON fields of one position's kinematics (rate fields only with a driver speed):
    the rates' status (ok, ill_conditioned or undefined), each rate's absolute error bound
    beside it, and the labels of the ill-conditioned ones."""
    if rates is None:
        return {}
    out: dict[str, Any] = {"joints": {k: list(v) for k, v in rates.joints.items()}}
    if rates.status != "ok" or rates.velocities:  # as the CSV's "rates status" column: "ok" too
        out["rates_status"] = rates.status
    if rates.velocities:
        out["velocities"] = rates.velocities
        out["accelerations"] = rates.accelerations
        out["joint_velocities"] = {k: list(v) for k, v in rates.joint_velocities.items()}
        out["joint_accelerations"] = {k: list(v) for k, v in rates.joint_accelerations.items()}
        out["rate_bounds"] = {"velocities": rates.velocity_bounds, "accelerations": rates.acceleration_bounds,
                              "joint_velocities": rates.joint_velocity_bounds,
                              "joint_accelerations": rates.joint_acceleration_bounds}
        if rates.ill_conditioned:
            out["ill_conditioned"] = list(rates.ill_conditioned)
    return out


def rate_headers(names: Any, kinds: Any, length_unit: str, joints: Any, motion: bool,
                 bounds: bool = True) -> list[str]:
    """CSV columns for the kinematics: with a driver speed the rates' status, the unknowns'
    rates (each followed by its error bound), then the joints (with the bounds of their
    velocity and acceleration, on each of x and y). ``bounds=False``: the unknowns' rates
    only, for a table whose cells carry their bounds as text (:func:`rate_cells`)."""
    out = ["rates status"] if motion and bounds else []
    if motion:
        for n, k in zip(names, kinds):
            v, a = rate_units(k, length_unit)
            out += [f"d{n}/dt ({v})", f"d{n}/dt bound ({v})", f"d2{n}/dt2 ({a})", f"d2{n}/dt2 bound ({a})"] \
                if bounds else [f"d{n}/dt ({v})", f"d2{n}/dt2 ({a})"]
    for j in joints:
        out += [f"{j}.x ({length_unit})", f"{j}.y ({length_unit})"]
        if motion:
            out += [f"{j}.vx ({length_unit}/s)", f"{j}.vy ({length_unit}/s)",
                    f"{j}.ax ({length_unit}/s^2)", f"{j}.ay ({length_unit}/s^2)",
                    f"{j}.v bound ({length_unit}/s)", f"{j}.a bound ({length_unit}/s^2)"]
    return out


def rate_cells(rates: Any, names: Any, joints: Any, motion: bool, bounds: bool = True) -> list[Any]:
    """One row of :func:`rate_headers` (empty cells where unsolved or undefined). With
    ``bounds=False`` (a table's cells): an ill-conditioned rate as text with its bound
    (:func:`uncertain`), an undefined one as "undefined"."""
    cells: list[Any] = []
    if motion:
        ok = rates is not None and bool(rates.velocities)
        if bounds:
            cells.append(rates.status if rates is not None else None)
        for n in names:
            if not ok:
                undefined = "undefined" if rates is not None and not bounds else None
                cells += [undefined] * (4 if bounds else 2)
                continue
            for order, value, bound in ((1, rates.velocities[n], rates.velocity_bounds.get(n)),
                                        (2, rates.accelerations[n], rates.acceleration_bounds.get(n))):
                if bounds:
                    cells += [value, bound]
                elif bound is not None and rates.flagged(rate_label(n, order)):
                    cells.append(uncertain(value, bound))
                else:
                    cells.append(value)
    for j in joints:
        xy = rates.joints.get(j) if rates is not None else None
        cells += list(xy) if xy else [None, None]
        if motion:
            v = rates.joint_velocities.get(j) if rates is not None else None
            a = rates.joint_accelerations.get(j) if rates is not None else None
            bv = rates.joint_velocity_bounds.get(j) if rates is not None else None
            ba = rates.joint_acceleration_bounds.get(j) if rates is not None else None
            cells += [*(v or (None, None)), *(a or (None, None)), bv, ba]
    return cells


def rates_blocks(rates: Any, names: Any, kinds: Any, length_unit: str, digits: int,
                 origin: tuple[float, float] = (0.0, 0.0)) -> list[Block]:
    """Tables of one position's kinematics: the unknowns' rates with their error bounds,
    then the joints; an ill-conditioned rate shows only the digits its bound leaves."""
    blocks: list[Block] = []
    if rates is None:
        return blocks
    if rates.velocities:
        # one row per rate, named as the sweep's columns, the CSV and the ill-conditioned
        # note name it, its unit beside the name: seven columns (unknown, velocity, bound,
        # unit, acceleration, bound, unit) were 82 wide and split at 80 columns, leaving the
        # acceleration's unit alone in a second table
        rows = []
        for order in (1, 2):
            for n, k in zip(names, kinds):
                unit = rate_units(k, length_unit)[order - 1]
                label = rate_label(n, order)
                value = rates.velocities[n] if order == 1 else rates.accelerations[n]
                bound = (rates.velocity_bounds if order == 1 else rates.acceleration_bounds).get(n)
                shown = value if rates.flagged(label) else denoise(value, 0.0, bound)
                rows.append((f"{label} ({unit})", _shown(rates, label, shown, bound), _bound(bound)))
        blocks.append(table("Velocities and accelerations", ("rate", "value", "± bound"), rows, digits))
    L = length_unit
    size = _largest(rates.joints.values())  # the mechanism's size: the scale of a coordinate's noise
    if rates.velocities:
        headers = ("joint", f"x ({L})", f"y ({L})", f"vx ({L}/s)", f"vy ({L}/s)", f"± v ({L}/s)",
                   f"ax ({L}/s^2)", f"ay ({L}/s^2)", f"± a ({L}/s^2)")
        rows = [(j, *(denoise(c, size) for c in xy), *_joint_cells(rates, j, 1),
                 _bound(rates.joint_velocity_bounds.get(j)),
                 *_joint_cells(rates, j, 2), _bound(rates.joint_acceleration_bounds.get(j)))
                for j, xy in rates.joints.items()]
    else:
        headers = ("joint", f"x ({L})", f"y ({L})")
        rows = [(j, *(denoise(c, size) for c in xy)) for j, xy in rates.joints.items()]
    if rows:
        where = ("the origin" if origin == (0.0, 0.0) else
                 f"({origin[0]:.{digits}g}, {origin[1]:.{digits}g}) {length_unit}")
        blocks.append(table(f"Joints (the first loop's first joint at {where}, x along 0 deg)", headers,
                            rows, digits))
    return blocks


def _bound(b: float | None) -> str | None:
    return None if b is None else f"{b:.2g}"


def _shown(rates: Any, label: str, value: float, bound: float | None) -> Any:
    """A table cell beside its bound's column: a flagged rate to the digits its bound leaves."""
    return uncertain(value, bound, with_bound=False) if bound is not None and rates.flagged(label) else value


def _largest(pairs: Any) -> float:
    """The largest finite magnitude among (x, y) pairs (0 for none)."""
    return max((abs(c) for xy in pairs if xy for c in xy if c is not None and math.isfinite(c)), default=0.0)


def _joint_cells(rates: Any, j: str, order: int) -> tuple[Any, Any]:
    table = rates.joint_velocities if order == 1 else rates.joint_accelerations
    xy = table[j]
    bound = rates.joint_velocity_bounds.get(j) if order == 1 else rates.joint_acceleration_bounds.get(j)
    label = rate_label(j, order, joint=True)
    if rates.flagged(label):
        return _shown(rates, label, xy[0], bound), _shown(rates, label, xy[1], bound)
    # a still joint's rate computed as 1e-13 cm/s beside joints moving at 600 cm/s: 0
    size = _largest(table.values())
    return denoise(xy[0], size, bound), denoise(xy[1], size, bound)
