"""Design-space scans: metrics against closed forms, the two engines against each other,
schedulers (a real dask.distributed cluster on loopback), streaming, and --where safety."""

from __future__ import annotations

import csv
import io
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from linkage.kinematics.design_continuation import sweep_engine as _sweep_engine
from linkage.kinematics.designs import solve_designs
from linkage.kinematics.loading import load
from linkage.problems.closed_form import fourbar_class
from linkage.scan.metrics import grashof_class

ROOT = Path(__file__).resolve().parent.parent
CRANK = ROOT / "sample_inputs" / "crank_rocker.toml"
SLIDER = ROOT / "sample_inputs" / "slider_crank.toml"
SIXBAR = ROOT / "sample_inputs" / "watt_sixbar.toml"


def run(*args: str, check: bool = True) -> subprocess.CompletedProcess[str]:
    proc = subprocess.run([sys.executable, "-m", "linkage", *args], capture_output=True, text=True,
                          timeout=300)
    if check:
        assert proc.returncode == 0, proc.stderr
    return proc


# --- an independent reference: the law of cosines, in plain Python -----------------------------

def reference_fourbar(r1: float, r2: float, r3: float, r4: float, branch: str) -> dict[str, float]:
    """Feasible fraction, theta4 swing and transmission extremes over theta2 = 0..359 deg
    (ground along x), one position at a time with math only."""
    sign = -1.0 if branch == "open" else 1.0
    feasible = 0
    theta4: list[float | None] = []
    mus = []
    for k in range(360):
        t2 = math.radians(k)
        ax, ay = r2 * math.cos(t2), r2 * math.sin(t2)
        d2 = (ax - r1) ** 2 + ay * ay
        if not (r3 - r4) ** 2 <= d2 <= (r3 + r4) ** 2:
            theta4.append(None)
            continue
        feasible += 1
        d = math.sqrt(d2)
        mu = math.degrees(math.acos(max(-1.0, min(1.0, (r3 * r3 + r4 * r4 - d2) / (2 * r3 * r4)))))
        psi = math.acos(max(-1.0, min(1.0, (r4 * r4 + d2 - r3 * r3) / (2 * r4 * d))))
        theta4.append(math.degrees(math.atan2(ay, ax - r1) + sign * psi))
        mus.append(min(mu, 180.0 - mu))
    # continuous: each value the representative nearest the previous feasible one, read
    # around the circle from the start of a feasible arc (one across 359 -> 0 is one piece)
    starts = [k for k in range(360) if theta4[k] is not None and theta4[k - 1] is None]
    begin = starts[0] if starts else 0
    smooth = []
    prev = None
    for k in range(360):
        v = theta4[(begin + k) % 360]
        if v is None:
            continue
        if prev is not None:
            v = prev + (v - prev + 180.0) % 360.0 - 180.0
        smooth.append(v)
        prev = v
    out = {"feasible_fraction": feasible / 360.0}
    if smooth:
        # a full turn at most; a rocker that turns fully (back at its start a turn away) 360
        turns_fully = feasible == 360 and abs(smooth[-1] - smooth[0]) > 180.0
        swing = 360.0 if turns_fully else min(max(smooth) - min(smooth), 360.0)
        out.update(theta4_range=swing, min_transmission_deg=min(mus),
                   max_transmission_deg=max(mus), theta4_any=smooth[0])
    return out


@pytest.mark.parametrize("branch", ["open", "crossed"])
def test_fourbar_metrics_match_the_law_of_cosines(branch):
    """Done-when 2: feasible fraction, rocker swing and transmission angle extremes of a few
    hundred random designs (every Grashof class, partly assemblable ones too)."""
    from linkage.files import read_input
    from linkage.scan import ScanJob, run_chunk

    rng = np.random.default_rng(7)
    n = 300
    designs = np.column_stack([rng.uniform(60, 140, n), rng.uniform(10, 90, n), rng.uniform(40, 160, n),
                               rng.uniform(30, 130, n)])
    job = ScanJob(read_input(CRANK), str(CRANK), (), ("r1", "r2", "r3", "r4"),
                  tuple(float(k) for k in range(360)), branch, 1e-12)
    got = run_chunk(job, 0, designs)
    partial = 0
    for i, (r1, r2, r3, r4) in enumerate(designs):
        ref = reference_fourbar(r1, r2, r3, r4, branch)
        assert got["feasible_fraction"][i] == ref["feasible_fraction"], i
        partial += 0.0 < ref["feasible_fraction"] < 1.0
        if ref["feasible_fraction"] == 0.0:
            assert math.isnan(got["theta4_range"][i]) and not got["full_cycle"][i]
            continue
        assert got["solved_fraction"][i] == ref["feasible_fraction"], i
        for key in ("theta4_range", "min_transmission_deg", "max_transmission_deg"):
            assert abs(got[key][i] - ref[key]) <= 1e-9, (i, key, got[key][i], ref[key])
        # the same turn up to whole turns
        shift = (got["theta4_min"][i] - min(ref["theta4_any"], got["theta4_min"][i])) % 360.0
        assert min(shift, 360.0 - shift) < 360.0
    assert partial >= 30  # the sample covers designs that assemble over part of the turn


def test_grashof_classes_match_the_scalar_classification():
    rng = np.random.default_rng(3)
    links = rng.integers(1, 8, size=(2000, 4)).astype(float)  # many ties and change points
    links = np.vstack([links, rng.uniform(1, 10, size=(500, 4))])
    got = grashof_class(*links.T)
    for row, name in zip(links, got):
        want = fourbar_class(*row)["type"].removeprefix("Grashof ").removeprefix("non-Grashof ")
        assert name == want, (row, name, want)


@pytest.mark.parametrize("path,params,branch", [
    (CRANK, {"r2": [30.0, 75.0, 95.0], "r4": [80.0, 40.0, 120.0]}, "open"),
    (CRANK, {"r2": [30.0, 75.0, 95.0], "r4": [80.0, 40.0, 120.0]}, "crossed"),
    (SLIDER, {"r2": [40.0, 130.0], "e": [10.0, -30.0]}, "open"),
    # (a rocker-driven four-bar's name changes along its sign branch, which the scan now
    # follows: tests/test_derived_scan.py checks it against the circle intersection)
])
def test_the_vectorised_engine_agrees_with_continuation_design_by_design(path, params, branch):
    """The closed-form engine and the continuation sweep (an independent path: tangent
    predictors, step halving, the sweep's own gap rules) give the same statuses and numbers."""
    m = load(path)
    arrays = {k: np.array(v) for k, v in params.items()}
    values = np.arange(0.0, 360.0, 3.0)
    fast = solve_designs(m, arrays, values, branch=branch)
    q, status, _, _ = _sweep_engine(m, arrays, values, branch, 1e-12, len(next(iter(params.values()))))
    status = status.reshape(fast.status.shape)
    assert (fast.status == status).all()
    for j, u in enumerate(m.unknowns):
        slow = np.degrees(q[j]) if u.kind == "angle" else q[j]
        slow = slow.reshape(fast.status.shape)
        ok = status == 0
        diff = fast.solution[:, :, j][ok] - slow[ok]
        if u.kind == "angle":
            diff = (diff + 180.0) % 360.0 - 180.0
        assert np.abs(diff).max() < 1e-9


def test_point_path_extents_match_the_sweep_joints():
    from linkage.kinematics.sweep import sweep_mechanism

    m = load(CRANK)
    values = list(np.arange(0.0, 360.0, 5.0))
    sol = solve_designs(m, {"r3": np.array([120.0, 140.0])}, np.array(values), branch="open", paths=True)
    for d, r3 in enumerate((120.0, 140.0)):
        result = sweep_mechanism(m.with_values({"r3": r3}, {}), values, branch="open", joints=True)
        xs = [p.rates.joints["P"][0] for p in result.positions if p.rates]
        z = sol.paths["P"][d]
        assert np.isfinite(z).all()
        # r3 = 140 puts theta2 = 0 exactly on a limit position (r3 - r4 = r1 - r2), where a
        # root within tolerance is determined only to about sqrt(tol): the sweep's Newton
        # stops 1e-6 deg from the fold that the closed form gives exactly
        assert abs(np.nanmin(z.real) - min(xs)) < 1e-5 and abs(np.nanmax(z.real) - max(xs)) < 1e-5


# --- the command ----------------------------------------------------------------------------------

def records(text: str) -> list[dict]:
    """The records of ``linkage scan -f json``: the document's one table, ``designs``, as
    a dict per row (the registry's shape: names, units and rows under "tables")."""
    (t,) = json.loads(text)["tables"]
    assert t["name"] == "designs"
    return [dict(zip(t["columns"], r)) for r in t["rows"]]


def test_scan_json_records_filter_sort_and_top(cli):
    r = cli("scan", str(CRANK), "--vary", "r2=20:60:5", "--vary", "r4=60:100:5", "--where",
            "full_cycle and min_transmission_deg >= 30", "--sort", "theta4_range", "--desc",
            "--top", "4", "-f", "json")
    assert r.code == 0, r.err
    rows = records(r.out)
    assert len(rows) == 4
    swings = [row["theta4_range"] for row in rows]
    assert swings == sorted(swings, reverse=True)
    assert all(row["full_cycle"] and row["min_transmission_deg"] >= 30 for row in rows)
    everything = records(cli("scan", str(CRANK), "--vary", "r2=20:60:5", "--vary", "r4=60:100:5",
                             "-f", "json").out)
    assert len(everything) == 25
    passing = [row for row in everything if row["full_cycle"] and row["min_transmission_deg"] >= 30]
    best = sorted(passing, key=lambda row: -row["theta4_range"])[:4]
    assert [row["design"] for row in rows] == [row["design"] for row in best]
    assert set(rows[0]) >= {"design", "r2", "r4", "feasible_fraction", "full_cycle", "theta3_min",
                            "theta4_range", "grashof", "min_transmission_deg", "P_x_min", "P_y_max"}


def test_nan_sorts_last_and_text_filters(cli):
    r = cli("scan", str(CRANK), "--vary", "r3=100:400:7", "--sort", "min_transmission_deg", "-f", "json")
    rows = records(r.out)
    keys = [row["min_transmission_deg"] for row in rows]
    assert keys[-1] is None and None not in keys[:2]
    present = [k for k in keys if k is not None]
    assert present == sorted(present)
    r = cli("scan", str(CRANK), "--vary", "r2=20:140:7", "--where", 'grashof == "crank-rocker"', "-f", "json")
    assert {row["grashof"] for row in records(r.out)} == {"crank-rocker"}


def test_csv_parquet_and_json_hold_the_same_records(cli, tmp_path):
    pq = pytest.importorskip("pyarrow.parquet")
    args = ["scan", str(CRANK), "--vary", "r2=20:60", "--vary", "r3=100:140", "--samples", "40",
            "--seed", "5"]
    assert cli(*args, "-o", str(tmp_path / "a.parquet")).code == 0
    assert cli(*args, "-o", str(tmp_path / "a.csv")).code == 0
    rows = records(cli(*args, "-f", "json").out)
    table = pq.read_table(tmp_path / "a.parquet")
    assert table.num_rows == 40 and table.schema.field("r2").metadata == {b"unit": b"mm"}
    parquet_rows = table.to_pylist()
    with open(tmp_path / "a.csv") as fh:
        csv_rows = list(csv.DictReader(fh))
    for j, p, c in zip(rows, parquet_rows, csv_rows):
        assert j["r2"] == p["r2"] == float(c["r2 (mm)"])
        assert j["theta4_range"] == p["theta4_range"] == float(c["theta4_range (deg)"])
        assert j["grashof"] == p["grashof"] == c["grashof"]
    # samples are reproducible from the seed and cover the ranges
    assert all(20 <= row["r2"] <= 60 and 100 <= row["r3"] <= 140 for row in rows)
    again = records(cli(*args, "-f", "json").out)
    assert again == rows


def test_results_do_not_depend_on_scheduler_or_chunk_size(cli):
    base = ["scan", str(CRANK), "--vary", "r2=20:80:9", "--vary", "r4=50:110:7", "-f", "csv"]
    outs = {cli(*base, *extra).out for extra in (
        [], ["--chunk", "5"], ["--chunk", "5", "--scheduler", "synchronous"],
        ["--chunk", "4", "--workers", "2"])}
    assert len(outs) == 1


def test_a_real_dask_cluster_gives_the_local_records():
    """Done-when 1: a dask.distributed scheduler and two worker processes on loopback."""
    distributed = pytest.importorskip("distributed")
    args = ["scan", str(CRANK), "--vary", "r2=20:90", "--vary", "r3=70:160", "--vary", "r4=40:130",
            "--samples", "300", "--seed", "11", "--chunk", "40", "-f", "json"]
    local = run(*args).stdout
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as cluster:
        assert cluster.scheduler_address.startswith("tcp://127.0.0.1:")
        with distributed.Client(cluster) as client:
            assert len(client.scheduler_info()["workers"]) == 2
        remote = run(*args, "--scheduler", cluster.scheduler_address).stdout
    assert json.loads(remote) == json.loads(local)
    assert len(records(local)) == 300


def test_a_mechanism_without_closed_form_scans_by_continuation(cli):
    m = load(SIXBAR)
    name = next(k for k, q in m.parameters.items() if q.kind == "length")
    value = m.parameters[name].value
    r = cli("scan", str(SIXBAR), "--vary", f"{name}={value}:{value * 1.02}:2", "--step", "30", "-f", "json")
    assert r.code == 0, r.err
    rows = records(r.out)
    assert len(rows) == 2 and rows[0]["solved_fraction"] > 0


def test_table_output_names_units_and_how_many_are_shown(cli):
    r = cli("scan", str(CRANK), "--vary", "r2=20:60:30", "-f", "plain")
    assert r.code == 0
    assert "showing 20 of 30" in r.out and "r2 (mm)" in r.out and "min_transmission_deg" in r.out
    assert "theta4_range (deg)" in r.out


def test_top_without_sort_stops_early(cli):
    r = cli("scan", str(CRANK), "--vary", "r2=20:60:1000", "--vary", "r4=60:100:100", "--top", "3",
            "--chunk", "500", "-f", "json")
    assert r.code == 0 and len(records(r.out)) == 3
    assert "stopped early" in r.err


BAD = {
    "no vary": ([], "at least one --vary"),
    "unknown name": (["--vary", "r9=1:2:3"], "not a parameter"),
    "the driver": (["--vary", "theta2=1:2:3"], "the driver"),
    "an unknown": (["--vary", "theta3=1:2:3"], "an unknown"),
    "negative length": (["--vary", "r2=-5:20:3"], "must be > 0"),
    "reversed": (["--vary", "r2=30:20:3"], "below LO"),
    "bad spec": (["--vary", "r2=20"], "NAME=LO:HI"),
    "bad count": (["--vary", "r2=20:30:x"], "whole number"),
    "nan": (["--vary", "r2=nan:30:3"], "finite number"),
    "overflow": (["--vary", "r2=1e999:1e999:2"], "finite number"),
    "grid and samples": (["--vary", "r2=20:30:3", "--samples", "5"], "without :N"),
    "samples without n": (["--vary", "r2=20:30"], "--samples"),
    "too many": (["--vary", "r2=20:30:10000", "--vary", "r3=100:120:10000"], "more than"),
    "sort unknown": (["--vary", "r2=20:30:3", "--sort", "nope"], "no such column"),
    "parquet to stdout": (["--vary", "r2=20:30:3", "-f", "parquet"], "-o FILE"),
    "scheduler": (["--vary", "r2=20:30:3", "--chunk", "1", "--scheduler", "fast"], "--scheduler"),
    "branch": (["--vary", "r2=20:30:3", "--branch", "left"], "open or crossed"),
    "desc alone": (["--vary", "r2=20:30:3", "--desc"], "--sort"),
    "huge positions": (["--vary", "r2=20:30:3", "--step", "1e-3"], "positions per design"),
}


@pytest.mark.parametrize("name", list(BAD))
def test_bad_scan_input_is_one_line(cli, name):
    args, words = BAD[name]
    r = cli("scan", str(CRANK), *args)
    assert r.code == 2, (r.out, r.err)
    assert words in r.err and len(r.err.strip().splitlines()) == 1, r.err


HOSTILE = [
    "__import__('os').system('touch {marker}')",
    "open('{marker}', 'w')",
    "().__class__.__bases__[0].__subclasses__()",
    "full_cycle.__class__",
    "[c for c in ()]",
    "lambda: 1",
    "(yield)",
    "exec('1')",
    "eval('1')",
    "globals()",
    "r2 if full_cycle else r3",
    "r2[0] > 1",
    "{'a': 1}",
    "f'{r2}' == 'x'",
    "r2 := 3",
    "__builtins__",
    "r2 in (1, 2)",
    "r2 is None",
    "not " * 5000 + "full_cycle",
    "(" * 300 + "r2 > 1" + ")" * 300,
    "9" * 5000 + " > r2",
    "r2 ** 9 ** 9 ** 9 > 1 or true and " + " and ".join(["r2 > 1"] * 100),
    "sin(r2, r3) > 0",
    "r2 > 'x'",
    "r2 + true > 1",
    "r2",
]


@pytest.mark.parametrize("expr", HOSTILE)
def test_where_cannot_execute_code(cli, tmp_path, expr):
    """Done-when 4: hostile filters are refused (or evaluated as plain arithmetic on
    columns) with one line; nothing runs."""
    marker = tmp_path / "pwned"
    r = cli("scan", str(CRANK), "--vary", "r2=20:30:3", "--where", expr.replace("{marker}", str(marker)),
            "-f", "json")
    assert not marker.exists()
    assert r.code in (0, 2), r.err
    assert "Traceback" not in r.err and "internal error" not in r.err
    if r.code == 2:
        assert len(r.err.strip().splitlines()) == 1, r.err


def test_a_failed_scan_leaves_the_old_output_intact(cli, tmp_path, monkeypatch):
    import linkage.scan.engine as scan_module

    out = tmp_path / "designs.csv"
    out.write_text("precious\n")
    calls = []
    real = scan_module.run_chunk

    def failing(job, start, designs):
        calls.append(start)
        if len(calls) > 1:
            raise OSError(28, "No space left on device")
        return real(job, start, designs)

    monkeypatch.setattr(scan_module, "run_chunk", failing)
    r = cli("scan", str(CRANK), "--vary", "r2=20:60:50", "--chunk", "10", "--scheduler", "synchronous",
            "-o", str(out))
    assert r.code != 0
    assert out.read_text() == "precious\n"
    assert [p.name for p in tmp_path.iterdir()] == ["designs.csv"]


def test_output_onto_the_mechanism_file_is_refused(cli, tmp_path):
    copy = tmp_path / "m.toml"
    copy.write_text(CRANK.read_text())
    r = cli("scan", str(copy), "--vary", "r2=20:60:3", "-o", str(copy), "-f", "csv")
    assert r.code == 2 and copy.read_text() == CRANK.read_text()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads ru_maxrss of a child")
def test_a_million_designs_stream_in_bounded_memory(tmp_path):
    """Done-when 3 (memory): a 10^6-design grid streams to CSV; the peak memory of the child
    is that of a 10^5-design scan, within a margin far below what holding the extra
    900,000 records would need (x 17 numbers: 122 MB as doubles, several times that as text)."""
    code = ("import resource, sys; from linkage.cli import run_cli; rc = run_cli(sys.argv[1:]); "
            "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, file=sys.stderr); sys.exit(rc)")

    def peak(n_r2: int) -> tuple[int, int]:
        out = tmp_path / f"scan{n_r2}.csv"
        proc = subprocess.run([sys.executable, "-c", code, "scan", str(CRANK), "--vary", f"r2=20:60:{n_r2}",
                               "--vary", "r4=50:120:1000", "--from", "0", "--to", "240", "--step", "120",
                               "--scheduler", "synchronous", "-o", str(out)],
                              capture_output=True, text=True, timeout=600)
        assert proc.returncode == 0, proc.stderr
        with open(out) as fh:
            lines = sum(1 for _ in fh)
        return int(proc.stderr.strip().splitlines()[-1]), lines

    small, n_small = peak(100)
    big, n_big = peak(1000)
    assert n_small == 100_001 and n_big == 1_000_001
    assert big - small < 60_000, (small, big)  # kB


def test_the_docs_name_the_scan_benchmark():
    text = (ROOT / "docs" / "scans.md").read_text()
    assert "benchmarks/scan.py" in text and "linkage scan" in text
    assert os.path.exists(ROOT / "benchmarks" / "scan.py")


def test_json_to_stdout_is_valid_even_when_empty(cli):
    r = cli("scan", str(CRANK), "--vary", "r2=20:60:3", "--where", "r2 > 1000", "-f", "json")
    assert r.code == 0 and records(r.out) == []
    r = cli("scan", str(CRANK), "--vary", "r2=20:60:3", "--where", "r2 > 1000", "-f", "csv")
    assert next(csv.reader(io.StringIO(r.out)))[0] == "design"


def test_without_dask_the_chunks_run_here_with_a_note(cli, monkeypatch):
    for name in ("dask", "dask.threaded", "dask.multiprocessing"):
        monkeypatch.setitem(sys.modules, name, None)
    base = ["scan", str(CRANK), "--vary", "r2=20:80:9", "-f", "csv"]
    r = cli(*base, "--chunk", "2")
    assert r.code == 0 and "dask is not installed" in r.err
    assert r.out == cli(*base).out


def test_columns_pick_what_is_written_and_filters_see_everything(cli):
    r = cli("scan", str(CRANK), "--vary", "r2=20:60:5", "--columns", "r2,theta4_r", "--where",
            "min_transmission_deg > 0", "--sort", "grashof", "-f", "json")
    assert r.code == 0, r.err
    assert set(records(r.out)[0]) == {"design", "r2", "theta4_range"}
    r = cli("scan", str(CRANK), "--vary", "r2=20:60:5", "--columns", "nothing")
    assert r.code == 2 and "matches no column" in r.err


def test_the_python_api_returns_the_command_records(cli):
    import linkage

    cols = linkage.scan_designs(str(CRANK), {"r2": (20, 60, 5), "r4": (60, 100, 5)},
                        where="full_cycle and min_transmission_deg >= 30", sort="theta4_range",
                        descending=True, top=4)
    rows = records(cli("scan", str(CRANK), "--vary", "r2=20:60:5", "--vary", "r4=60:100:5", "--where",
                       "full_cycle and min_transmission_deg >= 30", "--sort", "theta4_range", "--desc",
                       "--top", "4", "-f", "json").out)
    assert list(cols["design"]) == [r["design"] for r in rows]
    assert list(cols["theta4_range"]) == [r["theta4_range"] for r in rows]
    m = linkage.load_mechanism(str(CRANK))
    sampled = linkage.scan_designs(m, {"r3": (100, 140)}, samples=7, seed=2, values=[0.0, 90.0, 180.0])
    assert len(sampled["design"]) == 7 and ((100 <= sampled["r3"]) & (sampled["r3"] <= 140)).all()
    with pytest.raises(linkage.InputError):
        linkage.scan_designs(m, {"r3": (100,)})


def test_an_angle_in_radians_scans_like_the_same_angle_in_degrees(cli, tmp_path):
    rad = tmp_path / "rad.toml"
    rad.write_text(CRANK.read_text().replace('theta1 = { value = 0, unit = "deg" }',
                                             'theta1 = { value = 0, unit = "rad" }'))
    a = records(cli("scan", str(rad), "--vary", "theta1=0:0.2:3", "-f", "json").out)
    b = records(cli("scan", str(CRANK), "--vary", f"theta1=0:{math.degrees(0.2)!r}:3", "-f", "json").out)
    for x, y in zip(a, b):
        for key in ("theta4_min", "theta4_range", "min_transmission_deg", "max_transmission_deg", "P_x_max"):
            assert abs(x[key] - y[key]) < 1e-9, key


def test_help_reads_as_written(cli, monkeypatch):
    monkeypatch.setenv("COLUMNS", "200")
    r = cli("scan", "--help")
    text = " ".join(r.out.split())
    assert "extents of each [points] path" in text and "\U0001f4af" not in r.out
    # at 200 columns a paragraph is one line, not its docstring's source lines
    assert any("where an assembly exists), solved_fraction" in line for line in r.out.splitlines())


@pytest.mark.parametrize("name,param,lo,hi,count,step", [
    ("watt_sixbar.toml", "r5", 40.0, 120.0, 10, 3.0),   # one design reaches a gap
    ("rapier_drive.toml", "a1", 250.0, 420.0, 8, 3.0),
    ("offset_slider.toml", "a2", 10.0, 60.0, 3, 10.0),   # gaps and other assemblies
])
@pytest.mark.parametrize("full_turn", [False, True])
def test_vectorised_continuation_is_the_sweep(name, param, lo, hi, count, step, full_turn):
    """Mechanisms without a closed form: the batch continuation gives every design the
    statuses of its one-at-a-time sweep and the same solutions (designs that would need
    a halved step, a walk or a gap go through that sweep themselves)."""
    from linkage.kinematics.design_continuation import continuation_engine as _continuation_engine

    m = load(ROOT / "sample_inputs" / name)
    arrays = {param: np.linspace(lo, hi, count)}
    values = np.arange(0.0, 360.0 + (step if full_turn else 0.0), step)
    q_fast, st_fast, _, engine = _continuation_engine(m, arrays, values, 1e-12, count)
    q_slow, st_slow, _, _ = _sweep_engine(m, arrays, values, None, 1e-12, count)
    assert engine.startswith("vectorised continuation")
    assert (st_fast == st_slow).all()
    for a, b, u in zip(q_fast, q_slow, m.unknowns):
        solved = st_slow == 0
        diff = a[solved] - b[solved]
        if u.kind == "angle":
            diff = (diff + np.pi) % (2 * np.pi) - np.pi
        assert np.abs(diff).max(initial=0.0) < 1e-9
