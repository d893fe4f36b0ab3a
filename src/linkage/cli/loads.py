"""The loads over a sweep: a table beside the sweep's, and the torque curve (kinematics.forces
at every solved position)."""

from pathlib import Path
from typing import Any, Optional


def sweep_loads(report: Any, mechanism: Any, result: Any, loads: Any, speed: Optional[float],
                accel: Optional[float], digits: int, plot: Optional[Path]) -> Any:
    """The sweep's report with a ``loads`` table (and its summary lines) added; ``plot``:
    the input torque over the sweep, peak marked."""
    from ..kinematics.force_sweeps import with_forces
    from ..problems.loads import applied_rows
    from ..render.data import Report
    from ..render.forces import applied_block, sweep_force_table, torque_plot
    from ..render.report import Text, fmt, table

    angle = mechanism.driver.kind == "angle"
    cols = with_forces(mechanism, result, loads, speed, accel or 0.0).force_columns()
    keys = list(cols)
    pins = keys[keys.index("condition") + 1:]  # each pin's and slider's forces, after the summary
    rows = list(zip(result.inputs, cols["status"], cols["input"], cols["max_pin_force"],
                    cols["ground_fx"], cols["ground_fy"], cols["ground_moment"], cols["condition"],
                    cols["mechanical_advantage"], *(cols[k] for k in pins)))
    unit_in = "N" if mechanism.extra.get("drawing_driver", {}).get("slider") else "N m"
    unit = "deg" if angle else mechanism.length_unit
    name = mechanism.driver.name
    loads_table = sweep_force_table(rows, name, unit, unit_in, pins)
    (at_in, at_pin), flagged = peaks_of(rows)
    lines = [Text(""), Text("loads over the sweep (matrix method, SI units)", "bold")]
    applied = applied_rows(loads, mechanism.extra["drawing"])
    if applied:
        lines.append(applied_block(applied, digits))
    if at_in >= 0:
        peak, pin = rows[at_in], rows[at_pin]
        lines.append(Text(f"peak input {fmt(peak[2], digits)} {unit_in} at {name} = "
                          f"{fmt(peak[0], digits)} {unit}; largest pin force {fmt(pin[3], digits)} N at "
                          f"{fmt(pin[0], digits)} {unit}"))
    if flagged:
        lines.append(Text(f"{flagged} positions near a toggle (near_toggle, ill_conditioned or "
                          "undefined): their forces are flagged in the loads table, not counted in the peaks",
                          "yellow"))
    shown = [(r[0], r[1], r[2], r[3]) for r in rows]
    lines.append(table("", [f"{name} ({unit})", "forces status", f"input ({unit_in})", "max pin force (N)"],
                       shown, digits))
    if plot is not None:
        torque_plot(rows, name, unit, unit_in, plot, f"{mechanism.name}: input over the sweep", at_in)
    return Report(report.title, (*report.tables, loads_table), lambda: [*report.blocks(), *lines],
                  report.document)


def peaks_of(rows: list[tuple[Any, ...]]) -> tuple[list[int], int]:
    """The rows of the largest |input| and pin force, and the flagged count, by the one peak
    rule (kinematics.forces.force_peaks)."""
    import numpy as np

    from ..kinematics.forces import FORCE_STATUSES, force_peaks

    codes = np.array([[FORCE_STATUSES.index(r[1]) if r[1] in FORCE_STATUSES else -1 for r in rows]])
    cols = [np.array([[np.nan if r[k] is None else r[k] for r in rows]], dtype=float) for k in (2, 3)]
    at, flagged = force_peaks(codes, *cols)
    return [int(a[0]) for a in at], int(flagged[0])
