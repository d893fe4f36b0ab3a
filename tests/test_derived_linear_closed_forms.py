"""Linear closed forms derived from the loops (one assembly): regressions, each named after
the defect. References are written here independently: a linear closed form solved by
hand (s E + t F = r e^(i theta), Cramer), and the refusals solve already gives.
"""

from __future__ import annotations

import json
import math

import pytest

from derived_reference import XY

# s along x, t along y, closing on r e^(i theta): linear, one assembly,
# s = r cos(theta), t = r sin(theta)


@pytest.fixture
def xy(tmp_path):
    path = tmp_path / "xy.toml"
    path.write_text(XY)
    return path


@pytest.mark.parametrize("engine", ["--batch", "--no-batch"])
def test_sweep_of_a_linear_closed_form_labels_its_one_assembly_as_solve_does(cli, xy, engine):
    """Defect: the sweep labelled every position of a linear closed form 'det+' (the sign of
    det J, the label of a mechanism with no closed form) where solve calls its one assembly
    'only'."""
    doc = json.loads(cli("solve", str(xy), "--format", "json").out)
    assert doc["branch"] == "only"
    run = cli("sweep", str(xy), "--step", "90", "--format", "json", engine)
    assert run.code == 0, run.err
    sweep = json.loads(run.out)
    assert sweep["branch"] == "only"
    for p in sweep["positions"]:
        assert p["status"] == "converged" and p["branch"] == "only"
        th = math.radians(p["input"])
        assert p["solution"]["s"] == pytest.approx(50 * math.cos(th), abs=1e-12)
        assert p["solution"]["t"] == pytest.approx(50 * math.sin(th), abs=1e-12)


@pytest.mark.parametrize("text", ["garbage", "+", "open"])
def test_scan_refuses_a_branch_of_a_linear_closed_form_as_solve_does(cli, xy, text):
    """Defect: the scan took any --branch text for a closed form with no two-way step
    (read_branch has nothing to check against) and printed 'branch: garbage' over the
    designs; solve and sweep refuse it: there is nothing to choose."""
    run = cli("scan", str(xy), "--vary", "r=20:60:2", "--step", "90", "--branch", text)
    assert run.code == 2 and run.out == ""
    assert run.err == (f"error: --branch has nothing to choose: {xy} has one assembly "
                       "(its closed form is linear)\n")
    solve = cli("solve", str(xy), "--branch", text)
    assert solve.code == 2 and solve.err == run.err


def test_old_closed_form_module_names_only_what_it_has_and_keeps_no_branch_rule():
    """Defect: closed_form kept branch_rule (a second home of the open/crossed rule, keyed
    on the old closed_form key, that no engine calls any more) and its docstring sent the
    reader to feasible_arcs, which is gone. Every :func: it names must exist, and the
    branch names come from the derivation alone."""
    import re

    from linkage.problems import closed_form

    named = re.findall(r":func:`~?\.?([A-Za-z_][A-Za-z_0-9.]*)`", closed_form.__doc__ or "")
    for name in named:
        if "." not in name:
            assert hasattr(closed_form, name), name
    assert not hasattr(closed_form, "branch_rule")
    assert not hasattr(closed_form, "feasible_arcs")


@pytest.mark.parametrize("text", ["", "+-+", "\u00e9", "sideways", "open/open"])
def test_solve_does_not_call_a_text_that_is_no_branch_an_assembly_missing_here(cli, text):
    """Defect: solve answered any text it could not read (an empty --branch, '+-+' on a
    one-step four-bar, a unicode word) with "no such assembly at theta2 = 30 deg", as if
    it might assemble elsewhere; the crank-rocker has exactly the branches open and
    crossed (+ and -) and assembles at every crank angle (Grashof: 40 + 120 <= 100 + 80)."""
    from pathlib import Path

    path = Path(__file__).resolve().parent.parent / "sample_inputs" / "crank_rocker.toml"
    run = cli("solve", str(path), "--branch", text)
    assert run.code == 2 and run.out == "" and len(run.err.splitlines()) == 1
    assert run.err.startswith(f"error: --branch {text!r} is not a branch of this mechanism")
    assert "no such assembly" not in run.err
    for word in ("open", "crossed", "+", "-"):
        assert word in run.err
    for ok in ("open", "crossed", "+", "-"):
        assert cli("solve", str(path), "--branch", ok).code == 0


# two slides along x (s, and t at angle alpha) closing on r e^(i theta): with alpha = 0
# they are parallel, and at theta = 0 every s with t = r - s closes the loop
SLIDES = XY.replace('{ length = "t", angle = 90 }', '{ length = "t", angle = "alpha" }').replace(
    'r = { value = 50, unit = "mm" }', 'r = { value = 50, unit = "mm" }\nalpha = { value = 0, unit = "deg" }')


def test_parallel_slides_along_the_known_vectors_are_a_change_point_not_unassemblable(cli, tmp_path):
    """Defect: two_lengths returned None ("cannot be assembled") for parallel slides even
    where the known vectors lie along them and every s (with t = r - s) closes the loop;
    solve's JSON reference was {} beside a converged Newton answer. It is a change point:
    Indeterminate, reference None; off the line there is still no solution."""
    from linkage.kinematics.loading import load
    from linkage.problems.derive import Indeterminate

    path = tmp_path / "slides.toml"
    path.write_text(SLIDES)
    m = load(path)
    assert m.derivation.complete and not m.derivation.two_way
    with pytest.raises(Indeterminate):
        m.derivation.solve(0.0, ())
    assert m.derivation.solve(math.radians(30), ()) is None  # r sin(30) = 25 off the line
    doc = json.loads(cli("solve", str(path), "--set", "theta=0", "--format", "json").out)
    assert doc["reference"] is None
    s, t = doc["solution"]["s"], doc["solution"]["t"]
    assert s + t == pytest.approx(50.0, abs=1e-6)  # Newton's answer is one of them
    # off the line the closed form has no assembly ({}): the command line refuses it (exit 2)
    assert m.with_values({"theta": 30}, {}).problem().reference() == {}
    run = cli("solve", str(path), "--set", "theta=30", "--format", "json")
    assert run.code == 2 and "cannot be assembled at theta = 30" in run.err and run.out == ""
