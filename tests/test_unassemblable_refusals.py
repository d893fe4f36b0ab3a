"""A linkage that cannot be assembled is bad input: one line on stderr, exit 2, the same
"cannot be assembled" refusal for every command (docs/output.md, "Exit codes"), decided
by the closed form where one is derived. A sweep where some position assembles keeps its
no_solution rows and exits 0. The geometry is checked independently: the ME581 four-bar
(r1..r4 = 90, 30, 60, 45) closes at theta2 only while the diagonal A-O4, by the law of
cosines, is at most r3 + r4 (Norton, "Design of Machinery", section 4.12)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

import linkage

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
ME581 = str(SAMPLES / "fourbar_me581.toml")
R1, R2, R3, R4 = 90.0, 30.0, 60.0, 45.0


def _diagonal(theta2_deg: float) -> float:
    """|A - O4| of the ME581 four-bar at theta2 (law of cosines)."""
    t = math.radians(theta2_deg)
    return math.sqrt(R1 * R1 + R2 * R2 - 2 * R1 * R2 * math.cos(t))


LIMIT_DEG = math.degrees(math.acos((R1 * R1 + R2 * R2 - (R3 + R4) ** 2) / (2 * R1 * R2)))


def _refused(run, *words: str) -> None:
    assert run.code == 2, (run.code, run.err)
    lines = [ln for ln in run.err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: "), run.err
    for w in words:
        assert w in lines[0], lines[0]
    assert "Traceback" not in run.err and "internal error" not in run.err


@pytest.mark.parametrize("extra", [[], ["--batch"]])
def test_sweep_that_assembles_nowhere_is_refused(cli, tmp_path, extra):
    # r3 = 1: the diagonal is never below r1 - r2 = 60 > r3 + r4 = 46, so no theta2 closes
    assert min(_diagonal(t) for t in range(361)) > 1 + R4
    out = tmp_path / "s.csv"
    run = cli("sweep", ME581, "--set", "r3=1", *extra, "-o", str(out))
    _refused(run, "cannot be assembled at any theta2 from 0 to 360 deg", "361 positions")
    assert not out.exists()
    # the library still answers with its named statuses
    m = linkage.load_mechanism(ME581).with_values({"r3": 1.0}, {})
    assert linkage.sweep(m, [0.0, 90.0, 180.0]).summary == {"no_solution": 3}


def test_sweep_wholly_past_the_limit_is_refused_and_one_that_reaches_it_is_not(cli):
    assert 100 < LIMIT_DEG < 120 and _diagonal(120) > R3 + R4
    _refused(cli("sweep", ME581, "--from", "120", "--to", "240"),
             "cannot be assembled at any theta2 from 120 to 240 deg")
    run = cli("sweep", ME581, "--from", "100", "--to", "240", "--step", "10", "--format", "json")
    assert run.code == 0, run.err
    statuses = [p["status"] for p in json.loads(run.out)["positions"]]
    assert statuses[:2] == ["converged", "converged"] and set(statuses[2:]) == {"no_solution"}


def test_equation_sweep_that_assembles_nowhere_is_refused(cli):
    # links 1 100 1 1: the coupler is longer than the other three together
    _refused(cli("sweep", "--links", "1", "100", "1", "1", "--step", "30"),
             "cannot be assembled at any alpha from 0 to 360 deg")


@pytest.mark.parametrize("theta2, assembles", [
    (LIMIT_DEG - 1e-6, True), (LIMIT_DEG + 1e-6, False), (200.0, False), (-LIMIT_DEG + 1e-6, True)])
def test_solve_refuses_a_driver_value_where_the_closed_form_has_no_assembly(cli, theta2, assembles):
    assert (_diagonal(theta2) <= R3 + R4) == assembles
    run = cli("solve", ME581, "--set", f"theta2={theta2!r}", "--format", "json")
    if assembles:
        assert run.code == 0 and json.loads(run.out)["converged"] is True, run.err
    else:
        _refused(run, "cannot be assembled at theta2 = ", "(the closed form has no real solution)")


# each but --r3 has a link longer than the other three together: no angle closes it
@pytest.mark.parametrize("args", [["--links", "1", "100", "1", "1"], ["--links", "1", "1", "1000", "1"],
                                  ["--r3", "1000"], ["--links", "40", "20", "20", "100", "--alpha", "30"]])
def test_solve_links_that_cannot_close_says_so(cli, args):
    _refused(cli("solve", *args), "cannot be assembled at alpha = ", "no real root")


def test_solve_links_that_close_still_solve(cli):
    run = cli("solve", "--links", "40", "120", "80", "100", "--alpha", "30", "--format", "json")
    assert run.code == 0 and json.loads(run.out)["converged"] is True, run.err


def test_draw_at_a_pose_that_cannot_be_assembled_is_refused(cli, tmp_path):
    out = tmp_path / "d.png"
    _refused(cli("draw", ME581, "-o", str(out), "--set", "theta2=200"),
             "cannot be assembled at theta2 = 200 deg")
    assert not out.exists()


@pytest.mark.parametrize("command", [["tolerance", "--tol", "r2=0.1", "--samples", "10", "--step", "10"],
                                     ["centres", "--centrodes"]])
def test_a_tolerance_study_or_centrodes_wholly_past_the_limit_are_refused(cli, tmp_path, command):
    """tolerance and centres --centrodes over a range where the ME581 assembles nowhere
    (theta2 150..200, past its limit) exited 0 with every row not_assembled or no_solution;
    they are refused as a sweep is. A range that reaches the limit is an answer (exit 0)."""
    assert LIMIT_DEG < 150 and _diagonal(150) > R3 + R4
    name, *options = command
    out = tmp_path / "t.json"
    run = cli(name, ME581, *options, "--from", "150", "--to", "200", "-o", str(out))
    _refused(run, "cannot be assembled at any theta2 from 150 to 200 deg")
    assert not out.exists()
    assert cli(name, ME581, *options, "--from", "100", "--to", "200", "-f", "json").code == 0
