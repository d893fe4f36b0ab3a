"""A sweep's report: its table of positions (columns read from the engine's arrays), the
display blocks and the JSON document (built only when shown or written)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from ..kinematics.angles import angle_extent, closes_circle, driver_turn
from ..kinematics.columns import SweepColumns, sweep_columns
from ..kinematics.sweep import SweepResult
from ..problems.closed_form import TRANSMISSION
from .data import DataTable, Report, column, from_rows, split_header
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


def sweep_headers(s: SweepResult) -> list[str]:
    """The display table's headers, ``name (unit)``: the driver, status, the unknowns,
    branch, iterations, det J and the transmission angle (the rates are added beside)."""
    u = s.driver_unit
    headers = [f"{s.driver} ({u})", "status"]
    headers += [f"{n} ({unit})" for n, unit in zip(s.names, s.units)]
    headers += ["branch", "iterations", f"det J ({det_unit_of(s)})"]
    if s.classification:
        headers.append(f"{TRANSMISSION} (deg)")
    return headers


def sweep_table(s: SweepResult, cols: SweepColumns | None = None) -> DataTable:
    """The sweep's one table, ``positions``: the driver, status, each unknown, branch,
    iterations, det J, the transmission angle (a four-bar), with a driver speed the rates
    (each with its bound) and the joints' coordinates (and rates) where computed. Each
    column named as today's CSV header without its unit (``theta3``, ``det J``,
    ``A.x``), the unit beside it."""
    c = sweep_columns(s) if cols is None else cols
    out = [column(s.driver, s.driver_unit, c.inputs), column("status", "", c.status, "text")]
    out += [column(n, unit, c.solution[n]) for n, unit in zip(s.names, s.units)]
    out += [column("branch", "", c.branch, "text"), column("iterations", "", c.iterations, "int"),
            column("det J", det_unit_of(s), c.det)]
    if s.classification:
        out.append(column(TRANSMISSION, "deg", c.transmission))
    joints = list(c.joints)
    if c.rates is not None:  # the scalar rates, a row at a time (the one definition)
        from .rates import rate_headers  # a sweep without rates does not import them

        heads = rate_headers(s.names, _kinds(s), s.length_unit, joints, True)
        cells = RateCells(c.rates, s.names, joints, len(heads))
        for k, h in enumerate(heads):
            name, unit = split_header(h)
            kind = "text" if name == "rates status" else "number"
            out.append(column(name, unit, CellColumn(cells, k), kind))
    else:
        for j in joints:
            x, y = c.joints[j]
            out += [column(f"{j}.x", s.length_unit, x), column(f"{j}.y", s.length_unit, y)]
    return DataTable("positions", tuple(out))


class RateCells:
    """The rate columns' cells of a sweep's positions table (:func:`rate_cells`, one row
    per position), made a block of rows at a time as a writer asks for them: the last
    block's kept, so the table's columns read side by side compute each row once, and no
    more than a block of rows (and the rates' chunk, kinematics.columns.RateChunks) is
    held however long the sweep."""

    def __init__(self, rates: Sequence[Any], names: Sequence[str], joints: Sequence[str], width: int) -> None:
        self.rates, self.names, self.joints, self.width = rates, names, joints, width
        self._last: tuple[int, int, list[list[Any]]] = (-1, -1, [])

    def __len__(self) -> int:
        return len(self.rates)

    def block(self, start: int, stop: int) -> list[list[Any]]:
        """Rows ``start:stop``, one list per column."""
        if self._last[:2] != (start, stop):
            self._last = (-1, -1, [])
            from .rates import rate_cells

            if hasattr(self.rates, "block") and stop > start:  # a batch's: the cells as arrays
                cols = rate_cells(self.rates.block(start, stop), self.names, self.joints, True)
            else:
                rows = [rate_cells(self.rates[i], self.names, self.joints, True) for i in range(start, stop)]
                cols = [list(v) for v in zip(*rows)] if rows else [[] for _ in range(self.width)]
            self._last = (start, stop, cols)
        return self._last[2]


class CellColumn(Sequence):  # type: ignore[type-arg]
    """One rate column of :class:`RateCells`: a slice is a list of its cells (None where
    there is none); ``block``, the rows a writer should take at a time
    (render.writers.write_tables)."""

    def __init__(self, cells: RateCells, k: int) -> None:
        self.cells, self.k = cells, k
        # a few of the rates' chunks (a parquet row group, a CSV block, of that many rows)
        self.block = 4 * getattr(cells.rates, "chunk", BLOCK_ROWS // 4)

    def __len__(self) -> int:
        return len(self.cells)

    def __getitem__(self, i: Any) -> Any:
        if isinstance(i, slice):
            start, stop, step = i.indices(len(self))
            got = self.cells.block(start, max(start, stop))[self.k]
            return got if step == 1 else got[::step]
        if i < 0:
            i += len(self)
        return self.cells.block(i, i + 1)[self.k][0]


BLOCK_ROWS = 4096
"""Rows of rate cells made at a time where the rates are a list (the one-at-a-time engine's)."""


def sweep_report(s: SweepResult, digits: int, max_rows: int = 400, joints_note: str = "",
                 cols: SweepColumns | None = None) -> Report:
    """The sweep as a :class:`~.data.Report`: one table (:func:`sweep_table`), the display
    blocks and the JSON document built only when a format asks for them. ``joints_note``:
    a line the display adds (where the joints are written, say); ``cols``: the sweep's
    columns, if already read (a loaded sweep's loads reuse them)."""
    cols = sweep_columns(s) if cols is None else cols
    title = f"{s.mechanism}: sweep of {s.driver} over {len(cols)} positions"

    def blocks() -> list[Block]:
        out = sweep_blocks(s, digits, max_rows, cols)
        return [*out, Text(joints_note)] if joints_note else out

    return Report(title, (sweep_table(s, cols),), blocks, lambda: sweep_dict(s, cols))


def _cell(v: Any) -> Any:
    """A display cell: NaN (an array's no value) as None."""
    return None if isinstance(v, float) and v != v else v


def _extreme(values: Any, inputs: Any, low: bool) -> tuple[float, float]:
    """(min or max of the solved values, where it occurs: as min and max of (value, driver)
    pairs pick it, the smallest driver value of equal minima, the largest of maxima)."""
    if hasattr(values, "dtype"):
        import numpy as np

        best = float(np.nanmin(values) if low else np.nanmax(values))
        at = np.asarray(inputs)[values == best]
        return best, float(at.min() if low else at.max())
    pts = [(v, x) for v, x in zip(values, inputs) if v is not None]
    return min(pts) if low else max(pts)


def ranges_of(s: SweepResult, cols: SweepColumns | None = None) -> dict[str, dict[str, float]]:
    """Per unknown: min and max over solved positions, where they occur (the smallest
    driver value of equal minima, the largest of equal maxima), and the stroke (an angle's
    by the range rule of kinematics.angles: a full turn at most, 360 for one that turns
    fully)."""
    c = sweep_columns(s) if cols is None else cols
    out = {}
    inputs = c.inputs
    angle = s.driver_unit in ("deg", "rad")
    for name, unit in zip(s.names, s.units):
        values = c.solution[name]
        if c.arrays:
            import numpy as np

            from ..kinematics.angles import angle_extent_array, closes_circle_array

            if not np.isfinite(values).any():
                continue
            lo, hi = _extreme(values, inputs, True), _extreme(values, inputs, False)
            stroke = hi[0] - lo[0]
            if unit == "deg":
                closes = angle and closes_circle_array(inputs, driver_turn(s.driver_unit))
                stroke = float(angle_extent_array(values[None, :], closes)[2][0])
        else:
            if all(v is None for v in values):
                continue
            lo, hi = _extreme(values, inputs, True), _extreme(values, inputs, False)
            stroke = hi[0] - lo[0]
            if unit == "deg":
                closes = angle and closes_circle(inputs, driver_turn(s.driver_unit))
                stroke = angle_extent(values, closes)[2]
        out[name] = {"min": lo[0], "at_min": lo[1], "max": hi[0], "at_max": hi[1], "stroke": stroke}
    return out


def sweep_dict(s: SweepResult, cols: SweepColumns | None = None) -> dict[str, Any]:
    from .rates import rate_units_dict, rates_dict

    return {
        "mechanism": s.mechanism,
        "driver": {"name": s.driver, "unit": s.driver_unit},
        "method": s.method,
        "branch": s.branch,
        **({"branch_note": s.branch_note} if s.branch_note else {}),
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
        "meetings": list(s.meetings),
        "ranges": ranges_of(s, cols),
        "summary": s.summary,
    }


def sweep_blocks(s: SweepResult, digits: int, max_rows: int = 400,
                 cols: SweepColumns | None = None) -> list[Block]:
    c = sweep_columns(s) if cols is None else cols
    u = s.driver_unit
    n = len(c)
    blocks: list[Block] = [Text(f"{s.mechanism}: sweep of {s.driver} over {n} positions "
                                f"({s.method}, continuation)", "bold")]
    if s.classification:
        for cl in s.classification.get("loops", [s.classification]):
            where = f" loop {cl['loop']}" if "loop" in cl else ""
            blocks.append(Text(f"four-bar{where}: {cl['type']} (s + l = {fmt(cl['s_plus_l'], 6)}, "
                               f"p + q = {fmt(cl['p_plus_q'], 6)})"))
        if len(s.classification.get("loops", ())) > 1:  # one column for several loops
            blocks.append(Text(f"{TRANSMISSION}: at each position, of the four-bar loop "
                               "farthest from 90 deg"))
    headers = sweep_headers(s)
    every = -(-n // max_rows)  # ceil: the fewest rows skipped that fit max_rows
    shown = range(n) if every <= 1 else range(0, n, every)
    # only the rows shown are read from the columns (a batch sweep builds no position)
    data = [c.inputs, c.status, *[c.solution[name] for name in s.names], c.branch, c.iterations, c.det]
    if s.classification:
        data.append(c.transmission)
    picked = [v[shown.start:shown.stop:shown.step] for v in data]
    picked = [p.tolist() if hasattr(p, "tolist") else list(p) for p in picked]
    rows = [tuple(_cell(v) for v in r) for r in zip(*picked)]
    if s.motion is not None and c.rates is not None:  # the unknowns' rates beside their values
        from .rates import rate_cells, rate_headers

        headers += rate_headers(s.names, _kinds(s), s.length_unit, [], True, bounds=False)
        rows = [(*r, *rate_cells(c.rates[i], s.names, [], True, bounds=False)) for r, i in zip(rows, shown)]
    note = [] if every <= 1 else [f"(one row in {every} of {n} shown; "
                                  "--format csv or json gives all)"]
    blocks.append(Text(""))
    blocks.append(table("", headers, rows, digits, notes=note))
    counts = ", ".join(f"{k}: {v}" for k, v in sorted(s.summary.items()))
    blocks.append(Text(f"positions: {counts}; branch: {s.branch}", "bold"))
    if s.branch_note:
        blocks.append(Text(f"branch: {s.branch_note}"))
    blocks.append(Text("feasible ranges: " + (", ".join(f"[{fmt(a, 12)}, {fmt(b, 12)}] {u}"
                                                        for a, b in s.feasible_ranges) or "none")))
    blocks.append(Text("limit and toggle positions: " + (", ".join(f"{fmt(t, 13)} {u}" for t in s.toggles)
                                                         or "none")))
    if s.meetings:
        blocks.append(Text("assemblies meet (to rounding; the branch there is a matter of rounding, kept by "
                           "its signs) at: " + ", ".join(f"{fmt(t, 13)} {u}" for t in s.meetings)))
    for name, r in ranges_of(s, c).items():
        unit = dict(zip(s.names, s.units))[name]
        blocks.append(Text(f"{name}: min {fmt(r['min'], 10)} {unit} at {s.driver} = {fmt(r['at_min'], 8)}, "
                           f"max {fmt(r['max'], 10)} {unit} at {fmt(r['at_max'], 8)}, "
                           f"range {fmt(r['stroke'], 10)} {unit}"))
    return blocks


EQUATION = "f(phi) = R1 cos(alpha) - R2 cos(phi) + R3 - cos(alpha - phi)"
EQUATION_COLUMNS = (("alpha", "deg", "number"), ("status", "", "text"), ("phi", "deg", "number"),
                    ("iterations", "", "int"), ("f(phi)", "", "number"))
"""The equation sweep's columns: f(phi) is Freudenstein's dimensionless residual."""


def equation_report(rows: Sequence[Sequence[Any]], method: str, tol: float, heading: str,
                    digits: int) -> Report:
    """The four-bar input-output equation swept over alpha (rows of alpha, status, phi,
    iterations, f(phi); None where there is no value) as a Report: one table,
    ``positions``; ``heading`` names the coefficients."""
    headers = tuple(f"{n} ({u})" if u else n for n, u, _ in EQUATION_COLUMNS)

    def blocks() -> list[Block]:
        return [Text(f"four-bar input-output equation over alpha ({method}, each from the previous "
                     f"root): {heading}", "bold"), Text(""), table("", headers, list(rows), digits)]

    def document() -> dict[str, Any]:
        return {"equation": EQUATION, "method": method, "tol": tol,
                "positions": [dict(zip(("alpha", "status", "phi", "iterations", "residual"), r))
                              for r in rows]}

    return Report(f"four-bar input-output equation over alpha: {heading}",
                  (from_rows("positions", EQUATION_COLUMNS, rows),), blocks, document)
