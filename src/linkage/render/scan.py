"""Scan records out: CSV, JSON (a list of records) and Parquet written chunk by chunk, and
the table of the top rows.

A file is written to a temporary name beside it and renamed only when the scan is
complete, so a failed or interrupted scan never leaves a half-written file; standard
output receives each chunk as it is computed. CSV headers carry units (``r2 (mm)``);
JSON keys and Parquet columns are the bare names that ``--where`` and ``--sort`` use,
Parquet with each unit in its field's metadata.
"""

from __future__ import annotations

import contextlib
import csv
import json
import math
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import IO, Any

import numpy as np

from ..errors import InputError, OutputError
from .report import Block, Text, table

SLICE = 2048
"""Records formatted at a time."""

Column = tuple[str, str, str]  # name, type (number, int, bool, text), unit


def header(col: Column) -> str:
    name, _, unit = col
    return f"{name} ({unit})" if unit and not name.endswith(f"_{unit}") else name


def _cells(cols: Mapping[str, np.ndarray], spec: Sequence[Column]) -> list[list[Any]]:
    """Each column as Python values: floats at full precision, None for NaN."""
    out = []
    for name, kind, _ in spec:
        v = cols[name]
        if kind == "number":
            out.append([x if math.isfinite(x) else None for x in v.tolist()])
        else:
            out.append(v.tolist())
    return out


class RecordSink:
    """Writes records in ``fmt`` (csv, json or parquet) to ``path`` (None: standard output)."""

    def __init__(self, fmt_: str, path: Path | None, spec: Sequence[Column],
                 meta: Mapping[str, Any]) -> None:
        if fmt_ == "parquet" and path is None:
            raise InputError("parquet is a binary format: give -o FILE.parquet")
        self.fmt, self.path, self.spec, self.meta = fmt_, path, list(spec), dict(meta)
        self.count = 0
        self._stack = contextlib.ExitStack()
        self._fh: IO[str] | None = None
        self._parquet: Any = None

    def __enter__(self) -> RecordSink:
        if self.fmt == "parquet":
            try:
                import pyarrow.parquet  # noqa: F401
            except ImportError:
                raise InputError("parquet output needs pyarrow: pip install "
                                 "'linkage-kinematics[scan]'") from None
        if self.path is not None:
            from ..files import atomic_target

            self._tmp = self._stack.enter_context(atomic_target(self.path))
            if self.fmt != "parquet":
                self._fh = self._stack.enter_context(open(self._tmp, "w", encoding="utf-8", newline=""))
        else:
            self._fh = sys.stdout
        if self.fmt == "csv":
            self._csv = csv.writer(self._fh, lineterminator="\n")
            self._write(lambda: self._csv.writerow([header(c) for c in self.spec]))
        elif self.fmt == "json":
            self._write(lambda: self._fh.write("["))  # type: ignore[union-attr]
        return self

    def _write(self, action: Any) -> None:
        try:
            action()
        except OSError as exc:
            where = self.path if self.path is not None else "standard output"
            raise OutputError(f"cannot write to {where}: {exc.strerror or exc}") from None

    def __call__(self, cols: Mapping[str, np.ndarray]) -> None:
        n = len(cols["design"])
        for a in range(0, n, SLICE):  # Python objects for a slice at a time, never a chunk
            self._slice({k: v[a:a + SLICE] for k, v in cols.items()})

    def _slice(self, cols: Mapping[str, np.ndarray]) -> None:
        n = len(cols["design"])
        if self.fmt == "parquet":
            self._write(lambda: self._write_parquet(cols))
        else:
            columns = _cells(cols, self.spec)
            rows = list(zip(*columns))
            if self.fmt == "csv":
                fix = [i for i, c in enumerate(self.spec) if c[1] == "bool"]
                if fix:
                    rows = [tuple(("true" if v else "false") if i in fix else v for i, v in enumerate(r))
                            for r in rows]
                self._write(lambda: self._csv.writerows(
                    [["" if v is None else repr(v) if isinstance(v, float) else v for v in r] for r in rows]))
            else:
                names = [c[0] for c in self.spec]
                text = ("," if self.count else "") + ",".join(
                    "\n  " + json.dumps(dict(zip(names, r)), allow_nan=False) for r in rows)
                self._write(lambda: self._fh.write(text))  # type: ignore[union-attr]
            if self.path is None:
                self._write(sys.stdout.flush)
        self.count += n

    def _write_parquet(self, cols: Mapping[str, np.ndarray]) -> None:
        import pyarrow as pa

        if self._parquet is None:
            self._open_parquet()
        arrays = []
        for (name, kind, _), f in zip(self.spec, self._schema):
            v = cols[name]
            arrays.append(pa.array(v.tolist() if kind == "text" else v, type=f.type,
                                   from_pandas=kind == "number"))
        self._parquet.write_table(pa.Table.from_arrays(arrays, schema=self._schema))

    def __exit__(self, kind: Any, exc: Any, tb: Any) -> Any:
        if kind is None:
            try:
                self._finish()
            except BaseException:
                # the temporary file goes; the old file, if any, stays as it was
                self._stack.__exit__(*sys.exc_info())
                raise
        elif self._parquet is not None:
            with contextlib.suppress(Exception):
                self._parquet.close()
        return self._stack.__exit__(kind, exc, tb)

    def _finish(self) -> None:
        if self.fmt == "json":
            self._write(lambda: self._fh.write("\n]\n" if self.count else "]\n"))  # type: ignore[union-attr]
        elif self.fmt == "parquet":
            if self._parquet is None:  # no record: a valid file with the columns
                self._write(self._open_parquet)
            self._write(self._parquet.close)
        if self.path is None:
            self._write(sys.stdout.flush)

    def _open_parquet(self) -> None:
        import pyarrow as pa
        import pyarrow.parquet as pq

        types = {"number": pa.float64(), "int": pa.int64(), "bool": pa.bool_(), "text": pa.string()}
        fields = [pa.field(n, types[k], metadata={"unit": u} if u else None) for n, k, u in self.spec]
        self._schema = pa.schema(fields, metadata={"linkage": json.dumps(self.meta)})
        self._parquet = pq.ParquetWriter(self._tmp, self._schema)


def scan_blocks(cols: Mapping[str, np.ndarray], spec: Sequence[Column], summary: Sequence[str],
                digits: int) -> list[Block]:
    """The kept rows as a table, under the scan's summary lines."""
    blocks: list[Block] = [Text(summary[0], "bold"), *(Text(s) for s in summary[1:])]
    if cols and len(cols["design"]):
        cells = _cells(cols, spec)
        rows = [tuple(("yes" if v else "no") if k == "bool" else v for v, (_, k, _u) in zip(r, spec))
                for r in zip(*cells)]
        blocks.append(Text(""))
        blocks.append(table("", [header(c) for c in spec], rows, digits))
    return blocks
