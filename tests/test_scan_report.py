"""`linkage scan` through the one writer registry (issue 20): csv, json, parquet and xlsx
hold the same records, bit for bit, as the scan computed in this process, with the same
unit on every column; the display formats show the kept rows; an unknown suffix is one
line and exit 2; a streamed scan's memory does not grow with the scan."""

from __future__ import annotations

import csv
import json
import math
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

import linkage

ROOT = Path(__file__).resolve().parent.parent
CRANK = ROOT / "sample_inputs" / "crank_rocker.toml"
R1, R3 = 100.0, 120.0  # the file's ground and coupler (mm)
# r2 = 5, r4 = 10 mm assembles nowhere (r3 - r4 = 110 > r1 + r2: NaN extents); r4 = 10 mm
# with r2 = 25 or 45 and r2 = 45 with r4 = 50 assemble over part of the turn; the other five
# are crank-rockers (s + l <= p + q, the crank shortest)
GRID = {"r2": (5.0, 45.0, 3), "r4": (10.0, 90.0, 3)}
VARY = ["--vary", "r2=5:45:3", "--vary", "r4=10:90:3"]
STEP = 5.0
VALUES = [k * STEP for k in range(72)]  # 0..355 deg
DRIVER = ["--step", "5", "--to", "355"]


def expected_unit(name: str) -> str:
    """The unit of each column, from what the column is (not from the code's list): angles
    in deg (the transmission extremes too, whatever their names say), lengths in mm,
    fractions, flags, counts and words dimensionless."""
    if name.startswith(("theta", "min_transmission", "max_transmission")):
        return "deg"
    if name in ("r2", "r4") or name.startswith("P_"):
        return "mm"
    assert name in ("design", "feasible_fraction", "solved_fraction", "full_cycle", "meetings",
                    "grashof"), name
    return ""


def in_process() -> dict[str, np.ndarray]:
    return linkage.scan_designs(str(CRANK), GRID, values=VALUES)


def same(a: object, b: object, xlsx: bool = False) -> bool:
    """Equal bit for bit: floats by their hex form (-0.0 is not 0.0), NaN as no value.
    ``xlsx``: openpyxl writes a number as "%.16g" (16 significant digits, not the 17 a
    double may need) and reads a whole one back as an int: equal to half a unit in the
    16th digit."""
    if isinstance(b, float) and math.isnan(b):
        return a is None
    if isinstance(b, float) and xlsx:
        return type(a) in (int, float) and abs(a - b) <= 6e-16 * abs(b)
    if isinstance(b, float):
        return isinstance(a, float) and a.hex() == b.hex()
    return a == b and type(a) is type(b)


def python_rows(cols: dict[str, np.ndarray]) -> list[list[object]]:
    return [list(r) for r in zip(*(cols[k].tolist() for k in cols))]


# --- an independent closed form: the crank-rocker's rocker angle ----------------------------------

def theta4_open(r2: float, r4: float, theta2_deg: float) -> float | None:
    """The rocker's angle (deg) on the file's open branch, B where the circle of radius r3
    about A meets the circle of radius r4 about O4 = (r1, 0): from O4, B lies at the angle
    of A minus the angle at O4 of the triangle A-O4-B (law of cosines); None where the
    circles do not meet. The sign is the one that gives the file's 55.27 deg at 30 deg."""
    t = math.radians(theta2_deg)
    dx, dy = r2 * math.cos(t) - R1, r2 * math.sin(t)
    d = math.hypot(dx, dy)
    c = (d * d + r4 * r4 - R3 * R3) / (2.0 * d * r4)
    if abs(c) > 1.0:
        return None
    return math.degrees(math.atan2(dy, dx) - math.acos(c))


def test_the_closed_form_is_the_files_open_branch():
    assert theta4_open(40.0, 80.0, 30.0) == pytest.approx(55.27, abs=0.005)  # the file's comment


# --- the four data formats ------------------------------------------------------------------------

def write_all(cli, tmp_path: Path) -> dict[str, Path]:
    out = {}
    for fmt in ("csv", "json", "parquet", "xlsx"):
        out[fmt] = tmp_path / f"designs.{fmt}"
        r = cli("scan", str(CRANK), *VARY, *DRIVER, "-o", str(out[fmt]))
        assert r.code == 0, r.err
    return out


def test_csv_json_parquet_and_xlsx_read_back_the_records_bit_for_bit_with_units(cli, tmp_path):
    pq = pytest.importorskip("pyarrow.parquet")
    openpyxl = pytest.importorskip("openpyxl")
    ref = in_process()
    names = list(ref)
    kinds = {k: "bool" if v.dtype == bool else "text" if v.dtype == object else "num" for k, v in ref.items()}
    units = [expected_unit(n) for n in names]
    want = python_rows(ref)
    assert len(want) == 9 and any(math.isnan(r[names.index("theta4_range")]) for r in want)
    paths = write_all(cli, tmp_path)

    # CSV: "name (unit)", a dimensionless column its bare name; numbers read back exactly
    with open(paths["csv"], newline="") as fh:
        header, *body = list(csv.reader(fh))
    assert header == [f"{n} ({u})" if u else n for n, u in zip(names, units)]
    assert "min_transmission_deg (deg)" in header and "feasible_fraction" in header

    def from_csv(text: str, name: str) -> object:
        if kinds[name] == "bool":
            return {"true": True, "false": False}[text]
        if kinds[name] == "text":
            return text
        if name in ("design", "meetings"):  # counts
            return int(text)
        return None if text == "" else float(text)

    got = [[from_csv(t, n) for t, n in zip(r, names)] for r in body]
    # JSON: the scan's settings as the document, the records under "tables"
    doc = json.loads(paths["json"].read_text())
    assert doc["mechanism"] == "Grashof crank-rocker" and doc["designs"] == 9
    assert doc["driver"]["positions"] == len(VALUES)
    (table,) = doc["tables"]
    assert table["name"] == "designs" and table["columns"] == names and table["units"] == units
    # parquet: the bare names, each unit in its field's metadata, the settings in "linkage"
    pt = pq.read_table(paths["parquet"])
    assert pt.column_names == names
    assert [(f.metadata or {}).get(b"unit", b"").decode() for f in pt.schema] == units
    assert json.loads(pt.schema.metadata[b"linkage"])["designs"] == 9
    parquet_rows = [list(r.values()) for r in pt.to_pylist()]
    # xlsx: a sheet "designs", the CSV's headers, numbers as numbers
    book = openpyxl.load_workbook(paths["xlsx"], read_only=True)
    sheet = [list(r) for r in book["designs"].iter_rows(values_only=True)]
    book.close()
    assert sheet[0] == header
    for rows, fmt in ((got, "csv"), (table["rows"], "json"), (parquet_rows, "parquet"), (sheet[1:], "xlsx")):
        assert len(rows) == len(want), fmt
        for i, (row, ref_row) in enumerate(zip(rows, want)):
            bad = [n for n, a, b in zip(names, row, ref_row) if not same(a, b, fmt == "xlsx")]
            assert not bad, (fmt, i, bad)


def test_the_written_rocker_swing_is_the_closed_forms(cli, tmp_path):
    """theta4_range in the CSV against the open-branch closed form at the same driver values,
    for every design that assembles at all of them."""
    path = tmp_path / "designs.csv"
    assert cli("scan", str(CRANK), *VARY, *DRIVER, "-o", str(path)).code == 0
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    checked = 0
    for row in rows:
        r2, r4 = float(row["r2 (mm)"]), float(row["r4 (mm)"])
        angles = [theta4_open(r2, r4, t) for t in VALUES]
        if any(a is None for a in angles):
            assert row["full_cycle"] == "false"
            continue
        swing = np.unwrap(np.radians(angles))
        expect = math.degrees(swing.max() - swing.min())
        assert row["full_cycle"] == "true"
        assert abs(float(row["theta4_range (deg)"]) - expect) <= 1e-9, (r2, r4)
        checked += 1
    assert checked == 5


def test_a_display_format_shows_the_kept_rows_with_units(cli, tmp_path):
    path = tmp_path / "designs.md"
    r = cli("scan", str(CRANK), *VARY, *DRIVER, "--sort", "theta4_range", "--desc", "--top", "2",
            "--columns", "r2,r4,theta4_range,min_trans", "-o", str(path))
    assert r.code == 0, r.err
    text = path.read_text()
    header = next(ln for ln in text.splitlines() if ln.startswith("|"))
    assert [c.strip() for c in header.strip("|").split("|")] == [
        "design", "r2 (mm)", "r4 (mm)", "theta4_range (deg)", "min_transmission_deg (deg)"]
    ref = in_process()
    best = np.argsort(-np.nan_to_num(ref["theta4_range"], nan=-1.0), kind="stable")[:2]
    body = [ln for ln in text.splitlines() if ln.startswith("|")][2:]
    assert [int(ln.strip("|").split("|")[0]) for ln in body] == [int(ref["design"][i]) for i in best]


def test_sorted_and_streamed_files_hold_the_same_records(cli, tmp_path):
    """--sort holds the records and writes them once; unsorted, they stream chunk by chunk:
    the same registry writes both."""
    ref = in_process()
    order = np.argsort(ref["r4"], kind="stable")
    path = tmp_path / "sorted.json"
    assert cli("scan", str(CRANK), *VARY, *DRIVER, "--sort", "r4", "--chunk", "2", "-o", str(path)).code == 0
    (table,) = json.loads(path.read_text())["tables"]
    want = python_rows({k: v[order] for k, v in ref.items()})
    assert all(same(a, b) for row, w in zip(table["rows"], want) for a, b in zip(row, w))
    assert len(table["rows"]) == 9


def test_columns_use_the_registrys_rule_in_every_format(cli, tmp_path):
    pq = pytest.importorskip("pyarrow.parquet")
    path = tmp_path / "picked.parquet"
    assert cli("scan", str(CRANK), *VARY, *DRIVER, "--columns", "r4,min_transmission_deg (deg)",
               "-o", str(path)).code == 0
    assert pq.read_table(path).column_names == ["design", "r4", "min_transmission_deg"]
    r = cli("scan", str(CRANK), *VARY, *DRIVER, "--columns", "nothing", "-f", "csv")
    assert r.code == 2 and r.err.startswith("error: ") and "matches no column" in r.err


@pytest.mark.parametrize("name", ["x.mat", "x.csvx", "x.parquet.bak"])
def test_an_unknown_suffix_is_one_line_and_exit_2(cli, tmp_path, name):
    target = tmp_path / name
    r = cli("scan", str(CRANK), "--vary", "r2=20:30:3", "--step", "90", "-o", str(target))
    assert r.code == 2, (r.out, r.err)
    lines = r.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and ".csv" in lines[0], r.err
    assert not target.exists() and list(tmp_path.iterdir()) == []


# --- memory -----------------------------------------------------------------------------------------

def traced_peak(cli, path: Path, designs_r4: int) -> int:
    """The traced peak (bytes) of a streamed scan of 200 x designs_r4 designs to CSV, in
    chunks of 500 designs run here (no worker threads holding other chunks)."""
    tracemalloc.start()
    try:
        r = cli("scan", str(CRANK), "--vary", "r2=20:60:200", "--vary", f"r4=60:100:{designs_r4}",
                "--step", "90", "--chunk", "500", "--scheduler", "synchronous", "-o", str(path))
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert r.code == 0, r.err
    return peak


def test_a_streamed_scan_holds_a_chunk_not_the_scan(cli, tmp_path):
    """20,000 designs to CSV: the traced peak is a fraction of the file written, and no
    larger than a 2,000-design scan's (what is held does not grow with the scan)."""
    cli("scan", str(CRANK), "--vary", "r2=20:60:2", "--step", "90", "-f", "csv")  # imports, once
    small = traced_peak(cli, tmp_path / "small.csv", 10)
    big_path = tmp_path / "big.csv"
    big = traced_peak(cli, big_path, 100)
    size = big_path.stat().st_size
    with open(big_path) as fh:
        assert sum(1 for _ in fh) == 20_001
    assert size > 4_000_000
    print(f"traced peak {big:,} B (2,000 designs: {small:,} B) for a CSV of {size:,} B")
    assert big < size / 3, (big, size)
    assert big < 1.5 * small, (big, small)
