"""Reading our CSV back in tests: one table per file (render.formats.CsvSink), a report's
first table at the path given, each other beside it as ``stem.name.csv``."""

from __future__ import annotations

import csv
import io
from collections.abc import Sequence
from pathlib import Path


def csv_rows(text: str) -> list[list[str]]:
    """A CSV file's rows, the header first."""
    return list(csv.reader(io.StringIO(text)))


def csv_files(path: Path, names: Sequence[str]) -> dict[str, list[list[str]]]:
    """Table name -> its rows (the header first), for a report of the tables ``names``
    written to ``path``: the first there, the others in their sidecar files."""
    out = {}
    for k, name in enumerate(names):
        where = path if k == 0 else path.with_name(f"{path.stem}.{name}{path.suffix}")
        out[name] = csv_rows(where.read_text(encoding="utf-8"))
    return out
