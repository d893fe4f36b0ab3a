"""One report per command: its tables of numbers (each column with its name and unit) and
the blocks a terminal shows. Writers (:mod:`.writers`) read nothing else.

Numbers stay numbers here, at full double precision: a column holds floats (NaN or None
where there is no value), ints, booleans or text. Rounding happens in the display blocks
and nowhere else. The display and the JSON document are built only when a format needs
them (a 360,001-position sweep written to CSV never builds either).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from ..records import NamedTuple

KINDS = ("number", "int", "bool", "text")


# NamedTuples, not frozen dataclasses: every command's start pays for its classes
# (see render.report.Text).
class Column(NamedTuple):
    name: str
    """The bare name: JSON and parquet keys, --where, --sort and --columns use it."""
    unit: str = ""
    """"" for a count, a word or a dimensionless number."""
    values: Any = ()
    """A list, a tuple or a one-dimensional numpy array, one entry per row."""
    kind: str = "number"

    @property
    def header(self) -> str:
        """The name with its unit, as CSV, xlsx and the display write it: ``theta3 (deg)``."""
        return f"{self.name} ({self.unit})" if self.unit else self.name


class DataTable(NamedTuple):
    name: str
    """What a row is: iterations, positions, designs, joints, rates, ..."""
    columns: tuple[Column, ...]

    @property
    def row_count(self) -> int:  # not __len__: a NamedTuple's own length is its fields'
        return len(self.columns[0].values) if self.columns else 0


class Report(NamedTuple):
    title: str
    """One line saying what this is (a LaTeX table's caption, the JSON's ``title``)."""
    tables: tuple[DataTable, ...]
    blocks: Callable[[], Sequence[Any]]
    """The terminal's view (render.report Text and Table blocks), built when shown."""
    document: Callable[[], Any] | None = None
    """The command's JSON document (a dict), built when JSON is written; the tables are
    added to it under ``tables``."""


def column(name: str, unit: str, values: Any, kind: str = "number") -> Column:
    if kind not in KINDS:
        raise ValueError(f"column kind {kind!r} is not one of {KINDS}")
    return Column(name, unit, values, kind)


def from_rows(name: str, headers: Sequence[tuple[str, str, str]], rows: Sequence[Sequence[Any]]) -> DataTable:
    """A table from rows (a small table: an iteration history, a summary), given each
    column's (name, unit, kind)."""
    cols = list(zip(*rows)) if rows else [() for _ in headers]
    return DataTable(name, tuple(Column(n, u, list(v), k) for (n, u, k), v in zip(headers, cols)))


def split_header(header: str) -> tuple[str, str]:
    """``"theta3 (deg)"`` -> ("theta3", "deg"); a header without a unit -> (header, "")."""
    if header.endswith(")") and " (" in header:
        name, _, unit = header[:-1].rpartition(" (")
        return name, unit
    return header, ""


def from_history(name: str, columns: Sequence[str], rows: Sequence[Sequence[Any]]) -> DataTable:
    """An iteration history (headers such as ``x (deg)``) as a table; each column's kind
    read from its values."""
    def kind(j: int) -> str:
        seen = [r[j] for r in rows if r[j] is not None]
        if seen and all(isinstance(v, bool) for v in seen):
            return "bool"
        if seen and all(isinstance(v, int) and not isinstance(v, bool) for v in seen):
            return "int"
        if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in seen):
            return "number"
        return "text"

    return from_rows(name, [(*split_header(h), kind(j)) for j, h in enumerate(columns)], rows)
