"""Scan records out, through the one writer registry (:mod:`.writers`).

A scan's records are one table, ``designs``, written by :func:`.writers.open_sink` for
every data format (csv, json, parquet, xlsx) a chunk at a time as the scan computes them
(:class:`RecordSink`), and shown by any display format (table, plain, github, latex, ...)
from :func:`scan_report`, whose blocks hold the kept rows under the scan's summary.

Every column has a name, a unit and a kind (:func:`scan_columns`). The name is the bare
one ``--where``, ``--sort`` and ``--columns`` use (``min_transmission_deg``), the key in
JSON and parquet; the unit goes beside it: CSV, xlsx and the display write the header
``min_transmission_deg (deg)``, JSON lists ``units`` beside ``columns``, parquet puts it
in each field's metadata. A dimensionless column (a fraction, a count, a boolean, a word)
has the unit "" and its header is its bare name (``feasible_fraction``, no ``()``): an
empty pair of brackets would read as a unit someone forgot.

A file is written to a temporary name beside it and renamed only when the scan is
complete, so a failed or interrupted scan never leaves a half-written file; standard
output receives each chunk as it is computed. Memory stays bounded: a chunk's arrays go
to the sink as arrays, which formats a slice of rows at a time.
"""

from __future__ import annotations

import contextlib
import math
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .data import Column as DataColumn
from .data import DataTable, Report
from .report import Block, Text, table

BLOCK = 1000
"""Records handed to a text sink (csv, json, xlsx) at a time: its Python objects for a block
(about 2 MB) are what such a format holds. A scan's CSV numbers are Python's repr
throughout (a streamed table's size is not known when it begins, so the writers' pyarrow
path, chosen per table by its size, is never taken). Parquet takes a chunk at a time (a row
group per chunk)."""

TABLE = "designs"
"""The name of the scan's one table (what a row is)."""

Column = tuple[str, str, str]  # a scan spec entry: name, kind (number, int, bool, text), unit


def scan_columns(spec: Sequence[Column],
                 cols: Mapping[str, np.ndarray] | None = None) -> tuple[DataColumn, ...]:
    """The spec as the registry's columns (name, unit, kind), holding ``cols``' values
    (none if not given)."""
    return tuple(DataColumn(name, unit, cols[name] if cols else (), kind) for name, kind, unit in spec)


def header(col: Column) -> str:
    """A column's header: ``name (unit)``, the bare name where it has no unit."""
    name, _, unit = col
    return DataColumn(name, unit).header


def pick_spec(spec: Sequence[Column], names: str) -> list[Column]:
    """``--columns``: the registry's rule (:func:`.writers.pick_columns`: ``design`` and
    the columns whose name or header begins with one of ``names``), on the scan's spec, so
    the stream writes only the picked columns. None matching: an InputError."""
    from .writers import pick_columns

    probe = Report("", (DataTable(TABLE, scan_columns(spec)),), lambda: ())
    kept = {c.name for c in pick_columns(probe, names).tables[0].columns}
    return [c for c in spec if c[0] in kept]


class RecordSink:
    """The scan's records in a data format (csv, json, parquet or xlsx) to ``path`` (None
    or "-": standard output): :func:`.writers.open_sink` with one table, ``designs``,
    whose JSON document (and parquet ``linkage`` metadata) is ``meta``. Use as a context
    manager; call with a chunk's columns (name -> array) as often as there are chunks;
    ``count`` is the records written."""

    def __init__(self, fmt_: str, path: Path | None, spec: Sequence[Column],
                 meta: Mapping[str, Any]) -> None:
        from ..errors import InputError
        from .writers import choose_format, data_formats, is_data

        if not is_data(fmt_):
            raise InputError(f"{fmt_} is not a data format; use {data_formats()}")
        choose_format(fmt_, path)  # the registry's refusals: binary to standard output, a missing extra
        self.fmt, self.path, self.spec, self.meta = fmt_, path, list(spec), dict(meta)
        self.to_stdout = path is None or str(path) == "-"
        self.count = 0
        self._stack = contextlib.ExitStack()

    def __enter__(self) -> RecordSink:
        from .writers import open_sink

        self._sink = self._stack.enter_context(open_sink(self.fmt, None if self.to_stdout else self.path,
                                                         self.meta))
        try:
            self._sink.begin(TABLE, scan_columns(self.spec))
        except BaseException:
            self._stack.__exit__(*sys.exc_info())
            raise
        return self

    def __call__(self, cols: Mapping[str, np.ndarray]) -> None:
        n = len(cols["design"])
        if not n:
            return
        step = n if self.fmt == "parquet" else BLOCK
        for a in range(0, n, step):
            self._sink.rows([cols[name][a:a + step] for name, _, _ in self.spec])
        self.count += n
        if self.to_stdout:  # a pipe sees each chunk as it is computed
            self._flush()

    def _flush(self) -> None:
        from ..errors import OutputError

        try:
            sys.stdout.flush()
        except OSError as exc:
            raise OutputError(f"cannot write to standard output: {exc.strerror or exc}") from None

    def __exit__(self, kind: Any, exc: Any, tb: Any) -> Any:
        if kind is None:
            try:
                self._sink.end()
            except BaseException:
                # the temporary file goes; the old file, if any, stays as it was
                self._stack.__exit__(*sys.exc_info())
                raise
        return self._stack.__exit__(kind, exc, tb)


def scan_blocks(cols: Mapping[str, np.ndarray], spec: Sequence[Column], summary: Sequence[str],
                digits: int) -> list[Block]:
    """The kept rows as a table, under the scan's summary lines."""
    blocks: list[Block] = [Text(summary[0], "bold"), *(Text(s) for s in summary[1:])]
    if cols and len(cols["design"]):
        cells = []
        for name, kind, _ in spec:
            v = cols[name].tolist()
            cells.append(["yes" if x else "no" for x in v] if kind == "bool" else
                         [None if isinstance(x, float) and not math.isfinite(x) else x for x in v])
        blocks.append(Text(""))
        blocks.append(table("", [header(c) for c in spec], list(zip(*cells)), digits))
    return blocks


def scan_report(cols: Mapping[str, np.ndarray], spec: Sequence[Column], summary: Sequence[str],
                digits: int, meta: Mapping[str, Any] | None = None) -> Report:
    """The kept rows (a table's worth, or every sorted row) as a Report: one table,
    ``designs``, and the display of :func:`scan_blocks`; ``meta`` is the JSON document."""
    held = cols if cols and len(cols.get("design", ())) else {name: np.array([]) for name, _, _ in spec}
    doc = dict(meta or {})
    return Report(summary[0], (DataTable(TABLE, scan_columns(spec, held)),),
                  lambda: scan_blocks(cols, spec, summary, digits), lambda: doc)


def scan_meta(m: Any, source: str, setup: Any, driver: tuple[float, float, float], where: str | None,
              sort: str | None, descending: bool, motion: tuple[float, float] = (0.0, 0.0)
              ) -> dict[str, Any]:
    """The scan's settings: the JSON document (the records go under its ``tables``) and
    parquet's ``linkage`` metadata; with loads, the loads (SI) and the driver's motion
    (internal units) the load columns are for."""
    start, stop, step = driver
    out = {"mechanism": m.name, "source": source, "branch": setup.branch,
           "driver": {"name": m.driver.name, "unit": m.driver.unit, "from": start, "to": stop,
                      "step": step, "positions": len(setup.values)},
           "where": where, "sort": sort, "descending": descending, "designs": setup.plan.total}
    loads = setup.loads
    if loads is not None:
        from ..problems.loads import applied_rows

        per_s = "rad/s" if m.driver.kind == "angle" else f"{m.length_unit}/s"
        out["loads"] = {
            "forces_N": {k: list(v) for k, v in loads.forces.items()},
            "forces_on": {row[0]: row[2] for row in applied_rows(loads, m.extra["drawing"])
                          if row[1] == "force"},
            "torques_N_m": dict(loads.torques),
            "masses": {k: {"mass_kg": v.mass, f"cg_{m.length_unit}": list(v.cg), "inertia_kg_m2": v.inertia}
                       for k, v in loads.masses.items()},
            "gravity_m_s2": None if loads.gravity is None else list(loads.gravity),
            "speed": motion[0], "accel": motion[1], "speed_unit": per_s, "accel_unit": f"{per_s}^2"}
    return out


def loads_line(m: Any, loads: Any, motion: tuple[float, float]) -> str:
    """One line saying which loads the load columns are for, each force's link named."""
    from ..problems.loads import applied_rows

    acting = [f"{row[0]} on {row[2]}" for row in applied_rows(loads, m.extra["drawing"]) if row[1] == "force"]
    parts = [f"{len(loads.forces)} force(s)" + (f" ({', '.join(acting)})" if acting else ""),
             f"{len(loads.torques)} torque(s)", f"{len(loads.masses)} mass(es)"]
    if loads.gravity is not None:
        parts.append(f"gravity ({loads.gravity[0]:g}, {loads.gravity[1]:g}) m/s^2")
    per_s = "rad/s" if m.driver.kind == "angle" else f"{m.length_unit}/s"
    moving = (f"driver at {motion[0]:.6g} {per_s}" + (f", {motion[1]:.6g} {per_s}^2" if motion[1] else "")
              if motion[0] else "static (no --speed)")
    return (f"loads: {', '.join(parts)}; {moving}; peaks over the positions whose forces are ok "
            "(forces_flagged: the others)")


def scan_summary(m: Any, setup: Any, driver: tuple[float, float, float], scanned: int, keeper: Any,
                 held: Mapping[str, np.ndarray], elapsed: float, shown: bool,
                 motion: tuple[float, float] = (0.0, 0.0)) -> list[str]:
    """The lines over the display (the first also ends a file's "wrote" line): designs
    scanned and kept, the driver range, branch and engine, and (``shown``) how many rows
    the display holds."""
    from ..kinematics.designs import ENGINES, engine_for

    start, stop, step = driver
    total, top, sort = setup.plan.total, keeper.top, keeper.sort
    engine = ENGINES[engine_for(m, setup.branch)]
    where_note = f"; {keeper.kept:,} pass --where" if setup.where is not None else ""
    stopped = f" (stopped early: the first {top} are final)" if scanned < total else ""
    branch = setup.branch or "the one the file's guess is on"
    lines = [f"{m.name}: {scanned:,} of {total:,} designs scanned{stopped}{where_note}; {elapsed:.2f} s",
             f"{len(setup.values)} positions each ({m.driver.name} {start:g}..{stop:g} "
             f"{m.driver.unit}, step {step:g}); branch: {branch}; engine: {engine}"]
    if setup.branch_note:
        lines.append(f"branch: {setup.branch_note}")
    if setup.loads is not None:
        lines.append(loads_line(m, setup.loads, motion))
    from .formats import FORMATS
    from .writers import is_data

    n_held = len(held["design"]) if held else 0
    if shown and n_held < keeper.kept:
        lines.append(f"showing {n_held} of {keeper.kept:,}"
                     + (f" by {sort}{' (largest first)' if keeper.descending else ''}" if sort else "")
                     + f"; --top K or --format {'/'.join(f for f in FORMATS if is_data(f))} for more")
    return lines
