"""Refusals a long command (bench, stress) makes before it runs, not after minutes of work."""

from pathlib import Path
from typing import Optional

from ..errors import InputError

DATA_FORMATS = ("csv", "json", "parquet", "xlsx")
"""The formats --table picks a table of (render.writers.pick_table)."""


def refuse_csv_to_stdout(fmt: str, output: Optional[Path], table: Optional[str],
                         tables: tuple[str, ...]) -> None:
    """What the writer would refuse after the run (render.writers.write), refused before it,
    with the same words: csv holds one table, so a report of several ``tables`` needs
    --table NAME on standard output, and NAME must be one of them."""
    if table is not None:
        if fmt in DATA_FORMATS and table.strip() not in tables:
            raise InputError(f"--table {table!r}: no such table; this report has {', '.join(tables)}")
        return
    if fmt == "csv" and (output is None or str(output) == "-") and len(tables) > 1:
        raise InputError(f"csv holds one table and this report has {len(tables)} ({', '.join(tables)}): "
                         "add --table NAME for one on standard output, or -o FILE.csv (one file each)")
