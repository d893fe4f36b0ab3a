"""Whole-cycle sweeps: continuation, branches, no-solution gaps, limit positions."""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path

import pytest

from linkage import load_mechanism
from linkage.kinematics.sweep import driver_values, sweep
from linkage.problems.closed_form import fourbar_positions, wrap_degrees

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
ME581 = str(SAMPLES / "fourbar_me581.toml")


def test_me581_full_turn_matches_the_issue(cli):
    run = cli("sweep", ME581, "--from", "0", "--to", "359", "--step", "1", "--format", "json")
    assert run.code == 0, run.err
    doc = json.loads(run.out)
    assert doc["classification"]["grashof"] is False
    assert doc["summary"] == {"converged": 225, "no_solution": 135}
    limit = math.degrees(math.acos(-0.375))  # |A - O4| = r3 + r4: cos(theta2) = -3/8
    assert limit == pytest.approx(112.02, abs=5e-3)
    assert doc["feasible_ranges"] == [[0, pytest.approx(limit, abs=1e-12)],
                                      [pytest.approx(360 - limit, abs=1e-12), 359]]
    assert len(doc["toggles"]) == 2
    assert abs(doc["toggles"][0] - limit) < 1e-9 and abs(doc["toggles"][1] - (360 - limit)) < 1e-9
    worst = 0.0
    for p in doc["positions"]:
        inside = p["input"] <= limit or p["input"] >= 360 - limit
        if not inside:
            assert p["status"] == "no_solution" and p["solution"] is None and p["branch"] is None
            continue
        assert p["status"] == "converged" and p["branch"] == "open"
        exact = fourbar_positions(90, 30, 60, 45, 0, theta2=math.radians(p["input"]))["open"]
        for name in ("theta3", "theta4"):
            worst = max(worst, abs(wrap_degrees(p["solution"][name] - math.degrees(exact[name]))))
        assert math.sin(math.radians(p["solution"]["theta4"] - p["solution"]["theta3"])) > 0
    assert worst < 1e-10


@pytest.mark.parametrize("branch", [None, "crossed"])
def test_crank_rocker_turns_fully_on_one_branch(cli, branch):
    args = ["sweep", str(SAMPLES / "crank_rocker.toml"), "--from", "0", "--to", "360", "--format", "json"]
    if branch:
        args += ["--branch", branch]
    doc = json.loads(cli(*args).out)
    assert doc["summary"] == {"converged": 361}
    assert {p["branch"] for p in doc["positions"]} == {branch or "open"}
    assert doc["toggles"] == []
    assert doc["classification"]["type"] == "Grashof crank-rocker"
    for p in doc["positions"]:
        exact = fourbar_positions(100, 40, 120, 80, 0, theta2=math.radians(p["input"]))[branch or "open"]
        assert abs(wrap_degrees(p["solution"]["theta3"] - math.degrees(exact["theta3"]))) < 1e-10


def test_rapier_drive_sweeps_a_full_turn_and_reports_the_stroke(cli):
    run = cli("sweep", str(SAMPLES / "rapier_drive.toml"), "--step", "0.5", "--format", "json")
    doc = json.loads(run.out)
    assert doc["summary"] == {"converged": 721}
    s16 = doc["ranges"]["s16"]
    # P5: "between about -304.2 and 54.7 mm" (four significant digits)
    assert s16["min"] == pytest.approx(-304.2, abs=0.1) and s16["max"] == pytest.approx(54.7, abs=0.1)
    assert s16["stroke"] == pytest.approx(s16["max"] - s16["min"])
    # every solved position closes both loops
    m = load_mechanism(SAMPLES / "rapier_drive.toml")
    for p in doc["positions"][::40]:
        problem = m.with_values({"theta12": p["input"]}, {}).problem()
        q = problem.from_display([p["solution"][n] for n in problem.names])
        assert max(abs(v) for v in problem.F(q)) < 1e-9
    table = cli("sweep", str(SAMPLES / "rapier_drive.toml"), "--step", "5").out
    assert "s16: min" in table and "range" in table


def test_a_large_step_does_not_jump_branches():
    """Worked example P6: too large a step can land on the other branch; the sweep halves it."""
    m = load_mechanism(SAMPLES / "fourbar_me581.toml")
    coarse = sweep(m, driver_values(-110, 110, 55, None))
    assert {p.branch for p in coarse.positions} == {"open"}
    assert all(p.status == "converged" for p in coarse.positions)


def test_offset_slider_fold_gap_and_limits_are_found_numerically():
    """No closed form. The sweep follows the assembly of the file's guess (at 60 deg):
    it ends at a fold near 15.48 deg (det J -> 0) and at the assembly limit near
    132.43 deg. Elsewhere another assembly exists but is not connected to it
    (off_branch: no numbers, never a silent jump), and 132.43..185.75 has no assembly
    at all (no_solution)."""
    import random

    from linkage import solve_system
    from linkage.linalg import det_from_lu, lu

    m = load_mechanism(SAMPLES / "offset_slider.toml")
    s = sweep(m, driver_values(0, 360, 2, None))
    assert set(s.summary) == {"converged", "off_branch", "no_solution"}
    fold, limit = s.toggles
    assert fold == pytest.approx(15.477, abs=1e-2) and limit == pytest.approx(132.4256, abs=1e-3)
    at60 = next(p for p in s.positions if p.input == 60)
    assert at60.solution["theta14"] == pytest.approx(86.135718, abs=1e-5)  # the file's assembly
    for p in s.positions:
        expected = ("converged" if fold < p.input < limit else
                    "no_solution" if limit < p.input < 185.7 else
                    "off_branch" if p.input < fold or p.input > 185.8 else p.status)
        assert p.status == expected, (p.input, p.status)
    # both located limits are singular points of the branch: det J -> 0 there
    for t in (fold, limit):
        near = min((p for p in s.positions if p.status == "converged"), key=lambda p: abs(p.input - t))
        q = [math.radians(near.solution[n]) if n.startswith("theta") else near.solution[n]
             for n in ("theta14", "theta15", "s4", "s6")]
        inside = t - 1e-5 if near.input < t else t + 1e-5  # |det J| ~ sqrt(distance)
        for k in range(1, 41):  # walk up to the limit along the branch, ever closer
            v = inside + (near.input - inside) * (1 - k / 40) ** 3
            r = solve_system(m.with_values({"theta12": v}, {}).problem(), q, tol=1e-10, max_iter=200)
            assert r.converged, v
            q = list(r.x)
        det = det_from_lu(lu(m.with_values({"theta12": inside}, {}).problem().J(q)))
        assert abs(det) < 5.0  # against |det J| of about 1000 away from the limits
    # independent check of the two kinds of gap: multi-start Newton
    rng = random.Random(7)

    def some_assembly(theta12):
        problem = m.with_values({"theta12": theta12}, {}).problem()
        for _ in range(200):
            g = [rng.uniform(-math.pi, math.pi), rng.uniform(-math.pi, math.pi),
                 rng.uniform(-200, 200), rng.uniform(-200, 200)]
            if solve_system(problem, g, tol=1e-10, max_iter=60, record=False).converged:
                return True
        return False

    assert some_assembly(10.0) and some_assembly(250.0) and not some_assembly(160.0)


def test_sweep_csv_has_units_and_one_row_per_position(cli):
    run = cli("sweep", ME581, "--step", "10", "--format", "csv")
    rows = list(csv.reader(io.StringIO(run.out)))
    assert rows[0][:4] == ["theta2 (deg)", "status", "theta3 (deg)", "theta4 (deg)"]
    assert len(rows) == 1 + 37
    gap = [r for r in rows[1:] if r[1] == "no_solution"]
    assert gap and all(r[2] == "" and r[3] == "" for r in gap)


@pytest.mark.parametrize("args,message", [
    (["--step", "0"], "--step must be > 0"),
    (["--step", "1", "--points", "3"], "not both"),
    (["--from", "10", "--to", "0"], "must not be below"),
    (["--branch", "sideways"], "--branch must be open or crossed"),
    (["--method", "bisection"], "unknown method"),
    (["--from", "nan"], "--from must be finite"),
])
def test_sweep_bad_input(cli, args, message):
    run = cli("sweep", ME581, *args)
    assert run.code == 2 and message in run.err and len(run.err.strip().splitlines()) == 1


def test_branch_needs_a_closed_form(cli):
    run = cli("sweep", str(SAMPLES / "rapier_drive.toml"), "--branch", "open")
    assert run.code == 2 and "closed form" in run.err


def test_sweep_help_has_an_example(cli):
    out = cli("sweep", "--help").out
    assert "Example" in out and "linkage sweep" in out


# --- the batch engine ------------------------------------------------------------------

BATCH_CASES = [("crank_rocker", 0, 360), ("fourbar_me581", 0, 359), ("rapier_drive", 0, 360),
               ("offset_slider", 0, 360), ("slider_crank", 0, 360), ("fourbar_me581_theta4", 100, 260)]


@pytest.mark.parametrize("name,lo,hi", BATCH_CASES, ids=[c[0] for c in BATCH_CASES])
def test_batch_engine_matches_the_one_at_a_time_path(name, lo, hi):
    import numpy as np

    from linkage.kinematics.batch import STATUS_CODES, batch_sweep

    m = load_mechanism(SAMPLES / f"{name}.toml")
    values = driver_values(lo, hi, None, 1201)
    one = sweep(m, values)
    many = batch_sweep(m, values)
    codes = [STATUS_CODES[p.status] for p in one.positions]
    assert list(many.status) == codes
    assert many.branch == one.branch
    kinds = [u.kind for u in m.unknowns]
    for i, p in enumerate(one.positions):
        if p.solution is None:
            assert np.isnan(many.solution[i]).all()
            continue
        for j, (n, k) in enumerate(zip(one.names, kinds)):
            diff = p.solution[n] - many.solution[i, j]
            diff = math.radians(diff) if k == "angle" else diff / 1000.0  # rad, or m for mm
            assert abs(diff) <= 1e-12, (name, p.input, n, diff)


def test_large_sweeps_use_the_batch_engine(cli):
    run = cli("sweep", str(SAMPLES / "crank_rocker.toml"), "--points", "30001", "--format", "json")
    doc = json.loads(run.out)
    assert doc["method"] == "newton (batch)" and doc["summary"] == {"converged": 30001}
    small = json.loads(cli("sweep", str(SAMPLES / "crank_rocker.toml"), "--points", "31", "--batch",
                           "--format", "json").out)
    assert small["method"] == "newton (batch)"


def test_benchmark_script_runs_on_a_few_positions():
    import subprocess
    import sys

    script = Path(__file__).resolve().parents[1] / "benchmarks" / "sweep_batch.py"
    proc = subprocess.run([sys.executable, str(script), "-n", "2000", "--repeats", "1"],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "ratio sweep / closed form" in proc.stdout and "all converged: True" in proc.stdout


@pytest.mark.parametrize("name", ["crank_rocker.toml", "fourbar_me581.toml", "fourbar_me581_theta4.toml",
                                  "slider_crank.toml", "offset_slider.toml", "rapier_drive.toml",
                                  "watt_sixbar.toml"])
def test_the_lean_continuation_step_changes_no_position(name, monkeypatch):
    """The lean step (compiled functions, no problem or Result objects) must accept exactly
    what the full step accepts, with the same numbers: sweeps with it and without it are
    identical, position by position, on every sample and on random four-bars."""
    import numpy as np

    from linkage.kinematics import continuation
    from linkage.kinematics import sweep as sweep_module
    from linkage.kinematics.loading import load

    m = load(SAMPLES / name)
    designs = [m]
    if m.closed_form == "fourbar":
        rng = np.random.default_rng(5)
        designs += [m.with_values({k: float(rng.uniform(0.4, 1.6) * m.parameters[k].value)
                                   for k in ("r2", "r3", "r4")}, {}) for _ in range(6)]
    values = [float(v) for v in np.arange(0.0, 360.0, 2.5)]
    branches = ["open", "crossed"] if m.closed_form else [None]
    fast = [sweep_module.sweep(d, values, branch=b) for d in designs for b in branches]
    monkeypatch.setattr(continuation, "lean_step", lambda *args: None)
    slow = [sweep_module.sweep(d, values, branch=b) for d in designs for b in branches]
    for a, b in zip(fast, slow):
        assert a.positions == b.positions
        assert (a.toggles, a.feasible_ranges, a.branch) == (b.toggles, b.feasible_ranges, b.branch)


@pytest.mark.parametrize("name,lo,hi", BATCH_CASES, ids=[c[0] for c in BATCH_CASES])
def test_batch_blocks_give_the_answer_of_one_block(name, lo, hi, monkeypatch):
    """The batch engine settles positions a block at a time (cache-sized arrays); blocks
    of 97 positions, boundaries inside gaps and fallbacks included, give exactly what
    one block does."""
    import numpy as np

    import linkage.kinematics.batch as batch

    m = load_mechanism(SAMPLES / f"{name}.toml")
    values = np.array(driver_values(lo, hi, None, 1201))
    whole = batch.batch_sweep(m, values)
    monkeypatch.setattr(batch, "BLOCK", 97)
    parts = batch.batch_sweep(m, values)
    for f in ("status", "solution", "det", "iterations"):
        assert np.array_equal(getattr(whole, f), getattr(parts, f), equal_nan=True), f
    assert whole.fallback == parts.fallback


def test_batch_grid_index_equals_searchsorted():
    import numpy as np

    from linkage.kinematics.warm_starts import grid_left

    rng = np.random.default_rng(4)
    grid = np.linspace(-30.0, 400.0, 361)
    for vals in (np.sort(rng.uniform(-50, 420, 5000)), rng.uniform(-50, 420, 5000), grid.copy(),
                 np.repeat(grid[::7], 3), np.array([grid[5]]), np.array([-100.0, 1000.0])):
        want = np.clip(np.searchsorted(grid, vals, side="right"), 1, len(grid) - 1) - 1
        assert np.array_equal(grid_left(grid, vals), want)
    assert np.array_equal(grid_left(grid[:1], np.array([-1.0, 0.0, 5.0])), [0, 0, 0])


def test_batch_of_no_position_and_of_one():
    import numpy as np

    from linkage.kinematics.batch import batch_sweep

    m = load_mechanism(SAMPLES / "crank_rocker.toml")
    assert batch_sweep(m, np.zeros(0)).to_sweep().summary == {}
    one = batch_sweep(m, np.array([10.0]))
    assert list(one.status) == [0]
    want = sweep(m, [10.0]).positions[0].solution
    assert np.allclose(one.solution[0], [want["theta3"], want["theta4"]], rtol=0, atol=1e-10)
