"""Report blocks, CSV and JSON for sweeps."""

from __future__ import annotations

from typing import Any

from ..kinematics.angles import angle_extent, closes_circle, driver_turn
from ..kinematics.sweep import SweepResult
from .rates import rate_cells, rate_headers, rate_units_dict, rates_dict
from .report import Block, Text, fmt, table


def _kinds(s: SweepResult) -> list[str]:
    return ["angle" if u == "deg" else "length" for u in s.units]


def det_unit_of(s: SweepResult) -> str:
    """det J's unit: a length per radian for each angle unknown (a length unknown's column
    is dimensionless)."""
    n_angle = sum(u == "deg" for u in s.units)
    if not n_angle:
        return "1"
    top = s.length_unit if n_angle == 1 else f"{s.length_unit}^{n_angle}"
    return f"{top}/rad" if n_angle == 1 else f"{top}/rad^{n_angle}"


def joint_names(s: SweepResult) -> list[str]:
    """Every joint and point named at any solved position, in the order first met."""
    seen: dict[str, None] = {}
    for p in s.positions:
        if p.rates is not None:
            seen.update(dict.fromkeys(p.rates.joints))
            break
    return list(seen)


def sweep_headers(s: SweepResult, kinematics: bool = True) -> list[str]:
    u = s.driver_unit
    headers = [f"{s.driver} ({u})", "status"]
    headers += [f"{n} ({unit})" for n, unit in zip(s.names, s.units)]
    headers += ["branch", "iterations", f"det J ({det_unit_of(s)})"]
    if s.classification:
        headers.append("transmission angle (deg)")
    if kinematics:
        headers += rate_headers(s.names, _kinds(s), s.length_unit, joint_names(s), s.motion is not None)
    return headers


def sweep_rows(s: SweepResult, kinematics: bool = True) -> list[tuple[Any, ...]]:
    rows = []
    joints = joint_names(s) if kinematics else []
    motion = s.motion is not None
    for p in s.positions:
        sol = p.solution or {}
        row: list[Any] = [p.input, p.status, *[sol.get(n) for n in s.names], p.branch, p.iterations, p.det]
        if s.classification:
            row.append(p.transmission)
        if kinematics:
            row += rate_cells(p.rates, s.names, joints, motion)
        rows.append(tuple(row))
    return rows


def ranges_of(s: SweepResult) -> dict[str, dict[str, float]]:
    """Per unknown: min and max over solved positions, where they occur, and the stroke
    (an angle's by the range rule of kinematics.angles: a full turn at most, 360 for one
    that turns fully)."""
    out = {}
    inputs = [p.input for p in s.positions]
    closes = s.driver_unit in ("deg", "rad") and closes_circle(inputs, driver_turn(s.driver_unit))
    for name, unit in zip(s.names, s.units):
        pts = [(p.solution[name], p.input) for p in s.positions if p.solution]
        if not pts:
            continue
        lo, hi = min(pts), max(pts)
        stroke = hi[0] - lo[0]
        if unit == "deg":
            stroke = angle_extent([p.solution[name] if p.solution else None for p in s.positions],
                                  closes)[2]
        out[name] = {"min": lo[0], "at_min": lo[1], "max": hi[0], "at_max": hi[1], "stroke": stroke}
    return out


def sweep_dict(s: SweepResult) -> dict[str, Any]:
    return {
        "mechanism": s.mechanism,
        "driver": {"name": s.driver, "unit": s.driver_unit},
        "method": s.method,
        "branch": s.branch,
        "classification": s.classification or None,
        "units": dict(zip(s.names, s.units)),
        "length_unit": s.length_unit,
        "driver_motion": ({"speed": s.motion[0], "accel": s.motion[1]} if s.motion else None),
        **({"rate_units": rate_units_dict(s.names, _kinds(s), s.length_unit,
                                          "angle" if s.driver_unit in ("deg", "rad") else "length")}
           if s.motion else {}),
        "positions": [
            {"input": p.input, "status": p.status, "solution": p.solution, "branch": p.branch,
             "iterations": p.iterations, "det": p.det, "transmission": p.transmission,
             **({"note": p.note} if p.note else {}), **rates_dict(p.rates)}
            for p in s.positions
        ],
        "feasible_ranges": [list(r) for r in s.feasible_ranges],
        "toggles": list(s.toggles),
        "ranges": ranges_of(s),
        "summary": s.summary,
    }


def sweep_blocks(s: SweepResult, digits: int, max_rows: int = 400) -> list[Block]:
    u = s.driver_unit
    blocks: list[Block] = [Text(f"{s.mechanism}: sweep of {s.driver} over {len(s.positions)} positions "
                                f"({s.method}, continuation)", "bold")]
    if s.classification:
        for c in s.classification.get("loops", [s.classification]):
            where = f" loop {c['loop']}" if "loop" in c else ""
            blocks.append(Text(f"four-bar{where}: {c['type']} (s + l = {fmt(c['s_plus_l'], 6)}, "
                               f"p + q = {fmt(c['p_plus_q'], 6)})"))
        if len(s.classification.get("loops", ())) > 1:  # one column for several loops
            blocks.append(Text("transmission angle: at each position, of the four-bar loop "
                               "farthest from 90 deg"))
    rows = sweep_rows(s, kinematics=False)
    headers = sweep_headers(s, kinematics=False)
    if s.motion is not None:  # the unknowns' rates beside their values (joints: csv, json)
        headers += rate_headers(s.names, _kinds(s), s.length_unit, [], True, bounds=False)
        rows = [(*r, *rate_cells(p.rates, s.names, [], True, bounds=False))
                for r, p in zip(rows, s.positions)]
    every = -(-len(rows) // max_rows)  # ceil: the fewest rows skipped that fit max_rows
    shown = rows if every <= 1 else rows[::every]
    note = [] if shown is rows else [f"(one row in {every} of {len(rows)} shown; "
                                     "--format csv or json gives all)"]
    blocks.append(Text(""))
    blocks.append(table("", headers, shown, digits, notes=note))
    counts = ", ".join(f"{k}: {v}" for k, v in sorted(s.summary.items()))
    blocks.append(Text(f"positions: {counts}; branch: {s.branch}", "bold"))
    blocks.append(Text("feasible ranges: " + (", ".join(f"[{fmt(a, 12)}, {fmt(b, 12)}] {u}"
                                                        for a, b in s.feasible_ranges) or "none")))
    blocks.append(Text("limit and toggle positions: " + (", ".join(f"{fmt(t, 13)} {u}" for t in s.toggles)
                                                         or "none")))
    for name, r in ranges_of(s).items():
        unit = dict(zip(s.names, s.units))[name]
        blocks.append(Text(f"{name}: min {fmt(r['min'], 10)} {unit} at {s.driver} = {fmt(r['at_min'], 8)}, "
                           f"max {fmt(r['max'], 10)} {unit} at {fmt(r['at_max'], 8)}, "
                           f"range {fmt(r['stroke'], 10)} {unit}"))
    return blocks
