"""The writer registry (render.writers) on a report made here: every data format read back
gives the same numbers (CSV and JSON bit for bit) and the same units; refusals name what
works."""

from __future__ import annotations

import json
import math
import struct
from pathlib import Path

import numpy as np
import pytest

from linkage.errors import InputError
from linkage.render import cells, formats, writers
from linkage.render.data import Column, DataTable, Report, split_header
from linkage.render.report import Text, table
from report_reading import csv_files, csv_rows


def awkward_numbers(n: int = 3000) -> np.ndarray:
    rng = np.random.default_rng(7)
    head = [0.1, 1 / 3, -0.0, 100.0, 5e-324, 2.2250738585072014e-308, 1.7976931348623157e308, math.nan,
            math.inf, -math.inf, 123456789.0, 1e22, 1e16, 9007199254740993.0, 0.0]
    tail = rng.standard_normal(n) * 10.0 ** rng.integers(-300, 300, n)
    return np.concatenate([head, tail])


def report(x: np.ndarray | list[float]) -> Report:
    positions = DataTable("positions", (
        Column("theta2", "deg", x),
        Column("status", "", ["converged", "no_solution"] * (len(x) // 2) + ["converged"] * (len(x) % 2),
               "text"),
        Column("iterations", "", list(range(len(x))), "int"),
        Column("open", "", [k % 3 == 0 for k in range(len(x))], "bool"),
    ))
    joints = DataTable("joints", (Column("joint", "", ["A", 'B, "c"'], "text"),
                                  Column("x", "mm", [1.5, None])))
    return Report("a test, with 50% & an_underscore", (positions, joints),
                  lambda: [Text("a line"), table("", ["theta2 (deg)", "n"], [[1.0, 2]], 6)],
                  lambda: {"mechanism": "test"})


def bits(values: list[float]) -> list[int]:
    return [struct.unpack("<q", struct.pack("<d", v))[0] for v in values]


def finite(x: np.ndarray) -> list[float | None]:
    return [float(v) if math.isfinite(v) else None for v in x.tolist()]


@pytest.mark.parametrize("fast", [False, True])  # Python's repr, and pyarrow's for a big table
def test_csv_and_json_read_back_bit_for_bit(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                            fast: bool) -> None:
    if fast:
        pytest.importorskip("pyarrow")
        monkeypatch.setattr(cells, "FAST_CELLS", 1000)
    x = awkward_numbers(3000)
    rep = report(x)
    writers.write(rep, "csv", tmp_path / "a.csv")
    sections = csv_files(tmp_path / "a.csv", ["positions", "joints"])
    head, *rows = sections["positions"]
    assert [split_header(h) for h in head] == [("theta2", "deg"), ("status", ""), ("iterations", ""),
                                               ("open", "")]
    got = [float(r[0]) if r[0] else None for r in rows]
    assert ("100" in [r[0] for r in rows]) == fast and ("100.0" in [r[0] for r in rows]) != fast
    want = finite(x)
    assert [g is None for g in got] == [w is None for w in want]
    assert bits([g for g in got if g is not None]) == bits([w for w in want if w is not None])
    assert [r[1] for r in rows] == list(rep.tables[0].columns[1].values)
    assert [int(r[2]) for r in rows] == list(range(len(x)))
    assert [r[3] for r in rows] == ["true" if k % 3 == 0 else "false" for k in range(len(x))]
    assert sections["joints"] == [["joint", "x (mm)"], ["A", "1.5"], ['B, "c"', ""]]

    writers.write(rep, "json", tmp_path / "a.json")
    doc = json.loads((tmp_path / "a.json").read_text())
    assert doc["mechanism"] == "test"
    t = doc["tables"][0]
    assert t["name"] == "positions" and t["columns"][0] == "theta2" and t["units"][0] == "deg"
    got = [r[0] for r in t["rows"]]
    assert [g is None for g in got] == [w is None for w in want]
    assert bits([g for g in got if g is not None]) == bits([w for w in want if w is not None])
    assert doc["tables"][1] == {"name": "joints", "columns": ["joint", "x"], "units": ["", "mm"],
                                "rows": [["A", 1.5], ['B, "c"', None]]}


def test_arrow_columns_from_numpy_buffers_are_pyarrows_own_conversion() -> None:
    """cells.arrow_array (numeric columns made from the numpy buffer, no numpy.ma) gives the
    array pyarrow's pa.array makes, NaN and infinities masked: strided and big-endian
    arrays, integers of every width, booleans, text with None; not its kind: None."""
    pa = pytest.importorskip("pyarrow")
    x = awkward_numbers(300)
    numbers = [x, x[::3], x.astype(">f8"), np.array([]), np.full(9, math.nan), np.float32([1.5, math.inf])]
    for v in numbers:
        want = pa.array(np.asarray(v, dtype=float), mask=~np.isfinite(v))
        got = cells.arrow_array("number", v)
        assert got.equals(want) and got.null_count == want.null_count
    ints = [np.arange(-5, 5, dtype=t) for t in ("i1", "i2", "<i4", ">i4", "i8")] + [np.arange(7, dtype="u8")]
    for v in ints:
        assert cells.arrow_array("int", v).equals(pa.array(v.astype(v.dtype.newbyteorder("="))))
    flags = np.array([True, False, True] * 7)
    assert cells.arrow_array("bool", flags).equals(pa.array(flags))
    assert cells.arrow_array("bool", flags[::2]).equals(pa.array(flags[::2]))
    words = np.array(["a", None, "b, c"], dtype=object)
    assert cells.arrow_array("text", words).equals(pa.array(words, type=pa.string()))
    assert cells.arrow_array("number", np.arange(3)) is None and cells.arrow_array("int", x) is None


def test_a_column_of_one_double_is_written_as_pyarrow_formats_it() -> None:
    """A CSV column holding one double throughout goes out as its text repeated
    (cells.repeated_text): the same bytes as pyarrow formatting every cell, for awkward
    doubles (-0.0 and 0.0 apart, subnormals, 1e16, 1e-5 boundaries, long digits); a column
    that differs in one row, or by the sign of a zero, or holds a NaN, is formatted cell
    by cell."""
    pytest.importorskip("pyarrow")
    import pyarrow as pa

    n = cells.REPEATED_FROM + 5
    head = [v for v in awkward_numbers(200) if math.isfinite(v)]
    values = [*head, 1e-5, 9.999999999999999e-06, 1e-4, 0.0001234, 1e15, 1e21, -1.5e300, 4e-320, 0.1 + 0.2]
    cols = (Column("x", "mm", np.zeros(n)),)
    for v in values:
        x = np.full(n, v)
        table = cells.arrow_table(cols, [x])
        assert table.schema.types[0] == pa.string()
        double = pa.Table.from_arrays([cells.arrow_array("number", x)], names=["0"])
        assert cells.csv_bytes(table).to_pybytes() == cells.csv_bytes(double).to_pybytes()
    for other in (1.0, -0.0, math.nan):
        x = np.zeros(n)
        x[n // 2] = other
        assert cells.arrow_table(cols, [x]).schema.types[0] == pa.float64()
    assert cells.arrow_table(cols, [np.zeros(cells.REPEATED_FROM - 1)]).schema.types[0] == pa.float64()


def test_a_csv_slice_that_needs_quoting_goes_cell_by_cell_from_its_first_row() -> None:
    """Each slice's pyarrow table is made on its formatting thread (cells.csv_slices): a
    word with a comma in a later slice stops the block path at that slice's first row,
    the rest written cell by cell, and the file is the bytes the cell-by-cell path writes
    throughout; the slices before it and the rows after it are all there, once."""
    pytest.importorskip("pyarrow")
    import io

    n = max(3 * cells.CSV_WINDOW, cells.FAST_CELLS // 2) + 11
    words = np.array(["converged", None, "open"], dtype=object)[np.arange(n) % 3]
    words[2 * cells.CSV_WINDOW + 5] = "a,b"
    cols = (Column("k", "", np.arange(n) - 7, "int"), Column("s", "", words, "text"))
    out = {}
    for fast in (True, False):
        sink = formats.CsvSink(io.StringIO(), None)
        sink.begin("t", cols, n if fast else None)
        assert sink.fast is fast
        sink.rows([c.values for c in cols])
        out[fast] = sink.out.getvalue()
    assert out[True] == out[False]
    assert out[True].count("\n") == n + 1 and '"a,b"' in out[True]


def test_a_column_of_one_word_is_pyarrows_array_of_it(tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    """A long text column of one word throughout (cells.repeated_word: a sweep's status
    where every position solved) is the array pa.array makes (equal objects or not, any
    UTF-8), its CSV and parquet files the bytes written without the shortcut; one cell
    other (None, another word) or a short column: converted cell by cell."""
    pa = pytest.importorskip("pyarrow")
    n = cells.REPEATED_FROM + 3
    for word in ("converged", "öpen ∠", "x"):
        same = np.array([word] * n, dtype=object)
        equal = np.array(["".join(word)] * n, dtype=object)  # equal, not one object
        for v in (same, equal, [word] * n):
            got = cells.arrow_array("text", v)
            assert got.equals(pa.array(list(v), type=pa.string()))
            assert cells.repeated_word(list(v)) is not None
    for odd in (None, "conv", ""):
        v = ["converged"] * n
        v[n // 2] = odd
        assert cells.repeated_word(v) is None
        assert cells.arrow_array("text", v).equals(pa.array(v, type=pa.string()))
    assert cells.repeated_word(["a"] * (cells.REPEATED_FROM - 1)) is None
    big = cells.FAST_CELLS  # the CSV's block path too
    cols = (Column("s", "", np.array(["open"] * big, dtype=object), "text"),
            Column("x", "mm", np.full(big, 1.5)))
    files = {}
    for shortcut in (True, False):
        if not shortcut:
            monkeypatch.setattr(cells, "REPEATED_FROM", 10**9)
        for fmt in ("csv", "parquet"):
            (tmp_path / str(shortcut)).mkdir(exist_ok=True)
            out = tmp_path / str(shortcut) / f"t.{fmt}"  # the name is in the parquet file
            writers.write(Report("r", (DataTable("t", cols),), list), fmt, out)
            files[shortcut, fmt] = out.read_bytes()
    assert files[True, "csv"] == files[False, "csv"] and files[True, "parquet"] == files[False, "parquet"]


def test_parquet_file_is_the_bytes_pyarrow_parquet_writes(tmp_path: Path) -> None:
    """The sink's writer (pyarrow's own, without pyarrow.parquet's filesystem imports) writes
    the file pyarrow.parquet.ParquetWriter writes, byte for byte: with text dictionary-encoded,
    with no dictionary, and with no column at all."""
    pa = pytest.importorskip("pyarrow")
    pq = pytest.importorskip("pyarrow.parquet")
    x = awkward_numbers(500)
    words = np.array(["converged", "no_solution", None] * 172, dtype=object)[: len(x)]
    fields = [pa.field("theta2", pa.float64(), metadata={b"unit": b"deg"}), pa.field("status", pa.string())]
    schema = pa.schema(fields, metadata={"linkage": '{"title": "t"}'})
    table = pa.Table.from_arrays([pa.array(x, mask=~np.isfinite(x)), pa.array(words, type=pa.string())],
                                 schema=schema)
    for k, (s, t, dictionary) in enumerate([(schema, table, ["status"]), (schema, table, False),
                                             (pa.schema([], metadata={"linkage": "{}"}), None, True)]):
        ours, theirs = tmp_path / f"ours{k}.parquet", tmp_path / f"theirs{k}.parquet"
        for writer in (formats.parquet_writer(str(ours), s, dictionary),
                       pq.ParquetWriter(str(theirs), s, use_dictionary=dictionary)):
            if t is not None:
                writer.write_table(t)
            writer.close()
        assert ours.read_bytes() == theirs.read_bytes()


def test_an_int32_column_widened_by_numpy_is_pyarrows_cast(tmp_path: Path) -> None:
    """A sweep's iterations (int32) go to the int64 parquet field widened by numpy
    (formats.widened) instead of pyarrow's cast (which imports pyarrow.compute): the same
    array, and the same file bytes as the column given as int64; a column that does not fit
    int64 (uint64) is left to pyarrow."""
    pa = pytest.importorskip("pyarrow")
    counts = np.array([0, 1, 7, -3, 2**31 - 1, -(2**31)] * 400, dtype=np.int32)
    for v in (counts, counts.astype(np.int16), counts.astype(np.uint32)):
        ours = cells.arrow_array("int", formats.widened("int", v))
        assert ours.type == pa.int64()
        assert ours.equals(pa.array(v).cast(pa.int64()))
    big = np.array([2**64 - 1], dtype=np.uint64)
    assert formats.widened("int", big) is big
    x = np.linspace(0.0, 1.0, len(counts))
    files = []
    for k, iterations in enumerate((counts, counts.astype(np.int64))):
        out = tmp_path / f"k{k}" / "t.parquet"
        out.parent.mkdir()
        t = DataTable("positions", (Column("theta2", "deg", x), Column("iterations", "", iterations, "int")))
        writers.write(Report("t", (t,), lambda: [], None), "parquet", out)
        files.append(out.read_bytes())
    assert files[0] == files[1]


def test_parquet_and_xlsx_read_back(tmp_path: Path) -> None:
    pq = pytest.importorskip("pyarrow.parquet")
    openpyxl = pytest.importorskip("openpyxl")
    x = awkward_numbers(500)
    rep = report(x)
    writers.write(rep, "parquet", tmp_path / "a.parquet")
    t = pq.read_table(tmp_path / "a.parquet")
    assert t.schema.field("theta2").metadata == {b"unit": b"deg"}
    got = t.column("theta2").to_pylist()
    want = finite(x)
    assert [g is None or (isinstance(g, float) and math.isnan(g)) for g in got] == [w is None for w in want]
    assert bits([g for g, w in zip(got, want) if w is not None]) == bits([w for w in want if w is not None])
    side = pq.read_table(tmp_path / "a.joints.parquet")
    assert side.schema.field("x").metadata == {b"unit": b"mm"}
    assert side.to_pydict() == {"joint": ["A", 'B, "c"'], "x": [1.5, None]}

    writers.write(rep, "xlsx", tmp_path / "a.xlsx")
    book = openpyxl.load_workbook(tmp_path / "a.xlsx")
    assert book.sheetnames == ["positions", "joints"]
    rows = list(book["positions"].iter_rows(values_only=True))
    assert rows[0] == ("theta2 (deg)", "status", "iterations", "open")
    cells = [r[0] for r in rows[1:]]
    assert [c is None for c in cells] == [w is None for w in want]
    assert all(isinstance(c, (int, float)) for c in cells if c is not None)  # numbers, not text
    # xlsx is not bit for bit: openpyxl writes 16 significant digits ("%.16g"), so 1/3
    # comes back one ulp off, and the largest doubles (beyond Excel's 9.99e307) overflow;
    # Excel has no -0. To 16 significant digits (Excel shows 15), within Excel's range.
    for c, w in zip(cells, want):
        if w is not None and abs(w) < 9.99e307:
            assert abs(float(c) - w) <= 6e-16 * abs(w), (c, w)
    assert list(book["joints"].iter_rows(values_only=True)) == [("joint", "x (mm)"), ("A", 1.5),
                                                                 ('B, "c"', None)]


@pytest.mark.parametrize("name", ["x.mat", "x.xls", "x.CSVX", "x.parquet.bak"])
def test_unknown_suffix_is_refused_naming_the_ones_that_work(name: str) -> None:
    with pytest.raises(InputError) as e:
        writers.choose_format(None, Path(name))
    assert ".csv (csv)" in str(e.value) and ".xlsx (xlsx)" in str(e.value)


def test_suffixes_and_formats() -> None:
    assert writers.choose_format(None, Path("a.CSV")) == "csv"
    assert writers.choose_format(None, Path("a.tex")) == "latex"
    assert writers.choose_format(None, Path("noext")) == "plain"
    assert writers.choose_format("grid", Path("a.csv")) == "grid"  # --format wins
    assert writers.choose_format("CSV", None) == "csv"
    with pytest.raises(InputError, match="binary"):
        writers.choose_format("parquet", None)
    with pytest.raises(InputError, match="unknown format"):
        writers.choose_format("mat", None)


def test_latex_is_a_captioned_table(tmp_path: Path) -> None:
    rep = report([1.0, 2.0])
    writers.write(rep, "latex", tmp_path / "a.tex")
    text = (tmp_path / "a.tex").read_text()
    lines = text.splitlines()
    assert lines[0] == "% a line"
    assert lines.index("\\begin{table}[htbp]") < lines.index("\\begin{tabular}{rr}") < \
        lines.index("\\end{table}")
    assert "\\caption{a test, with 50\\% \\& an\\_underscore}" in lines
    # every line is a comment or LaTeX: no bare text outside the float
    inside = False
    for line in lines:
        inside = inside or line.startswith("\\begin{table}")
        assert inside or line.startswith("%"), line
        if line == "\\end{table}":
            inside = False


def test_a_failed_write_leaves_no_file(tmp_path: Path) -> None:
    rep = report([1.0, 2.0])._replace(tables=(DataTable("t", (Column("x", "", _Exploding()),)),))
    with pytest.raises(_ExplodingError):
        writers.write(rep, "csv", tmp_path / "a.csv")
    assert list(tmp_path.iterdir()) == []


class _Exploding(list):  # a column whose values fail half-way through the write
    def __len__(self) -> int:
        return 10

    def __getitem__(self, i: object) -> object:
        raise _ExplodingError


class _ExplodingError(Exception):
    pass


# --- CSV: one table per file (a loaded sweep's two tables read by any CSV reader) ---------------

ROOT = Path(__file__).resolve().parents[1]


def _uniform(rows: list[list[str]]) -> bool:
    """A CSV every reader takes: a header and rows all as wide as it, no '#' section lines."""
    return bool(rows) and all(len(r) == len(rows[0]) for r in rows) and not rows[0][0].startswith("#")


def test_a_loaded_sweeps_csv_is_one_table_per_file(cli, tmp_path: Path) -> None:
    """linkage sweep docs/crank_rocker_loads.toml -f csv -o x.csv wrote two tables into one
    file, which pandas.read_csv cannot read: now x.csv (positions) and x.loads.csv."""
    out = tmp_path / "x.csv"
    loaded = str(ROOT / "docs" / "crank_rocker_loads.toml")
    r = cli("sweep", loaded, "--step", "30", "-f", "csv", "-o", str(out))
    assert r.code == 0, r.err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.csv", "x.loads.csv"]
    assert f"wrote {out}, {tmp_path / 'x.loads.csv'}" in r.err
    files = csv_files(out, ["positions", "loads"])
    assert all(_uniform(rows) for rows in files.values())
    positions, loads = files["positions"], files["loads"]
    assert positions[0][0] == loads[0][0] == "theta_crank (deg)" and "input (N m)" in loads[0]
    assert [r[0] for r in positions[1:]] == [r[0] for r in loads[1:]] == \
        [repr(float(v)) for v in range(0, 361, 30)]
    # the same tables as the JSON, row for row
    cli("sweep", loaded, "--step", "30", "-o", str(tmp_path / "x.json"))
    doc = json.loads((tmp_path / "x.json").read_text())
    assert [t["name"] for t in doc["tables"]] == ["positions", "loads"]
    assert len(loads) - 1 == len(doc["tables"][1]["rows"])


def test_several_tables_of_csv_on_standard_output_need_table(cli) -> None:
    """Refused with one line naming the tables (never two tables in one stream); --table
    NAME writes that one, in any data format; an unknown name names those there are."""
    args = ("sweep", str(ROOT / "docs" / "crank_rocker_loads.toml"), "--step", "90")
    r = cli(*args, "-f", "csv")
    assert r.code == 2 and r.out == ""
    assert r.err.count("\n") == 1 and "(positions, loads)" in r.err and "--table NAME" in r.err
    r = cli(*args, "-f", "csv", "--table", "loads")
    assert r.code == 0, r.err
    rows = csv_rows(r.out)
    assert _uniform(rows) and "input (N m)" in rows[0] and len(rows) == 1 + 5
    r = cli(*args, "-f", "json", "--table", "loads")
    assert [t["name"] for t in json.loads(r.out)["tables"]] == ["loads"]
    r = cli(*args, "-f", "csv", "--table", "nosuch")
    assert r.code == 2 and "no such table; this report has positions, loads" in r.err
    r = cli(*args, "-f", "plain", "--table", "loads")
    assert r.code == 2 and "--table picks a table of csv" in r.err
    # a report of one table is unchanged on standard output
    r = cli("sweep", str(ROOT / "sample_inputs" / "crank_rocker.toml"), "--step", "90", "-f", "csv")
    assert r.code == 0 and _uniform(csv_rows(r.out))


def test_a_failed_second_table_leaves_no_csv_file(tmp_path: Path) -> None:
    """Atomic across the files: a failure in the sidecar's table leaves neither file (nor a
    temporary one)."""
    rep = report([1.0, 2.0])
    rep = rep._replace(tables=(rep.tables[0], DataTable("t", (Column("x", "", _Exploding()),))))
    with pytest.raises(_ExplodingError):
        writers.write(rep, "csv", tmp_path / "a.csv")
    assert list(tmp_path.iterdir()) == []


def test_csv_sidecars_stream_in_blocks(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """With a progress bar the rows go out a block at a time: each table's file whole."""
    monkeypatch.setattr(writers, "PROGRESS_ROWS", 7)
    x = np.arange(50, dtype=float) / 3.0
    rep = report(x)
    done: list[int] = []
    writers.write(rep, "csv", tmp_path / "b.csv", progress=done.append)
    assert done[-1] == 52 and len(done) > 8
    files = csv_files(tmp_path / "b.csv", ["positions", "joints"])
    assert [float(r[0]) for r in files["positions"][1:]] == x.tolist()
    assert files["joints"] == [["joint", "x (mm)"], ["A", "1.5"], ['B, "c"', ""]]


def test_a_word_needing_quotes_late_in_a_big_csv_is_quoted_and_no_row_is_written_twice(tmp_path):
    """The CSV block path (pyarrow's writer, a window of rows at a time) meeting a word with
    a comma in a later window: the windows before are written as blocks, that window and
    the rest cell by cell; the rows read back as the cell-by-cell path writes them."""
    pytest.importorskip("pyarrow")
    import csv
    import io

    n = max(2 * cells.CSV_WINDOW, cells.FAST_CELLS // 2) + 5  # two columns: the block path
    late = n - cells.CSV_WINDOW // 2  # in a later window than the first
    words = np.array(["ok"] * n, dtype=object)
    words[late] = "a,b"
    x = np.arange(n) * 0.5
    cols = (Column("x", "mm", x), Column("s", "", words, "text"))
    fast = tmp_path / "fast.csv"
    with open(fast, "w", encoding="utf-8", newline="") as fh:
        sink = formats.CsvSink(fh, None)
        sink.begin("t", cols, n)
        assert sink.fast
        sink.rows([c.values for c in cols])
        assert sink.count == n
    rows = list(csv.reader(io.StringIO(fast.read_text(encoding="utf-8"))))
    assert len(rows) == n + 1 and rows[0] == ["x (mm)", "s"]
    assert [float(r[0]) for r in rows[1:]] == list(x)
    assert rows[late + 1][1] == "a,b" and {r[1] for r in rows[1:]} == {"ok", "a,b"}
