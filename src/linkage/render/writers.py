"""One registry of output formats; each writes a :class:`~.data.Report`.

Display formats (table, plain and tabulate's) show the report's blocks. Data formats
(csv, json, parquet, xlsx) write its tables, every column with its unit, streamed a block
of rows at a time (never one Python object per cell of a large table):

- csv: a header row of ``name (unit)``, numbers as the shortest text that reads back to
  the same double, an empty cell where there is none: one table per file, so that any
  CSV reader (``pandas.read_csv``) reads it. A report of several tables written to a file
  puts the first at the path given and the others beside it as ``stem.name.csv``; on
  standard output it needs ``--table NAME`` (:func:`pick_table`), and is refused without.
- json: the command's document, with the tables under ``tables``: for each, its name,
  column names, units and rows.
- parquet: one file per table (the first at the path given, the others beside it as
  ``stem.name.parquet``, as csv), each field's unit in its metadata.
- xlsx: one sheet per table, ``name (unit)`` in the header row, numbers as numbers.

A file is written to a temporary name beside it and renamed when complete
(:func:`~linkage.files.atomic_target`): a failed or interrupted run leaves no
half-written file (nor sidecar: each is renamed only when the whole report is written).
``--table NAME`` keeps one table of any data format (:func:`pick_table`).
"""

from __future__ import annotations

import contextlib
import math
import sys
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import IO, Any, NamedTuple

from ..errors import InputError, OutputError
from .data import Column, DataTable, Report


class Format(NamedTuple):
    name: str
    suffixes: tuple[str, ...]
    data: bool  # writes the tables (else the display blocks)
    binary: bool = False
    help: str = ""


OWN_FORMATS = {f.name: f for f in (
    Format("table", (), False, help="rich, on a terminal"),
    Format("plain", (".txt", ""), False, help="headers over a rule"),
    Format("csv", (".csv",), True),
    Format("json", (".json",), True),
    Format("parquet", (".parquet",), True, binary=True, help="needs pyarrow"),
    Format("xlsx", (".xlsx",), True, binary=True, help="needs openpyxl"),
)}
TABULATE_SUFFIXES = {".md": "github", ".tex": "latex", ".html": "html", ".rst": "rst"}
EXTRAS = {"parquet": ("pyarrow.parquet", "pip install 'linkage-kinematics[scan]'"),
          "xlsx": ("openpyxl", "pip install 'linkage-kinematics[xlsx]'")}
COMMON_TABULATE = ("github", "grid", "latex", "latex_booktabs", "html", "rst", "tsv")
"""The tabulate formats an unknown --format names (the first eight by name were asciidoc,
colon_grid, double_grid, ...)."""
SLICE = 8192
"""Rows formatted at a time."""
FAST_CELLS = 200_000
"""From this many cells in a table, CSV numbers are formatted by pyarrow when it is
installed; the choice is made once per table, so a column's numbers read alike throughout."""


def tabulate_formats() -> list[str]:
    from tabulate import tabulate_formats as names

    return [n for n in names if n not in OWN_FORMATS]


def suffix_map() -> dict[str, str]:
    out = {s: f.name for f in OWN_FORMATS.values() for s in f.suffixes}
    return {**out, **TABULATE_SUFFIXES}


def known_suffixes() -> str:
    return ", ".join(f"{s} ({n})" for s, n in suffix_map().items() if s)


def choose_format(fmt: str | None, output: Path | None, *, terminal: bool | None = None) -> str:
    """The format of this run: --format if given (checked), else -o's suffix, else table on
    a terminal and plain when piped. An unknown format or suffix, or a binary format for
    standard output, is an InputError naming what works."""
    to_stdout = output is None or str(output) == "-"
    if fmt is not None:
        fmt = fmt.strip().lower()  # --format CSV as --format csv, as a suffix .CSV is .csv
    if fmt is None:
        if not to_stdout:
            suffix = output.suffix.lower()  # type: ignore[union-attr]
            chosen = suffix_map().get(suffix)
            if chosen is None:
                raise InputError(f"-o {output}: unknown suffix {suffix}; use {known_suffixes()}, "
                                 "or --format NAME (any format to any file name)")
            fmt = chosen
        else:
            tty = sys.stdout.isatty() if terminal is None else terminal
            fmt = "table" if tty else "plain"
    elif fmt not in OWN_FORMATS and fmt not in tabulate_formats():
        raise InputError(f"unknown format {fmt!r}; use {', '.join(OWN_FORMATS)} or a tabulate format "
                         f"({', '.join(f for f in COMMON_TABULATE if f in tabulate_formats())}, ...)")
    if to_stdout and fmt in OWN_FORMATS and OWN_FORMATS[fmt].binary:
        raise InputError(f"{fmt} is a binary format: give -o FILE.{fmt}")
    if fmt in EXTRAS:
        module, how = EXTRAS[fmt]
        try:
            __import__(module)
        except ImportError:
            raise InputError(f"{fmt} output needs {module.split('.')[0]}: {how}") from None
    return fmt


def is_data(fmt: str) -> bool:
    return fmt in OWN_FORMATS and OWN_FORMATS[fmt].data


# --- cells ----------------------------------------------------------------------------------

def number_texts(values: Any, fast: bool = False) -> list[str]:
    """Each number as the shortest text that reads back to the same double: Python's repr,
    or with ``fast`` (a large table, pyarrow installed) pyarrow's shortest form (``100``
    where repr says ``100.0``, ``0.000012345`` for ``1.2345e-05``); both read back bit for
    bit. "" for NaN, infinities and None."""
    if fast and _is_array(values) and values.dtype.kind == "f" and _pyarrow():
        import numpy as np
        import pyarrow as pa
        import pyarrow.compute as pc

        finite = np.isfinite(values)
        arr = pa.array(values, mask=~finite)
        return pc.fill_null(pc.cast(arr, pa.string()), "").to_pylist()  # type: ignore[no-any-return]
    seq = _plain(values)
    return ["" if v is None or (isinstance(v, float) and not math.isfinite(v)) else
            repr(v) if isinstance(v, float) else str(v) for v in seq]


def _is_array(values: Any) -> bool:
    return hasattr(values, "dtype") and hasattr(values, "tolist")


def _plain(values: Any) -> list[Any]:
    """The values as Python objects: an array's ``tolist``; in a list, numpy scalars (a
    median, a ratio) as Python numbers (numpy 2's repr of one is ``np.float64(0.1)``, and
    json cannot encode ``np.int64``)."""
    if _is_array(values):
        return values.tolist()  # type: ignore[no-any-return]
    return [v.item() if _is_array(v) else v for v in values]


_HAS_PYARROW: list[bool] = []


def _pyarrow() -> bool:
    if not _HAS_PYARROW:
        try:
            import pyarrow.compute  # noqa: F401
            _HAS_PYARROW.append(True)
        except ImportError:
            _HAS_PYARROW.append(False)
    return _HAS_PYARROW[0]


def _quote(text: str) -> str:
    if any(c in text for c in ',"\n\r'):
        return '"' + text.replace('"', '""') + '"'
    return text


def cell_texts(col: Column, values: Any, fast: bool = False) -> list[str]:
    """One column's cells as CSV text."""
    if col.kind == "number":
        return number_texts(values, fast)
    seq = _plain(values)
    if col.kind == "bool":
        return ["" if v is None else "true" if v else "false" for v in seq]
    if col.kind == "int":
        return ["" if v is None else str(int(v)) for v in seq]
    return ["" if v is None else _quote(str(v)) for v in seq]


def json_values(col: Column, values: Any) -> list[Any]:
    seq = _plain(values)
    if col.kind == "number":
        return [v if v is None or isinstance(v, int) or math.isfinite(v) else None for v in seq]
    if col.kind == "bool":
        return [None if v is None else bool(v) for v in seq]
    return seq


# --- sinks: a table at a time, a block of rows at a time --------------------------------------

class Sink:
    """Writes tables to one output: ``begin(name, columns)``, ``rows(values)`` (one
    sequence per column, any number of times), ``end()``; ``close()`` finishes the output."""

    def __init__(self, out: IO[Any] | None, path: str | None, meta: dict[str, Any] | None = None) -> None:
        self.out, self.path, self.meta = out, path, meta or {}
        self.count = 0  # rows written in the current table
        self.tables = 0
        self.columns: tuple[Column, ...] = ()

    def begin(self, name: str, columns: Sequence[Column], rows: int | None = None) -> None:
        """A new table; ``rows``, when known, its number of rows."""
        self.name, self.columns, self.count = name, tuple(columns), 0
        self.tables += 1

    def rows(self, values: Sequence[Any]) -> None:
        raise NotImplementedError

    def end(self) -> None:
        return None

    def close(self) -> None:
        return None

    def abandon(self) -> None:
        """Stop after a failure or an interrupt: release what is open, finish nothing (the
        temporary file is removed)."""
        return None


class CsvSink(Sink):
    """One table per output: a second table goes to the file ``paths(name)`` returns (the
    sidecar's temporary file, renamed with the first; :func:`open_sink`)."""

    def __init__(self, out: IO[Any] | None, path: str | None, meta: dict[str, Any] | None = None,
                 paths: Callable[[str], IO[Any]] | None = None) -> None:
        super().__init__(out, path, meta)
        self.paths = paths

    def begin(self, name: str, columns: Sequence[Column], rows: int | None = None) -> None:
        super().begin(name, columns, rows)
        if self.tables > 1:
            if self.paths is None:  # write() refuses this first; a caller of the sinks too
                raise InputError(f"csv holds one table: {name!r} is a second on standard output")
            self.out.flush()  # type: ignore[union-attr]
            self.out = self.paths(safe_name(name))
        self.fast = rows is not None and rows * len(self.columns) >= FAST_CELLS and _pyarrow()
        self.out.write(",".join(_quote(c.header) for c in self.columns) + "\n")  # type: ignore[union-attr]

    def rows(self, values: Sequence[Any]) -> None:
        n = len(values[0]) if values else 0
        done = self._arrow_rows(values) if self.fast and n else 0
        if done:
            values = [v[done:] for v in values]  # the rest (text that needs quoting) cell by cell
        for a in range(0, n - done, SLICE):
            b = min(n - done, a + SLICE)
            cells = [cell_texts(c, v[a:b], self.fast) for c, v in zip(self.columns, values)]
            self.out.write("\n".join(map(",".join, zip(*cells))) + "\n")  # type: ignore[union-attr]
        self.count += n

    def _arrow_rows(self, values: Sequence[Any]) -> int:
        """Rows written by pyarrow's CSV writer (:func:`arrow_table`; 0 where it cannot), a
        window of rows formatted in one pass then written into the file's bytes. A window
        refused (text that needs quoting) stops it at that window's first row, none of which
        is written. One thread: formatting side by side on two threads measured slower on
        this shared machine (benchmarks/writers_speed.py) and costs the same CPU."""
        table = arrow_table(self.columns, values)
        if table is None:
            return 0
        binary = getattr(self.out, "buffer", None)  # a file or standard output: its bytes
        self.out.flush()  # type: ignore[union-attr]
        for a in range(0, table.num_rows, CSV_WINDOW):
            text = csv_bytes(table.slice(a, CSV_WINDOW))
            if text is None:
                return a
            if binary is not None:
                binary.write(text)
            else:
                self.out.write(text.to_pybytes().decode("utf-8"))  # type: ignore[union-attr]
        return table.num_rows


CSV_WINDOW = 16 * SLICE
"""Rows formatted before they are written: their text (about 30 MB for a sweep's 18
columns) is all a CSV holds at once."""


def csv_bytes(table: Any) -> Any:
    """A table's rows as CSV (no header, nothing quoted) in a pyarrow buffer; None where a
    text cell needs quoting (pyarrow refuses it: the caller goes cell by cell)."""
    import pyarrow as pa
    import pyarrow.csv as pcsv

    out = pa.BufferOutputStream()
    try:
        pcsv.write_csv(table, out, pcsv.WriteOptions(include_header=False, quoting_style="none",
                                                     batch_size=ARROW_BATCH))
    except pa.ArrowInvalid:
        return None
    return out.getvalue()


ARROW_BATCH = 4 * SLICE
"""Rows pyarrow's CSV writer formats at a time (its write to the file between batches)."""


def arrow_table(columns: Sequence[Column], values: Sequence[Any]) -> Any:
    """A block of rows as a pyarrow table whose CSV text (``quoting_style="none"``) is the
    cells :func:`cell_texts` makes with pyarrow's numbers (tests check it): numbers
    NaN and infinities masked (no value), integers, booleans and text as they are; None
    where a column is not a numpy array of its kind (the caller goes cell by cell). Text
    that needs quoting is refused by the writer itself, before it writes a row."""
    import numpy as np
    import pyarrow as pa

    arrays = []
    for c, v in zip(columns, values):
        kind = v.dtype.kind if _is_array(v) else ""
        if c.kind == "number" and kind == "f":
            arrays.append(pa.array(v, mask=~np.isfinite(v)))
        elif (c.kind == "int" and kind in "iu" and kind) or (c.kind == "bool" and kind == "b"):
            arrays.append(pa.array(v))
        elif c.kind == "text" and kind in ("O", "U", ""):
            try:
                arrays.append(pa.array(v, type=pa.string()))
            except (pa.ArrowException, TypeError):  # not text throughout
                return None
        else:
            return None
    return pa.Table.from_arrays(arrays, names=[str(j) for j in range(len(arrays))])


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
        for a in range(0, n, SLICE):
            b = min(n, a + SLICE)
            cols = [json_values(c, v[a:b]) for c, v in zip(self.columns, values)]
            import json

            text = ",".join("\n      " + json.dumps(r, allow_nan=False) for r in map(list, zip(*cols)))
            self.out.write(("," if self.count or a else "") + text)  # type: ignore[union-attr]
        self.count += n

    def end(self) -> None:
        self.out.write("\n    ]}" if self.count else "]}")  # type: ignore[union-attr]

    def close(self) -> None:
        self.out.write("\n  ]\n}\n")  # type: ignore[union-attr]


class ParquetSink(Sink):
    """One parquet file per table: the first at the path, the others beside it."""

    def __init__(self, out: IO[Any] | None, path: str | None, meta: dict[str, Any] | None = None,
                 paths: Callable[[str], str] | None = None) -> None:
        super().__init__(out, path, meta)
        self.paths = paths
        self.writer: Any = None

    def begin(self, name: str, columns: Sequence[Column], rows: int | None = None) -> None:
        import pyarrow as pa
        import pyarrow.parquet as pq

        super().begin(name, columns, rows)
        types = {"number": pa.float64(), "int": pa.int64(), "bool": pa.bool_(), "text": pa.string()}
        fields = [pa.field(c.name, types[c.kind], metadata={"unit": c.unit} if c.unit else None)
                  for c in self.columns]
        import json

        from .export import clean

        self.schema = pa.schema(fields, metadata={"linkage": json.dumps(clean({**self.meta, "table": name}))})
        target = self.path if self.tables == 1 or self.paths is None else self.paths(safe_name(name))
        # a dictionary only for text (a status, a branch: few distinct words); tried on
        # every column of doubles it costs 3x the write (0.40 s against 0.13 s for a
        # 360,001-position sweep) and saves nothing, as the doubles rarely repeat
        words = [c.name for c in self.columns if c.kind == "text"]
        self.writer = pq.ParquetWriter(target, self.schema, use_dictionary=words or False)

    def rows(self, values: Sequence[Any]) -> None:
        import pyarrow as pa

        arrays = []
        for c, f, v in zip(self.columns, self.schema, values):
            if c.kind == "number":  # NaN and infinities are no value, as in CSV and JSON
                import numpy as np

                x = np.asarray(v if _is_array(v) else [math.nan if x is None else x for x in v], dtype=float)
                arrays.append(pa.array(x, type=f.type, mask=~np.isfinite(x)))
            else:
                arrays.append(pa.array(v.tolist() if _is_array(v) else list(v), type=f.type))
        self.writer.write_table(pa.Table.from_arrays(arrays, schema=self.schema))
        self.count += len(values[0]) if values else 0

    def end(self) -> None:
        self.writer.close()
        self.writer = None

    def close(self) -> None:
        if self.tables == 0 and self.path is not None:  # no table: still a parquet file
            import json

            import pyarrow as pa
            import pyarrow.parquet as pq

            from .export import clean

            schema = pa.schema([], metadata={"linkage": json.dumps(clean(self.meta))})
            pq.ParquetWriter(self.path, schema).close()
        self.abandon()

    def abandon(self) -> None:
        if self.writer is not None:
            with contextlib.suppress(Exception):
                self.writer.close()


XLSX_ROWS = 1_048_575
"""Rows a sheet holds below its header row (Excel's limit)."""


class XlsxSink(Sink):
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
        for a in range(0, n, SLICE):
            b = min(n, a + SLICE)
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


UNSAFE = frozenset('[]:*?/\\\0')
"""Characters an xlsx sheet name or a file name cannot hold."""


def safe_name(table: str) -> str:
    """A table's name as a sheet and a sidecar file name: ``_`` for each unsafe character."""
    return "".join("_" if c in UNSAFE else c for c in table)


def _sidecar(path: str) -> Callable[[str], str]:
    def name(table: str) -> str:
        p = Path(path)
        return str(p.with_name(f"{p.stem}.{safe_name(table)}{p.suffix}"))
    return name


SIDECAR_FORMATS = ("csv", "parquet")
"""The formats that hold one table per file: a report's others go beside the first."""


@contextlib.contextmanager
def open_sink(fmt: str, output: Path | None, meta: dict[str, Any] | None = None) -> Iterator[Sink]:
    """A sink for a data format, to ``output`` (None or "-": standard output), finished and
    renamed into place only if the block completes; csv and parquet put a second table
    in a sidecar file (:func:`side_paths`), renamed with the first."""
    to_stdout = output is None or str(output) == "-"
    kinds = {"csv": CsvSink, "json": JsonSink, "parquet": ParquetSink, "xlsx": XlsxSink}
    try:
        with contextlib.ExitStack() as stack:
            if to_stdout:
                sink: Sink = kinds[fmt](sys.stdout, None, meta)
                yield sink
                sink.close()
                sys.stdout.flush()
                return
            from ..files import atomic_target

            tmp = stack.enter_context(atomic_target(output))  # type: ignore[arg-type]
            if fmt in ("parquet", "xlsx"):
                sink = kinds[fmt](None, tmp, meta)
                if isinstance(sink, ParquetSink):
                    sink.paths = lambda t: _extra_target(stack, output, t)  # type: ignore[arg-type]
                try:
                    yield sink
                except BaseException:
                    sink.abandon()  # an interrupt stays an interrupt, and nothing is saved
                    raise
                sink.close()
            else:
                fh = stack.enter_context(open(tmp, "w", encoding="utf-8", newline=""))
                sink = kinds[fmt](fh, tmp, meta)
                if isinstance(sink, CsvSink):
                    sink.paths = lambda t: stack.enter_context(  # type: ignore[arg-type]
                        open(_extra_target(stack, output, t), "w", encoding="utf-8", newline=""))
                yield sink
                sink.close()
                sink.out.flush()  # type: ignore[union-attr]
    except OSError as exc:
        where = "standard output" if to_stdout else str(output)
        raise OutputError(f"cannot write to {where}: {exc.strerror or exc}") from None


def _extra_target(stack: contextlib.ExitStack, output: Path, table: str) -> str:
    """A sidecar file's temporary path, renamed into place (synced) with the main file."""
    from ..files import atomic_target

    final = Path(_sidecar(str(output))(table))
    return stack.enter_context(atomic_target(final))


def side_paths(output: Path, report: Report) -> list[Path]:
    """The files a csv or parquet report of several tables writes beside ``output``."""
    return [Path(_sidecar(str(output))(t.name)) for t in [t for t in report.tables if t.columns][1:]]


PROGRESS_ROWS = 16 * SLICE
"""Rows handed to a sink at a time when a progress bar is shown."""


def write_tables(sink: Sink, tables: Sequence[DataTable],
                 progress: Callable[[int], None] | None = None) -> None:
    """Every table into ``sink``; ``progress(rows written so far)`` after each block. A
    column made as it is read (its values with a ``block`` attribute: a sweep's rates,
    render.sweep.CellColumn) sets the rows handed over at a time, so no more than a block
    of it is ever made."""
    done = 0
    for t in tables:
        n = t.row_count
        sink.begin(t.name, t.columns, n)
        step = PROGRESS_ROWS if progress is not None else max(n, 1)
        blocks = [b for b in (getattr(c.values, "block", None) for c in t.columns) if b]
        if blocks:
            step = min(step, *blocks)
        for a in range(0, n, step):
            whole = step >= n
            sink.rows([c.values if whole else c.values[a:a + step] for c in t.columns])
            done += min(step, n - a)
            if progress is not None:
                progress(done)
        sink.end()


# --- the one entry point --------------------------------------------------------------------

def write(report: Report, fmt: str, output: Path | None, *,
          progress: Callable[[int], None] | None = None, table: str | None = None) -> None:
    """Write ``report`` in ``fmt`` to ``output`` (None or "-": standard output);
    ``progress(rows written)`` as a data format's rows go out; ``table`` (--table) keeps
    that one of the report's tables (:func:`pick_table`)."""
    to_stdout = output is None or str(output) == "-"
    sides: list[Path] = []  # a csv or parquet report's sidecar files
    if table is not None:
        report = pick_table(report, fmt, table)
    if is_data(fmt):
        tables = [t for t in report.tables if t.columns]
        if fmt == "csv" and to_stdout and len(tables) > 1:
            names = ", ".join(t.name for t in tables)
            raise InputError(f"csv holds one table and this report has {len(tables)} ({names}): add "
                             "--table NAME for one on standard output, or -o FILE.csv (one file each)")
        meta = report.document() if (fmt == "json" and report.document is not None) else \
            {"title": report.title} if fmt in ("json", "parquet") else {}
        if not isinstance(meta, dict):  # the tables go under a key: the document must be an object
            meta = {"title": report.title, "document": meta}
        to_side_files = fmt in SIDECAR_FORMATS and not to_stdout
        sides = side_paths(output, report) if to_side_files else []  # type: ignore[arg-type]
        if fmt == "parquet" and not to_stdout:
            # which files are this report's: a rerun with fewer tables leaves the last
            # run's sidecars beside it (nothing is deleted by pattern)
            files = [Path(str(output)).name] + [p.name for p in sides]
            meta = {**meta, "files": dict(zip([t.name for t in tables], files))}
        with open_sink(fmt, output, meta) as sink:
            write_tables(sink, tables, progress)
    else:
        from .display import display_text, print_table

        if fmt == "table" and to_stdout:
            try:
                print_table(report)
            except OSError as exc:
                raise OutputError(f"cannot write to standard output: {exc.strerror or exc}") from None
            return
        text = display_text(report, "plain" if fmt == "table" else fmt)
        if to_stdout:
            try:
                sys.stdout.write(text)
                sys.stdout.flush()
            except OSError as exc:
                raise OutputError(f"cannot write to standard output: {exc.strerror or exc}") from None
            return
        from ..files import write_atomic

        write_atomic(output, text)  # type: ignore[arg-type]
    if not to_stdout:
        made = [str(output)] + [str(p) for p in sides]
        print(f"wrote {', '.join(made)}", file=sys.stderr)


def pick_table(report: Report, fmt: str, name: str) -> Report:
    """``--table NAME``: the report with that one of its tables (any data format; the
    display formats show the whole report and refuse it). A name that is not one of the
    report's tables is an InputError naming those there are."""
    names = [t.name for t in report.tables if t.columns]
    if not is_data(fmt):
        raise InputError(f"--table picks a table of csv, json, parquet or xlsx output, not {fmt}")
    kept = tuple(t for t in report.tables if t.name == name.strip() and t.columns)
    if not kept:
        raise InputError(f"--table {name!r}: no such table; this report has {', '.join(names) or 'none'}")
    return report._replace(tables=kept)


def pick_columns(report: Report, names: str) -> Report:
    """``--columns``: keep each table's first column and the columns whose name (or
    header) begins with one of ``names`` (comma-separated, case-insensitive), in the tables
    and in the display; a display table says which columns it left out. None matching is
    an InputError naming the columns there are."""
    from .report import pick_columns as pick_blocks

    wanted = [w.strip().lower() for w in names.split(",") if w.strip()]

    def keep(c: Column) -> bool:
        return any(c.name.lower().startswith(w) or c.header.lower().startswith(w) for w in wanted)

    tables = []
    matched = False
    for t in report.tables:
        cols = t.columns[:1] + tuple(c for c in t.columns[1:] if keep(c))
        matched = matched or len(cols) > 1
        tables.append(t._replace(columns=cols) if len(cols) > 1 else t)
    if not matched:
        there = sorted({c.name for t in report.tables for c in t.columns[1:]})
        raise InputError(f"--columns {names!r} matches no column; the columns are {', '.join(there)}")
    blocks = report.blocks

    def picked() -> Any:
        try:
            return pick_blocks(blocks(), ((), ()), names)[0]
        except InputError:
            return blocks()  # the display shows fewer columns than the tables: keep it whole

    return report._replace(tables=tuple(tables), blocks=picked)
