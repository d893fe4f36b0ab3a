"""Edge cases of the writer registry (render/writers.py), each pinned by a test that
failed before its fix."""

from __future__ import annotations

import gc
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from linkage.render import formats, writers
from linkage.render.data import Column, DataTable, Report

ROOT = Path(__file__).resolve().parents[1]


def _report(*tables: DataTable) -> Report:
    return Report("review", tuple(tables), lambda: [], None)


def test_numpy_scalars_in_a_list_column_write_as_numbers(tmp_path: Path) -> None:
    # a table built from rows may hold numpy scalars (a median, a ratio): numpy 2's repr of
    # np.float64(0.1) is "np.float64(0.1)", and json cannot encode np.int64
    x = [np.float64(0.1), np.float64(1e-300), np.int64(3)]
    rep = _report(DataTable("t", (Column("x", "mm", x), Column("n", "", [np.int64(2)] * 3, "int"),
                                  Column("ok", "", [np.bool_(True)] * 3, "bool"))))
    writers.write(rep, "csv", tmp_path / "a.csv")
    lines = (tmp_path / "a.csv").read_text().splitlines()
    assert lines[0] == "x (mm),n,ok"
    assert [float(r.split(",")[0]) for r in lines[1:]] == [0.1, 1e-300, 3.0]
    assert all(r.split(",")[1:] == ["2", "true"] for r in lines[1:])
    writers.write(rep, "json", tmp_path / "a.json")
    rows = json.loads((tmp_path / "a.json").read_text())["tables"][0]["rows"]
    assert rows == [[0.1, 2, True], [1e-300, 2, True], [3, 2, True]]


def test_xlsx_text_cell_stays_text(tmp_path: Path) -> None:
    # a joint is named by the mechanism file: "=HYPERLINK(...)" must stay a word, not
    # become a live formula in the workbook
    openpyxl = pytest.importorskip("openpyxl")
    names = ['=HYPERLINK("http://x","B")', "+1", "A"]
    cols = (Column("joint", "", names, "text"), Column("x", "mm", [1.0, 2.0, 3.0]))
    rep = _report(DataTable("joints", cols))
    writers.write(rep, "xlsx", tmp_path / "j.xlsx")
    cells = list(openpyxl.load_workbook(tmp_path / "j.xlsx")["joints"]["A"])[1:]
    assert [(c.value, c.data_type) for c in cells] == [(n, "s") for n in names]


def test_parquet_without_a_table_is_a_readable_file(tmp_path: Path) -> None:
    # a solve that stops before its first iteration (sqrt(x) at x0 = -1) has no table:
    # the .parquet written was 0 bytes, which no reader opens
    pq = pytest.importorskip("pyarrow.parquet")
    writers.write(_report(DataTable("iterations", ())), "parquet", tmp_path / "e.parquet")
    t = pq.read_table(tmp_path / "e.parquet")
    assert t.num_rows == 0 and json.loads(t.schema.metadata[b"linkage"])["title"] == "review"


def test_table_names_fit_sheets_and_file_names(tmp_path: Path) -> None:
    openpyxl = pytest.importorskip("openpyxl")
    pq = pytest.importorskip("pyarrow.parquet")
    one = [Column("x", "", [1.0])]
    rep = _report(DataTable("a/b: [x]*?", tuple(one)), DataTable("c\\d/e", tuple(one)),
                  DataTable("y" * 40 + "1", tuple(one)), DataTable("y" * 40 + "2", tuple(one)))
    writers.write(rep, "xlsx", tmp_path / "n.xlsx")
    sheets = openpyxl.load_workbook(tmp_path / "n.xlsx").sheetnames
    assert len(sheets) == 4 and len(set(sheets)) == 4
    assert all(len(s) <= 31 and not set(s) & set("[]:*?/\\") for s in sheets)
    writers.write(rep, "parquet", tmp_path / "n.parquet")
    made = sorted(p.name for p in tmp_path.iterdir() if p.suffix == ".parquet")
    assert len(made) == 4 and all(pq.read_table(tmp_path / m).num_rows == 1 for m in made)
    assert sorted(p.name for p in writers.side_paths(tmp_path / "n.parquet", rep)) == \
        sorted(m for m in made if m != "n.parquet")


@pytest.mark.filterwarnings("error::pytest.PytestUnraisableExceptionWarning")
def test_interrupted_xlsx_is_not_saved_and_the_interrupt_is_kept(tmp_path: Path,
                                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    pytest.importorskip("openpyxl")
    saved: list[str] = []
    monkeypatch.setattr(formats.XlsxSink, "close", lambda self: saved.append("save"))
    with pytest.raises(KeyboardInterrupt):
        with writers.open_sink("xlsx", tmp_path / "i.xlsx") as sink:
            sink.begin("t", [Column("x", "", ())])
            sink.rows([[1.0]])
            raise KeyboardInterrupt
    gc.collect()  # an abandoned sheet's row stream printed a traceback when collected
    assert saved == [] and list(tmp_path.iterdir()) == []


def test_xlsx_to_a_full_disk_is_one_error_line() -> None:
    if not Path("/dev/full").exists():
        pytest.skip("no /dev/full")
    pytest.importorskip("openpyxl")
    env = {"PYTHONPATH": str(ROOT / "src"), "PATH": "/usr/bin:/bin"}
    run = subprocess.run([sys.executable, "-m", "linkage", "solve", "-f", "xlsx", "-o", "/dev/full"],
                         capture_output=True, text=True, env=env, timeout=60)
    assert run.returncode == 2
    assert run.stderr.splitlines() == [run.stderr.splitlines()[0]] and run.stderr.startswith("error: ")


def test_html_escapes_the_lines_around_its_tables() -> None:
    # the title line carries the mechanism file's name: raw in the HTML, a name such as
    # "<script>...</script>" ran in the browser that opened `-o x.html`
    from linkage.render.display import display_text
    from linkage.render.report import Table, Text

    hostile = "<script>alert(1)</script> & co"
    blocks = [Text(hostile, "bold"), Table(hostile, ("joint",), (("<b>B</b>",),), (hostile,))]
    out = display_text(Report(hostile, (), lambda: blocks), "html")
    assert "<script>" not in out and "<b>B" not in out
    assert out.count("&lt;script&gt;alert(1)&lt;/script&gt; &amp; co") == 3
    assert "<table>" in out


def test_latex_note_of_several_lines_stays_a_comment() -> None:
    from linkage.render.display import display_text
    from linkage.render.report import Table

    blocks = [Table("t", ("a",), (("1",),), ("first\n\\input{/etc/passwd}",))]
    out = display_text(Report("t", (), lambda: blocks), "latex")
    assert all(line.startswith("%") for line in out.splitlines() if "passwd" in line or "first" in line)


def test_json_document_that_is_not_an_object_still_gives_valid_json(tmp_path: Path) -> None:
    # the writer adds "tables" by cutting the document's closing brace: a list document
    # (a sweep's points, say) came out as broken JSON
    t = DataTable("t", (Column("x", "mm", [0.1]),))
    rep = Report("r", (t,), lambda: [], lambda: [{"x": 0.1}, {"x": 0.2}])
    writers.write(rep, "json", tmp_path / "l.json")
    doc = json.loads((tmp_path / "l.json").read_text())
    assert doc["document"] == [{"x": 0.1}, {"x": 0.2}] and doc["tables"][0]["rows"] == [[0.1]]


def test_parquet_names_the_files_of_its_report(tmp_path: Path) -> None:
    # a rerun with fewer tables leaves the last run's sidecars beside the new file (the
    # writer does not delete files by pattern); the metadata says which files belong
    pq = pytest.importorskip("pyarrow.parquet")
    one = (Column("x", "mm", [1.0]),)
    rep = _report(DataTable("iterations", one), DataTable("joints", one))
    writers.write(rep, "parquet", tmp_path / "r.parquet")
    for f in ("r.parquet", "r.joints.parquet"):
        meta = json.loads(pq.read_table(tmp_path / f).schema.metadata[b"linkage"])
        assert meta["files"] == {"iterations": "r.parquet", "joints": "r.joints.parquet"}
    writers.write(_report(DataTable("iterations", one)), "parquet", tmp_path / "r.parquet")
    meta = json.loads(pq.read_table(tmp_path / "r.parquet").schema.metadata[b"linkage"])
    assert meta["files"] == {"iterations": "r.parquet"}


def test_solve_file_honours_an_explicit_max_iter_of_100(cli: object, tmp_path: Path) -> None:
    # a file's default cap is 50; "--max-iter 100" given on purpose was read as "not given"
    # and became 50 (the plain Newton from this far start needs more than 50 steps)
    sample = ROOT / "sample_inputs" / "rapier_drive.toml"
    args = ["solve", str(sample), "--plain", "--set", "a2=3000", "-f", "json"]
    given = json.loads(cli(*args, "--max-iter", "100").out)  # type: ignore[operator]
    assert 50 < given["iteration_count"] <= 100
    default = json.loads(cli(*args).out)  # type: ignore[operator]
    assert default["status"] == "max_iter" and default["iteration_count"] == 50
