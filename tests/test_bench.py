"""Smoke tests for ``linkage bench``: the real benchmark is not part of the test run."""

from __future__ import annotations

import importlib
import json
import sys
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest


def test_bench_quick_on_one_problem(cli, tmp_path):
    pytest.importorskip("matplotlib")
    plot = tmp_path / "wp.png"
    run = cli("bench", "--quick", "--problem", "freudenstein", "--repeats", "1", "--no-cold",
              "--format", "json",
              "--plot", str(plot))
    assert run.code == 0, run.err
    doc = json.loads(run.out)
    contenders = {m["contender"] for m in doc["measurements"]}
    assert "hand-written Newton (10 lines)" in contenders
    assert "linkage newton (history off)" in contenders and "linkage newton (history on)" in contenders
    for m in doc["measurements"]:
        assert m["time per solve (us)"] > 0 and m["error"] >= 0
        if m["contender"].startswith("linkage newton") and m["tol"] <= 1e-8:
            assert m["error"] < 1e-8  # the benchmark measures errors against mpmath, not against itself
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert any(t["target"].startswith("scalar Newton, history off / hand loop") for t in doc["targets"])
    assert any(t["target"].startswith("issue 10: scalar Newton") for t in doc["targets"])


def _first_answer_kept(function: Callable[..., Any]) -> Callable[..., Any]:
    """``function`` answering every call after the first with the first call's answer (for
    two commands of the same options that differ only in how the report is written)."""
    kept: list[Any] = []

    def again(*args: Any, **kwargs: Any) -> Any:
        if not kept:
            kept.append(function(*args, **kwargs))
        return kept[0]

    return again


def test_bench_without_scipy_skips_its_rows_with_a_note(cli, monkeypatch):
    monkeypatch.setitem(sys.modules, "scipy", None)
    monkeypatch.setitem(sys.modules, "scipy.optimize", None)
    # the plain and the JSON report of one run without scipy: the second command renders
    # the first one's measurements and report instead of timing them again
    command = importlib.import_module("linkage.cli.bench")
    for name in ("work_precision", "run_targets"):
        monkeypatch.setattr(command, name, _first_answer_kept(getattr(command, name)))
    run = cli("bench", "--quick", "--problem", "quadratic", "--repeats", "1", "--no-cold")
    assert run.code == 0, run.err
    assert "scipy is not installed: its rows are skipped" in run.out
    # issue 34's rows in the plain output: the quick ones measured, Problem 3 only with --full
    from linkage.measure.continuation_targets import ROWS

    assert "Issue 34's targets" in run.out and "cores" in run.out and "Their roots at 50 digits" in run.out
    assert all(row.name in run.out for row in ROWS)
    assert "not measured (long: linkage bench --full)" in run.out.split("Issue 34's targets")[1]
    doc = json.loads(cli("bench", "--quick", "--problem", "quadratic", "--repeats", "1", "--no-cold",
                         "--format", "json").out)
    contenders = {m["contender"] for m in doc["measurements"]}
    assert not any(c.startswith("scipy") for c in contenders) and "linkage newton (history off)" in contenders
    assert doc["scipy"] is False


def test_bench_bad_input(cli):
    run = cli("bench", "--problem", "nope")
    assert run.code == 2 and "unknown problem" in run.err


def test_sample_mechanisms_ship_with_the_package():
    """Regression: an installed linkage looked for sample_inputs/ beside its source tree,
    so `linkage bench` failed outside a checkout. They are package data now."""
    from linkage.samples import sample_path

    for name in ("fourbar_me581.toml", "rapier_drive.toml"):
        assert sample_path(name).read_text().startswith("#")


ISSUE_33_ROWS = (
    # the measures of issue 33's table, in its order (backticks dropped)
    "scalar Newton, history off / hand loop",
    "scalar Newton, history on / hand loop",
    "system Newton off / hand 2x2",
    "scipy hybr / ours",
    "361-position linkage.sweep / numpy closed form",
    "10^6 positions / the same numpy closed form, written tight",
    "360,001 positions to CSV, CLI / API process",
    "the same to parquet",
    "36,001 positions to CSV with --speed 10 / without (rates, joint velocities)",
    "loaded scan / a hand-written numpy 9x9 batched solve",
    "synthesize --search / hand numpy, one thread",
    "cold start solve, sweep / import rich.table",
)


def test_bench_rows_are_the_rows_of_issue_33():
    from linkage.measure.targets import EARLIER, MEASURES, ROWS

    assert list(dict.fromkeys(r.name for r in ROWS)) == list(ISSUE_33_ROWS)
    assert list(MEASURES) == [*ROWS, *EARLIER]
    bounds = {(r.name, r.part): (r.bound, r.at_least) for r in ROWS}
    assert bounds[("scipy hybr / ours", "")] == (3.0, True)
    assert bounds[(ISSUE_33_ROWS[-1], "solve")] == (1.5, False)
    assert bounds[(ISSUE_33_ROWS[-1], "sweep")] == (1.8, False)


class FakeClock:
    """A clock that each call of A moves by ``a`` and each call of B by ``b``; it records
    the order of the calls."""

    def __init__(self, a: list[float], b: list[float]) -> None:
        self.now = 0.0
        self.a, self.b = iter(a), iter(b)
        self.calls: list[str] = []

    def __call__(self) -> float:
        return self.now

    def run(self, which: str) -> None:
        self.calls.append(which)
        self.now += next(self.a if which == "A" else self.b)


def test_a_ratio_is_the_median_of_interleaved_pairs():
    """A, B, A, B, ...: each pair's ratio from the two timings taken one after the other,
    the median of those ratios (not a ratio of two separate medians); one untimed call of
    each first."""
    from linkage.measure.timing import interleaved_pairs

    # A drifts slower with the machine; B with it: every pair's ratio is 2 but the third
    a = [99.0, 2.0, 4.0, 30.0, 8.0, 16.0]
    b = [99.0, 1.0, 2.0, 3.0, 4.0, 8.0]
    clock = FakeClock(a, b)
    pairs = interleaved_pairs(lambda: clock.run("A"), lambda: clock.run("B"), 5, clock=clock)
    assert clock.calls == ["A", "B"] * 6
    assert pairs.a == (2.0, 4.0, 30.0, 8.0, 16.0) and pairs.b == (1.0, 2.0, 3.0, 4.0, 8.0)
    assert pairs.ratio == 2.0  # the median of 2, 2, 10, 2, 2
    assert pairs.a_median / pairs.b_median == pytest.approx(8.0 / 3.0)


def test_a_short_call_is_timed_in_batches_and_per_call():
    from linkage.measure.timing import interleaved_pairs

    clock = FakeClock([1e-6] * 10_000, [4e-6] * 10_000)
    pairs = interleaved_pairs(lambda: clock.run("A"), lambda: clock.run("B"), 3, budget=1e-4, clock=clock)
    assert len(pairs.a) == 3 and pairs.a[0] == pytest.approx(1e-6) and pairs.b[0] == pytest.approx(4e-6)
    assert pairs.ratio == pytest.approx(0.25)
    assert clock.calls.count("A") > 3 * 50  # batches of about 1e-4 s: a hundred calls each


def test_each_row_is_judged_from_its_pairs_and_a_row_not_run_is_not_judged():
    """A quick run does not measure the long rows (a million positions, whole commands),
    nor the cold starts with --no-cold; a missing package skips its row, named."""
    from linkage.measure.targets import ROWS, Skipped, run_rows
    from linkage.measure.timing import Pairs

    def skip(_):
        raise Skipped("scipy is not installed")

    fast = Pairs((1.0, 1.0, 3.0), (1.0, 1.0, 1.0))
    measures = {row: (skip if row.name == "scipy hybr / ours" else (lambda s: fast)) for row in ROWS}
    quick = {o.row: o for o in run_rows(False, 3, 0.0, cold=False, measures=measures)}
    for row, o in quick.items():
        _, comparison, ratio, met = o.target
        if row.long or row.cold or row.name == "scipy hybr / ours":
            assert o.pairs is None and ratio is None and met is None
            assert ("skipped: scipy" if row.name == "scipy hybr / ours" else "not measured") in comparison
        else:
            assert ratio == 1.0 and met is True and "3 pairs" in comparison
    full = run_rows(True, 3, 0.0, measures=measures)
    assert all(o.pairs is fast for o in full if o.row.name != "scipy hybr / ours")
    scipy_row = next(o for o in full if o.row.name == "scipy hybr / ours")
    assert scipy_row.target[3] is None  # at least 3x: not judged when not measured


def test_csv_to_standard_output_is_refused_before_the_bench_runs(cli, monkeypatch):
    from linkage.measure import precision, stress

    def never(*a, **k):
        raise AssertionError("ran before refusing")

    monkeypatch.setattr(precision, "measure", never)
    monkeypatch.setattr(stress, "run", never)
    run = cli("bench", "--quick", "-f", "csv")
    assert run.code == 2 and "csv holds one table" in run.err and "--table NAME" in run.err
    run = cli("bench", "--quick", "-f", "csv", "--table", "nope")
    assert run.code == 2 and "no such table" in run.err
    run = cli("stress", "--quick", "-f", "csv")
    assert run.code == 2 and "csv holds one table" in run.err and "summary, hybrid" in run.err


def test_the_hand_baselines_compute_what_the_library_computes():
    """The reference of each ratio does the same work: the closed form is linkage.sweep's
    answer on crank_rocker.toml, the hand Newton loops reach linkage's roots."""
    import numpy as np

    import linkage
    from linkage.measure.hand import fourbar_open, hand_newton, hand_newton_2x2
    from linkage.measure.precision import scalar_problem, system_problem
    from linkage.samples import sample_path
    from linkage.units import radians

    m = linkage.load_mechanism(sample_path("crank_rocker.toml"))
    values = np.linspace(0.0, 360.0, 361)
    swept = linkage.sweep(m, [float(v) for v in values])
    t3, t4 = fourbar_open(radians(values), 100.0, 40.0, 120.0, 80.0)
    assert [p.solution["theta3"] for p in swept.positions] == pytest.approx(list(t3), abs=1e-10)
    assert [p.solution["theta4"] for p in swept.positions] == pytest.approx(list(t4), abs=1e-10)
    spec = scalar_problem("freudenstein")
    p = spec["problem"]
    assert hand_newton(p.f, p.fprime, spec["x0"], 1e-12) == pytest.approx(spec["root"], abs=1e-10)
    spec = system_problem("fourbar")
    got = hand_newton_2x2(spec["problem"].F, spec["problem"].J, spec["x0"], 1e-12)
    assert got == pytest.approx(spec["root"], abs=1e-10)


def test_the_sweep_floor_is_the_closed_form_with_linkage_s_evidence():
    """Row 5's floor (hand.fourbar_open_certified): the hand closed form's angles bit for bit,
    every position certified on crank_rocker.toml by the single solve's test, det J
    linkage.sweep's to rounding; refused as the closed-form engine refuses: values not
    ascending, a position beyond or at a limit (the crank of a non-Grashof four-bar), a
    margin under the floor."""
    import numpy as np

    import linkage
    from linkage.kinematics.closed import MARGIN_FLOOR
    from linkage.measure.hand import fourbar_open, fourbar_open_certified
    from linkage.rules import residual_gate
    from linkage.samples import sample_path
    from linkage.units import radians

    m = linkage.load_mechanism(sample_path("crank_rocker.toml"))
    values = [float(v) for v in np.linspace(0.0, 360.0, 361)]
    links = (100.0, 40.0, 120.0, 80.0)
    gate = residual_gate(1e-12, m.length_scale)
    t3, t4, det, certified = fourbar_open_certified(values, *links, 1e-12, gate, MARGIN_FLOOR)
    h3, h4 = fourbar_open(radians(np.array(values)), *links)
    assert np.array_equal(t3, h3) and np.array_equal(t4, h4)
    assert certified.all()
    swept = linkage.sweep(m, values)
    assert list(det) == pytest.approx([p.det for p in swept.positions], rel=1e-12)
    with pytest.raises(ValueError, match="ascending"):
        fourbar_open_certified(values[::-1], *links, 1e-12, gate, MARGIN_FLOOR)
    with pytest.raises(ValueError, match="limit"):
        fourbar_open_certified(values, 100.0, 90.0, 60.0, 70.0, 1e-12, gate, MARGIN_FLOOR)
    # the evidence is judged: at tol 1e-20 only positions whose Newton step is exactly 0 pass
    strict = fourbar_open_certified(values, *links, 1e-20, gate, MARGIN_FLOOR)[3]
    assert 0 < np.count_nonzero(~strict) < len(values)


def test_the_hand_loaded_scan_is_the_scans_forces():
    """The loaded scan row's reference: the same designs' peak input torque, pin force and
    ground force as linkage.scan_designs gives them (the 9x9 systems written by hand)."""
    import numpy as np

    from linkage.measure import api
    from linkage.measure.hand import DrawnFourbar, loaded_scan
    from linkage.samples import sample_path

    loads = api.Loads(forces={"P": (0.0, -20.0)}, torques={"rocker": -2.0})
    got = api.scan_designs(str(sample_path("crank_rocker_joints.toml")), {"O4.x": (90.0, 110.0)}, samples=12,
                           loads=loads, scheduler="synchronous")
    drawn = DrawnFourbar((34.64101615137755, 20.0), (145.57934415070798, 65.74590015195868), 100.0,
                         (71.2422462637832, 67.54313782512394))
    mine = loaded_scan(drawn, got["O4_x"], (0.0, -20.0), -2.0, np.arange(360.0))
    for column in ("peak_input", "max_pin_force", "max_shaking_force"):
        assert list(mine[column]) == pytest.approx(list(got[column]), rel=1e-9)


def test_the_hand_search_keeps_what_synthesize_search_keeps(cli, tmp_path):
    """The search row's reference: every candidate `synthesize --search` keeps is kept by
    hand, with the same max error and smallest transmission angle (the hand search checks
    assembly and transmission only, so it may keep a few more)."""
    import csv
    import math

    import numpy as np

    from linkage.measure.hand import function_search

    out = tmp_path / "search.csv"
    run = cli("synthesize", "--search", "--function", "log10(x)", "--x", "1:2", "--vary", "alpha0=0:350:6",
              "--vary", "alpha_span=40:120:3", "--vary", "phi0=0:350:6", "--vary", "phi_span=60:120:3",
              "--min-transmission", "40", "--top", "100000", "-o", str(out))
    assert run.code == 0, run.err
    names = ("alpha0 (deg)", "alpha_span (deg)", "phi0 (deg)", "phi_span (deg)")
    kept = {tuple(float(r[k]) for k in names): r for r in csv.DictReader(out.open())}
    grid = np.array([(a, da, p, dp) for a in np.linspace(0, 350, 6) for da in np.linspace(40, 120, 3)
                     for p in np.linspace(0, 350, 6) for dp in np.linspace(60, 120, 3)])
    xs = [1.5 - 0.5 * math.cos((2 * j - 1) * math.pi / 6) for j in (1, 2, 3)]
    gx = np.linspace(1.0, 2.0, 2001)
    mine = function_search(xs, [math.log10(x) for x in xs], gx, np.log10(gx), grid, 40.0)
    assert len(kept) > 20
    for i, c in enumerate(map(tuple, grid)):
        if c in kept:
            assert mine["ok"][i]
            assert mine["max_error_deg"][i] == pytest.approx(float(kept[c]["max_error_deg"]), rel=1e-9)
            assert mine["min_transmission_deg"][i] == pytest.approx(float(kept[c]["min_transmission_deg"]),
                                                                    rel=1e-9)


def test_a_command_that_fails_is_no_measurement():
    """A row whose command exits non-zero says so, with the command's last error line,
    instead of a ratio of how fast it failed."""
    import sys

    from linkage.measure.processes import ProcessFailed, runner
    from linkage.measure.targets import ROWS, run_rows
    from linkage.measure.timing import interleaved_pairs

    failing = runner([sys.executable, "-c", "import sys; sys.exit('no such file: x.toml')"])
    with pytest.raises(ProcessFailed, match=r"exit 1: no such file: x\.toml"):
        failing()
    row = next(r for r in ROWS if r.name.startswith("360,001"))
    (got,) = run_rows(True, 2, 0.0, measures={row: lambda s: interleaved_pairs(failing, failing, 2)})
    assert got.pairs is None and got.target[2] is None and got.target[3] is None
    assert "failed:" in got.target[1] and "no such file: x.toml" in got.target[1]


def _timed(seconds, complete=True, residual=1e-16, duplicates=0, spurious=0):
    from linkage.measure.continuation_targets import Certificate, Found, Timed

    checked = Certificate(3, residual, 0.0, duplicates, spurious)
    return Timed(tuple(seconds), Found("planted", complete, checked))


def test_issue_34_rows_are_judged_from_their_median_their_counts_and_their_roots():
    """Absolute times: met when the median run is within the bound and the run found all the
    target asks; the roots are certified when the worst residual is at most 1e-12 with no
    duplicate and no spurious root; Problem 3 runs only with --full (planted timings)."""
    from linkage.measure.continuation_targets import ROWS, run_rows, tables

    problem_3, burmester, sixbar = ROWS
    assert (problem_3.bound, problem_3.long) == (600.0, True)
    assert (burmester.bound, burmester.long) == (0.1, False) and (sixbar.bound, sixbar.long) == (0.05, False)
    assert burmester.met(_timed([0.09, 0.5, 0.01])) is True  # the median, not the mean nor the worst
    assert burmester.met(_timed([0.2, 0.11, 0.05])) is False
    assert burmester.met(_timed([0.01], complete=False)) is False  # fast, but a path failed
    planted = {problem_3: lambda r: _timed([30.0]), burmester: lambda r: _timed([0.06] * r),
               sixbar: lambda r: _timed([0.07] * r, residual=2e-12)}
    quick = run_rows(False, 3, measures=planted)
    assert quick[0].timed is None and quick[0].met is None and quick[0].certified is None
    assert "--full" in quick[0].note
    assert (quick[1].met, quick[1].certified) == (True, True)
    assert (quick[2].met, quick[2].certified) == (False, False)
    times, roots = tables(quick)
    assert times[0][2] is None and times[1][2:4] == (0.06, 3) and [r[0] for r in roots] == [burmester.name,
                                                                                          sixbar.name]
    full = run_rows(True, 3, measures=planted)
    assert full[0].met is True and len(tables(full)[1]) == 3
    for bad in (dict(duplicates=1), dict(spurious=1), dict(residual=1.1e-12)):
        assert _timed([1.0], **bad).found.certificate.met is False


def test_the_root_check_finds_a_duplicate_a_spurious_root_and_a_residual_at_50_digits():
    """x^2 - 2: sqrt(2) twice (a duplicate), 1.5 (50-digit Newton goes to sqrt(2), far from
    it: spurious); -sqrt(2) off by 1e-10 is confirmed (its root is that near), but its
    residual against the terms' size, |x^2 - 2| / (x^2 + 2), computed here at 50 digits, is
    above 1e-12."""
    import math

    import mpmath

    from linkage.homotopy import PolySystem
    from linkage.measure.continuation_targets import polynomial_certificate

    system = PolySystem(1, ({(2,): 1 + 0j, (0,): -2 + 0j},))
    root = math.sqrt(2.0)
    clean = polynomial_certificate(system, [np.array([root]), np.array([-root])])
    assert (clean.roots, clean.duplicates, clean.spurious, clean.above, clean.met) == (2, 0, 0, 0, True)
    assert clean.worst_residual <= 1e-16 and clean.worst_error <= 2e-16
    got = polynomial_certificate(system, [np.array([root]), np.array([root]), np.array([1.5])])
    assert (got.roots, got.duplicates, got.spurious, got.above, got.met) == (3, 1, 1, 1, False)
    assert got.worst_residual == pytest.approx(0.25 / 4.25) and got.worst_error > 0.05
    off = -root + 1e-10
    near = polynomial_certificate(system, [np.array([off])])
    with mpmath.workdps(50):
        want = float(abs(mpmath.mpf(off) ** 2 - 2) / (mpmath.mpf(off) ** 2 + 2))
    # a root, but not to 1e-12
    assert (near.duplicates, near.spurious, near.above, near.met) == (0, 0, 1, False)
    assert near.worst_residual == pytest.approx(want, rel=1e-6)


def test_the_nine_point_root_check_counts_a_cognate_as_a_duplicate():
    """A seed instance's four-bar is certified; its Roberts cognate listed beside it is the
    same four-bar up to the orbit (a duplicate); the four-bar moved by 1e-4 is spurious and
    its residual is far above 1e-12."""
    from linkage.homotopy import ninepoint as npt
    from linkage.measure.continuation_targets import nine_point_certificate

    z, d, db = npt.seed_instance(np.random.default_rng(11))
    alone = nine_point_certificate(z[None, :], d, db)
    assert alone.met and alone.worst_residual <= 1e-13 and alone.worst_error <= 1e-13
    cognate = npt.orbit(z)[2]
    moved = z + 1e-4
    got = nine_point_certificate(np.stack([z, cognate, moved]), d, db)
    assert (got.roots, got.duplicates, got.spurious, got.above, got.met) == (3, 1, 1, 1, False)
    assert got.worst_residual > 1e-8


def test_the_performance_tables_are_written_from_one_bench_json_between_their_markers(tmp_path):
    """benchmarks/performance_table.py writes issue 33's table and issue 34's two tables
    from the run's own figures, and leaves everything outside the markers as it was."""
    import importlib.util
    from pathlib import Path

    script = Path(__file__).resolve().parent.parent / "benchmarks" / "performance_table.py"
    spec = importlib.util.spec_from_file_location("performance_table", script)
    table = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(table)
    run = {"targets": [{"target": "row a", "measured": 2.345, "met": False, "ratio": "x: 2.3 / 1.0 us"}],
           "continuation": {"cores": "2 cores", "targets": [
               {"target": "six-bar", "bound": 0.05, "median": 0.0215, "runs": 5, "found": "4 paths",
                "met": True}],
               "certified": [{"target": "six-bar", "roots": 4, "worst residual": 1.1138e-16, "above 1e-12": 0,
                              "worst error": 1.6775e-16, "duplicates": 0, "spurious": 0, "met": True}]}}
    page = tmp_path / "page.md"
    page.write_text("before\n<!-- targets: begin -->\nold\n<!-- targets: end -->\nmiddle\n"
                    "<!-- continuation: begin -->\nold\n<!-- continuation: end -->\nafter\n")
    table.replace(page, table.table(run["targets"], "abc1234"))
    table.replace(page, table.continuation_tables(run["continuation"], "abc1234"),
                  "<!-- continuation: begin -->", "<!-- continuation: end -->")
    text = page.read_text()
    assert text.startswith("before\n") and "\nmiddle\n" in text and text.endswith("\nafter\n")
    assert "old" not in text
    assert "| row a | 2.35 | 2.3 / 1.0 us | no |" in text
    assert "| six-bar | 0.05 s | 21.5 ms | 5 | 4 paths | yes |" in text
    assert "| six-bar | 4 | 1.11e-16 | 0 | 1.68e-16 | 0 | 0 | yes |" in text
    with pytest.raises(SystemExit):
        table.replace(tmp_path / "page.md", "x", "<!-- none: begin -->", "<!-- none: end -->")


@pytest.mark.parametrize("suffix", ["csv", "parquet"])
def test_the_file_floor_writes_the_cli_s_varying_columns(tmp_path, suffix):
    """Rows 7 and 8's file by hand (hand.write_sweep_file): the columns it writes are the
    command line's same columns of crank_rocker.toml to rounding, read back from both files
    (by hand computing less than the file holds would flatter the hand, not the library).
    1,001 positions, across the crank's 0/360 deg end, in slices of 97 rows."""
    import numpy as np

    pq = pytest.importorskip("pyarrow.parquet")
    import pyarrow.csv as pcsv
    from typer.testing import CliRunner

    import linkage
    from linkage.cli import app
    from linkage.measure.hand import sweep_file_columns, write_sweep_file
    from linkage.samples import sample_path

    path = str(sample_path("crank_rocker.toml"))
    values = [k * 0.4 - 20.0 for k in range(1001)]
    r = linkage.sweep(linkage.load_mechanism(path), values)
    by_hand = tmp_path / f"hand.{suffix}"
    write_sweep_file(np.asarray(values), r.column("theta3"), r.column("theta4"), (100.0, 40.0, 120.0, 80.0),
                     str(by_hand), suffix, rows_per_slice=97)
    out = tmp_path / f"cli.{suffix}"
    got = CliRunner().invoke(app, ["sweep", path, "--from", "-20", "--step", "0.4", "--to", "380",
                                   "-o", str(out)])
    assert got.exit_code == 0, got.output
    if suffix == "parquet":
        cli, hand = pq.read_table(out), pq.read_table(by_hand)
    else:
        cli = pcsv.read_csv(out)
        hand = pcsv.read_csv(by_hand, read_options=pcsv.ReadOptions(column_names=list(
            sweep_file_columns(np.zeros(1), np.zeros(1), np.zeros(1), 1.0, 1.0, 1.0, 1.0))))
    assert hand.num_rows == cli.num_rows == 1001
    names = {"det": "det J", "transmission": "transmission angle 0..90"}
    for k in hand.column_names:
        base = names.get(k, k)  # the CSV's header also names the unit
        want = np.asarray(cli.column(next(c for c in cli.column_names if c in (base, f"{base} (deg)",
                                                                                  f"{base} (mm)",
                                                                                  f"{base} (mm^2/rad^2)"))))
        assert np.asarray(hand.column(k)) == pytest.approx(want, rel=1e-12, abs=1e-9), k


@pytest.mark.parametrize("repeats", ["0", "100000000"])
def test_bench_repeats_beyond_its_range_are_refused_at_once(cli, monkeypatch, repeats):
    """--repeats 100000000 was accepted and ran until killed; every other count has a ceiling.
    (Refused before any timing: a run that starts fails the test at once instead.)"""
    import linkage.cli.bench as bench_cli

    def ran(*args: object) -> None:
        raise AssertionError("the benchmark ran")

    monkeypatch.setattr(bench_cli, "work_precision", ran)
    run = cli("bench", "--quick", "--repeats", repeats, "--no-cold")
    assert run.code == 2 and run.err.count("\n") == 1
    assert "--repeats must be a whole number from 1 to" in run.err
