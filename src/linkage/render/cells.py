"""How a report's cells are written, whatever the format: numbers as the shortest text that
reads back to the same double, CSV quoting, JSON values, a block of rows through pyarrow's
CSV writer; and :class:`Sink`, what every format's writer is (:mod:`.formats`)."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Sequence
from typing import IO, Any

from .data import Column, Report

SLICE = 8192
"""Rows formatted at a time."""
FAST_CELLS = 200_000
"""From this many cells in a table, CSV numbers are formatted by pyarrow when it is
installed; the choice is made once per table, so a column's numbers read alike throughout."""


def number_texts(values: Any, fast: bool = False) -> list[str]:
    """Each number as the shortest text that reads back to the same double: Python's repr,
    or with ``fast`` (a large table, pyarrow installed) pyarrow's shortest form (``100``
    where repr says ``100.0``, ``0.000012345`` for ``1.2345e-05``); both read back bit for
    bit. "" for NaN, infinities and None."""
    if fast and is_array(values) and values.dtype.kind == "f" and has_pyarrow():
        import numpy as np
        import pyarrow as pa
        import pyarrow.compute as pc

        finite = np.isfinite(values)
        arr = pa.array(values, mask=~finite)
        return pc.fill_null(pc.cast(arr, pa.string()), "").to_pylist()  # type: ignore[no-any-return]
    seq = plain_values(values)
    return ["" if v is None or (isinstance(v, float) and not math.isfinite(v)) else
            repr(v) if isinstance(v, float) else str(v) for v in seq]


def is_array(values: Any) -> bool:
    return hasattr(values, "dtype") and hasattr(values, "tolist")


def plain_values(values: Any) -> list[Any]:
    """The values as Python objects: an array's ``tolist``; in a list, numpy scalars (a
    median, a ratio) as Python numbers (numpy 2's repr of one is ``np.float64(0.1)``, and
    json cannot encode ``np.int64``)."""
    if is_array(values):
        return values.tolist()  # type: ignore[no-any-return]
    return [v.item() if is_array(v) else v for v in values]


HAS_PYARROW: list[bool] = []


def has_pyarrow() -> bool:
    if not HAS_PYARROW:
        try:
            import pyarrow.csv  # noqa: F401  (the block path; pyarrow.compute, 30 ms more, only where used)
            HAS_PYARROW.append(True)
        except ImportError:
            HAS_PYARROW.append(False)
    return HAS_PYARROW[0]


def quote_csv(text: str) -> str:
    if any(c in text for c in ',"\n\r'):
        return '"' + text.replace('"', '""') + '"'
    return text


def cell_texts(col: Column, values: Any, fast: bool = False) -> list[str]:
    """One column's cells as CSV text."""
    if col.kind == "number":
        return number_texts(values, fast)
    seq = plain_values(values)
    if col.kind == "bool":
        return ["" if v is None else "true" if v else "false" for v in seq]
    if col.kind == "int":
        return ["" if v is None else str(int(v)) for v in seq]
    return ["" if v is None else quote_csv(str(v)) for v in seq]


def json_values(col: Column, values: Any) -> list[Any]:
    seq = plain_values(values)
    if col.kind == "number":
        return [v if v is None or isinstance(v, int) or math.isfinite(v) else None for v in seq]
    if col.kind == "bool":
        return [None if v is None else bool(v) for v in seq]
    return seq



CSV_WINDOW = 4 * SLICE
"""Rows formatted before they are written, over every core: their text (about 7 MB for a
sweep's 18 columns) is all a CSV holds at once."""
MAX_CSV_THREADS = 8
"""Threads formatting a CSV's slices side by side: one per core, at most this many."""


def csv_slices(columns: Sequence[Column], values: Sequence[Any], rows: int) -> Iterator[tuple[int, Any]]:
    """The rows of ``values`` (numpy arrays or lists, :func:`slices_ready`) as CSV, in
    order: (first row, its text, None where refused) for each slice of CSV_WINDOW / cores
    rows. Each slice is one task on a thread per core: made a pyarrow table
    (:func:`arrow_table`) and formatted in one pass (:func:`csv_bytes`, pyarrow releasing
    the GIL), a window of slices ahead of the one written; so the first slice's text is
    under way while the later slices' columns are converted, no per-column or per-block
    round trip, and the slices' text the only copy."""
    import os

    workers = max(1, min(os.cpu_count() or 1, MAX_CSV_THREADS))
    step = max(1, -(-CSV_WINDOW // workers))
    starts = range(0, rows, step)

    def text(a: int) -> Any:
        table = arrow_table(columns, [v[a:a + step] for v in values])
        return None if table is None else csv_bytes(table)

    if workers == 1 or len(starts) == 1:
        for a in starts:
            yield a, text(a)
        return
    from collections import deque
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(workers) as pool:
        ahead: deque[tuple[int, Any]] = deque()
        for a in starts:
            ahead.append((a, pool.submit(text, a)))
            if len(ahead) > 2 * workers:
                first, done = ahead.popleft()
                yield first, done.result()
        while ahead:
            first, done = ahead.popleft()
            yield first, done.result()


def slices_ready(values: Sequence[Any]) -> bool:
    """Every column a numpy array or a list: sliced on the formatting threads as they are
    (a column computed as it is read, a sweep's rates, is read on the writing thread)."""
    return all(is_array(v) or type(v) is list for v in values)


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
    cells :func:`cell_texts` makes with pyarrow's numbers (tests check it): each column by
    :func:`arrow_array` (a long column of one double throughout as its text repeated,
    :func:`repeated_text`); None where a column is not a numpy array of its kind (the caller
    goes cell by cell). Text that needs quoting is refused by the writer itself, before it
    writes a row."""
    import pyarrow as pa

    arrays = []
    for c, v in zip(columns, values):
        try:
            a = arrow_array(c.kind, v)
        except (pa.ArrowException, TypeError):  # text not text throughout
            return None
        if a is None:
            return None
        text = repeated_text(a) if c.kind == "number" else None
        arrays.append(a if text is None else text)
    return pa.Table.from_arrays(arrays, names=[str(j) for j in range(len(arrays))])


REPEATED_FROM = 1024
"""Rows from which a column of one double throughout (a ground pivot's x and y in a
sweep) is written as its text repeated (:func:`repeated_text`)."""


def repeated_text(column: Any) -> Any:
    """A pyarrow column of doubles that holds one finite value throughout (bit for bit:
    0.0 and -0.0 differ), as a string column of that value's text, as pyarrow's CSV writer
    formats it (it formats the one value: the same bytes); else None. A string cell is
    copied, a double formatted anew at every row (the same value at every row)."""
    import numpy as np
    import pyarrow as pa

    n = len(column)
    if n < REPEATED_FROM or column.null_count:
        return None
    bits = np.frombuffer(column.buffers()[1], dtype=np.int64, count=n, offset=column.offset * 8)
    if not (bits == bits[0]).all():
        return None
    text = csv_bytes(pa.Table.from_arrays([column.slice(0, 1)], names=["0"]))
    return repeated(text.to_pybytes().rstrip(b"\n") if text is not None else b"", n)


def repeated(word: bytes, n: int) -> Any:
    """A pyarrow string array of ``word`` (UTF-8) ``n`` times, made from its buffers; None
    for an empty word or past a string array's 2 GB."""
    import numpy as np
    import pyarrow as pa

    if not word or len(word) * n >= 2**31:
        return None
    offsets = np.arange(n + 1, dtype=np.int32) * np.int32(len(word))
    return pa.Array.from_buffers(pa.string(), n, [None, pa.py_buffer(offsets), pa.py_buffer(word * n)])


def arrow_array(kind: str, values: Any) -> Any:
    """A column of ``kind`` as a pyarrow array, if ``values`` is a numpy array of that kind
    (text: any object or str array, or a list), else None: numbers as doubles, NaN and
    infinities masked (no value); integers and booleans as they are. The numeric arrays are
    made from the numpy array's own buffer (pyarrow's ``pa.array`` of a numpy array imports
    numpy.ma, 10 to 15 ms of a fresh process, and makes a mask of every column)."""
    import numpy as np
    import pyarrow as pa

    dtype = values.dtype.kind if is_array(values) else ""
    if kind == "number" and dtype == "f":
        x = np.ascontiguousarray(values, dtype=np.float64)
        finite = np.isfinite(x)
        nulls = len(x) - int(np.count_nonzero(finite))
        valid = pa.py_buffer(np.packbits(finite, bitorder="little")) if nulls else None
        return pa.Array.from_buffers(pa.float64(), len(x), [valid, pa.py_buffer(x)], null_count=nulls)
    if kind == "int" and dtype and dtype in "iu":
        x = np.ascontiguousarray(values, dtype=values.dtype.newbyteorder("="))
        return pa.Array.from_buffers(pa.from_numpy_dtype(x.dtype), len(x), [None, pa.py_buffer(x)])
    if kind == "bool" and dtype == "b":
        bits = pa.py_buffer(np.packbits(np.ascontiguousarray(values), bitorder="little"))
        return pa.Array.from_buffers(pa.bool_(), len(values), [None, bits])
    if kind == "text" and dtype in ("O", "U", ""):
        seq = plain_values(values)
        word = repeated_word(seq)
        return pa.array(seq, type=pa.string()) if word is None else word
    return None


def repeated_word(seq: list[Any]) -> Any:
    """A long list of one text throughout (a sweep's status or branch where every
    position solved) as a pyarrow string array made from its buffers, the array
    ``pa.array`` makes of it (tests check it): counted at C speed (``list.count``, each
    cell the same object), not converted cell by cell; else None."""
    n = len(seq)
    if n < REPEATED_FROM or type(seq[0]) is not str or seq.count(seq[0]) != n:
        return None
    return repeated(seq[0].encode("utf-8"), n)


UNSAFE = frozenset('[]:*?/\\\0')
"""Characters an xlsx sheet name or a file name cannot hold."""


def safe_name(table: str) -> str:
    """A table's name as a sheet and a sidecar file name: ``_`` for each unsafe character."""
    return "".join("_" if c in UNSAFE else c for c in table)



class Sink:
    """Writes tables to one output: ``begin(name, columns)``, ``rows(values)`` (one
    sequence per column, any number of times), ``end()``; ``close()`` finishes the output.
    ``out`` is the text output (a text format's) or None, ``path`` the file (a binary
    format writes it itself); ``side(name)`` gives a one-table format's next table's output
    (an open text file, or a binary format's path), set by writers.open_sink."""

    def __init__(self, out: IO[Any] | None, path: str | None, meta: dict[str, Any] | None = None) -> None:
        self.out, self.path, self.meta = out, path, meta or {}
        self.side: Callable[[str], Any] | None = None
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

    @classmethod
    def modules(cls, rows: int | None) -> tuple[str, ...]:
        """The modules this format imports to write a table of ``rows`` rows (None: not
        known), for writers.prefetch."""
        return ()

    @classmethod
    def meta_of(cls, report: Report, files: Sequence[str]) -> dict[str, Any]:
        """What this format writes besides the tables, from ``report`` (``files``: the
        names of the files its tables go to, for a one-table format written to a file)."""
        return {}
