"""Change-point four-bars (s + l = p + q): where the open and crossed assemblies meet (all
four joints collinear), a sweep starts on the file's assembly, keeps its branch by its
signs through the meeting, flags the positions whose branch is a matter of rounding, and a
scan of such designs gives each design's own sweep. References: the two circle
intersections at 40 digits (mpmath), and the collinear pose by hand."""

from __future__ import annotations

import math
from pathlib import Path

import mpmath as mp
import numpy as np
import pytest

import linkage
from linkage.kinematics.loading import load
from linkage.kinematics.pose import file_branch
from linkage.kinematics.stepwise import MEETS_NOTE

SAMPLES = Path(__file__).resolve().parent.parent / "sample_inputs"
CRANK_ROCKER = SAMPLES / "crank_rocker.toml"
GRID = {"r2": (20.0, 60.0, 9), "r4": (40.0, 80.0, 9)}
"""r1 = 100, r3 = 120: every r4 = r2 + 20 is a change point (r2 + 120 = 100 + r4), folded at
theta2 = 0 (A, B, O4 collinear, B beyond O4); r2 = 60, r4 = 40 is one too (40 + 120 =
100 + 60), folded at theta2 = 180."""
CYCLE = [float(k) for k in range(360)]  # the scan's default driver values
RANGE_TOL = 1e-9  # deg: the closed form and Newton agree to a few ulps off the change point


def _design(r2: float, r4: float):
    return load(CRANK_ROCKER).with_values({"r2": r2, "r4": r4}, {})


def _reference(r2: float, r4: float, theta2_deg: str) -> dict[str, tuple[mp.mpf, mp.mpf]]:
    """Both assemblies (theta3, theta4 in deg) at 40 digits, named by the open/crossed rule
    written out: open where sin(theta4 - theta3) > 0. B is where the circle about A
    (radius r3) meets the circle about O4 (radius r4)."""
    mp.mp.dps = 40
    r1, r3 = mp.mpf(100), mp.mpf(120)
    t2 = mp.radians(mp.mpf(theta2_deg))
    ax, ay = mp.mpf(r2) * mp.cos(t2), mp.mpf(r2) * mp.sin(t2)
    dx, dy = r1 - ax, -ay
    d = mp.sqrt(dx * dx + dy * dy)
    a = (r3 * r3 - mp.mpf(r4) ** 2 + d * d) / (2 * d)
    h = mp.sqrt(r3 * r3 - a * a)
    out = {}
    for s in (1, -1):
        bx = ax + (a * dx - s * h * dy) / d
        by = ay + (a * dy + s * h * dx) / d
        t3 = mp.atan2(by - ay, bx - ax)
        t4 = mp.atan2(by, bx - r1)
        out["open" if mp.sin(t4 - t3) > 0 else "crossed"] = (mp.degrees(t3), mp.degrees(t4))
    return out


def _gap(a: float, b: mp.mpf) -> float:
    return abs(float(mp.mpf(a) - b))


def test_change_point_four_bar_is_swept_on_the_files_assembly():
    """The finding's command: the file's pose (theta2 = 30) is open, so the whole cycle is;
    the change point (theta2 = 0 and 360) is the collinear pose, theta3 = theta4 = 0 (by
    hand: A = (40, 0), O4 = (100, 0), B = (160, 0)), flagged as where the assemblies meet."""
    m = _design(40.0, 60.0)
    assert file_branch(m) == "+"
    result = linkage.sweep(m, [float(k) for k in range(361)])
    assert result.branch == "open"
    assert {p.branch for p in result.positions} == {"open"}
    assert result.meetings == (0.0, 360.0)
    for p in (result.positions[0], result.positions[-1]):
        assert abs(p.solution["theta3"]) <= 1e-12 and abs(p.solution["theta4"]) <= 1e-12
        assert MEETS_NOTE in p.note
    for p in result.positions[1:-1]:
        assert MEETS_NOTE not in p.note
        ref = _reference(40.0, 60.0, repr(p.input))["open"]
        assert _gap(p.solution["theta3"], ref[0]) <= 1e-9 and _gap(p.solution["theta4"], ref[1]) <= 1e-9


def test_change_point_sweep_says_where_the_branch_is_a_matter_of_rounding(tmp_path):
    from typer.testing import CliRunner

    from linkage.cli import app

    out = CliRunner().invoke(app, ["sweep", str(CRANK_ROCKER), "--set", "r2=40", "--set", "r4=60"])
    assert out.exit_code == 0, out.output
    assert "branch: open" in out.output
    assert "assemblies meet (to rounding" in out.output and "at: 0 deg, 360 deg" in out.output


@pytest.mark.parametrize("branch", ["open", "crossed"])
def test_change_point_within_1e_9_deg_on_both_branches(branch):
    """Through the change point on either branch, by its signs: off it every position is
    the 40-digit reference of its branch to 1e-9 deg and unflagged; within 1e-9 deg of it
    the two assemblies are 1.5e-9 deg apart, below what the loops can tell (their residuals
    differ by (1e-11)^2 of the size), so the position is flagged and is the meeting's
    configuration: within 1e-8 deg of both references."""
    m = _design(40.0, 60.0)
    values = [-2.0, -1.0, -1e-9, 0.0, 1e-9, 1.0, 2.0]
    result = linkage.sweep(m, values, branch=branch)
    # by its signs: + is open for theta2 > 0 and open for theta2 < 0 too (the name follows
    # the sign for a crank-driven loop), so the branch is one name throughout
    assert {p.status for p in result.positions} == {"converged"}
    assert result.meetings == (-1e-9, 0.0, 1e-9)
    for p in result.positions:
        refs = _reference(40.0, 60.0, repr(p.input))
        assert p.branch == branch
        if p.input in result.meetings:
            assert MEETS_NOTE in p.note
            for ref in refs.values():
                assert _gap(p.solution["theta3"], ref[0]) <= 1e-8
                assert _gap(p.solution["theta4"], ref[1]) <= 1e-8
        else:
            assert MEETS_NOTE not in p.note
            ref = refs[branch]
            assert _gap(p.solution["theta3"], ref[0]) <= 1e-9 and _gap(p.solution["theta4"], ref[1]) <= 1e-9
    # the references themselves: distinct off the change point, 1.5e-9 deg apart at 1e-9 deg
    near = _reference(40.0, 60.0, "1e-9")
    assert 1e-9 < _gap(float(near["open"][0]), near["crossed"][0]) < 2e-9


def _scan_and_sweeps(branch: str | None):
    cols = linkage.scan_designs(str(CRANK_ROCKER), GRID, branch=branch)
    change = np.flatnonzero(cols["grashof"] == "change point")
    out = []
    for i in change:
        m = _design(float(cols["r2"][i]), float(cols["r4"][i]))
        out.append((i, m, linkage.sweep(m, CYCLE, branch=branch, batch=False)))
    return cols, out


def _ranges_agree(cols, i, sweep) -> None:
    # the flag: the positions whose branch is a matter of rounding, as the sweep lists them
    assert cols["meetings"][i] == len(sweep.meetings)
    solved = [p for p in sweep.positions if p.status == "converged"]
    assert cols["solved_fraction"][i] == pytest.approx(len(solved) / len(CYCLE), abs=0)
    for u in ("theta3", "theta4"):
        values = [p.solution[u] for p in solved]
        assert abs(cols[f"{u}_min"][i] - min(values)) <= RANGE_TOL, u
        assert abs(cols[f"{u}_max"][i] - max(values)) <= RANGE_TOL, u


def test_change_point_designs_in_a_scan_equal_their_own_sweeps():
    """Every change-point design of the grid whose own pose assembles (theta2 = 30: its
    sweep follows that pose's branch, the scan the file's, both open) gives, in the scan,
    its own sweep's solved fraction and ranges. The one whose pose does not assemble
    (r2 = 60, r4 = 40: a rocker-crank, theta2 in [53.1, 306.9]) is swept from its guess's
    nearest assembly, a different rule; with the branch named, it agrees too (below)."""
    cols, swept = _scan_and_sweeps(None)
    assert len(swept) == 10
    # no other design of the grid has a position where its assemblies meet
    assert (cols["meetings"][cols["grashof"] != "change point"] == 0).all()
    compared = 0
    for i, m, sweep in swept:
        if file_branch(m) is None:
            assert (cols["r2"][i], cols["r4"][i]) == (60.0, 40.0)
            continue
        assert sweep.branch == "open"
        # the change point (theta2 = 0) is flagged, and the sweep follows open across it
        assert sweep.meetings == (0.0,)
        _ranges_agree(cols, i, sweep)
        compared += 1
    assert compared == 9


@pytest.mark.parametrize("branch", ["open", "crossed"])
def test_change_point_designs_in_a_scan_equal_their_own_sweeps_on_a_named_branch(branch):
    """Given the branch by name, every change-point design of the grid (the one folded at
    theta2 = 180 too): the scan's name is read where the assemblies do not meet, as the
    sweep's (at theta2 = 0 both are one configuration, named by rounding)."""
    cols, swept = _scan_and_sweeps(branch)
    for i, _m, sweep in swept:
        assert {p.branch for p in sweep.positions} - {None} == {branch}
        assert len(sweep.meetings) == 1  # 0 deg, or 180 deg for r2 = 60, r4 = 40
        _ranges_agree(cols, i, sweep)


def test_change_point_meets_rule_and_its_numpy_twin_agree():
    """Derivation.meets and meets_np give the same verdicts over a cycle through the
    change point, including 1e-9 deg either side of it."""
    m = _design(40.0, 60.0)
    d = m.derivation
    drivers = np.radians(np.array([-1.0, -1e-9, 0.0, 1e-9, 1e-3, 1.0, 90.0, 180.0, 360.0]))
    for signs in d.branches:
        q, ok = d.solve_np(drivers, signs)
        assert ok.all()
        twin = d.meets_np(q, drivers)[0]
        scalar = [d.meets([float(c[k]) for c in q], float(drivers[k]))[0] for k in range(len(drivers))]
        assert list(twin) == scalar
        assert scalar == [False, True, True, True, False, False, False, False, True]
    assert math.isclose(d.margins(math.radians(1e-3), (1.0,))[0], 8.46e-11, rel_tol=1e-2)


def test_change_point_batch_sweep_flags_what_the_one_at_a_time_sweep_flags():
    """The numpy batch engine: the same branch, the same meetings, the same positions (to
    1e-9 deg) as the one-at-a-time engine over the finding's cycle."""
    m = _design(40.0, 60.0)
    values = [float(k) for k in range(361)]
    one = linkage.sweep(m, values, batch=False)
    many = linkage.sweep(m, values, batch=True)
    assert many.branch == one.branch == "open"
    assert many.meetings == one.meetings == (0.0, 360.0)
    for u in ("theta3", "theta4"):
        assert np.max(np.abs(np.asarray(many.column(u), float) - np.asarray(one.column(u), float))) <= 1e-9


def test_change_point_as_the_files_pose_is_flagged_not_picked_silently():
    """A file drawn at its change point (theta2 = 0) names no branch: its guesses solve to
    one by rounding. The sweep follows that one and says so (branch_note), the scan's header
    too; with --branch nothing is flagged. Off the pose the note is absent."""
    from typer.testing import CliRunner

    from linkage.cli import app
    from linkage.kinematics.pose import POSE_MEETS, pose_meets

    at_pose = load(CRANK_ROCKER).with_values({"r2": 40.0, "r4": 60.0, "theta2": 0.0}, {})
    assert pose_meets(at_pose) and not pose_meets(_design(40.0, 60.0))
    values = [float(k) for k in range(0, 361, 10)]
    assert linkage.sweep(at_pose, values).branch_note == POSE_MEETS
    assert linkage.sweep(at_pose, values, branch="crossed").branch_note == ""
    assert linkage.sweep(_design(40.0, 60.0), values).branch_note == ""
    args = ["scan", str(CRANK_ROCKER), "--set", "r4=60", "--set", "theta2=0", "--vary", "r2=39:41:3",
            "-f", "plain"]
    out = CliRunner().invoke(app, args)
    assert out.exit_code == 0, out.output
    assert f"branch: {POSE_MEETS}" in out.output
    out = CliRunner().invoke(app, [*args, "--branch", "open"])
    assert out.exit_code == 0 and POSE_MEETS not in out.output


@pytest.mark.parametrize("branch", ["open", "crossed"])
def test_change_point_solves_on_either_named_branch(branch):
    """At the change point the one configuration is both assemblies: solve --branch takes
    either name (it said "no such assembly" for the one rounding did not give it), and the
    answer is the collinear pose, theta3 = theta4 = 0 (by hand)."""
    from typer.testing import CliRunner

    from linkage.cli import app

    args = ["solve", str(CRANK_ROCKER), "--set", "r2=40", "--set", "r4=60", "--set", "theta2=0",
            "--branch", branch, "-f", "json"]
    out = CliRunner().invoke(app, args)
    assert out.exit_code == 0, out.output
    named = _design(40.0, 60.0).derivation.named_solutions(0.0)
    assert set(named) == {"open", "crossed"} and named["open"] == named["crossed"]
    assert named["open"][1] == [0.0, 0.0]


@pytest.mark.parametrize("text", ["open", "crossed", "+", "-"])
def test_change_point_on_branch_twin_reads_meetings_as_its_scalar_rule(text):
    """on_branch_np (which reads a step's meeting only where a sign or word differs) gives
    on_branch's verdict position by position on both assemblies of a change-point design
    through its cycle, the collinear pose (theta2 = 0, where they meet) included: there
    either branch holds; elsewhere only the wanted one."""
    from linkage.problems.derive import read_branch

    m = _design(40.0, 60.0)
    d = m.derivation
    want = read_branch(d, text)
    drivers = np.radians(np.array([*CYCLE, 360.0]))
    interiors = []
    for signs in d.branches:
        q, ok = d.solve_np(drivers, signs)
        assert ok.all()
        twin = np.broadcast_to(d.on_branch_np(q, drivers, want), drivers.shape)
        scalar = [d.on_branch([float(c[k]) for c in q], float(drivers[k]), want) for k in range(len(drivers))]
        assert list(twin) == scalar
        assert twin[0] and twin[-1]  # the meeting: on either branch
        interiors.append(bool(twin[1:-1].all()) if twin[1:-1].all() or not twin[1:-1].any() else None)
    assert sorted(interiors) == [False, True]  # elsewhere one assembly is the branch, the other not


@pytest.mark.parametrize("scale", [1e-6, 1.0, 1e3])
def test_a_rhombus_sweep_through_its_indeterminate_pose_is_no_internal_error(tmp_path, scale):
    """Every link equal (a rhombus, s + l = p + q): at theta2 = 0 the crank pin A lies on O4,
    so B may be anywhere on its circle and the closed form has no one answer there
    (problems.assembly.Indeterminate): every theta3 = theta4 closes the loop. The sweep
    reports a root of that family there, flagged as a meeting, and the parallelogram
    assembly the file draws elsewhere (theta3 = 0, theta4 = theta2, by hand). Before, the
    meeting's exact closed form raised (an internal error from the command), and at 1e3 the
    position was failed: the closed form's path tried no Newton step where it was
    indeterminate."""
    from typer.testing import CliRunner

    from linkage.cli import app

    path = tmp_path / "rhombus.toml"
    r = f"{scale:g}"
    made = CliRunner().invoke(app, ["new", "fourbar", "--links", r, r, r, r, "-o", str(path)])
    assert made.exit_code == 0, made.output
    values = [0.0, 45.0, 90.0, 135.0]
    result = linkage.sweep(linkage.load_mechanism(str(path)), values)
    assert [p.status for p in result.positions] == ["converged"] * 4
    for p in result.positions:
        t3, t4 = p.solution["theta_coupler"], p.solution["theta_rocker"]
        if p.input == 0.0:
            assert abs(t3 - t4) <= 1e-9 and MEETS_NOTE in p.note
        else:
            assert abs(t3) <= 1e-9 and abs(t4 - p.input) <= 1e-9
    assert result.meetings == (0.0,)
    run = CliRunner().invoke(app, ["sweep", str(path), "--from", "0", "--to", "90", "--step", "45"])
    assert run.exit_code == 0 and "internal error" not in run.output


def test_sweep_through_a_change_point_where_the_closed_form_is_indeterminate():
    """A rhombus four-bar (r1 = r2 = r3 = r4) at theta2 = 0 has its crank pin on O4: the
    coupler and rocker turn about one point, and the closed form's circles coincide
    (problems.assembly.Indeterminate). The sweep through it is an answer, not an internal
    error: each position's joints checked by hand (|AB| = r3, |O4 B| = r4), the meeting flagged."""
    m = load(CRANK_ROCKER).with_values({"r2": 100.0, "r3": 100.0, "r4": 100.0}, {})
    result = linkage.sweep(m, [0.0, 45.0, 90.0])
    assert [p.status for p in result.positions] == ["converged"] * 3
    for p in result.positions:
        t2, t3, t4 = (math.radians(v) for v in (p.input, p.solution["theta3"], p.solution["theta4"]))
        a = (100 * math.cos(t2), 100 * math.sin(t2))
        b_from_a = (a[0] + 100 * math.cos(t3), a[1] + 100 * math.sin(t3))
        b_from_o4 = (100 + 100 * math.cos(t4), 100 * math.sin(t4))
        assert math.dist(b_from_a, b_from_o4) <= 1e-9
    assert MEETS_NOTE in result.positions[0].note
