"""The loads over a sweep: a table beside the sweep's, and the torque curve (kinematics.forces
at every solved position)."""

from pathlib import Path
from typing import Any, Optional


def sweep_loads(report: Any, mechanism: Any, result: Any, loads: Any, speed: Optional[float],
                accel: Optional[float], digits: int, plot: Optional[Path]) -> Any:
    """The sweep's report with a ``loads`` table (and its summary lines) added; ``plot``:
    the input torque over the sweep, peak marked."""
    from ..kinematics.forces import sweep_force_rows
    from ..render.data import Report
    from ..render.forces import sweep_force_table, torque_plot
    from ..render.report import Text, fmt, table

    angle = mechanism.driver.kind == "angle"
    rows = sweep_force_rows(mechanism, result, loads, speed or 0.0, accel or 0.0)
    unit_in = "N" if mechanism.extra.get("drawing_driver", {}).get("slider") else "N m"
    unit = "deg" if angle else mechanism.length_unit
    name = mechanism.driver.name
    loads_table = sweep_force_table(rows, name, unit, unit_in)
    good = [r for r in rows if r[1] == "ok"]
    flagged = [r for r in rows if r[1] in ("near_toggle", "ill_conditioned", "undefined")]
    lines = [Text(""), Text("loads over the sweep (matrix method, SI units)", "bold")]
    if good:
        peak = max(good, key=lambda r: abs(r[2]))
        pins = max(good, key=lambda r: r[3] or 0.0)
        lines.append(Text(f"peak input {fmt(peak[2], digits)} {unit_in} at {name} = "
                          f"{fmt(peak[0], digits)} {unit}; largest pin force {fmt(pins[3], digits)} N at "
                          f"{fmt(pins[0], digits)} {unit}"))
    if flagged:
        lines.append(Text(f"{len(flagged)} positions near a toggle (near_toggle, ill_conditioned or "
                          "undefined): their forces are flagged in the loads table, not counted in the peaks",
                          "yellow"))
    shown = [(r[0], r[1], r[2], r[3]) for r in rows]
    lines.append(table("", [f"{name} ({unit})", "forces status", f"input ({unit_in})", "max pin force (N)"],
                       shown, digits))
    if plot is not None:
        torque_plot(rows, name, unit, unit_in, plot, f"{mechanism.name}: input over the sweep")
    return Report(report.title, (*report.tables, loads_table), lambda: [*report.blocks(), *lines],
                  report.document)
