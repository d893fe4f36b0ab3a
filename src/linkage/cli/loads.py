"""The loads over a sweep: a table beside the sweep's, and the torque curve (kinematics.forces
at every solved position, a chunk of positions at a time: kinematics.force_sweeps)."""

import functools
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, Optional


def sweep_loads(report: Any, mechanism: Any, result: Any, loads: Any, speed: Optional[float],
                accel: Optional[float], digits: int, plot: Optional[Path], cols: Any = None
                ) -> tuple[Any, Callable[[], None] | None]:
    """The sweep's report with a ``loads`` table (and its summary lines) added, and with
    ``plot`` the call that draws the input torque over the sweep, peak marked, into it
    (made once the report is written: its tables beside -o are checked against the
    picture's path first, render.writers.check_report_paths). ``cols``: the sweep's
    columns as its report read them (kinematics.columns.sweep_columns; read here if not
    given), whose rates the loads reuse."""
    from ..kinematics.columns import sweep_columns
    from ..kinematics.force_sweeps import FORCE_KEYS, LoadColumns
    from ..problems.loads import applied_rows
    from ..render.data import Report
    from ..render.forces import applied_block, status_words, sweep_force_table, torque_plot
    from ..render.report import Text, fmt, table

    angle = mechanism.driver.kind == "angle"
    cols = sweep_columns(result) if cols is None else cols
    # computed as the positions table's rates are (a chunk at a time, in step with the
    # writer), whatever is left when the loads table, the display or the plot first asks
    acc = LoadColumns(mechanism, cols, loads, speed or 0.0, accel or 0.0)
    unit_in = "N" if mechanism.extra.get("drawing_driver", {}).get("slider") else "N m"
    unit = "deg" if angle else mechanism.length_unit
    name = mechanism.driver.name
    n = len(cols)
    later = {k: _Later(n, lambda k=k: acc.result().columns[k]) for k in (*FORCE_KEYS, *acc.pins())}
    words = _Later(n, functools.cache(lambda: status_words(acc.result().status)))
    loads_table = sweep_force_table(cols.inputs, words, later, name, unit, unit_in, acc.pins())

    def lines() -> list[Any]:  # the display's: built only when shown
        got = acc.result()
        at_in, at_pin, flagged = got.peak_input, got.peak_pin, got.flagged
        inputs, inp, pin = cols.inputs, got.columns["input"], got.columns["max_pin_force"]
        out = [Text(""), Text("loads over the sweep (matrix method, SI units)", "bold")]
        applied = applied_rows(loads, mechanism.extra["drawing"])
        if applied:
            out.append(applied_block(applied, digits))
        if at_in >= 0:
            out.append(Text(f"peak input {fmt(float(inp[at_in]), digits)} {unit_in} at {name} = "
                            f"{fmt(float(inputs[at_in]), digits)} {unit}; largest pin force "
                            f"{fmt(float(pin[at_pin]), digits)} N at "
                            f"{fmt(float(inputs[at_pin]), digits)} {unit}"))
        if flagged:
            out.append(Text(f"{flagged} positions near a toggle (near_toggle, ill_conditioned or "
                            "undefined): their forces are flagged in the loads table, not counted in the "
                            "peaks", "yellow"))
        shown = [(x, w, _cell(y), _cell(p)) for x, w, y, p in
                 zip(_plain(inputs), words[:].tolist(), inp.tolist(), pin.tolist())]
        out.append(table("", [f"{name} ({unit})", "forces status", f"input ({unit_in})", "max pin force (N)"],
                         shown, digits))
        return out

    def draw() -> None:
        got = acc.result()
        rows = list(zip(_plain(cols.inputs), words[:].tolist(), got.columns["input"].tolist()))
        torque_plot(rows, name, unit, unit_in, plot, f"{mechanism.name}: input over the sweep",
                    got.peak_input)

    return (Report(report.title, (*report.tables, loads_table), lambda: [*report.blocks(), *lines()],
                   report.document), None if plot is None else draw)


def _plain(values: Any) -> list[Any]:
    return values.tolist() if hasattr(values, "tolist") else list(values)


def _cell(v: float) -> Any:
    """A display cell: NaN (no number) as None."""
    return None if v != v else v


class _Later(Sequence):  # type: ignore[type-arg]
    """A column of the loads table, read from the sweep's loads (LoadColumns.result) when a
    writer first asks: after the positions table's pass has computed them chunk by chunk.
    ``block``: the rows a writer takes at a time (render.writers.write_tables), a slice
    of the array each."""

    block = 1 << 17

    def __init__(self, n: int, get: Callable[[], Any]) -> None:
        self.n, self.get = n, get

    def __len__(self) -> int:
        return self.n

    def __getitem__(self, i: Any) -> Any:
        return self.get()[i]
