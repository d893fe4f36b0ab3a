"""The sweep's report (issue 20): one table of positions whose columns are read from the
engine's arrays, written by the one writer registry. Its CSV, JSON, parquet and xlsx read
back to the API's numbers (bit for bit where the format keeps doubles, an array engine's
numpy-twin columns to a stated bound); the joints' numpy twin (rates.place_np) agrees with
the scalar definition; a crank-rocker's joints equal its closed form (derived here)."""

from __future__ import annotations

import csv
import json
import math
import random
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import linkage
from linkage.kinematics.loading import load
from linkage.kinematics.placing import place, place_np
from linkage.render import cells, formats, writers
from linkage.render.sweep import equation_report, ranges_of, sweep_report
from ulps import assert_ulps

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
SAMPLE_NAMES = sorted(p.name for p in SAMPLES.glob("*.toml"))
CRANK_ROCKER = SAMPLES / "crank_rocker.toml"


def _q_of(m, solution):
    return [math.radians(solution[u.name]) if u.kind == "angle" else solution[u.name] for u in m.unknowns]


def _driver_scale(m):
    return math.pi / 180.0 if m.driver.kind == "angle" else 1.0


# --- place_np: the numpy twin of the joints' sums --------------------------------------------

@pytest.mark.parametrize("name", SAMPLE_NAMES)
def test_place_np_agrees_with_the_scalar_place_on_every_sample(name):
    """Solved positions over a sweep and random (unsolved) configurations: every joint's x
    and y within 4 ulps of the mechanism's size of the scalar sums (bit for bit where
    numpy's cos and sin are the C library's)."""
    m = load(SAMPLES / name)
    if m.driver.kind == "angle":
        values = [float(v) for v in np.arange(0.0, 360.0, 7.3)]
    else:
        values = [float(v) for v in np.linspace(0.9 * m.driver.value, 1.1 * m.driver.value, 20)]
    r = linkage.sweep(m, values, batch=False)
    solved = [p for p in r.positions if p.solution]
    qs = [_q_of(m, p.solution) for p in solved]
    ds = [p.input * _driver_scale(m) for p in solved]
    rng = random.Random(20)
    for _ in range(30):  # any configuration: the sums are defined whether or not loops close
        qs.append([rng.uniform(-7.0, 7.0) if u.kind == "angle" else rng.uniform(-2.0, 2.0) * m.length_scale
                   for u in m.unknowns])
        ds.append(rng.uniform(-7.0, 7.0) if m.driver.kind == "angle" else rng.uniform(-1, 1) * m.length_scale)
    got = place_np(m.model, [np.array(c) for c in zip(*qs)], np.array(ds))
    size = m.length_scale
    for i, (q, d) in enumerate(zip(qs, ds)):
        ref = place(m.model, q, d)
        assert list(ref) == list(got)
        for k, (z, _, _) in ref.items():
            assert_ulps(got[k][0][i], z.real, 4, size, (name, k, i))
            assert_ulps(got[k][1][i], z.imag, 4, size, (name, k, i))
    if any(loop.joints for loop in m.loops):
        assert got


# --- the report's table read back -------------------------------------------------------------

def _cells(path):
    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    return rows[0], rows[1:]


def _number(text):
    return None if text == "" else float(text)


def _api_rows(r):
    """What the API says, position by position, in the report's column order (joints
    last): (driver, status, unknowns..., branch, iterations, det, transmission, joints)."""
    names = list(r.names)
    out = []
    joints = None
    for p in r.positions:
        if joints is None and p.rates is not None:
            joints = list(p.rates.joints)
    for p in r.positions:
        sol = p.solution or {}
        row = [p.input, p.status, *[sol.get(n) for n in names], p.branch, p.iterations,
               p.det if p.solution else None]
        if r.classification:
            row.append(p.transmission)
        for j in joints or []:
            row += list(p.rates.joints[j]) if p.rates is not None else [None, None]
        out.append(row)
    return out, joints or []


ENGINES = {"one at a time": dict(batch=False), "batch": dict(batch=True), "closed form": {}}


@pytest.mark.parametrize("name", ["crank_rocker.toml", "watt_sixbar_joints.toml", "slider_crank.toml"])
def test_place_np_on_threads_is_bit_for_bit_place_np_in_line(name, monkeypatch):
    """A long block's vectors computed on threads (placing.THREAD_FROM) give the very
    bits of the same sums computed in line, for solved and random configurations."""
    from linkage.kinematics import placing

    m = load(SAMPLES / name)
    n = placing.THREAD_FROM + 7
    rng = np.random.default_rng(33)
    q = [rng.uniform(-7.0, 7.0, n) if u.kind == "angle" else rng.uniform(-2.0, 2.0, n) * m.length_scale
         for u in m.unknowns]
    d = rng.uniform(-7.0, 7.0, n) if m.driver.kind == "angle" else rng.uniform(-1, 1, n) * m.length_scale
    threaded = place_np(m.model, q, d)
    monkeypatch.setattr(placing, "THREAD_FROM", 10**12)
    in_line = place_np(m.model, q, d)
    assert list(threaded) == list(in_line) and threaded
    for k, (x, y) in in_line.items():
        assert threaded[k][0].tobytes() == x.tobytes() and threaded[k][1].tobytes() == y.tobytes()


@pytest.mark.parametrize("engine", list(ENGINES))
def test_the_csv_and_json_read_back_to_the_apis_numbers_bit_for_bit(engine, tmp_path):
    """CSV and JSON hold the same doubles; they are the API's own numbers bit for bit except
    an array engine's numpy-twin columns (transmission, joints), held to a stated bound."""
    m = load(CRANK_ROCKER)
    values = [float(v) for v in np.arange(0.0, 360.5, 2.5)]
    r = linkage.sweep(m, values, joints=True, **ENGINES[engine])
    assert r.method == {"one at a time": "newton", "batch": "newton (batch)",
                        "closed form": "newton (closed form)"}[engine]
    assert (engine == "one at a time") == isinstance(r.positions, tuple)
    api, joints = _api_rows(r)
    assert joints == ["O2", "A", "B", "O4", "P"]
    report = sweep_report(r, 10)
    writers.write(report, "csv", tmp_path / "s.csv")
    writers.write(report, "json", tmp_path / "s.json")
    head, rows = _cells(tmp_path / "s.csv")
    assert head[:9] == ["theta2 (deg)", "status", "theta3 (deg)", "theta4 (deg)", "branch", "iterations",
                        "det J (mm^2/rad^2)", "transmission angle 0..90 (deg)", "O2.x (mm)"]
    assert head[-2:] == ["P.x (mm)", "P.y (mm)"]
    doc = json.loads((tmp_path / "s.json").read_text())
    table = doc["tables"][0]
    assert table["name"] == "positions" and table["units"][0] == "deg" and table["columns"][-1] == "P.y"
    assert len(rows) == len(table["rows"]) == len(values)
    text_at = {1, 4}
    first_joint = head.index("O2.x (mm)")
    # an array engine's transmission column is the derivation's numpy twin of the rule the
    # API's positions use (transmission_np: numpy's atan2, on AVX-512 a SIMD routine that
    # differs from math.atan2 in the last bit): to 4 ulps of 180 deg (tests/ulps.py)
    twin_at = {head.index("transmission angle 0..90 (deg)")} if engine != "one at a time" else set()
    for want, got_csv, got_json in zip(api, rows, table["rows"]):
        assert len(got_csv) == len(want) == len(got_json)
        for k, (w, c, j) in enumerate(zip(want, got_csv, got_json)):
            if k in text_at:
                assert c == (w or "") and j == w
            elif k in twin_at:
                assert _number(c) == j, (k, w, c, j)
                assert_ulps(_number(c), w, 4, 180.0, (k, w, c, j))
            elif k < first_joint or engine == "one at a time":
                assert _number(c) == w and j == w, (k, w, c, j)  # bit for bit
            else:  # an array engine's joints: rates.place_np, to its agreement with the scalar sums
                assert _number(c) == j, (k, w, c, j)
                assert_ulps(_number(c), w, 4, 100.0, (k, w, c, j))
    # the document keeps the sweep's keys
    assert {"mechanism", "driver", "positions", "ranges", "summary", "feasible_ranges"} <= set(doc)


def test_the_joints_equal_the_crank_rockers_closed_form(tmp_path):
    """A = r2 e^(i theta2); B = O4 + r4 e^(i theta4), O4 = (r1, 0); P = A + 60 e^(i (theta3 +
    30 deg)): from the file's numbers, against the batch engine's report."""
    m = load(CRANK_ROCKER)
    r = linkage.sweep(m, [float(v) for v in np.arange(0.0, 360.0, 0.25)], batch=True, joints=True)
    writers.write(sweep_report(r, 10), "csv", tmp_path / "s.csv")
    head, rows = _cells(tmp_path / "s.csv")
    at = {h: k for k, h in enumerate(head)}
    for row in rows:
        t2, t3, t4 = (math.radians(float(row[at[f"{h} (deg)"]])) for h in ("theta2", "theta3", "theta4"))
        want = {"A.x": 40 * math.cos(t2), "A.y": 40 * math.sin(t2), "B.x": 100 + 80 * math.cos(t4),
                "B.y": 80 * math.sin(t4), "O4.x": 100.0, "O4.y": 0.0,
                "P.x": 40 * math.cos(t2) + 60 * math.cos(t3 + math.radians(30)),
                "P.y": 40 * math.sin(t2) + 60 * math.sin(t3 + math.radians(30))}
        for k, w in want.items():
            assert abs(float(row[at[f"{k} (mm)"]]) - w) <= 1e-12 * 100, (k, row)


@pytest.mark.parametrize("engine", ["one at a time", "batch"])
def test_parquet_and_xlsx_read_back_to_the_apis_numbers(engine, tmp_path):
    pq = pytest.importorskip("pyarrow.parquet")
    openpyxl = pytest.importorskip("openpyxl")
    m = load(CRANK_ROCKER)
    r = linkage.sweep(m, [float(v) for v in range(0, 361, 5)], joints=True, **ENGINES[engine])
    api, _ = _api_rows(r)
    report = sweep_report(r, 10)
    writers.write(report, "parquet", tmp_path / "s.parquet")
    writers.write(report, "xlsx", tmp_path / "s.xlsx")
    t = pq.read_table(tmp_path / "s.parquet")
    assert t.schema.field("theta3").metadata[b"unit"] == b"deg"
    assert t.schema.field("det J").metadata[b"unit"] == b"mm^2/rad^2"
    assert [list(x) for x in zip(*t.to_pydict().values())] == api
    sheet = openpyxl.load_workbook(tmp_path / "s.xlsx", read_only=True)["positions"]
    got = [list(x) for x in sheet.iter_rows(values_only=True)]
    assert got[0][:3] == ["theta2 (deg)", "status", "theta3 (deg)"]
    assert len(got) == len(api) + 1
    for g, w in zip(got[1:], api):  # a sheet keeps 16 significant digits, as Excel shows them
        words = [[x for x in row if isinstance(x, str) or x is None] for row in (g, w)]
        assert words[0] == words[1]
        assert all(math.isclose(a, b, rel_tol=1e-15, abs_tol=1e-300) for a, b in zip(g, w)
                   if isinstance(b, (int, float))), (g, w)


def test_a_big_batch_sweep_to_csv_equals_the_one_at_a_time_engine(tmp_path):
    """25,000 positions through the batch engine (its columns, the pyarrow number
    formatting when installed) against the one-at-a-time engine, to the engines'
    documented agreement (1e-12 relative to the size, kinematics/batch.py)."""
    m = load(CRANK_ROCKER)
    values = [k * 360.0 / 25_000 for k in range(25_000)]
    big = linkage.sweep(m, values, batch=True, joints=True)
    writers.write(sweep_report(big, 10), "csv", tmp_path / "big.csv")
    head, rows = _cells(tmp_path / "big.csv")
    one = linkage.sweep(m, values, batch=False)
    assert len(rows) == 25_000
    at = {h: k for k, h in enumerate(head)}
    for row, p in zip(rows, one.positions):
        assert row[1] == p.status == "converged"
        assert float(row[0]) == p.input
        for n in ("theta3", "theta4"):
            assert abs(float(row[at[f"{n} (deg)"]]) - p.solution[n]) <= 1e-10
        assert abs(float(row[at["transmission angle 0..90 (deg)"]]) - p.transmission) <= 1e-10
        assert abs(float(row[at["det J (mm^2/rad^2)"]]) - p.det) <= 1e-12 * 1e4 * 10


def test_the_ranges_read_from_columns_equal_the_one_at_a_time_ranges():
    m = load(CRANK_ROCKER)
    values = [float(v) for v in np.arange(0.0, 360.0, 0.5)]
    a = ranges_of(linkage.sweep(m, values, batch=True))
    b = ranges_of(linkage.sweep(m, values, batch=False))
    assert a.keys() == b.keys() == {"theta3", "theta4"}
    for name in a:
        for key in ("min", "max", "stroke"):
            assert abs(a[name][key] - b[name][key]) <= 1e-9
        assert a[name]["at_min"] == b[name]["at_min"] and a[name]["at_max"] == b[name]["at_max"]
    # the rocker's swing by the law of cosines (its extremes where crank and coupler line up)
    lo = math.degrees(math.acos((100 ** 2 + 80 ** 2 - 80 ** 2) / (2 * 100 * 80)))
    hi = math.degrees(math.acos((100 ** 2 + 80 ** 2 - 160 ** 2) / (2 * 100 * 80)))
    assert abs(a["theta4"]["stroke"] - (hi - lo)) < 1e-3  # 0.5-degree grid


def test_with_a_speed_the_csv_has_the_rate_columns_with_units(tmp_path):
    m = load(CRANK_ROCKER)
    r = linkage.sweep(m, [0.0, 30.0, 60.0], speed=10.0, batch=False)
    writers.write(sweep_report(r, 10), "csv", tmp_path / "s.csv")
    head, rows = _cells(tmp_path / "s.csv")
    for h in ("rates status", "dtheta3/dt (rad/s)", "dtheta3/dt bound (rad/s)", "d2theta4/dt2 (rad/s^2)",
              "A.vx (mm/s)", "A.ay (mm/s^2)", "B.v bound (mm/s)"):
        assert h in head, h
    at = {h: k for k, h in enumerate(head)}
    for row, p in zip(rows, r.positions):
        assert row[at["rates status"]] == p.rates.status
        assert float(row[at["dtheta3/dt (rad/s)"]]) == p.rates.velocities["theta3"]
        assert float(row[at["A.vx (mm/s)"]]) == p.rates.joint_velocities["A"][0]
        # the crank pin's speed is r2 omega, by hand
        vx, vy = float(row[at["A.vx (mm/s)"]]), float(row[at["A.vy (mm/s)"]])
        assert abs(math.hypot(vx, vy) - 400.0) < 1e-9


def test_the_display_samples_rows_and_shows_the_ranges():
    m = load(CRANK_ROCKER)
    r = linkage.sweep(m, [float(v) for v in np.arange(0.0, 360.0, 0.01)], batch=True)
    report = sweep_report(r, 6, joints_note="joints: in the csv")
    from linkage.render.display import display_text

    text = display_text(report, "plain")
    assert "one row in 90 of 36000 shown" in text
    assert "theta4: min" in text and "joints: in the csv" in text
    assert report.tables[0].row_count == 36_000


def test_the_equation_sweeps_report_has_its_columns_and_units(tmp_path):
    rows = [(10.0, "converged", 40.5, 4, 1e-17), (20.0, "no_solution", None, 0, None)]
    report = equation_report(rows, "newton", 1e-12, "R1 = 1, R2 = 2, R3 = 3", 6)
    writers.write(report, "csv", tmp_path / "e.csv")
    head, got = _cells(tmp_path / "e.csv")
    assert head == ["alpha (deg)", "status", "phi (deg)", "iterations", "f(phi)"]
    assert got == [["10.0", "converged", "40.5", "4", "1e-17"], ["20.0", "no_solution", "", "0", ""]]
    assert report.document()["positions"][1]["status"] == "no_solution"


def test_a_small_sweeps_report_does_not_import_numpy():
    code = ("import sys, io\n"
            "import linkage\n"
            "from linkage.render.sweep import sweep_report\n"
            "from linkage.render import writers\n"
            f"r = linkage.sweep({str(CRANK_ROCKER)!r}, [0.0, 10.0, 20.0], batch=False, joints=True)\n"
            "rep = sweep_report(r, 6)\n"
            "from linkage.render.writers import open_sink, write_tables\n"
            "out = io.StringIO()\n"
            "from linkage.render.formats import CsvSink\n"
            "sink = CsvSink(out, None)\n"
            "write_tables(sink, rep.tables)\n"
            "assert out.getvalue().count('\\n') == 4\n"
            "print('HEAVY', [m for m in ('numpy', 'pyarrow') if m in sys.modules])\n")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert "HEAVY []" in proc.stdout


def test_the_csv_block_path_reads_back_as_the_plain_repr_path(tmp_path):
    """pyarrow's block formatting (render.cells.arrow_table written by pyarrow.csv, for big tables) against
    Python's repr, cell by cell: the same doubles back (NaN and infinities empty), the same
    integers and words; text that needs quoting goes cell by cell."""
    pytest.importorskip("pyarrow")
    import io

    from linkage.render.data import Column, DataTable

    rng = np.random.default_rng(20)
    n = cells.FAST_CELLS // 3 + cells.SLICE + 17
    x = rng.standard_normal(n) * 10.0 ** rng.integers(-300, 300, n)
    x[::97] = np.nan
    x[5] = np.inf
    x[6] = -0.0
    x[7] = 100.0
    words = np.array(["converged", None, "no_solution"], dtype=object)[np.arange(n) % 3]
    cols = (Column("x", "mm", x), Column("k", "", np.arange(n) - 5, "int"), Column("s", "", words, "text"))
    fast, plain = io.StringIO(), io.StringIO()
    sink = formats.CsvSink(fast, None)
    sink.begin("t", cols, n)
    assert sink.fast
    sink.rows([c.values for c in cols])
    sink = formats.CsvSink(plain, None)
    sink.begin("t", cols)  # no row count: the cell-by-cell path with repr
    assert not sink.fast
    sink.rows([c.values for c in cols])
    a = list(csv.reader(io.StringIO(fast.getvalue())))
    b = list(csv.reader(io.StringIO(plain.getvalue())))
    assert a[0] == b[0] == ["x (mm)", "k", "s"] and len(a) == len(b) == n + 1
    for ra, rb, v in zip(a[1:], b[1:], x):
        assert ra[1:] == rb[1:]
        assert _number(ra[0]) == _number(rb[0]) == (v if math.isfinite(v) else None)
        if v == 0.0:
            assert math.copysign(1.0, float(ra[0])) == math.copysign(1.0, v)
    # a word with a comma: quoted, cell by cell
    quoted = (Column("s", "", np.array(["a,b"] * n, dtype=object), "text"), cols[0])
    out = io.StringIO()
    writers.write_tables(formats.CsvSink(out, None), [DataTable("t", quoted)])
    assert [r[0] for r in csv.reader(io.StringIO(out.getvalue()))][1:] == ["a,b"] * n
