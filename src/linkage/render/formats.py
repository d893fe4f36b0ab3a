"""The output formats: one registry, :data:`FORMATS`, of each format's name, file suffixes,
writer (a :class:`~.cells.Sink`) and how it writes (whether it streams the tables or shows
the display, binary, one table per file, the package it needs). The command line's
--format choices, -o suffix detection and help are read from it (:mod:`.writers`): a new
format is a Sink here and its entry in FORMATS, nothing else.

- csv: a header row of ``name (unit)``, numbers as the shortest text that reads back to
  the same double, an empty cell where there is none: one table per file, so that any
  CSV reader (``pandas.read_csv``) reads it. A report of several tables written to a file
  puts the first at the path given and the others beside it as ``stem.name.csv``; on
  standard output it needs ``--table NAME``, and is refused without.
- json: the command's document, with the tables under ``tables``: for each, its name,
  column names, units and rows.
- parquet: one file per table (the first at the path given, the others beside it as
  ``stem.name.parquet``, as csv), each field's unit in its metadata.
- xlsx: one sheet per table, ``name (unit)`` in the header row, numbers as numbers.
- table, plain and tabulate's formats show the report's display blocks (render.display).
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Sequence
from typing import IO, Any

from ..errors import InputError
from ..records import NamedTuple
from . import cells
from .cells import (
    Sink,
    cell_texts,
    has_pyarrow,
    is_array,
    json_values,
    plain_values,
    quote_csv,
    safe_name,
)
from .data import Column, Report


class CsvSink(Sink):
    """One table per output: a second table goes to the file ``side(name)`` opens (the
    sidecar's temporary file, renamed with the first; writers.open_sink)."""

    def begin(self, name: str, columns: Sequence[Column], rows: int | None = None) -> None:
        super().begin(name, columns, rows)
        if self.tables > 1:
            if self.side is None:  # write() refuses this first; a caller of the sinks too
                raise InputError(f"csv holds one table: {name!r} is a second on standard output")
            self.out.flush()  # type: ignore[union-attr]
            self.out = self.side(safe_name(name))
        self.fast = rows is not None and rows * len(self.columns) >= cells.FAST_CELLS and has_pyarrow()
        self.out.write(",".join(quote_csv(c.header) for c in self.columns) + "\n")  # type: ignore[union-attr]

    @classmethod
    def modules(cls, rows: int | None) -> tuple[str, ...]:
        # the block path, from FAST_CELLS cells (every table has two columns at least),
        # its slices formatted on a thread pool (cells.csv_slices)
        return ("pyarrow.csv", "concurrent.futures") if cls.blocks(rows) else ()

    @classmethod
    def blocks(cls, rows: int | None) -> bool:
        """A table of ``rows`` rows may go through pyarrow's CSV writer (:meth:`rows`)."""
        return rows is not None and 2 * rows >= cells.FAST_CELLS

    def rows(self, values: Sequence[Any]) -> None:
        n = len(values[0]) if values else 0
        done = self._arrow_rows(values) if self.fast and n else 0
        if done:
            values = [v[done:] for v in values]  # the rest (text that needs quoting) cell by cell
        for a in range(0, n - done, cells.SLICE):
            b = min(n - done, a + cells.SLICE)
            texts = [cell_texts(c, v[a:b], self.fast) for c, v in zip(self.columns, values)]
            self.out.write("\n".join(map(",".join, zip(*texts))) + "\n")  # type: ignore[union-attr]
        self.count += n

    def _arrow_rows(self, values: Sequence[Any]) -> int:
        """Rows written by pyarrow's CSV writer (:func:`.cells.arrow_table`; 0 where it
        cannot), its slices formatted in one pass each (:func:`.cells.csv_slices`) and
        written in order into the file's bytes. A slice refused (text that needs quoting)
        stops it at that slice's first row, none of which is written."""
        if not cells.slices_ready(values):
            return 0
        binary = getattr(self.out, "buffer", None)  # a file or standard output: its bytes
        self.out.flush()  # type: ignore[union-attr]
        n = len(values[0])
        for a, text in cells.csv_slices(self.columns, values, n):
            if text is None:
                return a
            if binary is not None:
                binary.write(text)
            else:
                self.out.write(text.to_pybytes().decode("utf-8"))  # type: ignore[union-attr]
        return n


class JsonSink(Sink):
    """The document's keys, then ``"tables": [{"name", "columns", "units", "rows"}, ...]``."""

    def __init__(self, out: IO[Any] | None, path: str | None, meta: dict[str, Any] | None = None) -> None:
        super().__init__(out, path, meta)
        import json

        from .export import clean

        head = json.dumps(clean(self.meta), indent=2, allow_nan=False)
        self.out.write(head[:-1].rstrip() + (",\n" if self.meta else "") + '  "tables": [')  # type: ignore[union-attr]

    def begin(self, name: str, columns: Sequence[Column], rows: int | None = None) -> None:
        super().begin(name, columns, rows)
        spec = {"name": name, "columns": [c.name for c in self.columns],
                "units": [c.unit for c in self.columns]}
        import json

        text = json.dumps(spec, allow_nan=False)[:-1] + ', "rows": ['
        self.out.write(("," if self.tables > 1 else "") + "\n    " + text)  # type: ignore[union-attr]

    def rows(self, values: Sequence[Any]) -> None:
        n = len(values[0]) if values else 0
        for a in range(0, n, cells.SLICE):
            b = min(n, a + cells.SLICE)
            cols = [json_values(c, v[a:b]) for c, v in zip(self.columns, values)]
            import json

            text = ",".join("\n      " + json.dumps(r, allow_nan=False) for r in map(list, zip(*cols)))
            self.out.write(("," if self.count or a else "") + text)  # type: ignore[union-attr]
        self.count += n

    def end(self) -> None:
        self.out.write("\n    ]}" if self.count else "]}")  # type: ignore[union-attr]

    @classmethod
    def meta_of(cls, report: Report, files: Sequence[str]) -> dict[str, Any]:
        """The command's document (an object: the tables go under a key), else its title."""
        meta = report.document() if report.document is not None else {"title": report.title}
        return meta if isinstance(meta, dict) else {"title": report.title, "document": meta}

    def close(self) -> None:
        self.out.write("\n  ]\n}\n")  # type: ignore[union-attr]


class ParquetSink(Sink):
    """One parquet file per table: the first at the path, the others beside it."""

    @classmethod
    def modules(cls, rows: int | None) -> tuple[str, ...]:
        return (PARQUET_WRITER,)

    def __init__(self, out: IO[Any] | None, path: str | None, meta: dict[str, Any] | None = None) -> None:
        super().__init__(out, path, meta)
        self.writer: Any = None

    def begin(self, name: str, columns: Sequence[Column], rows: int | None = None) -> None:
        import pyarrow as pa

        super().begin(name, columns, rows)
        types = {"number": pa.float64(), "int": pa.int64(), "bool": pa.bool_(), "text": pa.string()}
        fields = [pa.field(c.name, types[c.kind], metadata={"unit": c.unit} if c.unit else None)
                  for c in self.columns]
        import json

        from .export import clean

        self.schema = pa.schema(fields, metadata={"linkage": json.dumps(clean({**self.meta, "table": name}))})
        target = self.path if self.tables == 1 or self.side is None else self.side(safe_name(name))
        # a dictionary only for text (a status, a branch: few distinct words); tried on
        # every column of doubles it costs 3x the write (0.40 s against 0.13 s for a
        # 360,001-position sweep) and saves nothing, as the doubles rarely repeat
        words = [c.name for c in self.columns if c.kind == "text"]
        self.writer = parquet_writer(target, self.schema, words or False)

    def rows(self, values: Sequence[Any]) -> None:
        import pyarrow as pa

        arrays = []
        for c, f, v in zip(self.columns, self.schema, values):
            if c.kind == "number" and not (is_array(v) and v.dtype.kind == "f"):
                import numpy as np  # NaN and infinities are no value, as in CSV and JSON

                v = np.asarray(v if is_array(v) else [math.nan if x is None else x for x in v], dtype=float)
            v = widened(c.kind, v)
            a = cells.arrow_array(c.kind, v)
            if a is None:
                a = pa.array(plain_values(v), type=f.type)
            arrays.append(a if a.type == f.type else a.cast(f.type))
        self.writer.write_table(pa.Table.from_arrays(arrays, schema=self.schema))
        self.count += len(values[0]) if values else 0

    def end(self) -> None:
        self.writer.close()
        self.writer = None

    @classmethod
    def meta_of(cls, report: Report, files: Sequence[str]) -> dict[str, Any]:
        """The title, and written to files which file holds each table: a rerun with fewer
        tables leaves the last run's sidecars beside it (nothing is deleted by pattern)."""
        tables = [t.name for t in report.tables if t.columns]
        return {"title": report.title, **({"files": dict(zip(tables, files))} if files else {})}

    def close(self) -> None:
        if self.tables == 0 and self.path is not None:  # no table: still a parquet file
            import json

            import pyarrow as pa

            from .export import clean

            schema = pa.schema([], metadata={"linkage": json.dumps(clean(self.meta))})
            parquet_writer(self.path, schema, True).close()
        self.abandon()

    def abandon(self) -> None:
        if self.writer is not None:
            with contextlib.suppress(Exception):
                self.writer.close()


def widened(kind: str, values: Any) -> Any:
    """An integer column (a sweep's iterations, int32) as int64, the parquet field's type,
    widened by numpy where every value fits (the same numbers): pyarrow's own cast imports
    pyarrow.compute, a large import in a fresh process, for a copy numpy makes directly.
    Any other column as it is (pyarrow casts it, and refuses what does not fit)."""
    if kind != "int" or not is_array(values) or values.dtype.kind not in "iu":
        return values
    import numpy as np

    if values.dtype == np.int64 or not np.can_cast(values.dtype, np.int64):
        return values
    return values.astype(np.int64)


PARQUET_WRITER = "pyarrow._parquet"
"""The module of pyarrow's Parquet writer itself. ``pyarrow.parquet`` wraps it, and imports
pyarrow.fs for the wrapper's filesystems (with ssl, urllib and S3's client: 0.05 s of a
fresh process, a sixth of a 360,001-position sweep's computing); a sink writes a local
file, which needs none of them."""
PARQUET_OPTIONS = {"version": "2.6", "compression": "snappy", "write_statistics": True,
                   "use_deprecated_int96_timestamps": False, "writer_engine_version": "V2",
                   "data_page_version": "1.0", "use_compliant_nested_type": True, "store_schema": True}
"""``pyarrow.parquet.ParquetWriter``'s defaults, as it hands them to the writer (pyarrow 14
to 26): the file's bytes are the wrapper's (tests/test_writers.py checks it)."""


class ParquetFile:
    """pyarrow's Parquet writer on a local file, and the file closed with it."""

    def __init__(self, path: str, schema: Any, use_dictionary: Any) -> None:
        import pyarrow as pa
        from pyarrow import _parquet  # pyarrow's own writer: see PARQUET_WRITER

        self.file = pa.OSFile(path, "wb")
        try:
            self.writer = _parquet.ParquetWriter(self.file, schema, use_dictionary=use_dictionary,
                                                 **PARQUET_OPTIONS)
        except BaseException:
            self.file.close()
            raise

    def write_table(self, table: Any) -> None:
        self.writer.write_table(table)

    def close(self) -> None:
        try:
            self.writer.close()
        finally:
            self.file.close()


def parquet_writer(path: str, schema: Any, use_dictionary: Any) -> Any:
    """A Parquet writer of ``schema`` to the local file ``path`` (``use_dictionary``: True,
    False or the columns to dictionary-encode), as ``pyarrow.parquet.ParquetWriter`` makes
    it, without the wrapper's imports (:data:`PARQUET_WRITER`); the wrapper itself where
    this pyarrow's writer takes other arguments."""
    try:
        return ParquetFile(path, schema, use_dictionary)
    except (ImportError, AttributeError, TypeError):  # a pyarrow whose private writer moved or changed
        import pyarrow.parquet as pq

        return pq.ParquetWriter(path, schema, use_dictionary=use_dictionary)


XLSX_ROWS = 1_048_575
"""Rows a sheet holds below its header row (Excel's limit)."""


class XlsxSink(Sink):
    @classmethod
    def modules(cls, rows: int | None) -> tuple[str, ...]:
        return ("openpyxl",)

    def __init__(self, out: IO[Any] | None, path: str | None, meta: dict[str, Any] | None = None) -> None:
        super().__init__(out, path, meta)
        from openpyxl import Workbook

        self.book = Workbook(write_only=True)
        self.sheet: Any = None

    def begin(self, name: str, columns: Sequence[Column], rows: int | None = None) -> None:
        super().begin(name, columns, rows)
        title = safe_name(name)[:31] or f"table {self.tables}"
        used = {s.title for s in self.book.worksheets}
        k = 1
        while title in used:  # two names alike in their first 31 characters
            k += 1
            title = f"{safe_name(name)[:31 - len(str(k)) - 1]} {k}"
        self.sheet = self.book.create_sheet(title=title)
        self.sheet.append([self._cell(c.header) for c in self.columns])

    def _cell(self, v: Any) -> Any:
        """Text as text: openpyxl makes a string beginning with "=" a formula (a joint
        named "=HYPERLINK(...)" in a mechanism file would be live in the workbook)."""
        if not (isinstance(v, str) and v.startswith("=")):
            return v
        from openpyxl.cell import WriteOnlyCell

        cell = WriteOnlyCell(self.sheet, value=v)
        cell.data_type = "s"
        return cell

    def rows(self, values: Sequence[Any]) -> None:
        n = len(values[0]) if values else 0
        if self.count + n > XLSX_ROWS:
            raise InputError(f"{self.count + n:,} rows is more than an xlsx sheet holds ({XLSX_ROWS:,}); "
                             "use csv or parquet")
        for a in range(0, n, cells.SLICE):
            b = min(n, a + cells.SLICE)
            cols = [json_values(c, v[a:b]) for c, v in zip(self.columns, values)]
            text = [j for j, c in enumerate(self.columns) if c.kind == "text"]
            for r in zip(*cols):
                if text:
                    r = tuple(self._cell(v) if j in text else v for j, v in enumerate(r))
                self.sheet.append(r)
        self.count += n

    def abandon(self) -> None:
        # each sheet's row stream closed here, not left to the garbage collector (which
        # printed "Exception ignored" tracebacks after an interrupt)
        for ws in self.book.worksheets:
            with contextlib.suppress(Exception):
                ws.close()

    def close(self) -> None:
        if self.sheet is None:
            self.book.create_sheet(title="empty")
        # saved in memory, then written: openpyxl saving straight to a full disk left its
        # half-closed zip to the garbage collector, which printed tracebacks after the error
        import io

        buf = io.BytesIO()
        self.book.save(buf)
        with open(self.path, "wb") as fh:  # type: ignore[arg-type]
            fh.write(buf.getbuffer())


class Format(NamedTuple):
    """One output format."""

    name: str
    suffixes: tuple[str, ...]
    """-o suffixes that choose it (the first is its own)."""
    sink: type[Sink] | None
    """Its writer; None: it shows the display blocks (render.display)."""
    binary: bool = False
    """Written to a file only, by its sink from the path."""
    one_table: bool = False
    """A file holds one table: a report's others go beside it (``stem.name.suffix``)."""
    needs: tuple[str, str] | None = None
    """The module it needs and how to install it."""
    help: str = ""

    @property
    def streams(self) -> bool:
        """Writes the report's tables, a block of rows at a time (else the display)."""
        return self.sink is not None


FORMATS: dict[str, Format] = {f.name: f for f in (
    Format("table", (), None, help="rich, default on a terminal"),
    Format("plain", (".txt", ""), None, help="default when piped"),
    Format("csv", (".csv",), CsvSink, one_table=True),
    Format("json", (".json",), JsonSink),
    Format("parquet", (".parquet",), ParquetSink, binary=True, one_table=True,
           needs=(PARQUET_WRITER, "pip install 'linkage-kinematics[scan]'")),
    Format("xlsx", (".xlsx",), XlsxSink, binary=True,
           needs=("openpyxl", "pip install 'linkage-kinematics[xlsx]'")),
)}
"""Every format of linkage's own, in the order help lists them."""
TABULATE_SUFFIXES = {".md": "github", ".tex": "latex", ".html": "html", ".rst": "rst"}
"""-o suffixes that choose one of tabulate's formats."""
COMMON_TABULATE = ("github", "grid", "latex", "latex_booktabs", "html", "rst", "tsv")
"""The tabulate formats an unknown --format names (the first eight by name were asciidoc,
colon_grid, double_grid, ...)."""
