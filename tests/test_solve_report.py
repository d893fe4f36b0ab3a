"""`linkage solve` returns one report: every quantity (iterations, unknowns with their
rates, joints) in every format, read back with the same numbers (CSV and JSON bit for bit)
and the same units; the header keeps --digits; rounding noise prints as 0 on screen only."""

from __future__ import annotations

import cmath
import json
import math
import struct
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from linkage.render.data import split_header
from linkage.render.report import NOISE_ULPS, denoise, is_noise
from report_reading import csv_files

SAMPLES = Path(__file__).resolve().parent.parent / "sample_inputs"
ME581 = str(SAMPLES / "fourbar_me581.toml")
INVERTED = str(SAMPLES / "inverted_slider_crank.toml")
EPS = 2.220446049250313e-16


def bits(values: list[float]) -> list[bytes]:
    return [struct.pack("<d", v) for v in values]


def by_name(rows: list[list[str]]) -> dict[str, dict[str, str]]:
    """CSV rows keyed by their first cell, each a dict of header -> cell."""
    head, *body = rows
    return {r[0]: dict(zip(head, r)) for r in body}


# --- the rates in the CSV ---------------------------------------------------------------------

def test_speed_csv_carries_the_rates_bit_for_bit_with_the_json(cli, tmp_path):
    args = ("solve", ME581, "--speed", "600rpm", "--accel", "15")
    assert cli(*args, "-o", str(tmp_path / "f.csv")).code == 0
    assert cli(*args, "-o", str(tmp_path / "f.json")).code == 0
    doc = json.loads((tmp_path / "f.json").read_text())
    csvs = csv_files(tmp_path / "f.csv", [t["name"] for t in doc["tables"]])
    assert set(csvs) == {"iterations", "unknowns", "joints", "outcome"}

    unknowns = by_name(csvs["unknowns"])
    assert set(unknowns) == {"theta3", "theta4"}
    for n, row in unknowns.items():
        assert bits([float(row["velocity"])]) == bits([doc["velocities"][n]])
        assert bits([float(row["acceleration"])]) == bits([doc["accelerations"][n]])
        assert bits([float(row["velocity bound"])]) == bits([doc["rate_bounds"]["velocities"][n]])
        assert bits([float(row["value"])]) == bits([doc["solution"][n]])
        assert row["unit"] == doc["units"][n] == "deg"
        assert row["velocity unit"] == doc["rate_units"]["velocities"][n] == "rad/s"
        assert row["acceleration unit"] == doc["rate_units"]["accelerations"][n] == "rad/s^2"
        assert row["rates status"] == "ok"
    joints = by_name(csvs["joints"])
    assert csvs["joints"][0] == ["joint", "x (cm)", "y (cm)", "vx (cm/s)", "vy (cm/s)", "v bound (cm/s)",
                                 "ax (cm/s^2)", "ay (cm/s^2)", "a bound (cm/s^2)"]
    for j, row in joints.items():
        assert bits([float(row["x (cm)"]), float(row["y (cm)"])]) == bits(doc["joints"][j])
        assert bits([float(row["vx (cm/s)"]), float(row["vy (cm/s)"])]) == bits(doc["joint_velocities"][j])
        assert bits([float(row["ax (cm/s^2)"]), float(row["ay (cm/s^2)"])]) == \
            bits(doc["joint_accelerations"][j])

    # and the numbers are the mechanism's (the loop r2 e^(i t2) + r3 e^(i t3) - r4 e^(i t4)
    # - r1 = 0 differentiated once and twice, solved here as a 2x2 real system)
    a, b, c = 30.0, 60.0, 45.0
    w2, al2 = 600 * math.pi / 30, 15.0
    t2, t3, t4 = (math.radians(v) for v in (65.0, doc["solution"]["theta3"], doc["solution"]["theta4"]))
    e2, e3, e4 = (cmath.exp(1j * t) for t in (t2, t3, t4))
    m = np.array([[(1j * b * e3).real, (-1j * c * e4).real], [(1j * b * e3).imag, (-1j * c * e4).imag]])
    rhs = -1j * a * w2 * e2
    w3, w4 = np.linalg.solve(m, [rhs.real, rhs.imag])
    rhs2 = -(1j * a * al2 - a * w2**2) * e2 + b * w3**2 * e3 - c * w4**2 * e4
    al3, al4 = np.linalg.solve(m, [rhs2.real, rhs2.imag])
    for got, want in ((unknowns["theta3"]["velocity"], w3), (unknowns["theta4"]["velocity"], w4),
                      (unknowns["theta3"]["acceleration"], al3), (unknowns["theta4"]["acceleration"], al4)):
        assert float(got) == pytest.approx(want, rel=1e-11)
    vb = 1j * a * w2 * e2 + 1j * b * w3 * e3
    assert float(joints["B"]["vx (cm/s)"]) == pytest.approx(vb.real, rel=1e-11)
    assert float(joints["B"]["vy (cm/s)"]) == pytest.approx(vb.imag, rel=1e-11)


# --- every solve report in every data format --------------------------------------------------

CASES = {
    "scalar": ("solve", "--method", "secant"),
    "all": ("solve", "--method", "all"),
    "file": ("solve", ME581),
    "file-speed": ("solve", ME581, "--speed", "25", "--accel", "15"),
}
TABLES = {"scalar": ["iterations"], "all": ["summary"],
          "file": ["iterations", "unknowns", "joints", "outcome"],
          "file-speed": ["iterations", "unknowns", "joints", "outcome"]}


def _number(cell: str) -> float | None:
    return float(cell) if cell else None


@pytest.mark.parametrize("case", list(CASES))
def test_every_solve_report_reads_back_in_every_format(cli, tmp_path, case):
    pq = pytest.importorskip("pyarrow.parquet")
    openpyxl = pytest.importorskip("openpyxl")
    args = CASES[case]
    for suffix in ("csv", "json", "parquet", "xlsx"):
        run = cli(*args, "-o", str(tmp_path / f"r.{suffix}"))
        assert run.code == 0, run.err
    doc = json.loads((tmp_path / "r.json").read_text())
    tables = {t["name"]: t for t in doc["tables"]}
    assert list(tables) == TABLES[case]
    csvs = csv_files(tmp_path / "r.csv", TABLES[case])  # one file per table
    book = openpyxl.load_workbook(tmp_path / "r.xlsx")
    assert book.sheetnames == TABLES[case]

    for k, (name, t) in enumerate(tables.items()):
        head, *rows = csvs[name]
        # the same names and units in CSV, JSON, parquet and xlsx
        assert [split_header(h) for h in head] == list(zip(t["columns"], t["units"]))
        parquet = pq.read_table(tmp_path / ("r.parquet" if k == 0 else f"r.{name}.parquet"))
        assert parquet.column_names == t["columns"]
        assert [(f.metadata or {}).get(b"unit", b"").decode() for f in parquet.schema] == t["units"]
        sheet = list(book[name].iter_rows(values_only=True))
        assert list(sheet[0]) == head
        assert len(rows) == len(t["rows"]) == parquet.num_rows == len(sheet) - 1 > 0

        columns = parquet.to_pydict()
        for j, col in enumerate(t["columns"]):
            kind = parquet.schema.field(col).type
            json_col = [r[j] for r in t["rows"]]
            if str(kind) != "double":
                assert [r[j] for r in rows] == ["" if v is None else str(v).lower() if isinstance(v, bool)
                                                else str(v) for v in json_col]
                continue
            csv_col = [_number(r[j]) for r in rows]
            assert [v is None for v in csv_col] == [v is None for v in json_col] == \
                [v is None for v in columns[col]]
            if col == "time per solve":
                continue  # measured again by each run
            # CSV, JSON and parquet bit for bit; xlsx to its 16 significant digits
            expected = bits([v for v in json_col if v is not None])
            assert bits([v for v in csv_col if v is not None]) == expected
            assert bits([v for v in columns[col] if v is not None]) == expected
            for cell, want in zip((r[j] for r in sheet[1:]), json_col):
                assert (cell is None) if want is None else abs(float(cell) - want) <= 6e-16 * abs(want)

    # the tables hold the document's numbers
    if case == "scalar":
        assert [list(r.values()) for r in doc["iterations"]] == tables["iterations"]["rows"]
        assert tables["iterations"]["units"][1] == "deg"
    elif case == "all":
        runs = doc["runs"]
        summary = tables["summary"]
        assert [r["method"] for r in runs] == [row[0] for row in summary["rows"]]
        root = summary["columns"].index("phi")
        assert summary["units"][root] == "deg"
        assert summary["units"][summary["columns"].index("time per solve")] == "us"
        for r, row in zip(runs, summary["rows"]):
            assert row[root] == r["solution"]["phi"]
    else:
        unknowns = {r[0]: dict(zip(tables["unknowns"]["columns"], r)) for r in tables["unknowns"]["rows"]}
        for n, value in doc["solution"].items():
            assert unknowns[n]["value"] == value
            if case == "file-speed":
                assert unknowns[n]["velocity"] == doc["velocities"][n]
                assert unknowns[n]["acceleration"] == doc["accelerations"][n]
            else:
                assert "velocity" not in unknowns[n]
        assert [r[0] for r in tables["joints"]["rows"]] == list(doc["joints"])


def test_method_all_json_is_one_document_with_its_runs(cli):
    """A document is an object (the writer adds its tables): --method all's runs are under
    "runs", each the one-method document."""
    doc = json.loads(cli("solve", "--method", "all", "--format", "json").out)
    assert doc["units"] == {"phi": "deg"}
    assert {"method", "status", "solution", "iterations", "seconds_per_solve"} <= set(doc["runs"][0])


# --- headers keep --digits ------------------------------------------------------------------

def test_digits_reach_the_driver_in_the_header(cli):
    args = ("solve", ME581, "--set", "theta2=65.1234567", "--format", "plain")
    assert cli(*args, "--digits", "7").out.splitlines()[0] == "ME581 four-bar: theta2 = 65.12346 deg"
    assert cli(*args, "--digits", "12").out.splitlines()[0] == "ME581 four-bar: theta2 = 65.1234567 deg"
    assert cli(*args, "--digits", "3").out.splitlines()[0] == "ME581 four-bar: theta2 = 65.1 deg"


def test_digits_reach_the_four_bar_equation_header(cli):
    first = cli("solve", "--alpha", "70.123456789", "--format", "plain", "--digits", "5").out.splitlines()[0]
    assert first == ("four-bar input-output equation, alpha = 70.123 deg, R1 = 1.6667, R2 = 2.5, "
                     "R3 = 1.8333")
    first = cli("solve", "--alpha", "70.123456789", "--format", "plain", "--digits", "12").out.splitlines()[0]
    assert "alpha = 70.123456789 deg, R1 = 1.66666666667," in first


# --- rounding noise -------------------------------------------------------------------------

def test_the_rounding_noise_rule():
    # within NOISE_ULPS rounding errors of the scale: noise; beyond it: a number
    assert is_noise(0.0, 90.0) and is_noise(-0.0, 0.0)
    assert is_noise(9.18e-15, 90.0)  # the joint, in a 90 cm mechanism
    assert is_noise(NOISE_ULPS * EPS * 90.0, 90.0)
    assert not is_noise(2 * NOISE_ULPS * EPS * 90.0, 90.0)
    assert not is_noise(1e-12, 90.0)  # a genuine small number stays
    assert not is_noise(1e-12, 1.0)
    # within its own error bound: indistinguishable from 0
    assert is_noise(-2.27e-14, 900.0, bound=1.7e-12)
    assert not is_noise(3e-12, 0.0, bound=1.7e-12)
    assert denoise(9.18e-15, 90.0) == 0.0 and denoise(1e-12, 90.0) == 1e-12
    for v in (math.nan, math.inf, None, "text", 3):
        assert not is_noise(v, 90.0)


def test_a_still_joint_prints_0_and_the_file_keeps_every_bit(cli, tmp_path):
    args = ("solve", INVERTED, "--speed", "25")
    text = cli(*args, "--format", "plain").out
    assert cli(*args, "-o", str(tmp_path / "s.csv")).code == 0
    joints = by_name(csv_files(tmp_path / "s.csv", ["iterations", "unknowns", "joints"])["joints"])
    lines = {ln.split()[0]: ln.split() for ln in text.split("Joints")[1].splitlines()[3:] if ln.strip()}
    assert set(lines) == set(joints)
    for j, row in joints.items():
        vx, bound = float(row["vx (mm/s)"]), float(row["v bound (mm/s)"])
        if abs(vx) <= bound:  # rounding noise (F: -2.3e-14 mm/s within its 1.7e-12 bound)
            assert lines[j][3] == "0", (j, lines[j])
        else:
            assert float(lines[j][3]) == pytest.approx(vx, rel=1e-11)
    assert lines["O2"][1:3] == ["0", "0"]  # a joint at exactly 0
    assert any(0.0 < abs(float(r["vx (mm/s)"])) <= float(r["v bound (mm/s)"]) for r in joints.values()), \
        "no joint here has a noisy zero to show: the test of the rule needs another mechanism"


def test_a_genuine_small_error_in_an_iteration_table_still_prints(cli):
    text = cli("solve", "--equation", "x**2 - 2", "--x0", "1", "--format", "plain").out
    row = next(ln for ln in text.splitlines() if ln.split()[:1] == ["5"])
    # Newton on x^2 - 2 from 1 in exact arithmetic: x_5 = 665857/470832, its step (x^2-2)/2x
    x5 = Fraction(665857, 470832)
    step = float((x5 * x5 - 2) / (2 * x5))
    assert 1e-12 < step < 2e-12
    assert float(row.split()[-1]) == pytest.approx(step, rel=1e-3), row


# --- the convergence plot -----------------------------------------------------------------

def test_convergence_plot_has_integer_iteration_ticks(tmp_path, monkeypatch):
    pytest.importorskip("matplotlib")
    from linkage.render import plots

    seen = []
    real_save = plots.save_figure

    def keep(fig, path):
        fig.canvas.draw()
        seen.append([t for t in fig.axes[0].get_xticks()])
        real_save(fig, path)

    monkeypatch.setattr(plots, "save_figure", keep)
    plots.convergence_plot([("newton", [1.0, 0.1, 1e-3, 1e-7])], tmp_path / "c.png", "four iterations")
    ticks = seen[0]
    assert ticks and all(t == int(t) for t in ticks), ticks
    assert (tmp_path / "c.png").stat().st_size > 0


def test_a_failed_file_solve_says_so_in_every_file(cli, tmp_path) -> None:
    """A run that did not converge: its outcome table (status, message) is in the CSV too,
    not only in the JSON and on the screen."""
    r = cli("solve", str(SAMPLES / "fourbar_me581.toml"), "--max-iter", "1", "-o", str(tmp_path / "f.csv"))
    assert r.code == 1
    parts = csv_files(tmp_path / "f.csv", ["iterations", "outcome"])
    assert not (tmp_path / "f.unknowns.csv").exists() and not (tmp_path / "f.joints.csv").exists()
    head, row = parts["outcome"][0], parts["outcome"][1]
    outcome = dict(zip(head, row))
    assert outcome["converged"] == "false" and outcome["status"] == "max_iter"
    assert outcome["iterations"] == "1"
