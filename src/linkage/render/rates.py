"""Velocities, accelerations and joint coordinates: JSON fields, CSV columns, tables."""

from __future__ import annotations

from typing import Any

from .report import Block, table


def rate_units(kind: str, length_unit: str) -> tuple[str, str]:
    """(velocity unit, acceleration unit) of an unknown of this kind."""
    base = "rad" if kind == "angle" else length_unit
    return f"{base}/s", f"{base}/s^2"


def rates_dict(rates: Any) -> dict[str, Any]:
    """The JSON fields of one position's kinematics (rate fields only with a driver speed)."""
    if rates is None:
        return {}
    out: dict[str, Any] = {"joints": {k: list(v) for k, v in rates.joints.items()}}
    if rates.status != "ok":
        out["rates_status"] = rates.status
    if rates.velocities:
        out["velocities"] = rates.velocities
        out["accelerations"] = rates.accelerations
        out["joint_velocities"] = {k: list(v) for k, v in rates.joint_velocities.items()}
        out["joint_accelerations"] = {k: list(v) for k, v in rates.joint_accelerations.items()}
    return out


def rate_headers(names: Any, kinds: Any, length_unit: str, joints: Any, motion: bool) -> list[str]:
    """CSV columns for the kinematics: unknown rates (with a driver speed), then joints."""
    out = []
    if motion:
        for n, k in zip(names, kinds):
            v, a = rate_units(k, length_unit)
            out += [f"d{n}/dt ({v})", f"d2{n}/dt2 ({a})"]
    for j in joints:
        out += [f"{j}.x ({length_unit})", f"{j}.y ({length_unit})"]
        if motion:
            out += [f"{j}.vx ({length_unit}/s)", f"{j}.vy ({length_unit}/s)",
                    f"{j}.ax ({length_unit}/s^2)", f"{j}.ay ({length_unit}/s^2)"]
    return out


def rate_cells(rates: Any, names: Any, joints: Any, motion: bool) -> list[Any]:
    """One row of :func:`rate_headers` (empty cells where unsolved or singular)."""
    cells: list[Any] = []
    if motion:
        for n in names:
            ok = rates is not None and rates.velocities
            cells += [rates.velocities[n], rates.accelerations[n]] if ok else [None, None]
    for j in joints:
        xy = rates.joints.get(j) if rates is not None else None
        cells += list(xy) if xy else [None, None]
        if motion:
            v = rates.joint_velocities.get(j) if rates is not None else None
            a = rates.joint_accelerations.get(j) if rates is not None else None
            cells += [*(v or (None, None)), *(a or (None, None))]
    return cells


def rates_blocks(rates: Any, names: Any, kinds: Any, length_unit: str, digits: int) -> list[Block]:
    """Tables of one position's kinematics: the unknowns' rates, then the joints."""
    blocks: list[Block] = []
    if rates is None:
        return blocks
    if rates.velocities:
        rows = []
        for n, k in zip(names, kinds):
            v, a = rate_units(k, length_unit)
            rows.append((n, rates.velocities[n], v, rates.accelerations[n], a))
        blocks.append(table("Velocities and accelerations", ("unknown", "velocity", "unit", "acceleration",
                                                             "unit"), rows, digits))
    L = length_unit
    if rates.velocities:
        headers = ("joint", f"x ({L})", f"y ({L})", f"vx ({L}/s)", f"vy ({L}/s)", f"ax ({L}/s^2)",
                   f"ay ({L}/s^2)")
        rows = [(j, *xy, *rates.joint_velocities[j], *rates.joint_accelerations[j])
                for j, xy in rates.joints.items()]
    else:
        headers = ("joint", f"x ({L})", f"y ({L})")
        rows = [(j, *xy) for j, xy in rates.joints.items()]
    if rows:
        blocks.append(table("Joints (the first loop's first joint at the origin, x along 0 deg)", headers,
                            rows, digits))
    return blocks
