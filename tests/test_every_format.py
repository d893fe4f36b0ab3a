"""Every command's report in every format (issue 20, done-when 1 and 3).

Each command runs once per data format (csv, json, parquet, xlsx) and the four files are
read back against each other: the same tables, the same column names and units, the
same numbers (CSV and JSON bit for bit, parquet bit for bit, xlsx to the 16 significant
digits openpyxl writes). Display formats (plain, github, latex, rst) write a file that is
not empty; LaTeX is a captioned table. An unknown suffix is refused by every command with
one line and exit 2. Whether the numbers are right is other tests' business (they compare
with closed forms, mpmath and docs/worked_examples.md); here they must be the same everywhere.
"""

from __future__ import annotations

import json
import math
import struct
from pathlib import Path
from typing import Any

import pytest

from linkage.measure import continuation_targets, precision, sweeps, targets, timing
from report_reading import csv_files

pq = pytest.importorskip("pyarrow.parquet")
openpyxl = pytest.importorskip("openpyxl")

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"

COMMANDS: dict[str, list[str]] = {
    "solve": ["solve"],
    "solve-all": ["solve", "--method", "all"],
    "solve-equation": ["solve", "--equation", "x**2 - 4*x + 1", "--x0", "5"],
    "solve-file": ["solve", str(SAMPLES / "fourbar_me581.toml")],
    "solve-file-rates": ["solve", str(SAMPLES / "fourbar_me581.toml"), "--speed", "600rpm", "--accel", "15"],
    "sweep": ["sweep", str(SAMPLES / "crank_rocker.toml"), "--step", "30"],
    "sweep-rates": ["sweep", str(SAMPLES / "rapier_drive.toml"), "--step", "45", "--speed", "10"],
    "sweep-equation": ["sweep", "--step", "30"],
    "centres": ["centres", str(SAMPLES / "slider_crank.toml")],
    "centrodes": ["centres", str(SAMPLES / "crank_rocker_joints.toml"), "--centrodes", "--step", "90"],
    "scan": ["scan", str(SAMPLES / "crank_rocker.toml"), "--vary", "r2=30:40:3", "--step", "30"],
    "tolerance": ["tolerance", str(SAMPLES / "crank_rocker.toml"), "--tol", "r2=0.05", "--tol", "r4=0.05",
                  "--step", "90", "--samples", "200"],
    "simulate": ["simulate", str(SAMPLES.parent / "docs" / "crank_rocker_loads.toml"), "--time", "0:0.2",
                 "--omega0", "39", "--drive", "0.1", "--flywheel", "0.01", "--samples", "5"],
    "samples": ["samples"],
    "synthesize": ["synthesize", "--function", "log10(x)", "--x", "1:2", "--alpha", "90:150",
                   "--phi", "0:90"],
    "stress": ["stress", "--quick", "--method", "newton"],
    "bench": ["bench", "--quick", "--no-cold", "--problem", "freudenstein", "--repeats", "1"],
}
OUTPUT_OPTION = {"samples": "--format"}  # the listing goes to standard output only


@pytest.fixture
def quick_bench(monkeypatch: pytest.MonkeyPatch) -> None:
    """bench's measurements stubbed with fixed figures: the writers are under test, and a
    timing differs from run to run."""
    m = precision.Measurement
    fixed = [m("freudenstein", "linkage newton", 1e-12, 2.5e-5, (2.25e-5, 3e-5), 1e-16, 5, 6),
             m("freudenstein", "scipy brentq", 1e-12, 1e-4, (0.9e-4, 1.1e-4), 0.0, None, 9)]
    monkeypatch.setattr(precision, "measure", lambda *a, **k: fixed)
    monkeypatch.setattr(sweeps, "sweep_times", lambda *a, **k: {"a sweep": 0.25, "another": 0.5})
    pairs = timing.Pairs((2e-6, 3e-6), (1e-6, 1e-6))
    monkeypatch.setattr(targets, "run_rows", lambda *a, **k: [targets.Outcome(row, pairs)
                                                               for row in targets.ROWS])
    ct = continuation_targets
    checked = ct.Certificate(4, 6.25e-17, 1.5e-16, 0, 0)
    timed = ct.Timed((0.0625, 0.0625), ct.Found("4 real cranks", True, checked))
    monkeypatch.setattr(ct, "run_rows", lambda *a, **k: [ct.Outcome(row, None if row.long else timed,
                                                                     "not measured" if row.long else "")
                                                          for row in ct.ROWS])
    # solve --method all times each method: its "time per solve" column, too
    monkeypatch.setattr(timing, "time_per_solve", lambda *a, **k: 2.5e-5)


def run(cli: Any, tmp_path: Path, name: str, fmt: str) -> Path:
    path = tmp_path / f"{name}.{fmt}"
    if name in OUTPUT_OPTION:
        if fmt in ("parquet", "xlsx"):
            r = cli(*COMMANDS[name], "--format", fmt)
            assert r.code == 2 and "binary" in r.err, r.err
            pytest.skip("a listing to standard output: no binary format")
        r = cli(*COMMANDS[name], "--format", fmt)
        assert r.code == 0, r.err
        path.write_text(r.out)
        return path
    r = cli(*COMMANDS[name], "-o", str(path))
    assert r.code in (0, 1), r.err
    assert path.exists()
    return path


def bits(v: float) -> int:
    return struct.unpack("<q", struct.pack("<d", v))[0]


def same_number(a: Any, b: Any) -> bool:
    if a is None or b is None:
        return a is None and b is None
    return bits(float(a)) == bits(float(b))


def csv_tables(path: Path, names: list[str]) -> list[tuple[str, list[list[str]]]]:
    """Each table's rows: one file per table, the first at ``path`` (render.writers)."""
    return list(csv_files(path, names).items())


def header(name: str, unit: str) -> str:
    return f"{name} ({unit})" if unit else name


@pytest.mark.usefixtures("quick_bench")
@pytest.mark.parametrize("name", list(COMMANDS))
def test_every_data_format_reads_back_the_same(cli: Any, tmp_path: Path, name: str) -> None:
    doc = json.loads(run(cli, tmp_path, name, "json").read_text())
    tables = doc["tables"]
    assert tables, "a report without tables"
    for t in tables:
        assert len(t["columns"]) == len(t["units"]) and all(isinstance(u, str) for u in t["units"])

    # CSV: the same tables, headers "name (unit)", numbers bit for bit
    found = csv_tables(run(cli, tmp_path, name, "csv"), [t["name"] for t in tables])
    assert len(found) == len(tables)
    for (_, rows), t in zip(found, tables):
        assert rows[0] == [header(c, u) for c, u in zip(t["columns"], t["units"])]
        assert len(rows) - 1 == len(t["rows"])
        for got, want in zip(rows[1:], t["rows"]):
            for g, w in zip(got, want):
                if isinstance(w, bool):
                    assert g == ("true" if w else "false")
                elif isinstance(w, (int, float)):
                    assert same_number(float(g), w), (g, w)
                elif w is None:
                    assert g == ""
                else:
                    assert g == w

    if name in OUTPUT_OPTION:
        return
    # parquet: one file per table, units in the fields' metadata, numbers bit for bit
    path = run(cli, tmp_path, name, "parquet")
    for k, t in enumerate(tables):
        p = path if k == 0 else path.with_name(f"{path.stem}.{t['name']}.parquet")
        table = pq.read_table(p)
        assert table.column_names == t["columns"]
        for c, u in zip(t["columns"], t["units"]):
            meta = table.schema.field(c).metadata
            assert (meta or {}).get(b"unit", b"").decode() == u
        for j, c in enumerate(t["columns"]):
            got = table.column(c).to_pylist()
            want = [r[j] for r in t["rows"]]
            for g, w in zip(got, want):
                if isinstance(w, float) or (isinstance(g, float) and isinstance(w, int)):
                    assert same_number(g, w), (c, g, w)
                else:
                    assert g == w, (c, g, w)

    # xlsx: a sheet per table, units in the header row, numbers as numbers
    book = openpyxl.load_workbook(run(cli, tmp_path, name, "xlsx"))
    assert book.sheetnames == [t["name"][:31] for t in tables]
    for sheet, t in zip(book.worksheets, tables):
        rows = list(sheet.iter_rows(values_only=True))
        assert list(rows[0]) == [header(c, u) for c, u in zip(t["columns"], t["units"])]
        for got, want in zip(rows[1:], t["rows"]):
            for g, w in zip(got, want):
                if isinstance(w, float) and not isinstance(w, bool):
                    assert isinstance(g, (int, float)) and abs(g - w) <= 6e-16 * abs(w), (g, w)
                elif w is None or w == "":
                    assert g in (None, "")
                else:
                    assert g == w, (g, w)


@pytest.mark.usefixtures("quick_bench")
@pytest.mark.parametrize("name", ["solve", "solve-file-rates", "sweep", "scan", "samples", "stress"])
@pytest.mark.parametrize("fmt", ["plain", "github", "latex", "rst"])
def test_every_display_format_writes(cli: Any, tmp_path: Path, name: str, fmt: str) -> None:
    if name in OUTPUT_OPTION:
        r = cli(*COMMANDS[name], "--format", fmt)
        text = r.out
    else:
        path = tmp_path / "out.txt"
        r = cli(*COMMANDS[name], "--format", fmt, "-o", str(path))
        text = path.read_text()
    assert r.code in (0, 1), r.err
    assert text.strip()
    if fmt == "latex" and name != "samples":  # the listing is lines: LaTeX comments
        assert "\\begin{table}" in text and "\\caption{" in text and "\\end{table}" in text


@pytest.mark.parametrize("name", [*COMMANDS, "draw"])
def test_an_unknown_suffix_is_refused(cli: Any, tmp_path: Path, name: str) -> None:
    args = ["draw", str(SAMPLES / "crank_rocker.toml")] if name == "draw" else COMMANDS[name]
    if name == "samples":
        args = ["samples", "crank_rocker"]
    r = cli(*args, "-o", str(tmp_path / "x.mat"))
    assert r.code == 2
    assert r.err.count("\n") == 1 and r.err.startswith("error: ") and ".mat" in r.err
    assert list(tmp_path.iterdir()) == []


def test_solve_csv_carries_the_rates(cli: Any, tmp_path: Path) -> None:
    """solve FILE --speed -o f.csv: the velocities and accelerations JSON has, bit for bit."""
    doc = json.loads(run(cli, tmp_path, "solve-file-rates", "json").read_text())
    path = run(cli, tmp_path, "solve-file-rates", "csv")
    names = [t["name"] for t in doc["tables"]]
    cells = {c for _, rows in csv_tables(path, names) for r in rows[1:] for c in r}
    for value in [*doc["velocities"].values(), *doc["accelerations"].values()]:
        assert any(c and same_number(float(c), value) for c in cells if _is_number(c)), value


def _is_number(text: str) -> bool:
    try:
        return math.isfinite(float(text))
    except ValueError:
        return False
