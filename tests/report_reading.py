"""Reading our CSV back in tests: a report of one table is a plain CSV; of several, each
table under a "# name" line, a blank line between (render.writers.CsvSink)."""

from __future__ import annotations

import csv
import io


def csv_sections(text: str) -> dict[str, list[list[str]]]:
    """Table name -> its rows (the header first); "only" for a CSV of one table."""
    out: dict[str, list[list[str]]] = {}
    for part in text.split("\n\n"):
        lines = part.strip("\n").split("\n")
        name = lines[0][2:] if lines[0].startswith("# ") else "only"
        out[name] = list(csv.reader(io.StringIO("\n".join(lines[1:] if name != "only" else lines))))
    return out
